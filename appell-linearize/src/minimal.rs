//! The linearization in a minimal state: the retained coordinates fixed by
//! holonomic constraints eliminated, and the privileged speeds an operating
//! point holds fixed dropped.

use super::checks::{check_configuration, finite, indices};
use super::error::LinearizeError;
use super::holonomic::{jacobian_at, svd, RANK_RTOL};
use super::jacobian::{linearize, Linearization};
use appell_core::{check_len, Model};
use nalgebra::DMatrix;

// Items the documentation links to.
#[cfg(doc)]
use super::solve_holonomic;
#[cfg(doc)]
use appell_core::ModelInfo;

/// What remains of the constraint derivatives on the independent coordinates
/// after the elimination must be below this fraction of the Jacobian's scale.
const CONSISTENCY_RTOL: f64 = 1e-8;

/// A configuration is on the manifold when its holonomic residuals are below
/// this fraction of the first-order scale `max(1, ‖J‖ ‖q‖)`.
const MANIFOLD_RTOL: f64 = 1e-8;

/// The linearization in a minimal state at a full configuration `q_full`
/// (every coordinate, ignorable ones included), privileged speeds `u` (one
/// per [`ModelInfo::speeds`]) and `inputs`.
///
/// A reduced state can hold more than the motion needs:
///
/// * a retained coordinate fixed by a holonomic constraint (a bicycle's
///   pitch, determined by its lean and steer; `y` of a pendulum in
///   Cartesian coordinates) is eliminated: with J = ∂f/∂q at `q_full`, the
///   dependent retained coordinates the constraints involve follow the
///   others at first order, δq_dep = −J_dep⁺ J_indep δq_indep. The ignorable
///   coordinates (not retained) are free in this relation (they do not enter
///   the reduced rhs; any constraint they take up does not restrict the
///   retained ones), so J is first projected onto the complement of their
///   columns' range;
/// * the privileged speeds named in `fixed_speeds` (by their coordinate's
///   name, as in [`ModelInfo::speeds`], or as the state name
///   `"{coordinate}_dot"`) are held at their values in `u`: their rows and
///   columns are dropped (a bicycle's rear-wheel rate, i.e. its forward
///   speed, is a parameter of the steady motion being linearized about).
///
/// With x the reduced state (retained coordinates, then speeds) and z the
/// minimal one (the retained coordinates not eliminated, then the speeds not
/// fixed, in that order), `x − x0 = T (z − z0)` to first order, and the
/// result is `A_z = P A T`, `B_z = P B` where A, B come from [`linearize`]
/// and P selects z's rows.
///
/// Assumptions: first order about the point; `q_full` satisfies the
/// holonomic constraints (use [`solve_holonomic`]); the fixed speeds are
/// parameters of the operating point (their own dynamics, and any drift of
/// them, are ignored); the point need not be an equilibrium.
///
/// Errors: wrong lengths and non-finite values ([`LinearizeError::Model`]),
/// [`LinearizeError::UnknownName`] for a name that is not a speed,
/// [`LinearizeError::InvalidInfo`] for an inconsistent [`ModelInfo`],
/// [`LinearizeError::NotOnManifold`] when the residuals exceed
/// `1e-8 · max(1, ‖J‖ ‖q‖)`, [`LinearizeError::RankDeficient`] when the
/// constraints do not determine the dependent retained coordinates they
/// involve, [`LinearizeError::SingularCoordinates`] when they restrict the
/// others at first order, and any error of the model. Example in the module
/// documentation.
pub fn minimal_linearization<M: Model>(
    model: &M,
    t: f64,
    q_full: &[f64],
    u: &[f64],
    inputs: &[f64],
    fixed_speeds: &[&str],
) -> Result<Linearization, LinearizeError> {
    let info = M::info();
    let (nr, nl) = (info.retained.len(), info.speeds.len());
    check_configuration(info, t, q_full)?;
    check_len("u", u, nl)?;
    finite(u, "u")?;
    model.validate()?;
    let retained = indices(info, info.retained, "retained")?;
    let dependent = indices(info, info.dependent, "dependent")?;
    indices(info, info.speeds, "speeds")?;

    let mut fixed = vec![false; nl];
    for name in fixed_speeds {
        let k = info
            .speeds
            .iter()
            .position(|s| s == name)
            .or_else(|| {
                info.speeds
                    .iter()
                    .position(|s| name.strip_suffix("_dot") == Some(*s))
            })
            .ok_or_else(|| LinearizeError::UnknownName(name.to_string()))?;
        fixed[k] = true;
    }

    let state: Vec<f64> = retained
        .iter()
        .map(|&i| q_full[i])
        .chain(u.iter().copied())
        .collect();
    let full = linearize(model, t, &state, inputs)?;

    let Elimination {
        eliminated,
        kept,
        follow,
    } = eliminate(model, t, q_full, inputs, &retained, &dependent)?;

    // z: the kept retained coordinates, then the speeds not fixed.
    let speeds: Vec<usize> = (0..nl).filter(|&k| !fixed[k]).collect();
    let rows: Vec<usize> = kept
        .iter()
        .copied()
        .chain(speeds.iter().map(|&k| nr + k))
        .collect();
    let nz = rows.len();
    let mut tmat = DMatrix::<f64>::zeros(nr + nl, nz);
    for (col, &row) in rows.iter().enumerate() {
        tmat[(row, col)] = 1.0;
    }
    for (e, &p) in eliminated.iter().enumerate() {
        for k in 0..kept.len() {
            tmat[(p, k)] = follow[(e, k)];
        }
    }
    let a = full.a.select_rows(&rows) * tmat;
    let b = full.b.select_rows(&rows);
    finite(a.as_slice(), "the minimal state Jacobian")?;
    let state_names = rows.iter().map(|&r| full.state_names[r].clone()).collect();
    Ok(Linearization {
        a,
        b,
        state_names,
        input_names: full.input_names,
    })
}

/// The retained coordinates a holonomic constraint fixes, as positions in
/// the retained list, and the first-order dependence of each on the kept
/// ones.
struct Elimination {
    /// Positions eliminated.
    eliminated: Vec<usize>,
    /// Positions kept.
    kept: Vec<usize>,
    /// |eliminated| × |kept|: δq_eliminated = follow δq_kept.
    follow: DMatrix<f64>,
}

/// [`Elimination`] at `q_full` (every coordinate), `retained` and
/// `dependent` the coordinates' indices; errors as
/// [`minimal_linearization`]'s for the constraints.
fn eliminate<M: Model>(
    model: &M,
    t: f64,
    q_full: &[f64],
    inputs: &[f64],
    retained: &[usize],
    dependent: &[usize],
) -> Result<Elimination, LinearizeError> {
    let info = M::info();
    let (n, nr) = (info.coordinates.len(), retained.len());
    let mut eliminated: Vec<usize> = Vec::new();
    let mut kept: Vec<usize> = (0..nr).collect();
    let mut follow = DMatrix::<f64>::zeros(0, nr);
    if info.holonomic > 0 {
        let all: Vec<usize> = (0..n).collect();
        // At the inputs: a driven coordinate's constraint reads its command
        // (for every other model they are not read).
        let (f0, jac) = jacobian_at(model, t, q_full, Some(inputs), &all)?;
        let residual = f0.norm();
        let q_scale = q_full.iter().fold(0.0_f64, |s, x| s.max(x.abs()));
        let tolerance = MANIFOLD_RTOL * (jac.norm() * q_scale).max(1.0);
        if residual > tolerance {
            return Err(LinearizeError::NotOnManifold {
                residual,
                tolerance,
            });
        }
        let scale = jac.amax();
        let cutoff = RANK_RTOL * scale;
        // Project out what the ignorable coordinates can take up.
        let free: Vec<usize> = (0..n).filter(|i| !retained.contains(i)).collect();
        let jg = jac.select_columns(&free);
        let projected = if jg.amax() > cutoff {
            let h = info.holonomic;
            let pinv = svd(jg.clone())?
                .pseudo_inverse(cutoff)
                .map_err(|_| LinearizeError::DecompositionFailed { what: "SVD" })?;
            (DMatrix::<f64>::identity(h, h) - &jg * pinv) * &jac
        } else {
            jac
        };
        let involved = |c: usize| -> bool { projected.column(c).iter().any(|x| x.abs() > cutoff) };
        eliminated = (0..nr)
            .filter(|&p| dependent.contains(&retained[p]) && involved(retained[p]))
            .collect();
        kept = (0..nr).filter(|p| !eliminated.contains(p)).collect();
        let cols = |ps: &[usize]| -> Vec<usize> { ps.iter().map(|&p| retained[p]).collect() };
        let j_kept = projected.select_columns(&cols(&kept));
        let remainder;
        if eliminated.is_empty() {
            follow = DMatrix::zeros(0, kept.len());
            remainder = j_kept;
        } else {
            let j_elim = projected.select_columns(&cols(&eliminated));
            let dec = svd(j_elim.clone())?;
            let rank = dec.singular_values.iter().filter(|&&s| s > cutoff).count();
            if rank < eliminated.len() {
                return Err(LinearizeError::RankDeficient {
                    rank,
                    expected: eliminated.len(),
                });
            }
            follow = -dec
                .solve(&j_kept, cutoff)
                .map_err(|_| LinearizeError::DecompositionFailed { what: "SVD" })?;
            remainder = &j_elim * &follow + &j_kept;
        }
        // Whatever the elimination leaves must vanish: otherwise the
        // constraints restrict the kept coordinates themselves.
        let left = remainder.amax();
        if left > CONSISTENCY_RTOL * scale * follow.amax().max(1.0) {
            return Err(LinearizeError::SingularCoordinates { residual: left });
        }
        finite(follow.as_slice(), "the constraint elimination")?;
    }
    Ok(Elimination {
        eliminated,
        kept,
        follow,
    })
}
