//! The TR-BDF2 stages: the coefficients, the two implicit stages of a step
//! and its error estimate.

use super::coefficients::{D, E1, E2, E3, GAMMA, W};
use super::control::wrms;
use super::newton::{Iteration, Newton};
use super::stats::TrBdf2Stats;
use appell_core::ModelError;

/// The work vectors of one step: the Newton right-hand side `psi`, the
/// stages `y2` (at `t + γh`) and `y3` (at `t + h`, the new state) with
/// their derivatives, and the error estimate.
pub(super) struct Stages {
    psi: Vec<f64>,
    y2: Vec<f64>,
    f2: Vec<f64>,
    /// The new state.
    pub(super) y3: Vec<f64>,
    /// The derivative at the new state (the next step's first stage).
    pub(super) f3: Vec<f64>,
    est: Vec<f64>,
}

impl Stages {
    /// Work vectors for a state of `n` components.
    pub(super) fn new(n: usize) -> Self {
        Stages {
            psi: vec![0.0; n],
            y2: vec![0.0; n],
            f2: vec![0.0; n],
            y3: vec![0.0; n],
            f3: vec![0.0; n],
            est: vec![0.0; n],
        }
    }

    /// The two implicit stages of the step of signed size `hs` from
    /// `(t, x)` (derivative `f0`) to `t_new`: the trapezoidal rule to
    /// `t + γh` from an Euler predictor, then, if it converged, BDF2 to
    /// `t_new` from a predictor extrapolating `x` and `y2`. Both solve by
    /// [`Iteration::newton`]; converged, the larger contraction rate of the
    /// two, else the failure.
    #[allow(clippy::too_many_arguments)] // the step, its start and the Newton settings
    pub(super) fn solve<F>(
        &mut self,
        it: &mut Iteration,
        f: &mut F,
        kappa: f64,
        max_newton: usize,
        t: f64,
        hs: f64,
        t_new: f64,
        x: &[f64],
        f0: &[f64],
        sk: &[f64],
        stats: &mut TrBdf2Stats,
    ) -> Result<Newton, ModelError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
    {
        let n = x.len();
        // Stage 2 (trapezoidal rule to t + γh), Euler predictor.
        let hd = hs * D;
        for i in 0..n {
            self.psi[i] = x[i] + hd * f0[i];
            self.y2[i] = x[i] + GAMMA * hs * f0[i];
        }
        let outcome = it.newton(
            f,
            kappa,
            max_newton,
            t + GAMMA * hs,
            hd,
            &self.psi,
            sk,
            &mut self.y2,
            &mut self.f2,
            stats,
        )?;
        let Newton::Converged { theta } = outcome else {
            return Ok(outcome);
        };
        // Stage 3 (BDF2 to t + h), predictor extrapolating x and y2.
        for i in 0..n {
            self.psi[i] = x[i] + hs * W * (f0[i] + self.f2[i]);
            self.y3[i] = x[i] + (self.y2[i] - x[i]) / GAMMA;
        }
        let outcome = it.newton(
            f,
            kappa,
            max_newton,
            t_new,
            hd,
            &self.psi,
            sk,
            &mut self.y3,
            &mut self.f3,
            stats,
        )?;
        Ok(match outcome {
            Newton::Converged { theta: th } => Newton::Converged {
                theta: theta.max(th),
            },
            failed => failed,
        })
    }

    /// The error norm of the solved step of signed size `hs` from `x`
    /// (derivative `f0`): the difference of the embedded solutions,
    /// filtered by the iteration matrix of `it`, in the RMS norm weighted by
    /// `atol + rtol · max(|x_i|, |y3_i|)`; NaN when the filtering fails.
    #[allow(clippy::needless_range_loop)] // one index into several parallel arrays
    pub(super) fn error(
        &mut self,
        it: &Iteration,
        hs: f64,
        x: &[f64],
        f0: &[f64],
        atol: f64,
        rtol: f64,
    ) -> f64 {
        let n = x.len();
        for i in 0..n {
            self.est[i] = hs * (E1 * f0[i] + E2 * self.f2[i] + E3 * self.f3[i]);
        }
        let filtered = it.solve(&mut self.est);
        let scale: Vec<f64> = (0..n)
            .map(|i| atol + rtol * x[i].abs().max(self.y3[i].abs()))
            .collect();
        if filtered {
            wrms(&self.est, &scale)
        } else {
            f64::NAN
        }
    }
}
