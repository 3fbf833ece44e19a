//! The holonomic constraints: their Jacobian by dual numbers, Newton
//! (Gauss-Newton) onto the constraint manifold, the choice of the
//! coordinates to adjust, and projection and checks of a reduced state.

use super::checks::{check_configuration, finite, indices};
use super::error::LinearizeError;
use appell_core::Scalar;
use appell_core::{check_len, Model, ModelError};
use nalgebra::{DMatrix, DVector};
use num_dual::Dual64;

// Items the documentation links to.
#[cfg(doc)]
use appell_core::ModelInfo;

/// Singular values below this fraction of the largest entry of the full
/// holonomic Jacobian count as zero.
pub(super) const RANK_RTOL: f64 = 1e-10;

/// Halvings of a Newton step before giving up on decreasing the residual.
const MAX_BACKTRACKS: usize = 30;

/// The residuals of the holonomic constraints (and of the velocity rows)
/// at `q` with zero coordinate rates: [`Model::constraint_residuals`], or
/// [`Model::driven_constraint_residuals`] at `inputs` when they are given.
fn residuals_at<M: Model, T: Scalar>(
    model: &M,
    t: T,
    q: &[T],
    inputs: Option<&[T]>,
    holonomic: &mut [T],
    velocity: &mut [T],
) -> Result<(), ModelError> {
    let qdot = vec![T::zero(); q.len()];
    match inputs {
        Some(inputs) => model.driven_constraint_residuals(t, q, &qdot, inputs, holonomic, velocity),
        None => model.constraint_residuals(t, q, &qdot, holonomic, velocity),
    }
}

/// The holonomic residuals at `q` and their Jacobian columns at the
/// coordinates `cols` (h × cols.len()), one [`Dual64`] pass per column. The
/// coordinate rates passed to the model are zero; the residuals are those
/// at `inputs` ([`Model::driven_constraint_residuals`]) when given.
pub(super) fn jacobian_at<M: Model>(
    model: &M,
    t: f64,
    q: &[f64],
    inputs: Option<&[f64]>,
    cols: &[usize],
) -> Result<(DVector<f64>, DMatrix<f64>), LinearizeError> {
    let info = M::info();
    let (h, m) = (info.holonomic, info.constraints);
    let mut values = DVector::<f64>::zeros(h);
    let mut jac = DMatrix::<f64>::zeros(h, cols.len());
    if cols.is_empty() {
        let mut vel = vec![0.0; m];
        residuals_at(model, t, q, inputs, values.as_mut_slice(), &mut vel)?;
    } else {
        let td = Dual64::from_re(t);
        let mut qd: Vec<Dual64> = q.iter().map(|&x| Dual64::from_re(x)).collect();
        let id: Option<Vec<Dual64>> =
            inputs.map(|i| i.iter().map(|&x| Dual64::from_re(x)).collect());
        let mut res = vec![Dual64::from_re(0.0); h];
        let mut vel = vec![Dual64::from_re(0.0); m];
        for (k, &c) in cols.iter().enumerate() {
            qd[c].eps = 1.0;
            let r = residuals_at(model, td, &qd, id.as_deref(), &mut res, &mut vel);
            qd[c].eps = 0.0;
            r?;
            for (i, v) in res.iter().enumerate() {
                jac[(i, k)] = v.eps;
            }
        }
        for (i, v) in res.iter().enumerate() {
            values[i] = v.re;
        }
    }
    finite(values.as_slice(), "a holonomic residual")?;
    finite(jac.as_slice(), "the holonomic Jacobian")?;
    Ok((values, jac))
}

/// A thin SVD of `j` (non-empty), or a typed error if it does not converge.
pub(super) fn svd(
    j: DMatrix<f64>,
) -> Result<nalgebra::SVD<f64, nalgebra::Dyn, nalgebra::Dyn>, LinearizeError> {
    let iterations = 100 * j.nrows().max(j.ncols());
    nalgebra::SVD::try_new(j, true, true, f64::EPSILON, iterations)
        .ok_or(LinearizeError::DecompositionFailed { what: "SVD" })
}

/// Solves the holonomic constraints f(q, t) = 0 of [`Model::constraint_residuals`]
/// for the coordinates at the indices `unknowns` (into
/// [`ModelInfo::coordinates`]), starting from and updating `q` (all
/// coordinates); the other coordinates are held.
///
/// Newton's method on the Jacobian of the residuals with respect to the
/// unknowns ([`Dual64`] seeds through the generated code; the coordinate
/// rates passed are zero and the velocity rows are ignored). With as many
/// unknowns as residuals it is Newton's method; with more residuals it is
/// Gauss-Newton (least squares); with more unknowns, the minimum-norm step.
/// A step that does not decrease the residual norm is halved (up to 30
/// times). Converged when the Euclidean norm of the residuals is at most
/// `tol` (absolute, in the residuals' units; it must be above their rounding
/// level). Returns the number of Newton steps taken (0 when `q` already
/// satisfies the constraints).
///
/// Errors (`q` then holds the last iterate): wrong lengths or non-finite
/// arguments ([`LinearizeError::Model`]); an index out of range or repeated,
/// or a negative or non-finite `tol` ([`LinearizeError::InvalidArgument`]);
/// [`LinearizeError::RankDeficient`] when the Jacobian with respect to the
/// unknowns has rank below min(residuals, unknowns) (relative to the largest
/// entry of the Jacobian over all coordinates); [`LinearizeError::NotConverged`]
/// after `max_iter` steps, when no step decreases the residual (an
/// inconsistent least-squares problem), or when there are no unknowns and the
/// constraints are violated; and any error of the model. Example in the
/// module documentation.
pub fn solve_holonomic<M: Model>(
    model: &M,
    t: f64,
    q: &mut [f64],
    unknowns: &[usize],
    tol: f64,
    max_iter: usize,
) -> Result<usize, LinearizeError> {
    solve_at(model, t, q, None, unknowns, tol, max_iter)
}

/// [`solve_holonomic`] of a model with driven coordinates: the holonomic
/// residuals are [`Model::driven_constraint_residuals`] at `inputs` (a
/// driven coordinate is solved onto its command). For a model without
/// driven coordinates it is `solve_holonomic`. Errors also for `inputs` of
/// the wrong length or not finite. Example at [`driven_project_holonomic`].
pub fn driven_solve_holonomic<M: Model>(
    model: &M,
    t: f64,
    q: &mut [f64],
    inputs: &[f64],
    unknowns: &[usize],
    tol: f64,
    max_iter: usize,
) -> Result<usize, LinearizeError> {
    check_inputs::<M>(inputs)?;
    solve_at(model, t, q, Some(inputs), unknowns, tol, max_iter)
}

/// Checks `inputs` against the model's input count and for finiteness.
fn check_inputs<M: Model>(inputs: &[f64]) -> Result<(), LinearizeError> {
    check_len("inputs", inputs, M::info().inputs.len())?;
    Ok(finite(inputs, "inputs")?)
}

/// [`solve_holonomic`] at `inputs`, when given.
fn solve_at<M: Model>(
    model: &M,
    t: f64,
    q: &mut [f64],
    inputs: Option<&[f64]>,
    unknowns: &[usize],
    tol: f64,
    max_iter: usize,
) -> Result<usize, LinearizeError> {
    let info = M::info();
    let n = info.coordinates.len();
    check_configuration(info, t, q)?;
    if !(tol.is_finite() && tol >= 0.0) {
        return Err(LinearizeError::InvalidArgument(format!(
            "the tolerance must be finite and non-negative, not {tol}"
        )));
    }
    for (k, &i) in unknowns.iter().enumerate() {
        if i >= n {
            return Err(LinearizeError::InvalidArgument(format!(
                "unknown index {i} is out of range for {n} coordinates"
            )));
        }
        if unknowns[..k].contains(&i) {
            return Err(LinearizeError::InvalidArgument(format!(
                "unknown index {i} is repeated"
            )));
        }
    }
    let h = info.holonomic;
    let all: Vec<usize> = (0..n).collect();
    let mut trial = q.to_vec();
    let mut vel = vec![0.0; info.constraints];
    let mut res = vec![0.0; h];
    let mut iter = 0;
    loop {
        let (r, jfull) = jacobian_at(model, t, q, inputs, &all)?;
        let norm = r.norm();
        if norm <= tol {
            return Ok(iter);
        }
        if iter >= max_iter || unknowns.is_empty() {
            return Err(LinearizeError::NotConverged {
                iterations: iter,
                residual: norm,
            });
        }
        let j = jfull.select_columns(unknowns);
        let scale = jfull.amax();
        let dec = svd(j)?;
        let cutoff = RANK_RTOL * scale;
        let rank = dec.singular_values.iter().filter(|&&s| s > cutoff).count();
        let expected = h.min(unknowns.len());
        if scale == 0.0 || rank < expected {
            return Err(LinearizeError::RankDeficient { rank, expected });
        }
        let step = dec
            .solve(&(-&r), cutoff)
            .map_err(|_| LinearizeError::DecompositionFailed { what: "SVD" })?;
        // Backtracking: the first step length that decreases ‖f‖.
        let mut alpha = 1.0;
        let mut accepted = false;
        for _ in 0..=MAX_BACKTRACKS {
            trial.copy_from_slice(q);
            for (k, &i) in unknowns.iter().enumerate() {
                trial[i] += alpha * step[k];
            }
            if trial.iter().all(|x| x.is_finite()) {
                residuals_at(model, t, &trial, inputs, &mut res, &mut vel)?;
                let trial_norm = res.iter().map(|x| x * x).sum::<f64>().sqrt();
                if trial_norm < norm {
                    accepted = true;
                    break;
                }
            }
            alpha *= 0.5;
        }
        if !accepted {
            return Err(LinearizeError::NotConverged {
                iterations: iter,
                residual: norm,
            });
        }
        q.copy_from_slice(&trial);
        iter += 1;
    }
}

/// The dependent coordinates ([`ModelInfo::dependent`]) that the holonomic
/// residuals involve at `(q, t)`: those whose [`Dual64`] seed gives a
/// non-zero derivative of some residual. Indices into
/// [`ModelInfo::coordinates`], ascending; the natural `unknowns` of
/// [`solve_holonomic`]. Example in the module documentation.
///
/// Errors: wrong length or non-finite arguments, an inconsistent
/// [`ModelInfo`], and any error of [`Model::constraint_residuals`].
pub fn holonomic_unknowns<M: Model>(
    model: &M,
    t: f64,
    q: &[f64],
) -> Result<Vec<usize>, LinearizeError> {
    unknowns_at(model, t, q, None)
}

/// [`holonomic_unknowns`] of a model with driven coordinates, its
/// residuals at `inputs` ([`Model::driven_constraint_residuals`]); a
/// driven coordinate is among them (its constraint involves it). For a
/// model without driven coordinates it is `holonomic_unknowns`.
pub fn driven_holonomic_unknowns<M: Model>(
    model: &M,
    t: f64,
    q: &[f64],
    inputs: &[f64],
) -> Result<Vec<usize>, LinearizeError> {
    check_inputs::<M>(inputs)?;
    unknowns_at(model, t, q, Some(inputs))
}

/// [`holonomic_unknowns`] at `inputs`, when given.
fn unknowns_at<M: Model>(
    model: &M,
    t: f64,
    q: &[f64],
    inputs: Option<&[f64]>,
) -> Result<Vec<usize>, LinearizeError> {
    let info = M::info();
    check_configuration(info, t, q)?;
    let mut dep = indices(info, info.dependent, "dependent")?;
    dep.sort_unstable();
    dep.dedup();
    if info.holonomic == 0 {
        return Ok(Vec::new());
    }
    let (_, jac) = jacobian_at(model, t, q, inputs, &dep)?;
    Ok(dep
        .iter()
        .enumerate()
        .filter(|&(k, _)| jac.column(k).iter().any(|&x| x != 0.0))
        .map(|(_, &c)| c)
        .collect())
}

/// Projects a reduced state (retained coordinates, then privileged speeds,
/// as [`Model::rhs`] takes it) back onto the holonomic constraint manifold:
/// the dependent retained coordinates the constraints involve are corrected
/// by [`solve_holonomic`] with the others held; the speeds are left alone
/// (the reduced equations satisfy the velocity constraints by construction).
/// Integrators drift off the manifold at the size of their local error; a
/// projection between output times (or after every step) keeps a bicycle's
/// pitch consistent with its lean and steer over long runs.
///
/// Coordinates the reduced state does not carry are taken as 0, as in the
/// command line's `eval`. Returns the Euclidean norm of the residuals before
/// the projection and the number of Newton steps taken.
///
/// Errors: a state of the wrong length or with non-finite values
/// ([`LinearizeError::Model`]); [`LinearizeError::InvalidArgument`] when a
/// constraint involves a coordinate outside the reduced state (it cannot be
/// projected there); and the errors of [`solve_holonomic`] (`state` is then
/// unchanged).
///
/// ```
/// # use appell_core::{check_len, BodyInfo, Model, ModelError, ModelInfo, OpCounts, Scalar};
/// # struct Ring { l: f64 }
/// # static INFO: ModelInfo = ModelInfo {
/// #     name: "Ring", parameters: &["l"], coordinates: &["x", "y"],
/// #     speeds: &["x"], dependent: &["y"], cyclic: &[], ignorable: &[],
/// #     retained: &["x", "y"], inputs: &[], effects: &[], outputs: &[], row_sources: &[], contacts: &[], holonomic: 1,
/// #     constraints: 1, bodies: &[BodyInfo { name: "P", rigid: false }],
/// #     force_points: 0, torques: 0, form: "closed form", symbolic_elimination: true,
/// #     rhs_ops: OpCounts { add: 0, mul: 0, div: 0, calls: 0, total: 0 }, jacobian: None, equations: "",
/// # };
/// # fn unused() -> Result<(), ModelError> { Err(ModelError::NonFinite { what: "unused" }) }
/// # impl Model for Ring {
/// #     type Prepared<T: Scalar> = ();
/// #     fn info() -> &'static ModelInfo { &INFO }
/// #     fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> {
/// #         check_len("out", out, 1)?; out[0] = self.l; Ok(())
/// #     }
/// #     fn set_parameter(&mut self, _: &str, _: f64) -> bool { false }
/// #     fn prepare<T: Scalar>(&self) {}
/// #     fn rhs<T: Scalar>(&self, _: &(), _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn coordinate_rates<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn mass_matrix_and_forcing<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn speed_transform<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn constraint_residuals<T: Scalar>(&self, _: T, q: &[T], qd: &[T], h: &mut [T], v: &mut [T]) -> Result<(), ModelError> {
/// #         check_len("q", q, 2)?; check_len("qdot", qd, 2)?;
/// #         let l = T::from_f64(self.l);
/// #         h[0] = (q[0] * q[0] + q[1] * q[1] - l * l) / T::from_f64(2.0);
/// #         v[0] = q[0] * qd[0] + q[1] * qd[1];
/// #         Ok(())
/// #     }
/// #     fn kinetic_energy<T: Scalar>(&self, _: T, _: &[T], _: &[T]) -> Result<T, ModelError> { unused().map(|_| T::zero()) }
/// #     fn mass_properties(&self, _: &mut [f64], _: &mut [[f64; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn body_poses<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn constraint_rows<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn load_geometry<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn load_values<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [[T; 3]], _: &mut [[T; 3]]) -> Result<(), ModelError> { unused() }
/// # }
/// use appell_linearize::project_holonomic;
///
/// // A particle on a circle of radius 1 in Cartesian coordinates, state
/// // (x, y, ẋ), drifted off the circle.
/// let mut state = [0.6, -0.81, 0.3];
/// let (residual, steps) = project_holonomic(&Ring { l: 1.0 }, 0.0, &mut state, 1e-14, 20).unwrap();
/// assert!(residual > 1e-3 && steps > 0);
/// assert!((state[0] * state[0] + state[1] * state[1] - 1.0).abs() < 1e-13);
/// assert_eq!((state[0], state[2]), (0.6, 0.3)); // x and the speed are held
/// ```
pub fn project_holonomic<M: Model>(
    model: &M,
    t: f64,
    state: &mut [f64],
    tol: f64,
    max_iter: usize,
) -> Result<(f64, usize), LinearizeError> {
    project_at(model, t, state, None, tol, max_iter)
}

/// [`project_holonomic`] of a model with driven coordinates: the residuals
/// are [`Model::driven_constraint_residuals`] at `inputs` (the inputs at
/// time `t`, companions included), so a driven coordinate the reduced state
/// carries is put back on its command. For a model without driven
/// coordinates it is `project_holonomic`. Errors also for `inputs` of the
/// wrong length or not finite.
///
/// ```
/// # use appell_core::{check_len, BodyInfo, Model, ModelError, ModelInfo, OpCounts, RowSource, Scalar};
/// # struct Servo;
/// # static INFO: ModelInfo = ModelInfo {
/// #     name: "Servo", parameters: &[], coordinates: &["theta", "x"],
/// #     speeds: &["x"], dependent: &["theta"], cyclic: &[], ignorable: &[],
/// #     retained: &["theta", "x"], inputs: &["q_cmd", "q_cmd_rate", "q_cmd_accel"], effects: &[], outputs: &[],
/// #     row_sources: &[RowSource::Driven { holonomic: true, index: 0, constraint: "holonomic: theta == q_cmd" }],
/// #     contacts: &[], holonomic: 1, constraints: 1, bodies: &[BodyInfo { name: "P", rigid: false }],
/// #     force_points: 0, torques: 0, form: "closed form", symbolic_elimination: true,
/// #     rhs_ops: OpCounts { add: 0, mul: 0, div: 0, calls: 0, total: 0 }, jacobian: None, equations: "",
/// # };
/// # fn unused() -> Result<(), ModelError> { Err(ModelError::NonFinite { what: "unused" }) }
/// # impl Model for Servo {
/// #     type Prepared<T: Scalar> = ();
/// #     fn info() -> &'static ModelInfo { &INFO }
/// #     fn parameter_values(&self, _: &mut [f64]) -> Result<(), ModelError> { Ok(()) }
/// #     fn set_parameter(&mut self, _: &str, _: f64) -> bool { false }
/// #     fn prepare<T: Scalar>(&self) {}
/// #     fn rhs<T: Scalar>(&self, _: &(), _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn coordinate_rates<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn mass_matrix_and_forcing<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn speed_transform<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn constraint_residuals<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> {
/// #         Err(ModelError::NeedsInputs { function: "constraint_residuals" })
/// #     }
/// #     fn driven_constraint_residuals<T: Scalar>(&self, _: T, q: &[T], qd: &[T], i: &[T], h: &mut [T], v: &mut [T]) -> Result<(), ModelError> {
/// #         check_len("q", q, 2)?; check_len("inputs", i, 3)?;
/// #         h[0] = q[0] - i[0];
/// #         v[0] = qd[0] - i[1];
/// #         Ok(())
/// #     }
/// #     fn kinetic_energy<T: Scalar>(&self, _: T, _: &[T], _: &[T]) -> Result<T, ModelError> { unused().map(|_| T::zero()) }
/// #     fn mass_properties(&self, _: &mut [f64], _: &mut [[f64; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn body_poses<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn constraint_rows<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn load_geometry<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn load_values<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [[T; 3]], _: &mut [[T; 3]]) -> Result<(), ModelError> { unused() }
/// # }
/// use appell_linearize::{driven_check_holonomic, driven_project_holonomic, project_holonomic};
///
/// // A joint position-controlled to q_cmd = 0.5, state (theta, x, ẋ)
/// // drifted off the command.
/// let (mut state, inputs) = ([0.52, 1.0, 0.3], [0.5, 0.0, 0.0]);
/// let (residual, _) = driven_project_holonomic(&Servo, 0.0, &mut state, &inputs, 1e-14, 20).unwrap();
/// assert!((residual - 0.02).abs() < 1e-12);
/// assert!((state[0] - 0.5).abs() < 1e-14 && state[1..] == [1.0, 0.3]);
/// assert!(driven_check_holonomic(&Servo, 0.0, &state, &inputs, 1e-14).is_ok());
/// // Without the inputs the constraint cannot be evaluated.
/// assert!(project_holonomic(&Servo, 0.0, &mut state, 1e-14, 20).is_err());
/// ```
pub fn driven_project_holonomic<M: Model>(
    model: &M,
    t: f64,
    state: &mut [f64],
    inputs: &[f64],
    tol: f64,
    max_iter: usize,
) -> Result<(f64, usize), LinearizeError> {
    check_inputs::<M>(inputs)?;
    project_at(model, t, state, Some(inputs), tol, max_iter)
}

/// [`project_holonomic`] at `inputs`, when given.
fn project_at<M: Model>(
    model: &M,
    t: f64,
    state: &mut [f64],
    inputs: Option<&[f64]>,
    tol: f64,
    max_iter: usize,
) -> Result<(f64, usize), LinearizeError> {
    let info = M::info();
    check_len("state", state, info.state_len())?;
    finite(state, "state")?;
    if info.holonomic == 0 {
        return Ok((0.0, 0));
    }
    let retained = indices(info, info.retained, "retained")?;
    let mut q = vec![0.0; info.coordinates.len()];
    for (k, &i) in retained.iter().enumerate() {
        q[i] = state[k];
    }
    let all: Vec<usize> = (0..q.len()).collect();
    let (r, jac) = jacobian_at(model, t, &q, inputs, &all)?;
    if let Some(c) =
        (0..q.len()).find(|&c| !retained.contains(&c) && jac.column(c).iter().any(|&x| x != 0.0))
    {
        return Err(LinearizeError::InvalidArgument(format!(
            "the holonomic constraints involve `{}`, which the reduced state does not carry",
            info.coordinates[c]
        )));
    }
    let unknowns: Vec<usize> = unknowns_at(model, t, &q, inputs)?
        .into_iter()
        .filter(|i| retained.contains(i))
        .collect();
    let steps = solve_at(model, t, &mut q, inputs, &unknowns, tol, max_iter)?;
    for (k, &i) in retained.iter().enumerate() {
        state[k] = q[i];
    }
    Ok((r.norm(), steps))
}

/// Checks a reduced state (retained coordinates, then speeds, as
/// [`Model::rhs`] takes it) against the holonomic constraints: their
/// residuals f(q, t) with the ignorable coordinates at zero (they do not
/// enter the reduced equations). Returns the residuals when every one is
/// within `tol`, and [`LinearizeError::HolonomicViolated`] naming the first
/// one that is not, so a caller can refuse (or project, with
/// [`project_holonomic`]) a state the reduced equations were not derived
/// for. Errors also for wrong lengths and non-finite values.
///
/// ```
/// # use appell_core::{Model, ModelError, ModelInfo, OpCounts, Scalar};
/// # struct Ring { l: f64 }
/// # static INFO: ModelInfo = ModelInfo {
/// #     name: "Ring", parameters: &["l"], coordinates: &["x", "y"], speeds: &["x"],
/// #     dependent: &["y"], cyclic: &[], ignorable: &[], retained: &["x", "y"], inputs: &[],
/// #     effects: &[], outputs: &[], row_sources: &[], contacts: &[], holonomic: 1, constraints: 1, bodies: &[], force_points: 0,
/// #     torques: 0, form: "closed form", symbolic_elimination: false,
/// #     rhs_ops: OpCounts { add: 0, mul: 0, div: 0, calls: 0, total: 0 }, jacobian: None, equations: "",
/// # };
/// # fn unused() -> Result<(), ModelError> { Err(ModelError::NonFinite { what: "unused" }) }
/// # impl Model for Ring {
/// #     type Prepared<T: Scalar> = ();
/// #     fn info() -> &'static ModelInfo { &INFO }
/// #     fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> { out[0] = self.l; Ok(()) }
/// #     fn set_parameter(&mut self, _: &str, _: f64) -> bool { false }
/// #     fn prepare<T: Scalar>(&self) {}
/// #     fn rhs<T: Scalar>(&self, _: &(), _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn mass_matrix_and_forcing<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn speed_transform<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn coordinate_rates<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn constraint_residuals<T: Scalar>(&self, _: T, q: &[T], _: &[T], h: &mut [T], _: &mut [T]) -> Result<(), ModelError> {
/// #         let l = T::from_f64(self.l);
/// #         h[0] = q[0] * q[0] + q[1] * q[1] - l * l;
/// #         Ok(())
/// #     }
/// #     fn kinetic_energy<T: Scalar>(&self, _: T, _: &[T], _: &[T]) -> Result<T, ModelError> { unused().map(|_| T::zero()) }
/// #     fn mass_properties(&self, _: &mut [f64], _: &mut [[f64; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn body_poses<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn constraint_rows<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn load_geometry<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn load_values<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [[T; 3]], _: &mut [[T; 3]]) -> Result<(), ModelError> { unused() }
/// # }
/// use appell_linearize::{check_holonomic, LinearizeError};
/// // A particle on a circle of radius 1, state (x, y, ẋ).
/// assert!(check_holonomic(&Ring { l: 1.0 }, 0.0, &[0.6, -0.8, 0.3], 1e-12).is_ok());
/// assert!(matches!(
///     check_holonomic(&Ring { l: 1.0 }, 0.0, &[0.6, -0.81, 0.3], 1e-12),
///     Err(LinearizeError::HolonomicViolated { index: 0, .. })
/// ));
/// ```
pub fn check_holonomic<M: Model>(
    model: &M,
    t: f64,
    state: &[f64],
    tol: f64,
) -> Result<Vec<f64>, LinearizeError> {
    check_at(model, t, state, None, tol)
}

/// [`check_holonomic`] of a model with driven coordinates, the residuals
/// at `inputs` ([`Model::driven_constraint_residuals`]): a driven
/// coordinate's is its distance from the command. For a model without
/// driven coordinates it is `check_holonomic`. Errors also for `inputs` of
/// the wrong length or not finite. Example at [`driven_project_holonomic`].
pub fn driven_check_holonomic<M: Model>(
    model: &M,
    t: f64,
    state: &[f64],
    inputs: &[f64],
    tol: f64,
) -> Result<Vec<f64>, LinearizeError> {
    check_inputs::<M>(inputs)?;
    check_at(model, t, state, Some(inputs), tol)
}

/// [`check_holonomic`] at `inputs`, when given.
fn check_at<M: Model>(
    model: &M,
    t: f64,
    state: &[f64],
    inputs: Option<&[f64]>,
    tol: f64,
) -> Result<Vec<f64>, LinearizeError> {
    let info = M::info();
    check_len("state", state, info.state_len())?;
    finite(state, "state")?;
    if tol.is_nan() || tol < 0.0 {
        return Err(LinearizeError::InvalidArgument(format!(
            "the tolerance must be non-negative, not {tol}"
        )));
    }
    let retained = indices(info, info.retained, "retained")?;
    let n = info.coordinates.len();
    let mut q = vec![0.0; n];
    for (k, &i) in retained.iter().enumerate() {
        q[i] = state[k];
    }
    let (mut h, mut v) = (vec![0.0; info.holonomic], vec![0.0; info.constraints]);
    residuals_at(model, t, &q, inputs, &mut h, &mut v)?;
    if let Some((index, &residual)) = h
        .iter()
        .enumerate()
        .find(|(_, r)| r.is_nan() || r.abs() > tol)
    {
        return Err(LinearizeError::HolonomicViolated {
            index,
            residual,
            tolerance: tol,
        });
    }
    Ok(h)
}
