//! The coordinate rates from the privileged speeds, and the reduced
//! right-hand side in the layout of [`Model::rhs`].

use super::error::OracleError;
use super::kkt::{accelerations_with, lu_solve_checked};
use super::layout::{finite_all, Layout};
use appell_core::dynamic::DynModel;
use appell_core::{check_len, Model};
use nalgebra::{DMatrix, DVector};

// Items the documentation links to.
#[cfg(doc)]
use super::accelerations;
#[cfg(doc)]
use appell_core::ModelInfo;

/// All coordinate rates q̇ from the privileged speeds `u` (one per
/// [`ModelInfo::speeds`], in that order): the privileged rates are `u` and
/// the others solve D q̇ + d = 0 (LU with partial pivoting on the columns of
/// D at the dependent coordinates; a pivot within rounding noise of zero,
/// relative to the largest entry of D, counts as singular). Independent of
/// [`Model::coordinate_rates`]; example in the module documentation.
///
/// Errors: wrong lengths, non-finite values, an inconsistent [`ModelInfo`],
/// model errors, and [`OracleError::SingularConstraints`] when the dependent
/// block of D is singular.
pub fn coordinate_rates<M: Model>(
    model: &M,
    t: f64,
    q_full: &[f64],
    u: &[f64],
) -> Result<Vec<f64>, OracleError> {
    coordinate_rates_dyn(model, t, q_full, u)
}

/// [`coordinate_rates`] of any [`DynModel`] (compiled once for `dyn DynModel`).
pub(crate) fn coordinate_rates_dyn<K: DynModel + ?Sized>(
    model: &K,
    t: f64,
    q_full: &[f64],
    u: &[f64],
) -> Result<Vec<f64>, OracleError> {
    let lay = Layout::new(model.dyn_info())?;
    coordinate_rates_with(model, &lay, t, q_full, u, &[])
}

/// [`coordinate_rates`] at `inputs` too, for a model whose constraints
/// read inputs (driven coordinates; [`Model::driven_constraint_rows`]).
pub(crate) fn driven_coordinate_rates_dyn<K: DynModel + ?Sized>(
    model: &K,
    t: f64,
    q_full: &[f64],
    u: &[f64],
    inputs: &[f64],
) -> Result<Vec<f64>, OracleError> {
    let lay = Layout::new(model.dyn_info())?;
    coordinate_rates_with(model, &lay, t, q_full, u, inputs)
}

fn coordinate_rates_with<K: DynModel + ?Sized>(
    model: &K,
    lay: &Layout,
    t: f64,
    q_full: &[f64],
    u: &[f64],
    inputs: &[f64],
) -> Result<Vec<f64>, OracleError> {
    let (n, m, l) = (lay.n, lay.m, lay.l);
    check_len("q", q_full, n)?;
    check_len("u", u, l)?;
    finite_all([t], "t")?;
    finite_all(q_full.iter().copied(), "q")?;
    finite_all(u.iter().copied(), "u")?;
    let mut dmat = vec![0.0; m * n];
    let mut doff = vec![0.0; m];
    model.dyn_driven_constraint_rows(t, q_full, inputs, &mut dmat, &mut doff)?;
    finite_all(dmat.iter().chain(&doff).copied(), "the constraint rows")?;
    let mut w = vec![0.0; l * n];
    let mut w0 = vec![0.0; l];
    model.dyn_speed_definitions(t, q_full, &mut w, &mut w0)?;
    finite_all(w.iter().chain(&w0).copied(), "the speed definitions")?;
    // [D; W] q̇ = [−d; u − w]
    let mut a = DMatrix::<f64>::zeros(n, n);
    let mut b = DVector::<f64>::zeros(n);
    for row in 0..m {
        for c in 0..n {
            a[(row, c)] = dmat[row * n + c];
        }
        b[row] = -doff[row];
    }
    for k in 0..l {
        for c in 0..n {
            a[(m + k, c)] = w[k * n + c];
        }
        b[m + k] = u[k] - w0[k];
    }
    let info = model.dyn_info();
    // Measured against the whole system: a column can be negligible only
    // relative to the rows it belongs to.
    let scale = dmat.iter().chain(&w).fold(0.0_f64, |s, x| s.max(x.abs()));
    let qdot = lu_solve_checked(a, b, scale, |k, pivot, tolerance| {
        OracleError::SingularConstraints {
            coordinate: info.coordinates[k.min(n - 1)],
            pivot,
            tolerance,
        }
    })?;
    finite_all(qdot.iter().copied(), "the coordinate rates")?;
    Ok(qdot.iter().copied().collect())
}

/// The reduced right-hand side in the layout of [`Model::rhs`]'s `dstate`:
/// the rates of the [`ModelInfo::retained`] coordinates, then the privileged
/// accelerations, at full coordinates `q_full` (ignorable ones included),
/// privileged speeds `u` and `inputs`.
///
/// q̇ comes from [`coordinate_rates`] (this module's, not the model's), q̈
/// from [`accelerations`]; errors are theirs. Example in the module
/// documentation.
pub fn reduced_rhs<M: Model>(
    model: &M,
    t: f64,
    q_full: &[f64],
    u: &[f64],
    inputs: &[f64],
) -> Result<Vec<f64>, OracleError> {
    reduced_rhs_dyn(model, t, q_full, u, inputs)
}

/// [`reduced_rhs`] of any [`DynModel`] (compiled once for `dyn DynModel`).
// Shared with the crates built on this one; not part of the API.
#[doc(hidden)]
pub fn reduced_rhs_dyn<K: DynModel + ?Sized>(
    model: &K,
    t: f64,
    q_full: &[f64],
    u: &[f64],
    inputs: &[f64],
) -> Result<Vec<f64>, OracleError> {
    let lay = Layout::new(model.dyn_info())?;
    let qdot = coordinate_rates_with(model, &lay, t, q_full, u, inputs)?;
    let sol = accelerations_with(model, &lay, t, q_full, &qdot, inputs)?;
    let mut out = Vec::with_capacity(lay.retained.len() + lay.l);
    out.extend(lay.retained.iter().map(|&i| qdot[i]));
    out.extend(sol.privileged);
    Ok(out)
}
