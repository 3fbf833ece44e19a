//! Newton onto the holonomic constraints of a [`DynModel`]: the coordinates
//! the constraints fix (a bicycle's pitch) solved from the others. The
//! generic [`crate::solve_holonomic`] needs a [`Model`](appell_core::Model)
//! (it seeds dual numbers); this works on the object-safe model the command
//! line holds, with the Jacobian read from the holonomic rows of D.

use appell_core::dynamic::DynModel;
use appell_core::{ModelError, ModelInfo, RowSource};
use nalgebra::{DMatrix, DVector};

/// Converged when every holonomic residual is at most this × (1 + max |q|).
pub const TOLERANCE: f64 = 1e-12;

/// Newton steps before giving up.
const MAX_ITERATIONS: usize = 50;

/// Halvings of a step before giving up on decreasing the residual.
const MAX_BACKTRACKS: usize = 30;

/// A Jacobian column at most this × its largest entry counts as zero.
const RANK_RTOL: f64 = 1e-10;

/// Why the coordinates could not be solved.
#[derive(Debug)]
pub enum OntoError {
    /// The model failed (a singular configuration, wrong lengths, ..).
    Model(ModelError),
    /// No step brought the residuals under the tolerance.
    NotConverged {
        /// Newton steps taken.
        iterations: usize,
        /// The largest |residual| left.
        residual: f64,
    },
}

impl From<ModelError> for OntoError {
    fn from(e: ModelError) -> Self {
        OntoError::Model(e)
    }
}

impl core::fmt::Display for OntoError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            OntoError::Model(e) => write!(f, "{e}"),
            OntoError::NotConverged {
                iterations,
                residual,
            } => write!(
                f,
                "Newton's method left a holonomic residual of {residual:e} after {iterations} steps"
            ),
        }
    }
}

/// For every holonomic residual, its row of D (the constraint
/// differentiated): found through [`ModelInfo::row_sources`], or the first
/// rows when the model does not list its rows' sources.
fn holonomic_rows(info: &ModelInfo) -> Vec<usize> {
    let listed: Option<Vec<usize>> = (0..info.holonomic)
        .map(|k| {
            info.row_sources.iter().position(|s| match *s {
                RowSource::Holonomic { index } => index == k,
                RowSource::Driven {
                    holonomic, index, ..
                } => holonomic && index == k,
                _ => false,
            })
        })
        .collect();
    match listed {
        Some(rows) if info.row_sources.len() == info.constraints => rows,
        _ => (0..info.holonomic).collect(),
    }
}

/// The holonomic residuals at `q` (zero coordinate rates).
pub fn residuals(
    model: &dyn DynModel,
    t: f64,
    q: &[f64],
    inputs: &[f64],
) -> Result<Vec<f64>, ModelError> {
    let info = model.dyn_info();
    let (mut h, mut v) = (vec![0.0; info.holonomic], vec![0.0; info.constraints]);
    let qdot = vec![0.0; q.len()];
    model.dyn_driven_constraint_residuals(t, q, &qdot, inputs, &mut h, &mut v)?;
    Ok(h)
}

/// The Jacobian of the holonomic residuals at `q` with respect to the
/// coordinates `cols` (holonomic × cols.len()).
fn jacobian(
    model: &dyn DynModel,
    t: f64,
    q: &[f64],
    inputs: &[f64],
    cols: &[usize],
) -> Result<DMatrix<f64>, ModelError> {
    let info = model.dyn_info();
    let (n, m) = (info.coordinates.len(), info.constraints);
    let (mut d, mut d0) = (vec![0.0; m * n], vec![0.0; m]);
    model.dyn_driven_constraint_rows(t, q, inputs, &mut d, &mut d0)?;
    let rows = holonomic_rows(info);
    Ok(DMatrix::from_fn(rows.len(), cols.len(), |i, k| {
        d.get(rows[i] * n + cols[k]).copied().unwrap_or(0.0)
    }))
}

/// The largest |x|.
fn amax(x: &[f64]) -> f64 {
    x.iter().fold(0.0f64, |a, v| a.max(v.abs()))
}

/// Which of `candidates` (indices into [`ModelInfo::coordinates`]) the
/// holonomic constraints involve at `q`, and which constraints involve
/// them: the columns and rows of the constraints' Jacobian, restricted to
/// the candidates, that are not zero. Both ascending.
pub fn involved(
    model: &dyn DynModel,
    t: f64,
    q: &[f64],
    inputs: &[f64],
    candidates: &[usize],
) -> Result<(Vec<usize>, Vec<usize>), ModelError> {
    if model.dyn_info().holonomic == 0 || candidates.is_empty() {
        return Ok((Vec::new(), Vec::new()));
    }
    let j = jacobian(model, t, q, inputs, candidates)?;
    let small = RANK_RTOL * j.amax();
    let nonzero = j.map(|x| x.abs() > small && small > 0.0);
    let cols = (0..j.ncols())
        .filter(|&k| nonzero.column(k).iter().any(|&b| b))
        .map(|k| candidates[k])
        .collect();
    let rows = (0..j.nrows())
        .filter(|&i| nonzero.row(i).iter().any(|&b| b))
        .collect();
    Ok((cols, rows))
}

/// Solves the holonomic constraints `rows` (indices of residuals) for the
/// coordinates `unknowns`, starting from and updating `q` (the others
/// held): Newton's method, the least-squares (minimum-norm) step when the
/// Jacobian is not square or not of full rank, each step halved until it
/// decreases the residuals' norm. Converged when each of the residuals is
/// at most [`TOLERANCE`] × (1 + max |q|). Returns the largest of them left.
/// The other constraints are not looked at: they do not involve the
/// unknowns, and may be violated by the coordinates held.
pub fn solve(
    model: &dyn DynModel,
    t: f64,
    q: &mut [f64],
    inputs: &[f64],
    unknowns: &[usize],
    rows: &[usize],
) -> Result<f64, OntoError> {
    let some = |h: Vec<f64>| -> Vec<f64> {
        rows.iter()
            .map(|&i| h.get(i).copied().unwrap_or(f64::NAN))
            .collect()
    };
    let mut r = some(residuals(model, t, q, inputs)?);
    let mut trial = q.to_vec();
    let mut iteration = 0;
    loop {
        if r.iter().any(|x| !x.is_finite()) {
            return Err(ModelError::NonFinite {
                what: "a holonomic residual",
            }
            .into());
        }
        let left = amax(&r);
        if left <= TOLERANCE * (1.0 + amax(q)) {
            return Ok(left);
        }
        let stuck = OntoError::NotConverged {
            iterations: iteration,
            residual: left,
        };
        if iteration == MAX_ITERATIONS || unknowns.is_empty() {
            return Err(stuck);
        }
        let full = jacobian(model, t, q, inputs, unknowns)?;
        let j = full.select_rows(rows);
        let cutoff = RANK_RTOL * j.amax();
        if cutoff.is_nan() || cutoff <= 0.0 || j.iter().any(|x| !x.is_finite()) {
            // Flat in every unknown here, or not finite: no direction.
            return Err(stuck);
        }
        let rhs = -DVector::from_column_slice(&r);
        let step = nalgebra::SVD::try_new(j, true, true, f64::EPSILON, 200)
            .and_then(|svd| svd.solve(&rhs, cutoff).ok())
            .ok_or(stuck)?;
        let norm = |x: &[f64]| x.iter().map(|v| v * v).sum::<f64>().sqrt();
        let (start, mut alpha) = (norm(&r), 1.0);
        let mut accepted = None;
        for _ in 0..=MAX_BACKTRACKS {
            trial.copy_from_slice(q);
            for (k, &i) in unknowns.iter().enumerate() {
                trial[i] += alpha * step[k];
            }
            if trial.iter().all(|x| x.is_finite()) {
                // A model error at a trial point (a singular configuration
                // overshot into) is a step too long, not the end.
                if let Ok(rt) = residuals(model, t, &trial, inputs).map(some) {
                    if norm(&rt) < start {
                        accepted = Some(rt);
                        break;
                    }
                }
            }
            alpha *= 0.5;
        }
        let Some(rt) = accepted else {
            return Err(OntoError::NotConverged {
                iterations: iteration,
                residual: left,
            });
        };
        q.copy_from_slice(&trial);
        r = rt;
        iteration += 1;
    }
}
