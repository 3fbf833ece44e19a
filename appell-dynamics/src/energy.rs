//! Energies along the motion: the kinetic energy T, the potential V of the
//! `gravity` effect, their rate d(T + V)/dt, and the power of the inputs.
//!
//! The rate is exact, not a finite difference: T + V is evaluated once in
//! [`Dual64`] numbers seeded with the rates of the motion (q̇ from
//! [`Model::coordinate_rates`], u̇ from [`Model::rhs`], ṫ = 1). For a model
//! whose only non-conservative loads are its inputs the rate equals
//! [`Model::input_power`]; the difference measures the power of every
//! other load left out of V (friction, damping, a motor without an input),
//! and on a scene it shows what the chosen effects put in.
//!
//! A model with driven coordinates (constraints that read inputs) has its
//! kinetic energy from [`Model::driven_kinetic_energy`] at the inputs, and
//! the commands change along the motion at their companion inputs (`x` at
//! `x_rate`, `x_rate` at `x_accel`); the rate then also contains the power
//! of the drives, each driving row's multiplier (the
//! [`contact_forces`](crate::constraint_forces::contact_forces) output)
//! times its coordinate's rate, which [`Model::input_power`] leaves out.

use crate::motion::{first_rates, seeded_inputs};
use appell_core::dynamic::DynModel;
use appell_core::{Model, ModelError};
use num_dual::Dual64;

/// The energies at one state, from [`energies`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Energies {
    /// Kinetic energy T.
    pub kinetic: f64,
    /// Potential energy V of the `gravity` effect ([`Model::potential_energy`]).
    pub potential: f64,
    /// d(T + V)/dt along the motion.
    pub rate: f64,
    /// Power of the loads that depend on the inputs ([`Model::input_power`]).
    pub input_power: f64,
}

/// T, V, d(T + V)/dt and the input power at time `t`, coordinates `q` (all
/// of them, as [`Model::kinetic_energy`] takes them; the ignorable ones may
/// be 0), privileged speeds `u` and `inputs`.
///
/// Errors: wrong lengths ([`ModelError::Length`]), non-finite arguments or
/// results ([`ModelError::NonFinite`]), and any error of the model (a
/// singular configuration, say).
///
/// ```
/// # use appell_core::{check_len, BodyInfo, Model, ModelError, ModelInfo, OpCounts, Scalar};
/// # struct Drop { m: f64, g: f64 }
/// # static INFO: ModelInfo = ModelInfo {
/// #     name: "Drop", parameters: &["m", "g"], coordinates: &["z"], speeds: &["z"],
/// #     dependent: &[], cyclic: &[], ignorable: &[], retained: &["z"], inputs: &["f"],
/// #     effects: &["gravity", "push"], outputs: &[], row_sources: &[], contacts: &[], holonomic: 0, constraints: 0,
/// #     bodies: &[BodyInfo { name: "P", rigid: false }], force_points: 2, torques: 0,
/// #     form: "closed form", symbolic_elimination: true, rhs_ops: OpCounts { add: 0, mul: 0, div: 0, calls: 0, total: 0 }, jacobian: None, equations: "",
/// # };
/// # fn unused() -> Result<(), ModelError> { Err(ModelError::NonFinite { what: "unused" }) }
/// # impl Model for Drop {
/// #     type Prepared<T: Scalar> = ();
/// #     fn info() -> &'static ModelInfo { &INFO }
/// #     fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> {
/// #         check_len("out", out, 2)?; out.copy_from_slice(&[self.m, self.g]); Ok(())
/// #     }
/// #     fn set_parameter(&mut self, _: &str, _: f64) -> bool { false }
/// #     fn prepare<T: Scalar>(&self) {}
/// #     fn rhs<T: Scalar>(&self, _: &(), _: T, s: &[T], i: &[T], ds: &mut [T]) -> Result<(), ModelError> {
/// #         check_len("state", s, 2)?; check_len("inputs", i, 1)?; check_len("dstate", ds, 2)?;
/// #         ds[0] = s[1];
/// #         ds[1] = i[0] / T::from_f64(self.m) - T::from_f64(self.g);
/// #         Ok(())
/// #     }
/// #     fn coordinate_rates<T: Scalar>(&self, _: T, q: &[T], u: &[T], qd: &mut [T]) -> Result<(), ModelError> {
/// #         check_len("q", q, 1)?; check_len("u", u, 1)?; check_len("qdot", qd, 1)?; qd[0] = u[0]; Ok(())
/// #     }
/// #     fn potential_energy<T: Scalar>(&self, _: T, q: &[T]) -> Result<T, ModelError> {
/// #         Ok(T::from_f64(self.m * self.g) * q[0])
/// #     }
/// #     fn input_power<T: Scalar>(&self, _: T, _: &[T], u: &[T], i: &[T]) -> Result<T, ModelError> {
/// #         Ok(i[0] * u[0])
/// #     }
/// #     fn kinetic_energy<T: Scalar>(&self, _: T, _: &[T], u: &[T]) -> Result<T, ModelError> {
/// #         Ok(T::from_f64(self.m / 2.0) * u[0] * u[0])
/// #     }
/// #     fn mass_matrix_and_forcing<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn speed_transform<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn constraint_residuals<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn mass_properties(&self, _: &mut [f64], _: &mut [[f64; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn body_poses<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn constraint_rows<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn load_geometry<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn load_values<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [[T; 3]], _: &mut [[T; 3]]) -> Result<(), ModelError> { unused() }
/// # }
/// use appell_dynamics::energy::energies;
///
/// // A mass of 2 kg at height 3 m, rising at 1.5 m/s, pushed up with 5 N.
/// let e = energies(&Drop { m: 2.0, g: 9.81 }, 0.0, &[3.0], &[1.5], &[5.0]).unwrap();
/// assert_eq!(e.kinetic, 2.25);
/// assert!((e.potential - 58.86).abs() < 1e-12);
/// // Gravity is in V, so the energy grows at the push's power, 5 N × 1.5 m/s.
/// assert!((e.rate - 7.5).abs() < 1e-12 && e.input_power == 7.5);
/// ```
pub fn energies<M: Model>(
    model: &M,
    t: f64,
    q: &[f64],
    u: &[f64],
    inputs: &[f64],
) -> Result<Energies, ModelError> {
    energies_dyn(model, t, q, u, inputs)
}

/// [`energies`] of any [`DynModel`] (compiled once for `dyn DynModel`).
// Shared with the crates built on this one; not part of the API.
#[doc(hidden)]
pub fn energies_dyn<K: DynModel + ?Sized>(
    model: &K,
    t: f64,
    q: &[f64],
    u: &[f64],
    inputs: &[f64],
) -> Result<Energies, ModelError> {
    let (qdot, udot) = first_rates(model, t, q, u, inputs, "energy arguments")?;

    let seeded = |x: &[f64], dx: &[f64]| -> Vec<Dual64> {
        x.iter().zip(dx).map(|(&v, &d)| Dual64::new(v, d)).collect()
    };
    let (td, qd, ud) = (Dual64::new(t, 1.0), seeded(q, &qdot), seeded(u, &udot));
    let id = seeded_inputs(model.dyn_info(), inputs);
    let kinetic = model.dyn_driven_kinetic_energy_dual(td, &qd, &ud, &id)?;
    let potential = model.dyn_potential_energy_dual(td, &qd)?;
    let input_power = model.dyn_input_power(t, q, u, inputs)?;
    let e = Energies {
        kinetic: kinetic.re,
        potential: potential.re,
        rate: kinetic.eps + potential.eps,
        input_power,
    };
    if [e.kinetic, e.potential, e.rate, e.input_power]
        .iter()
        .all(|x| x.is_finite())
    {
        Ok(e)
    } else {
        Err(ModelError::NonFinite { what: "energy" })
    }
}
