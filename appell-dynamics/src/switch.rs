//! The state map between two scenes of one model (or two models of the same
//! coordinates) at a switch: where the physics changes, a constraint is
//! released or imposed, and the motion goes on in the other scene's
//! privileged speeds.
//!
//! The configuration q does not jump. The coordinate rates do only where
//! the target scene has constraints the motion violates: then the map
//! applies the impulse those constraints need, Appell's equations in
//! impulsive form in the source scene's speeds u (Kane's equations of
//! impulsive motion): with q̇ = C u + c (eq. 31) and the target's rows
//! D q̇ + d = 0 (eq. 25) written in u as G u + g = 0, G = D C,
//! g = D c + d,
//!
//! M Δu = Gᵀ Λ,   G (u + Δu) + g = 0,
//!
//! so Λ = −(G M⁻¹ Gᵀ)⁺ (G u + g): the impulse that makes the least change of
//! kinetic energy (a perfectly plastic impact at the new constraints; rows
//! the source satisfies identically get none; nothing forbids a pulling
//! impulse, so a guard should switch only where the contact closes). The
//! target's speeds are then
//! read off q̇⁺ with its speed definitions u' = W q̇⁺ + w (eq. 54's W).
//! Releasing a constraint needs no impulse: q̇ and the kinetic energy are
//! the same on both sides of the switch.
//!
//! ```
//! # use appell_core::{check_len, Model, ModelError, ModelInfo, OpCounts, RowSource, Scalar};
//! # use appell_dynamics::switch::switch_state;
//! # // A particle in the plane, free (speeds x, y) or on a rail y = 0.
//! # macro_rules! particle {
//! #     ($name:ident, $speeds:expr, $rows:expr, $sources:expr) => {
//! # struct $name;
//! # impl Model for $name {
//! #     type Prepared<T: Scalar> = ();
//! #     fn info() -> &'static ModelInfo {
//! #         static INFO: ModelInfo = ModelInfo {
//! #             name: stringify!($name), parameters: &[], coordinates: &["x", "y"], speeds: $speeds,
//! #             dependent: &[], cyclic: &[], ignorable: &[], retained: &["x", "y"], inputs: &[],
//! #             effects: &[], outputs: &[], row_sources: $sources, contacts: &[], holonomic: 0, constraints: $rows,
//! #             bodies: &[], force_points: 0, torques: 0, form: "closed form", symbolic_elimination: true,
//! #             rhs_ops: OpCounts { add: 0, mul: 0, div: 0, calls: 0, total: 0 }, jacobian: None, equations: "",
//! #         };
//! #         &INFO
//! #     }
//! #     fn parameter_values(&self, _: &mut [f64]) -> Result<(), ModelError> { Ok(()) }
//! #     fn set_parameter(&mut self, _: &str, _: f64) -> bool { false }
//! #     fn prepare<T: Scalar>(&self) {}
//! #     fn rhs<T: Scalar>(&self, _: &(), _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { Ok(()) }
//! #     fn mass_matrix_and_forcing<T: Scalar>(&self, _: T, _: &[T], u: &[T], _: &[T], m: &mut [T], _: &mut [T]) -> Result<(), ModelError> {
//! #         for (k, x) in m.iter_mut().enumerate() { *x = if k % (u.len() + 1) == 0 { T::from_f64(2.0) } else { T::zero() }; }
//! #         Ok(())
//! #     }
//! #     fn speed_transform<T: Scalar>(&self, _: T, _: &[T], c: &mut [T], c0: &mut [T]) -> Result<(), ModelError> {
//! #         let l = c.len() / 2;
//! #         for (k, x) in c.iter_mut().enumerate() { *x = if k / l == k % l { T::one() } else { T::zero() }; }
//! #         c0.iter_mut().for_each(|x| *x = T::zero());
//! #         Ok(())
//! #     }
//! #     fn coordinate_rates<T: Scalar>(&self, _: T, _: &[T], u: &[T], qd: &mut [T]) -> Result<(), ModelError> {
//! #         qd[0] = u[0]; qd[1] = if u.len() == 2 { u[1] } else { T::zero() }; Ok(())
//! #     }
//! #     fn constraint_residuals<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { Ok(()) }
//! #     fn kinetic_energy<T: Scalar>(&self, _: T, _: &[T], u: &[T]) -> Result<T, ModelError> {
//! #         Ok(u.iter().fold(T::zero(), |s, &v| s + v * v))
//! #     }
//! #     fn mass_properties(&self, _: &mut [f64], _: &mut [[f64; 9]]) -> Result<(), ModelError> { Ok(()) }
//! #     fn body_poses<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { Ok(()) }
//! #     fn constraint_rows<T: Scalar>(&self, _: T, _: &[T], d: &mut [T], d0: &mut [T]) -> Result<(), ModelError> {
//! #         if d.len() == 2 { d[0] = T::zero(); d[1] = T::one(); d0[0] = T::zero(); }
//! #         Ok(())
//! #     }
//! #     fn load_geometry<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { Ok(()) }
//! #     fn load_values<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [[T; 3]], _: &mut [[T; 3]]) -> Result<(), ModelError> { Ok(()) }
//! # }
//! #     };
//! # }
//! # particle!(Free, &["x", "y"], 0, &[]);
//! # particle!(OnRail, &["x"], 1, &[RowSource::Holonomic { index: 0 }]);
//! // A particle of mass 2 moving at (3, −1) lands on the rail y = 0: the
//! // impulse takes its normal momentum, 2 N s, and 1 J of its 10 J.
//! let landed = switch_state(&Free, &OnRail, 0.0, &[0.0, 0.0], &[3.0, -1.0], &[], &[]).unwrap();
//! assert_eq!(landed.speeds, [3.0]);
//! assert!((landed.impulses[0] - 2.0).abs() < 1e-12);
//! assert!((landed.energy_lost() - 1.0).abs() < 1e-12);
//! // Leaving the rail changes nothing.
//! let left = switch_state(&OnRail, &Free, 0.0, &[0.0, 0.0], &[3.0], &[], &[]).unwrap();
//! assert_eq!((left.energy_lost(), left.impulses.len()), (0.0, 0));
//! assert_eq!(left.speeds, [3.0, 0.0]);
//! ```

use nalgebra::{DMatrix, DVector};

use appell_core::dynamic::DynModel;
use appell_core::{ModelError, ModelInfo};

/// Relative size below which the target's constraint residual counts as
/// satisfied (no impulse), and below which a singular value of G M⁻¹ Gᵀ
/// counts as zero (a row the source's motion satisfies identically).
const TOLERANCE: f64 = 1e-12;

/// The motion just after a switch, in the target's terms.
#[derive(Clone, Debug, PartialEq)]
pub struct Switched {
    /// Every coordinate after the switch: the same, but put back on the
    /// target's holonomic constraints where the event left them a
    /// round-off away (a foot a hair below the ground it lands on).
    pub q: Vec<f64>,
    /// The target's privileged speeds (its [`ModelInfo::speeds`] order).
    pub speeds: Vec<f64>,
    /// Every coordinate's rate after the switch.
    pub qdot: Vec<f64>,
    /// The impulse of each of the target's constraint rows (its
    /// [`ModelInfo::row_sources`] order), the multiplier of the row in
    /// impulsive form: empty when no impulse was needed.
    pub impulses: Vec<f64>,
    /// The source's kinetic energy before the switch.
    pub kinetic_before: f64,
    /// The target's kinetic energy after it.
    pub kinetic_after: f64,
}

impl Switched {
    /// The kinetic energy the switch dissipated (zero for a release).
    pub fn energy_lost(&self) -> f64 {
        self.kinetic_before - self.kinetic_after
    }
}

/// Why a switch could not be made.
#[derive(Clone, Debug, PartialEq)]
pub enum SwitchError {
    /// A model function failed (wrong lengths, a singular configuration).
    Model(ModelError),
    /// The two models do not have the same coordinates in the same order.
    CoordinatesDiffer,
    /// A coefficient of restitution outside [0, 1].
    InvalidRestitution(f64),
    /// No impulse in the source's speeds satisfies the target's
    /// constraints: the target constrains what the source holds fixed some
    /// other way. The largest residual left, relative to the rates.
    Unattainable {
        /// max |D q̇ + d| after the impulse, over max |q̇|.
        residual: f64,
    },
}

impl core::fmt::Display for SwitchError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            SwitchError::Model(e) => write!(f, "the switch failed: {e}"),
            SwitchError::InvalidRestitution(e) => {
                write!(f, "the coefficient of restitution must be in [0, 1], not {e}")
            }
            SwitchError::CoordinatesDiffer => {
                write!(f, "the two scenes do not have the same coordinates")
            }
            SwitchError::Unattainable { residual } => write!(
                f,
                "no impulse in the first scene's speeds satisfies the second scene's constraints (relative residual {residual:e})"
            ),
        }
    }
}

impl std::error::Error for SwitchError {}

impl From<ModelError> for SwitchError {
    fn from(e: ModelError) -> Self {
        SwitchError::Model(e)
    }
}

/// Maps the motion of `from` at time `t`, coordinates `q` (every one) and
/// privileged speeds `u`, to `to`'s privileged speeds, applying the impulse
/// `to`'s constraints need (see the module documentation). `inputs_from`
/// and `inputs_to` are each model's inputs (commands of driven
/// coordinates among them).
///
/// Errors: [`SwitchError::CoordinatesDiffer`], any model error, and
/// [`SwitchError::Unattainable`].
pub fn switch_state<A: DynModel + ?Sized, B: DynModel + ?Sized>(
    from: &A,
    to: &B,
    t: f64,
    q: &[f64],
    u: &[f64],
    inputs_from: &[f64],
    inputs_to: &[f64],
) -> Result<Switched, SwitchError> {
    let met = meet(from, to, t, q, u, inputs_from, inputs_to, 0.0)?;
    met.in_speeds_of(to, t, inputs_to)
}

/// An impact that leaves `from`'s scene as it is: the motion of `from`
/// meets the constraints of `contact` (a ball the ground) and rebounds with
/// Newton's coefficient of `restitution` e ∈ [0, 1]: the impulse makes
/// the contact rows' residual −e times what it was at impact, so e = 0 is
/// the plastic impact of [`switch_state`] and e = 1 keeps the kinetic
/// energy. The configuration is put on `contact`'s holonomic constraints;
/// the speeds returned are `from`'s.
///
/// Errors: as [`switch_state`], and a restitution outside [0, 1].
// switch_state's arguments (two scenes, each with its own inputs, at one t, q, u) plus the
// coefficient of restitution
#[allow(clippy::too_many_arguments)]
pub fn impact_state<A: DynModel + ?Sized, C: DynModel + ?Sized>(
    from: &A,
    contact: &C,
    t: f64,
    q: &[f64],
    u: &[f64],
    inputs_from: &[f64],
    inputs_contact: &[f64],
    restitution: f64,
) -> Result<Switched, SwitchError> {
    if !(0.0..=1.0).contains(&restitution) {
        return Err(SwitchError::InvalidRestitution(restitution));
    }
    let met = meet(
        from,
        contact,
        t,
        q,
        u,
        inputs_from,
        inputs_contact,
        restitution,
    )?;
    met.in_speeds_of(from, t, inputs_from)
}

/// The motion of `from` after it meets `contact`'s constraints: the
/// configuration settled on them, every coordinate's rate after the impulse
/// (none where the motion already satisfies them), the impulses, and the
/// kinetic energy before.
struct Met {
    q: Vec<f64>,
    qdot: Vec<f64>,
    impulses: Vec<f64>,
    kinetic_before: f64,
}

impl Met {
    /// The switch's result in `target`'s speeds.
    fn in_speeds_of<B: DynModel + ?Sized>(
        self,
        target: &B,
        t: f64,
        inputs: &[f64],
    ) -> Result<Switched, SwitchError> {
        let speeds = speeds_of(target, target.dyn_info(), t, &self.q, &self.qdot)?;
        let kinetic_after = target.dyn_driven_kinetic_energy(t, &self.q, &speeds, inputs)?;
        Ok(Switched {
            q: self.q,
            speeds,
            qdot: self.qdot,
            impulses: self.impulses,
            kinetic_before: self.kinetic_before,
            kinetic_after,
        })
    }
}

/// `from`'s motion meeting `contact`'s constraints with Newton's
/// coefficient `restitution`: after the impulse the rows' residual is −e
/// times what it was, checked.
// impact_state's arguments; switch_state shares this body and passes restitution 0
#[allow(clippy::too_many_arguments)]
fn meet<A: DynModel + ?Sized, C: DynModel + ?Sized>(
    from: &A,
    contact: &C,
    t: f64,
    q: &[f64],
    u: &[f64],
    inputs_from: &[f64],
    inputs_contact: &[f64],
    restitution: f64,
) -> Result<Met, SwitchError> {
    let (ia, ic) = (from.dyn_info(), contact.dyn_info());
    if ia.coordinates != ic.coordinates {
        return Err(SwitchError::CoordinatesDiffer);
    }
    let q = settle(contact, ic, t, q, inputs_contact)?;
    let mut qdot = vec![0.0; q.len()];
    from.dyn_driven_coordinate_rates(t, &q, u, inputs_from, &mut qdot)?;
    let kinetic_before = from.dyn_driven_kinetic_energy(t, &q, u, inputs_from)?;
    let (d, d0) = rows(contact, ic, t, &q, inputs_contact)?;
    let scale = qdot.iter().fold(f64::MIN_POSITIVE, |m, x| m.max(x.abs()));
    let residual = |v: &[f64]| &d * DVector::from_column_slice(v) + &d0;
    let before = residual(&qdot);
    let mut impulses = Vec::new();
    if ic.constraints > 0 && before.amax() / scale > TOLERANCE {
        let (after, lambda) = impulse(from, ia, t, &q, u, inputs_from, &d, &d0, restitution)?;
        let left = (residual(&after) + restitution * before).amax() / scale;
        if left > 1e3 * TOLERANCE {
            return Err(SwitchError::Unattainable { residual: left });
        }
        (qdot, impulses) = (after, lambda);
    }
    Ok(Met {
        q,
        qdot,
        impulses,
        kinetic_before,
    })
}

/// `q` moved onto `model`'s holonomic constraints h(q, t) = 0 by
/// Gauss–Newton steps along their rows of D (the least change of q): at
/// most a few, since the event leaves q within its tolerance of them. A q
/// far from them is an [`SwitchError::Unattainable`].
fn settle<B: DynModel + ?Sized>(
    model: &B,
    info: &ModelInfo,
    t: f64,
    q: &[f64],
    inputs: &[f64],
) -> Result<Vec<f64>, SwitchError> {
    let (n, h, m) = (info.coordinates.len(), info.holonomic, info.constraints);
    let mut q = q.to_vec();
    if h == 0 {
        return Ok(q);
    }
    let scale = q.iter().fold(1.0f64, |a, x| a.max(x.abs()));
    let (mut res, mut vel) = (vec![0.0; h], vec![0.0; m]);
    for _ in 0..4 {
        model.dyn_driven_constraint_residuals(t, &q, &vec![0.0; n], inputs, &mut res, &mut vel)?;
        let r = DVector::from_column_slice(&res);
        if r.amax() <= 1e-15 * scale {
            return Ok(q);
        }
        let (d, _) = rows(model, info, t, &q, inputs)?;
        let dh = d.rows(0, h).into_owned();
        let gram = &dh * dh.transpose();
        let eps = TOLERANCE * gram.amax().max(f64::MIN_POSITIVE);
        let step = dh.transpose()
            * gram
                .pseudo_inverse(eps)
                .map_err(|_| SwitchError::Unattainable { residual: r.amax() })?
            * r;
        for (x, dx) in q.iter_mut().zip(step.iter()) {
            *x -= dx;
        }
    }
    model.dyn_driven_constraint_residuals(t, &q, &vec![0.0; n], inputs, &mut res, &mut vel)?;
    let left = res.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    if left > 1e-9 * scale {
        return Err(SwitchError::Unattainable {
            residual: left / scale,
        });
    }
    Ok(q)
}

/// D (m×n) and d of `model` at `(t, q)` and its inputs.
fn rows<B: DynModel + ?Sized>(
    model: &B,
    info: &ModelInfo,
    t: f64,
    q: &[f64],
    inputs: &[f64],
) -> Result<(DMatrix<f64>, DVector<f64>), ModelError> {
    let (n, m) = (info.coordinates.len(), info.constraints);
    let (mut d, mut d0) = (vec![0.0; m * n], vec![0.0; m]);
    model.dyn_driven_constraint_rows(t, q, inputs, &mut d, &mut d0)?;
    Ok((DMatrix::from_row_slice(m, n, &d), DVector::from_vec(d0)))
}

/// The impulse in `from`'s speeds after which the rows' residual
/// `D q̇ + d` is `−restitution` times what it was (0: onto the rows): the
/// coordinate rates after it, and the rows' impulses.
// meet's t, q, u with `from`, its info and inputs, the rows D and d meet already computed
// from `contact`, and the restitution
#[allow(clippy::too_many_arguments)]
fn impulse<A: DynModel + ?Sized>(
    from: &A,
    info: &ModelInfo,
    t: f64,
    q: &[f64],
    u: &[f64],
    inputs: &[f64],
    d: &DMatrix<f64>,
    d0: &DVector<f64>,
    restitution: f64,
) -> Result<(Vec<f64>, Vec<f64>), SwitchError> {
    let (n, l) = (info.coordinates.len(), info.speeds.len());
    let (mut c, mut c0) = (vec![0.0; n * l], vec![0.0; n]);
    from.dyn_driven_speed_transform(t, q, inputs, &mut c, &mut c0)?;
    let (mut mass, mut forcing) = (vec![0.0; l * l], vec![0.0; l]);
    from.dyn_mass_matrix_and_forcing(t, q, u, inputs, &mut mass, &mut forcing)?;
    let c = DMatrix::from_row_slice(n, l, &c);
    let c0 = DVector::from_vec(c0);
    let mass = DMatrix::from_row_slice(l, l, &mass);
    let u = DVector::from_column_slice(u);
    let g = d * &c;
    let g0 = d * &c0 + d0;
    let chol = mass.cholesky().ok_or(ModelError::SingularMassMatrix {
        index: 0,
        pivot: 0.0,
    })?;
    let minv_gt = chol.solve(&g.transpose());
    let k = &g * &minv_gt;
    let rhs = -(1.0 + restitution) * (&g * &u + g0);
    let eps = TOLERANCE * k.amax().max(f64::MIN_POSITIVE);
    let lambda = k
        .pseudo_inverse(eps)
        .map_err(|_| SwitchError::Unattainable { residual: f64::NAN })?
        * rhs;
    let u_after = u + minv_gt * &lambda;
    let qdot = c * u_after + c0;
    Ok((qdot.as_slice().to_vec(), lambda.as_slice().to_vec()))
}

/// `model`'s privileged speeds for the coordinate rates `qdot`: W q̇ + w.
fn speeds_of<B: DynModel + ?Sized>(
    model: &B,
    info: &ModelInfo,
    t: f64,
    q: &[f64],
    qdot: &[f64],
) -> Result<Vec<f64>, ModelError> {
    let (n, l) = (info.coordinates.len(), info.speeds.len());
    let (mut w, mut w0) = (vec![0.0; l * n], vec![0.0; l]);
    model.dyn_speed_definitions(t, q, &mut w, &mut w0)?;
    Ok((0..l)
        .map(|k| (0..n).map(|r| w[k * n + r] * qdot[r]).sum::<f64>() + w0[k])
        .collect())
}
