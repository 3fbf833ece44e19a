//! The Jacobian and the factored iteration matrices of the real and the
//! complex Newton system, `γ/h − J` and `(α − iβ)/h − J`.

use super::coefficients::{ALPHA, BETA, GAMMA};
use super::linear::{factor_pair, solve_pair, Lu, C64};
use super::stats::Radau5Stats;
use crate::implicit::all_finite;
use crate::solution::IntegrateError;
use appell_core::ModelError;

/// The Jacobian, its age and the LU factors of both iteration matrices.
pub(super) struct Iteration {
    jac: Vec<f64>,
    /// A Jacobian has been computed (at some earlier state).
    pub(super) have_jac: bool,
    /// The Jacobian was computed at the start of the current step.
    pub(super) fresh: bool,
    real: Lu<f64>,
    complex: Lu<C64>,
    /// The signed step both factorizations are for, if they are valid.
    lu_h: Option<f64>,
}

impl Iteration {
    /// No Jacobian yet, for a state of `n` components.
    pub(super) fn new(n: usize) -> Self {
        Iteration {
            jac: vec![0.0; n * n],
            have_jac: false,
            fresh: false,
            real: Lu::new(n),
            complex: Lu::new(n),
            lu_h: None,
        }
    }

    /// Evaluates the Jacobian at `(t, x)` by `jac_fn` unless one is kept;
    /// a new one is fresh and invalidates the factorizations.
    pub(super) fn refresh<J>(
        &mut self,
        jac_fn: &mut J,
        t: f64,
        x: &[f64],
        stats: &mut Radau5Stats,
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
            self.lu_h = None;
        }
        Ok(())
    }

    /// Makes the factorizations those for the signed step `hs`
    /// (refactoring only when the step or the Jacobian changed); false when
    /// an iteration matrix is singular.
    pub(super) fn prepare(&mut self, hs: f64, stats: &mut Radau5Stats) -> bool {
        if self.lu_h == Some(hs) {
            return true;
        }
        stats.lu_factorizations += 1;
        let mu = C64::new(ALPHA / hs, -BETA / hs);
        let ok = factor_pair(&mut self.real, &mut self.complex, GAMMA / hs, mu, &self.jac);
        self.lu_h = ok.then_some(hs);
        ok
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

    /// After a rejected step: a stale Jacobian is recomputed for the retry.
    pub(super) fn after_rejection(&mut self) {
        if !self.fresh {
            self.have_jac = false;
        }
    }

    /// Solves `(γ/h − J) y = b` in place.
    pub(super) fn solve_real(&self, b: &mut [f64]) {
        self.real.solve(b);
    }

    /// Solves `(γ/h − J) y = b` and `((α − iβ)/h − J) w = c` in place, in
    /// one interleaved pass.
    pub(super) fn solve_both(&self, b: &mut [f64], c: &mut [C64]) {
        solve_pair(&self.real, &self.complex, b, c);
    }
}
