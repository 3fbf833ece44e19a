//! The Newton iteration of the implicit stages: the Jacobian, the
//! factored iteration matrix `I − h d J` and the simplified Newton solve.

use super::coefficients::D;
use super::control::{all_finite, wrms, FAC_NEWTON};
use super::stats::TrBdf2Stats;
use crate::solution::IntegrateError;
use appell_core::ModelError;
use nalgebra::{DMatrix, DVector};

const NEWTON_KAPPA: f64 = 0.01;
const NEWTON_DIVERGE: f64 = 0.9;
pub(super) const JAC_SLOW: f64 = 0.2;

/// The Newton tolerance κ for the relative tolerance `rtol`: 0.01, not
/// below what rounding allows (as in RADAU5).
pub(super) fn newton_tolerance(rtol: f64) -> f64 {
    if rtol > 0.0 {
        NEWTON_KAPPA.max(10.0 * f64::EPSILON / rtol)
    } else {
        NEWTON_KAPPA
    }
}

/// How a Newton solve of a stage ended (model errors are passed on).
pub(super) enum Newton {
    /// Converged, with the largest contraction rate seen.
    Converged { theta: f64 },
    /// Diverged, too slow, or a non-finite value (`true`).
    Failed { non_finite: bool },
}

/// The state of the iteration matrix and its factorization.
pub(super) struct Iteration {
    pub(super) n: usize,
    pub(super) jac: Vec<f64>,
    /// A Jacobian has been computed (at some earlier point).
    pub(super) have_jac: bool,
    /// The Jacobian was computed at the start of the current step.
    pub(super) fresh: bool,
    pub(super) lu: Option<nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>>,
    /// The signed step the factorization is for.
    pub(super) lu_h: f64,
    /// The Newton rate estimate η carried between solves.
    pub(super) eta: f64,
}

impl Iteration {
    /// No Jacobian yet, for a state of `n` components.
    pub(super) fn new(n: usize) -> Self {
        Iteration {
            n,
            jac: vec![0.0; n * n],
            have_jac: false,
            fresh: false,
            lu: None,
            lu_h: 0.0,
            eta: 1.0,
        }
    }

    /// Evaluates the Jacobian at `(t, x)` by `jac_fn` unless one is current
    /// (it then counts as fresh and needs a new factorization).
    pub(super) fn refresh<J>(
        &mut self,
        jac_fn: &mut J,
        t: f64,
        x: &[f64],
        stats: &mut TrBdf2Stats,
    ) -> Result<(), IntegrateError>
    where
        J: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
    {
        if !self.have_jac {
            jac_fn(t, x, &mut self.jac)?;
            stats.jacobians += 1;
            if !all_finite(&self.jac) {
                return Err(IntegrateError::NonFinite { t });
            }
            self.have_jac = true;
            self.fresh = true;
            self.lu = None;
        }
        Ok(())
    }

    /// After an accepted step: the Jacobian is no longer fresh, and is
    /// recomputed for the next step when Newton's iteration converged
    /// `slow`ly under it.
    pub(super) fn after_acceptance(&mut self, slow: bool) {
        self.fresh = false;
        if slow {
            self.have_jac = false;
        }
    }

    /// After a Newton failure or a singular iteration matrix, which rejects
    /// the step (counted in `stats`): the step size to try next, `h` again
    /// with a new Jacobian when the current one is stale, else `h` 4×
    /// smaller.
    pub(super) fn after_failure(&mut self, h: f64, stats: &mut TrBdf2Stats) -> f64 {
        stats.newton_failures += 1;
        stats.rejected += 1;
        if self.fresh {
            h * FAC_NEWTON
        } else {
            // Retry the same step with a new Jacobian.
            self.have_jac = false;
            h
        }
    }

    /// Factors `I − h d J`; false when it is singular or not finite.
    pub(super) fn factor(&mut self, h: f64, stats: &mut TrBdf2Stats) -> bool {
        let n = self.n;
        let hd = h * D;
        let jac = &self.jac;
        let m = DMatrix::from_fn(n, n, |i, j| {
            (if i == j { 1.0 } else { 0.0 }) - hd * jac[i * n + j]
        });
        stats.lu_factorizations += 1;
        let lu = m.lu();
        if !lu.is_invertible() {
            self.lu = None;
            return false;
        }
        self.lu = Some(lu);
        self.lu_h = h;
        true
    }

    /// Solves `(I − h d J) y = b` in place; false on failure.
    pub(super) fn solve(&self, b: &mut [f64]) -> bool {
        let Some(lu) = &self.lu else { return false };
        let mut v = DVector::from_column_slice(b);
        if !lu.solve_mut(&mut v) {
            return false;
        }
        b.copy_from_slice(v.as_slice());
        all_finite(b)
    }

    /// Solves `y = psi + h d f(t, y)` for `y` (holding the predictor on
    /// entry), scaled by `sk`; on success `fy` is `(y − psi)/(h d)`.
    // called once per stage (TR, then BDF2) with that stage's time, psi and y/fy buffers from
    // Stages; self is the Iteration, a separate struct holding the factored matrix
    #[allow(clippy::too_many_arguments)]
    pub(super) fn newton<F>(
        &mut self,
        f: &mut F,
        kappa: f64,
        max_newton: usize,
        t: f64,
        hd: f64,
        psi: &[f64],
        sk: &[f64],
        y: &mut [f64],
        fy: &mut [f64],
        stats: &mut TrBdf2Stats,
    ) -> Result<Newton, ModelError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
    {
        let n = self.n;
        let mut dy = vec![0.0; n];
        let mut norm_old = 0.0;
        let mut theta_max: f64 = 0.0;
        let mut eta = self.eta.max(f64::EPSILON).powf(0.8);
        for k in 0..max_newton {
            stats.rhs_calls += 1;
            f(t, y, fy)?;
            if !all_finite(fy) {
                return Ok(Newton::Failed { non_finite: true });
            }
            for i in 0..n {
                dy[i] = psi[i] + hd * fy[i] - y[i];
            }
            if !self.solve(&mut dy) {
                return Ok(Newton::Failed { non_finite: true });
            }
            stats.newton_iterations += 1;
            for i in 0..n {
                y[i] += dy[i];
            }
            let norm = wrms(&dy, sk);
            if !norm.is_finite() {
                return Ok(Newton::Failed { non_finite: true });
            }
            if k > 0 {
                let theta = norm / norm_old;
                theta_max = theta_max.max(theta);
                if theta >= NEWTON_DIVERGE {
                    return Ok(Newton::Failed { non_finite: false });
                }
                eta = theta / (1.0 - theta);
            }
            if eta * norm <= kappa || norm == 0.0 {
                self.eta = eta;
                for i in 0..n {
                    fy[i] = (y[i] - psi[i]) / hd;
                }
                return Ok(Newton::Converged { theta: theta_max });
            }
            norm_old = norm;
        }
        Ok(Newton::Failed { non_finite: false })
    }
}
