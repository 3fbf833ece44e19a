//! The adaptive loop behind every `solve*` of [`TrBdf2`].

use super::control::{accepted_factor, all_finite, rejected_factor, FAC_NEWTON};
use super::dense::{EventG, Hermite};
use super::newton::{newton_tolerance, Iteration, Newton, JAC_SLOW};
use super::settings::TrBdf2;
use super::shared::{
    check_problem, derivative, error_scale, initial_step, next_step, Hooks, ProjectG,
};
use super::stages::Stages;
use super::stats::{TrBdf2Solution, TrBdf2Stats};
use crate::solution::IntegrateError;
use appell_core::ModelError;

impl TrBdf2 {
    /// The integration loop behind every `solve*`: `f` and its Jacobian
    /// `jac_fn` from `(t0, x0)` to `t_end`, with the outputs `out` (times
    /// given, states written), an optional event function and an optional
    /// projection after every accepted step.
    // one loop for solve, solve_at, solve_until and solve_projected (and run_prepared): each
    // passes `&mut []` or None for the outputs, event or projection it does not take
    #[allow(clippy::too_many_arguments)]
    pub(super) fn run<F, J>(
        &self,
        mut f: F,
        mut jac_fn: J,
        t0: f64,
        x0: &[f64],
        t_end: f64,
        out: &mut [(f64, Vec<f64>)],
        event: Option<&mut EventG<'_>>,
        project: Option<&mut ProjectG<'_>>,
    ) -> Result<TrBdf2Solution, IntegrateError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
        J: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
    {
        self.check_settings()?;
        let dir = check_problem(t0, x0, t_end, out)?;
        let n = x0.len();
        let mut stats = TrBdf2Stats::default();
        let mut t = t0;
        let mut x = x0.to_vec();
        let mut hooks = Hooks::start(out, event, self.event_tol, project, (t0, &x))?;
        if t_end == t0 {
            return Ok(solution(t, x, stats, 0.0, false, hooks.next_out));
        }

        let mut f0 = vec![0.0; n];
        derivative(&mut f, t, &x, &mut f0, &mut stats.rhs_calls)?;
        let h_max = self.h_max.unwrap_or(f64::INFINITY).min((t_end - t0).abs());
        let mut sk: Vec<f64> = x.iter().map(|v| self.atol + self.rtol * v.abs()).collect();
        let mut h = initial_step(self.h_init, &x, &f0, &sk, h_max);

        let mut it = Iteration::new(n);
        let kappa = newton_tolerance(self.rtol);
        let mut steps = 0usize;
        // The last step was rejected; a non-finite value was why.
        let (mut rejected_last, mut failure_non_finite) = (false, false);
        let mut st = Stages::new(n);

        loop {
            if steps >= self.max_steps {
                return Err(IntegrateError::TooManySteps { t, steps });
            }
            let last;
            (h, last) = next_step(self.h_min, t, t_end, h, failure_non_finite)?;
            steps += 1;
            let hs = dir * h;

            it.refresh(&mut jac_fn, t, &x, &mut stats)?;
            if (it.lu.is_none() || it.lu_h != hs) && !it.factor(hs, &mut stats) {
                // A singular iteration matrix: a new Jacobian, else a
                // smaller step.
                h = it.after_failure(h, &mut stats);
                failure_non_finite = false;
                rejected_last = true;
                continue;
            }

            let t_new = if last { t_end } else { t + hs };
            let outcome = st.solve(
                &mut it,
                &mut f,
                kappa,
                self.max_newton,
                t,
                hs,
                t_new,
                &x,
                &f0,
                &sk,
                &mut stats,
            )?;
            let theta = match outcome {
                Newton::Converged { theta } => theta,
                Newton::Failed { non_finite } => {
                    h = it.after_failure(h, &mut stats);
                    rejected_last = true;
                    failure_non_finite = non_finite;
                    it.eta = 1.0;
                    continue;
                }
            };

            // Error estimate, filtered by the iteration matrix.
            let err = st.error(&it, hs, &x, &f0, self.atol, self.rtol);
            if let Some((non_finite, factor)) = self.rejection(err, &st.y3) {
                stats.rejected += 1;
                (rejected_last, failure_non_finite) = (true, non_finite);
                h *= factor;
                continue;
            }
            stats.accepted += 1;

            let dense = Hermite::between(t, t_new, (&x, &f0), (&st.y3, &st.f3));
            if let Some((te, xe)) = hooks.end_of_step(&dense, dir)? {
                return Ok(solution(te, xe, stats, h, true, hooks.next_out));
            }

            t = t_new;
            x.copy_from_slice(&st.y3);
            f0.copy_from_slice(&st.f3);
            // Back onto the manifold; a moved state needs its own
            // derivative (one rhs call) and event value.
            hooks.project(&mut f, (t, &mut x), &mut f0, &mut stats.rhs_calls)?;
            error_scale(&mut sk, &x, self.atol, self.rtol);
            it.after_acceptance(theta > JAC_SLOW);
            let h_new = self.accepted_step(h, h_max, err, rejected_last);
            (rejected_last, failure_non_finite) = (false, false);
            if last {
                return Ok(solution(t, x, stats, h_new, false, hooks.next_out));
            }
            h = h_new;
        }
    }
}

impl TrBdf2 {
    /// Whether an attempted step is rejected: its new state `y3` not finite
    /// (then the step shrinks by the Newton failure's factor), or, adaptive,
    /// its error norm over 1. Returns whether for a non-finite value, and
    /// the factor of the step size.
    fn rejection(&self, err: f64, y3: &[f64]) -> Option<(bool, f64)> {
        let within = err <= 1.0;
        if !all_finite(y3) {
            Some((true, FAC_NEWTON))
        } else if self.adaptive && !within {
            Some((!err.is_finite(), rejected_factor(err)))
        } else {
            None
        }
    }

    /// The size of the step after an accepted one of size `h` with error
    /// norm `err`: grown by the controller (not past `h_max`), or
    /// `h_init` (else `h`) in a run without step-size control.
    fn accepted_step(&self, h: f64, h_max: f64, err: f64, rejected_last: bool) -> f64 {
        if self.adaptive {
            (h * accepted_factor(err, rejected_last)).min(h_max)
        } else {
            self.h_init.map_or(h, f64::abs).min(h_max)
        }
    }
}

/// The result of an integration ending at `t` in state `x`.
fn solution(
    t: f64,
    x: Vec<f64>,
    stats: TrBdf2Stats,
    h_next: f64,
    event: bool,
    outputs: usize,
) -> TrBdf2Solution {
    TrBdf2Solution {
        t,
        x,
        stats,
        h_next,
        event,
        outputs,
    }
}
