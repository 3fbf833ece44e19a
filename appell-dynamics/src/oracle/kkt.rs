//! The solve: the KKT system of the assembled equations by LU with partial
//! pivoting, and the privileged accelerations from its q̈.

use super::assembly::{full_dynamics_with, FullDynamics};
use super::error::OracleError;
use super::layout::{finite_all, Layout};
use appell_core::dynamic::DynModel;
use appell_core::Model;
use nalgebra::{DMatrix, DVector};
use num_dual::Dual64;

// Items the documentation links to.
#[cfg(doc)]
use super::full_dynamics;
#[cfg(doc)]
use appell_core::ModelInfo;

/// Relative size (in units of `dim · ε · scale`) below which an LU pivot
/// counts as zero: a little above the rounding noise of the elimination.
const PIVOT_TOLERANCE: f64 = 64.0;

/// Solves the square system `a x = b` by LU with partial pivoting; a pivot
/// below `PIVOT_TOLERANCE · dim · ε · scale` is reported through
/// `singular(index, pivot, tol)`. `scale` is the magnitude the entries are
/// measured against (the largest entry of the whole system they come from).
pub(super) fn lu_solve_checked(
    a: DMatrix<f64>,
    b: DVector<f64>,
    scale: f64,
    singular: impl Fn(usize, f64, f64) -> OracleError,
) -> Result<DVector<f64>, OracleError> {
    let dim = a.nrows();
    if dim == 0 {
        return Ok(b);
    }
    let tol = PIVOT_TOLERANCE * scale * dim as f64 * f64::EPSILON;
    let lu = a.lu();
    let u = lu.u();
    let (mut index, mut pivot) = (0, f64::INFINITY);
    for i in 0..dim {
        let p = u[(i, i)].abs();
        if p < pivot {
            pivot = p;
            index = i;
        }
    }
    if scale == 0.0 || pivot <= tol {
        return Err(singular(index, pivot, tol));
    }
    lu.solve(&b).ok_or_else(|| singular(index, pivot, tol))
}

/// Solves the KKT system of `full`.
fn solve_kkt(full: &FullDynamics) -> Result<(Vec<f64>, Vec<f64>), OracleError> {
    let (n, m) = (full.n, full.m);
    let dim = n + m;
    let mut a = DMatrix::<f64>::zeros(dim, dim);
    let mut b = DVector::<f64>::zeros(dim);
    for r in 0..n {
        for c in 0..n {
            a[(r, c)] = full.mass[r * n + c];
        }
        b[r] = full.forces[r] - full.bias[r];
    }
    for i in 0..m {
        for c in 0..n {
            let dic = full.constraint_matrix[i * n + c];
            a[(n + i, c)] = dic;
            a[(c, n + i)] = dic;
        }
        b[n + i] = -full.constraint_bias[i];
    }
    let scale = a.amax();
    let x = lu_solve_checked(a, b, scale, |index, pivot, tolerance| {
        OracleError::SingularKkt {
            index,
            pivot,
            tolerance,
        }
    })?;
    finite_all(x.iter().copied(), "the accelerations")?;
    let qddot = x.rows(0, n).iter().copied().collect();
    let multipliers = x.rows(n, m).iter().map(|v| -v).collect();
    Ok((qddot, multipliers))
}

/// The result of [`accelerations`].
#[derive(Clone, Debug, PartialEq)]
pub struct OracleSolution {
    /// q̈ for every coordinate, in [`ModelInfo::coordinates`] order.
    pub qddot: Vec<f64>,
    /// The multipliers λ, one per velocity constraint row.
    pub multipliers: Vec<f64>,
    /// The privileged accelerations: q̈ at the coordinates named in
    /// [`ModelInfo::speeds`], in that order.
    pub privileged: Vec<f64>,
}

/// The accelerations q̈, the multipliers λ and the privileged accelerations at
/// `(t, q, q̇)` and `inputs`, by the full-coordinate multiplier route (example
/// in the module documentation).
///
/// `q̇` should satisfy the velocity constraints D q̇ + d = 0 (the result
/// answers "what would q̈ be at this state"; it is computed for any q̇).
/// Errors as for [`full_dynamics`], plus [`OracleError::SingularKkt`] when
/// the KKT matrix is singular.
pub fn accelerations<M: Model>(
    model: &M,
    t: f64,
    q: &[f64],
    qdot: &[f64],
    inputs: &[f64],
) -> Result<OracleSolution, OracleError> {
    accelerations_dyn(model, t, q, qdot, inputs)
}

/// [`accelerations`] of any [`DynModel`] (compiled once for `dyn DynModel`).
pub(crate) fn accelerations_dyn<K: DynModel + ?Sized>(
    model: &K,
    t: f64,
    q: &[f64],
    qdot: &[f64],
    inputs: &[f64],
) -> Result<OracleSolution, OracleError> {
    let lay = Layout::new(model.dyn_info())?;
    accelerations_with(model, &lay, t, q, qdot, inputs)
}

pub(super) fn accelerations_with<K: DynModel + ?Sized>(
    model: &K,
    lay: &Layout,
    t: f64,
    q: &[f64],
    qdot: &[f64],
    inputs: &[f64],
) -> Result<OracleSolution, OracleError> {
    let full = full_dynamics_with(model, lay, t, q, qdot, inputs)?;
    let (qddot, multipliers) = solve_kkt(&full)?;
    // u = W q̇ + w  ⇒  u̇ = W q̈ + (Ẇ q̇ + ẇ), the bias by a dual number
    // along (q̇, 1).
    let (n, l) = (lay.n, lay.l);
    let mut w = vec![0.0; l * n];
    let mut w0 = vec![0.0; l];
    model.dyn_speed_definitions(t, q, &mut w, &mut w0)?;
    let qd: Vec<Dual64> = q
        .iter()
        .zip(qdot)
        .map(|(&a, &b)| Dual64::new(a, b))
        .collect();
    let mut wd = vec![Dual64::from(0.0); l * n];
    let mut w0d = vec![Dual64::from(0.0); l];
    model.dyn_speed_definitions_dual(Dual64::new(t, 1.0), &qd, &mut wd, &mut w0d)?;
    let privileged: Vec<f64> = (0..l)
        .map(|k| {
            let mut acc = w0d[k].eps;
            for c in 0..n {
                acc += w[k * n + c] * qddot[c] + wd[k * n + c].eps * qdot[c];
            }
            acc
        })
        .collect();
    finite_all(privileged.iter().copied(), "the privileged accelerations")?;
    Ok(OracleSolution {
        qddot,
        multipliers,
        privileged,
    })
}
