//! Motion through singular configurations in full coordinates: the
//! augmented Lagrangian formulation with mass-orthogonal projections (after
//! Bayo and Ledesma, 1996).
//!
//! The reduced equations need the dependent block of the constraint matrix
//! to be invertible. Where a mechanism passes a singular configuration (a
//! parallelogram four-bar whose cranks are horizontal: the loop-closure
//! Jacobian loses rank and the mechanism has extra instantaneous degrees of
//! freedom) the generated rhs reports
//! [`ModelError::SingularConstraints`]
//! instead of producing NaN. This module continues through such
//! configurations. It uses only the model's kinematic description, through
//! [`full_dynamics`]:
//!
//! * **accelerations**: with all coordinates q and their rates q̇ as the
//!   state, q̈ solves (M + α DᵀD) q̈ = Q − h − Dᵀλ* − α Dᵀ(Ḋq̇ + ḋ), with the
//!   multiplier estimate λ* updated by λ* ← λ* + α (D q̈ + Ḋq̇ + ḋ) until the
//!   acceleration constraints hold. M + α DᵀD stays positive definite when D
//!   loses rank (M is positive definite in a model whose every coordinate
//!   moves some mass), so nothing is singular there; λ* is then not unique,
//!   q̈ still is;
//! * **projections** after each step: positions onto the holonomic
//!   constraints f(q, t) = 0 by Gauss–Newton steps (M + α JᵀJ) Δq = −α Jᵀ f,
//!   velocities onto D q̇ + d = 0 by (M + α DᵀD) Δq̇ = −α Dᵀ(D q̇ + d): the
//!   smallest corrections in the kinetic-energy metric, defined at rank loss
//!   too.
//!
//! α is `penalty` times the largest diagonal entry of M.
//!
//! # Example
//!
//! ```
//! use appell_dynamics::augmented::{Settings, integrate};
//! # use appell_core::{check_len, BodyInfo, Model, ModelError, ModelInfo, OpCounts, Scalar};
//! # // A particle on the unit circle in (x, y) coordinates, with gravity:
//! # // the holonomic constraint x² + y² − 1 = 0.
//! # struct Ring { g: f64 }
//! # static INFO: ModelInfo = ModelInfo {
//! #     name: "Ring", parameters: &["g"], coordinates: &["x", "y"], speeds: &["x"],
//! #     dependent: &["y"], cyclic: &[], ignorable: &[], retained: &["x", "y"], inputs: &[],
//! #     effects: &["gravity"], outputs: &[], row_sources: &[], contacts: &[], holonomic: 1,
//! #     constraints: 1, bodies: &[BodyInfo { name: "P", rigid: false }], force_points: 1,
//! #     torques: 0, form: "closed form", symbolic_elimination: false,
//! #     rhs_ops: OpCounts { add: 0, mul: 0, div: 0, calls: 0, total: 0 }, jacobian: None, equations: "",
//! # };
//! # fn unused() -> Result<(), ModelError> { Err(ModelError::NonFinite { what: "unused" }) }
//! # impl Model for Ring {
//! #     type Prepared<T: Scalar> = ();
//! #     fn info() -> &'static ModelInfo { &INFO }
//! #     fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> { out[0] = self.g; Ok(()) }
//! #     fn set_parameter(&mut self, _: &str, _: f64) -> bool { false }
//! #     fn prepare<T: Scalar>(&self) {}
//! #     fn rhs<T: Scalar>(&self, _: &(), _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { unused() }
//! #     fn mass_matrix_and_forcing<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
//! #     fn speed_transform<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
//! #     fn coordinate_rates<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { unused() }
//! #     fn constraint_residuals<T: Scalar>(&self, _: T, q: &[T], qd: &[T], h: &mut [T], v: &mut [T]) -> Result<(), ModelError> {
//! #         h[0] = q[0] * q[0] + q[1] * q[1] - T::one();
//! #         v[0] = T::from_f64(2.0) * (q[0] * qd[0] + q[1] * qd[1]);
//! #         Ok(())
//! #     }
//! #     fn kinetic_energy<T: Scalar>(&self, _: T, _: &[T], _: &[T]) -> Result<T, ModelError> { unused().map(|_| T::zero()) }
//! #     fn mass_properties(&self, m: &mut [f64], i: &mut [[f64; 9]]) -> Result<(), ModelError> { m[0] = 1.0; i[0] = [0.0; 9]; Ok(()) }
//! #     fn body_poses<T: Scalar>(&self, _: T, q: &[T], p: &mut [[T; 3]], r: &mut [[T; 9]]) -> Result<(), ModelError> {
//! #         p[0] = [q[0], q[1], T::zero()];
//! #         r[0] = [T::one(), T::zero(), T::zero(), T::zero(), T::one(), T::zero(), T::zero(), T::zero(), T::one()];
//! #         Ok(())
//! #     }
//! #     fn constraint_rows<T: Scalar>(&self, _: T, q: &[T], d: &mut [T], d0: &mut [T]) -> Result<(), ModelError> {
//! #         d[0] = T::from_f64(2.0) * q[0]; d[1] = T::from_f64(2.0) * q[1]; d0[0] = T::zero(); Ok(())
//! #     }
//! #     fn load_geometry<T: Scalar>(&self, _: T, q: &[T], p: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> {
//! #         p[0] = [q[0], q[1], T::zero()]; Ok(())
//! #     }
//! #     fn load_values<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], f: &mut [[T; 3]], _: &mut [[T; 3]]) -> Result<(), ModelError> {
//! #         f[0] = [T::zero(), T::from_f64(-self.g), T::zero()]; Ok(())
//! #     }
//! # }
//! // A bead on a unit hoop, let go at the top with a little speed: it runs
//! // round and round through every configuration.
//! let model = Ring { g: 9.81 };
//! let (mut q, mut qdot) = (vec![0.0, 1.0], vec![1.0, 0.0]);
//! let mut worst: f64 = 0.0;
//! integrate(&model, 0.0, &mut q, &mut qdot, 1e-3, 2000, &[], &Settings::default(), |_, q, _| {
//!     worst = worst.max((q[0] * q[0] + q[1] * q[1] - 1.0).abs());
//! })
//! .unwrap();
//! assert!(worst < 1e-12);
//! ```

use nalgebra::{DMatrix, DVector};

use crate::oracle::{full_dynamics, FullDynamics, OracleError};
use appell_core::Model;
use appell_core::ModelError;

/// Settings of the augmented Lagrangian formulation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// α relative to the largest diagonal entry of M (default 1e6).
    pub penalty: f64,
    /// Multiplier updates per acceleration (default 20).
    pub iterations: usize,
    /// Stop the updates when |D q̈ + Ḋq̇ + ḋ| is below this, relative to the
    /// scale of the terms (default 1e-14); also the projections' tolerance on
    /// the residuals, absolute (default 1e-14).
    pub tolerance: f64,
    /// Gauss–Newton steps per position projection (default 10).
    pub projection_steps: usize,
    /// Project after every step in [`integrate`] (default true); off, the
    /// state drifts off the constraints at the size of the integration
    /// error, which shows what the projections remove.
    pub project: bool,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            penalty: 1e6,
            iterations: 20,
            tolerance: 1e-14,
            projection_steps: 10,
            project: true,
        }
    }
}

/// What a projection did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projection {
    /// Largest holonomic residual before and after.
    pub position: (f64, f64),
    /// Largest velocity-constraint residual before and after.
    pub velocity: (f64, f64),
}

fn invalid(what: &'static str) -> OracleError {
    OracleError::Model(ModelError::NonFinite { what })
}

/// M + α Aᵀ A for the first `rows` rows of `a` (row-major, n columns), and α.
fn augmented_matrix(full: &FullDynamics, rows: usize, penalty: f64) -> (DMatrix<f64>, f64) {
    let n = full.n;
    let m = DMatrix::from_row_slice(n, n, &full.mass);
    let scale = (0..n)
        .map(|i| m[(i, i)].abs())
        .fold(0.0f64, f64::max)
        .max(1e-300);
    let alpha = penalty * scale;
    let a = DMatrix::from_row_slice(rows, n, &full.constraint_matrix[..rows * n]);
    (m + alpha * a.transpose() * &a, alpha)
}

fn cholesky(a: DMatrix<f64>) -> Result<nalgebra::Cholesky<f64, nalgebra::Dyn>, OracleError> {
    let n = a.nrows();
    a.cholesky().ok_or(OracleError::SingularKkt {
        index: n,
        pivot: 0.0,
        tolerance: 0.0,
    })
}

/// q̈ at `(t, q, q̇)` by the augmented Lagrangian iteration (module
/// documentation). Errors: those of [`full_dynamics`], and
/// [`OracleError::SingularKkt`] when M + α DᵀD is not positive definite
/// (some motion carries no mass).
///
/// ```
/// use appell_dynamics::augmented::{accelerations, Settings};
/// # use appell_core::{BodyInfo, Model, ModelError, ModelInfo, OpCounts, Scalar};
/// # // A particle on the unit circle in (x, y) coordinates, with gravity:
/// # // the holonomic constraint x² + y² − 1 = 0.
/// # struct Ring { g: f64 }
/// # static INFO: ModelInfo = ModelInfo {
/// #     name: "Ring", parameters: &["g"], coordinates: &["x", "y"], speeds: &["x"],
/// #     dependent: &["y"], cyclic: &[], ignorable: &[], retained: &["x", "y"], inputs: &[],
/// #     effects: &["gravity"], outputs: &[], row_sources: &[], contacts: &[], holonomic: 1,
/// #     constraints: 1, bodies: &[BodyInfo { name: "P", rigid: false }], force_points: 1,
/// #     torques: 0, form: "closed form", symbolic_elimination: false,
/// #     rhs_ops: OpCounts { add: 0, mul: 0, div: 0, calls: 0, total: 0 }, jacobian: None, equations: "",
/// # };
/// # fn unused() -> Result<(), ModelError> { Err(ModelError::NonFinite { what: "unused" }) }
/// # impl Model for Ring {
/// #     type Prepared<T: Scalar> = ();
/// #     fn info() -> &'static ModelInfo { &INFO }
/// #     fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> { out[0] = self.g; Ok(()) }
/// #     fn set_parameter(&mut self, _: &str, _: f64) -> bool { false }
/// #     fn prepare<T: Scalar>(&self) {}
/// #     fn rhs<T: Scalar>(&self, _: &(), _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn mass_matrix_and_forcing<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn speed_transform<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn coordinate_rates<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn constraint_residuals<T: Scalar>(&self, _: T, q: &[T], qd: &[T], h: &mut [T], v: &mut [T]) -> Result<(), ModelError> {
/// #         h[0] = q[0] * q[0] + q[1] * q[1] - T::one();
/// #         v[0] = T::from_f64(2.0) * (q[0] * qd[0] + q[1] * qd[1]);
/// #         Ok(())
/// #     }
/// #     fn kinetic_energy<T: Scalar>(&self, _: T, _: &[T], _: &[T]) -> Result<T, ModelError> { unused().map(|_| T::zero()) }
/// #     fn mass_properties(&self, m: &mut [f64], i: &mut [[f64; 9]]) -> Result<(), ModelError> { m[0] = 1.0; i[0] = [0.0; 9]; Ok(()) }
/// #     fn body_poses<T: Scalar>(&self, _: T, q: &[T], p: &mut [[T; 3]], r: &mut [[T; 9]]) -> Result<(), ModelError> {
/// #         p[0] = [q[0], q[1], T::zero()];
/// #         r[0] = [T::one(), T::zero(), T::zero(), T::zero(), T::one(), T::zero(), T::zero(), T::zero(), T::one()];
/// #         Ok(())
/// #     }
/// #     fn constraint_rows<T: Scalar>(&self, _: T, q: &[T], d: &mut [T], d0: &mut [T]) -> Result<(), ModelError> {
/// #         d[0] = T::from_f64(2.0) * q[0]; d[1] = T::from_f64(2.0) * q[1]; d0[0] = T::zero(); Ok(())
/// #     }
/// #     fn load_geometry<T: Scalar>(&self, _: T, q: &[T], p: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> {
/// #         p[0] = [q[0], q[1], T::zero()]; Ok(())
/// #     }
/// #     fn load_values<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], f: &mut [[T; 3]], _: &mut [[T; 3]]) -> Result<(), ModelError> {
/// #         f[0] = [T::zero(), T::from_f64(-self.g), T::zero()]; Ok(())
/// #     }
/// # }
/// // A bead at rest at the side of a unit hoop under gravity: it starts to
/// // fall straight down, q̈ = (0, −g).
/// let a = accelerations(&Ring { g: 9.81 }, 0.0, &[1.0, 0.0], &[0.0, 0.0], &[], &Settings::default()).unwrap();
/// assert!(a[0].abs() < 1e-9 && (a[1] + 9.81).abs() < 1e-9);
/// ```
pub fn accelerations<M: Model>(
    model: &M,
    t: f64,
    q: &[f64],
    qdot: &[f64],
    inputs: &[f64],
    settings: &Settings,
) -> Result<Vec<f64>, OracleError> {
    let full = full_dynamics(model, t, q, qdot, inputs)?;
    let (n, m) = (full.n, full.m);
    let (a, alpha) = augmented_matrix(&full, m, settings.penalty);
    let chol = cholesky(a)?;
    let d = DMatrix::from_row_slice(m, n, &full.constraint_matrix);
    let c = DVector::from_row_slice(&full.constraint_bias);
    let mut base = DVector::from_iterator(n, (0..n).map(|i| full.forces[i] - full.bias[i]));
    base -= alpha * d.transpose() * &c;
    let scale = base.amax().max(c.amax()).max(1e-300);
    let mut lambda = DVector::<f64>::zeros(m);
    let mut qddot = chol.solve(&base);
    for _ in 0..settings.iterations {
        let violation = &d * &qddot + &c;
        if violation.amax() <= settings.tolerance * scale {
            break;
        }
        lambda += alpha * violation;
        qddot = chol.solve(&(&base - d.transpose() * &lambda));
    }
    if qddot.iter().any(|x| !x.is_finite()) {
        return Err(invalid("the accelerations"));
    }
    Ok(qddot.iter().copied().collect())
}

/// Projects `q` onto the holonomic constraints and then `q̇` onto the
/// velocity constraints, by the smallest corrections in the kinetic-energy
/// metric (module documentation). Errors: those of [`full_dynamics`],
/// [`OracleError::SingularKkt`] as for [`accelerations`], and
/// [`ModelError::NonFinite`] when a correction is not finite.
///
/// ```
/// use appell_dynamics::augmented::{project, Settings};
/// # use appell_core::{BodyInfo, Model, ModelError, ModelInfo, OpCounts, Scalar};
/// # // A particle on the unit circle in (x, y) coordinates, with gravity:
/// # // the holonomic constraint x² + y² − 1 = 0.
/// # struct Ring { g: f64 }
/// # static INFO: ModelInfo = ModelInfo {
/// #     name: "Ring", parameters: &["g"], coordinates: &["x", "y"], speeds: &["x"],
/// #     dependent: &["y"], cyclic: &[], ignorable: &[], retained: &["x", "y"], inputs: &[],
/// #     effects: &["gravity"], outputs: &[], row_sources: &[], contacts: &[], holonomic: 1,
/// #     constraints: 1, bodies: &[BodyInfo { name: "P", rigid: false }], force_points: 1,
/// #     torques: 0, form: "closed form", symbolic_elimination: false,
/// #     rhs_ops: OpCounts { add: 0, mul: 0, div: 0, calls: 0, total: 0 }, jacobian: None, equations: "",
/// # };
/// # fn unused() -> Result<(), ModelError> { Err(ModelError::NonFinite { what: "unused" }) }
/// # impl Model for Ring {
/// #     type Prepared<T: Scalar> = ();
/// #     fn info() -> &'static ModelInfo { &INFO }
/// #     fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> { out[0] = self.g; Ok(()) }
/// #     fn set_parameter(&mut self, _: &str, _: f64) -> bool { false }
/// #     fn prepare<T: Scalar>(&self) {}
/// #     fn rhs<T: Scalar>(&self, _: &(), _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn mass_matrix_and_forcing<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn speed_transform<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn coordinate_rates<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn constraint_residuals<T: Scalar>(&self, _: T, q: &[T], qd: &[T], h: &mut [T], v: &mut [T]) -> Result<(), ModelError> {
/// #         h[0] = q[0] * q[0] + q[1] * q[1] - T::one();
/// #         v[0] = T::from_f64(2.0) * (q[0] * qd[0] + q[1] * qd[1]);
/// #         Ok(())
/// #     }
/// #     fn kinetic_energy<T: Scalar>(&self, _: T, _: &[T], _: &[T]) -> Result<T, ModelError> { unused().map(|_| T::zero()) }
/// #     fn mass_properties(&self, m: &mut [f64], i: &mut [[f64; 9]]) -> Result<(), ModelError> { m[0] = 1.0; i[0] = [0.0; 9]; Ok(()) }
/// #     fn body_poses<T: Scalar>(&self, _: T, q: &[T], p: &mut [[T; 3]], r: &mut [[T; 9]]) -> Result<(), ModelError> {
/// #         p[0] = [q[0], q[1], T::zero()];
/// #         r[0] = [T::one(), T::zero(), T::zero(), T::zero(), T::one(), T::zero(), T::zero(), T::zero(), T::one()];
/// #         Ok(())
/// #     }
/// #     fn constraint_rows<T: Scalar>(&self, _: T, q: &[T], d: &mut [T], d0: &mut [T]) -> Result<(), ModelError> {
/// #         d[0] = T::from_f64(2.0) * q[0]; d[1] = T::from_f64(2.0) * q[1]; d0[0] = T::zero(); Ok(())
/// #     }
/// #     fn load_geometry<T: Scalar>(&self, _: T, q: &[T], p: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> {
/// #         p[0] = [q[0], q[1], T::zero()]; Ok(())
/// #     }
/// #     fn load_values<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], f: &mut [[T; 3]], _: &mut [[T; 3]]) -> Result<(), ModelError> {
/// #         f[0] = [T::zero(), T::from_f64(-self.g), T::zero()]; Ok(())
/// #     }
/// # }
/// // Off the hoop and moving across it: back onto it, moving along it.
/// let (mut q, mut qdot) = ([0.9, 0.1], [0.3, 1.0]);
/// let p = project(&Ring { g: 9.81 }, 0.0, &mut q, &mut qdot, &[], &Settings::default()).unwrap();
/// assert!(p.position.0 > 0.1 && p.position.1 < 1e-14 && p.velocity.1 < 1e-12);
/// assert!((q[0] * qdot[0] + q[1] * qdot[1]).abs() < 1e-12);
/// ```
pub fn project<M: Model>(
    model: &M,
    t: f64,
    q: &mut [f64],
    qdot: &mut [f64],
    inputs: &[f64],
    settings: &Settings,
) -> Result<Projection, OracleError> {
    let info = M::info();
    let (n, mh) = (info.coordinates.len(), info.holonomic);
    let m = info.constraints;
    let zero_rates = vec![0.0; n];
    let holonomic = |q: &[f64]| -> Result<Vec<f64>, OracleError> {
        let (mut h, mut v) = (vec![0.0; mh], vec![0.0; m]);
        model.driven_constraint_residuals(t, q, &zero_rates, inputs, &mut h, &mut v)?;
        Ok(h)
    };
    let worst = |v: &[f64]| v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    let mut h = holonomic(q)?;
    let position_before = worst(&h);
    for _ in 0..settings.projection_steps {
        if worst(&h) <= settings.tolerance {
            break;
        }
        let full = full_dynamics(model, t, q, &zero_rates, inputs)?;
        let (a, alpha) = augmented_matrix(&full, mh, settings.penalty);
        let jac = DMatrix::from_row_slice(mh, n, &full.constraint_matrix[..mh * n]);
        let rhs = -alpha * jac.transpose() * DVector::from_row_slice(&h);
        let dq = cholesky(a)?.solve(&rhs);
        if dq.iter().any(|x| !x.is_finite()) {
            return Err(invalid("the position correction"));
        }
        for (x, d) in q.iter_mut().zip(dq.iter()) {
            *x += d;
        }
        h = holonomic(q)?;
    }
    let position_after = worst(&h);
    let full = full_dynamics(model, t, q, qdot, inputs)?;
    let d = DMatrix::from_row_slice(m, n, &full.constraint_matrix);
    let offset = DVector::from_row_slice(&full.constraint_offset);
    let residual = |qd: &[f64]| &d * DVector::from_row_slice(qd) + &offset;
    let mut r = residual(qdot);
    let velocity_before = r.amax();
    let (a, alpha) = augmented_matrix(&full, m, settings.penalty);
    let chol = cholesky(a)?;
    for _ in 0..3 {
        if r.amax() <= settings.tolerance {
            break;
        }
        let dv = chol.solve(&(-alpha * d.transpose() * &r));
        if dv.iter().any(|x| !x.is_finite()) {
            return Err(invalid("the velocity correction"));
        }
        for (x, d) in qdot.iter_mut().zip(dv.iter()) {
            *x += d;
        }
        r = residual(qdot);
    }
    Ok(Projection {
        position: (position_before, position_after),
        velocity: (velocity_before, r.amax()),
    })
}

/// `steps` classical Runge–Kutta steps of size `h` of the full-coordinate
/// equations from `(t0, q, q̇)`, each followed by [`project`] (unless
/// [`Settings::project`] is off); `on_step(t,
/// q, q̇)` sees the projected state after every step. `q` and `q̇` hold the
/// final state on return.
///
/// Errors: those of [`accelerations`] and [`project`]; a non-finite state
/// is reported, never returned.
// accelerations' and project's arguments (q and q̇ in and out here) plus the fixed-step grid
// h, steps and the per-step callback
#[allow(clippy::too_many_arguments)]
pub fn integrate<M: Model>(
    model: &M,
    t0: f64,
    q: &mut [f64],
    qdot: &mut [f64],
    h: f64,
    steps: usize,
    inputs: &[f64],
    settings: &Settings,
    mut on_step: impl FnMut(f64, &[f64], &[f64]),
) -> Result<(), OracleError> {
    let n = q.len();
    if qdot.len() != n || n != M::info().coordinates.len() {
        return Err(OracleError::Model(ModelError::Length {
            argument: "q, qdot",
            expected: M::info().coordinates.len(),
            found: n.min(qdot.len()),
        }));
    }
    let f = |t: f64, x: &[f64]| -> Result<Vec<f64>, OracleError> {
        let a = accelerations(model, t, &x[..n], &x[n..], inputs, settings)?;
        let mut dx = x[n..].to_vec();
        dx.extend(a);
        Ok(dx)
    };
    let mut x: Vec<f64> = q.iter().chain(qdot.iter()).copied().collect();
    for k in 0..steps {
        let t = t0 + k as f64 * h;
        let k1 = f(t, &x)?;
        let x2: Vec<f64> = x.iter().zip(&k1).map(|(a, b)| a + 0.5 * h * b).collect();
        let k2 = f(t + 0.5 * h, &x2)?;
        let x3: Vec<f64> = x.iter().zip(&k2).map(|(a, b)| a + 0.5 * h * b).collect();
        let k3 = f(t + 0.5 * h, &x3)?;
        let x4: Vec<f64> = x.iter().zip(&k3).map(|(a, b)| a + h * b).collect();
        let k4 = f(t + h, &x4)?;
        for i in 0..2 * n {
            x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
        if settings.project {
            let (qs, vs) = x.split_at_mut(n);
            project(model, t + h, qs, vs, inputs, settings)?;
        }
        if x.iter().any(|v| !v.is_finite()) {
            return Err(invalid("the state"));
        }
        on_step(t + h, &x[..n], &x[n..]);
    }
    q.copy_from_slice(&x[..n]);
    qdot.copy_from_slice(&x[n..]);
    Ok(())
}
