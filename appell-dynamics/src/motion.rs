//! The motion at one instant: q̇, u̇ and q̈ of every coordinate, the
//! dependent ones included.
//!
//! u̇ comes from [`Model::rhs`] and q̇ from [`Model::driven_coordinate_rates`]
//! (which is [`Model::coordinate_rates`] unless the model has driven
//! coordinates); q̈ is the exact time derivative of q̇ = C(q, t) u + c(q, t)
//! along the motion (eq. 31 differentiated: C u̇ + Ċ u + ċ), from one
//! evaluation of `driven_coordinate_rates` in [`Dual64`] numbers seeded with
//! ṫ = 1, q̇, u̇ and, for the commands of driven coordinates, their
//! companion inputs (`x` changes at `x_rate`, `x_rate` at `x_accel`).

use appell_core::dynamic::DynModel;
use appell_core::{check_len, Model, ModelError, ModelInfo};
use num_dual::Dual64;

/// One instant of a motion: the time and every coordinate, what the
/// pictures of `animate` draw and a hybrid run samples.
///
/// ```
/// use appell_dynamics::motion::Frame;
/// let f = Frame { t: 0.5, q: vec![0.1, -0.2] };
/// assert_eq!(f.q.len(), 2);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// The time.
    pub t: f64,
    /// Every coordinate, in [`ModelInfo::coordinates`] order.
    pub q: Vec<f64>,
}

/// The rates of the motion at one state, from [`rates`].
#[derive(Clone, Debug, PartialEq)]
pub struct Rates {
    /// q̇ of every coordinate, in [`appell_core::ModelInfo::coordinates`] order.
    pub qdot: Vec<f64>,
    /// u̇ of the privileged speeds, in [`appell_core::ModelInfo::speeds`] order.
    pub udot: Vec<f64>,
    /// q̈ of every coordinate, the dependent ones included.
    pub qddot: Vec<f64>,
}

/// q̇, u̇ and q̈ at time `t`, coordinates `q` (all of them; the ignorable
/// ones may be 0), privileged speeds `u` and `inputs`.
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
/// use appell_dynamics::motion::rates;
///
/// // A mass of 2 kg rising at 1.5 m/s, pushed up with 5 N.
/// let r = rates(&Drop { m: 2.0, g: 9.81 }, 0.0, &[3.0], &[1.5], &[5.0]).unwrap();
/// assert_eq!(r.qdot, [1.5]);
/// assert!((r.udot[0] - (2.5 - 9.81)).abs() < 1e-12);
/// assert_eq!(r.qddot, r.udot);
/// ```
pub fn rates<M: Model>(
    model: &M,
    t: f64,
    q: &[f64],
    u: &[f64],
    inputs: &[f64],
) -> Result<Rates, ModelError> {
    let (qdot, udot) = first_rates(model, t, q, u, inputs, "motion arguments")?;
    let seeded = |x: &[f64], dx: &[f64]| -> Vec<Dual64> {
        x.iter().zip(dx).map(|(&v, &d)| Dual64::new(v, d)).collect()
    };
    let (td, qd, ud) = (Dual64::new(t, 1.0), seeded(q, &qdot), seeded(u, &udot));
    let id = seeded_inputs(M::info(), inputs);
    let mut rates = vec![Dual64::from(0.0); q.len()];
    model.driven_coordinate_rates(td, &qd, &ud, &id, &mut rates)?;
    let qddot: Vec<f64> = rates.iter().map(|r| r.eps).collect();
    if qddot.iter().all(|x| x.is_finite()) {
        Ok(Rates { qdot, udot, qddot })
    } else {
        Err(ModelError::NonFinite {
            what: "coordinate accelerations",
        })
    }
}

/// q̇ and u̇ at a full state, its arguments checked first (`what` names
/// them in the non-finite error).
pub(crate) fn first_rates<K: DynModel + ?Sized>(
    model: &K,
    t: f64,
    q: &[f64],
    u: &[f64],
    inputs: &[f64],
    what: &'static str,
) -> Result<(Vec<f64>, Vec<f64>), ModelError> {
    let info = model.dyn_info();
    check_len("q", q, info.coordinates.len())?;
    check_len("u", u, info.speeds.len())?;
    check_len("inputs", inputs, info.inputs.len())?;
    let finite = |xs: &[f64]| xs.iter().all(|x| x.is_finite());
    if !(t.is_finite() && finite(q) && finite(u) && finite(inputs)) {
        return Err(ModelError::NonFinite { what });
    }
    let mut state = Vec::with_capacity(info.state_len());
    for name in info.retained {
        let i = info.coordinate_index(name).ok_or(ModelError::NonFinite {
            what: "retained coordinate",
        })?;
        state.push(q[i]);
    }
    state.extend_from_slice(u);
    let mut dstate = vec![0.0; info.state_len()];
    model.dyn_rhs(t, &state, inputs, &mut dstate)?;
    let udot = dstate[info.retained.len()..].to_vec();
    let mut qdot = vec![0.0; q.len()];
    model.dyn_driven_coordinate_rates(t, q, u, inputs, &mut qdot)?;
    Ok((qdot, udot))
}

/// The inputs as [`Dual64`] numbers seeded with their time derivatives
/// where the model knows them: a driven coordinate's command `x` changes
/// at its companion input `x_rate`, and `x_rate` at `x_accel` (when the
/// model has it, for a holonomic drive). Every other input is held (its
/// derivative is 0), as the integrators hold it.
pub(crate) fn seeded_inputs(info: &ModelInfo, inputs: &[f64]) -> Vec<Dual64> {
    let value = |name: &str| {
        info.inputs
            .iter()
            .position(|i| *i == name)
            .and_then(|k| inputs.get(k).copied())
    };
    info.inputs
        .iter()
        .zip(inputs)
        .map(|(name, &v)| {
            let rate = value(&format!("{name}_rate")).or_else(|| {
                name.strip_suffix("_rate")
                    .and_then(|base| value(&format!("{base}_accel")))
            });
            Dual64::new(v, rate.unwrap_or(0.0))
        })
        .collect()
}
