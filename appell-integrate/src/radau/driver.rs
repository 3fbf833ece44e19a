//! The adaptive loop behind every `solve*` of [`Radau5`].

use super::control::{
    keeps_step, newton_tolerance, step_factor, Gustafsson, FAC_FAIL, FAC_FIRST, REUSE_GIVEN,
};
use super::dense::{coefficients, end_derivative, Collocation, Previous};
use super::iteration::Iteration;
use super::settings::Radau5;
use super::stages::{Newton, Stages};
use super::stats::{Radau5Solution, Radau5Stats};
use crate::implicit::{
    all_finite, check_problem, derivative, error_scale, initial_step, next_step, EventG, Hooks,
    ProjectG,
};
use crate::solution::IntegrateError;
use appell_core::ModelError;

impl Radau5 {
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
    ) -> Result<Radau5Solution, IntegrateError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
        J: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
    {
        self.check_settings()?;
        let dir = check_problem(t0, x0, t_end, out)?;
        let n = x0.len();
        let mut stats = Radau5Stats::default();
        let (mut t, mut x) = (t0, x0.to_vec());
        let mut hooks = Hooks::start(out, event, self.event_tol, project, (t0, &x))?;
        if t_end == t0 {
            return Ok(solution(t, x, stats, 0.0, false, hooks.next_out));
        }

        let mut f0 = vec![0.0; n];
        derivative(&mut f, t, &x, &mut f0, &mut stats.rhs_calls)?;
        let (rtol, atol) = self.internal_tolerances();
        let fnewt = newton_tolerance(rtol);
        let reuse = self.jacobian_reuse.unwrap_or(REUSE_GIVEN);
        let h_max = self.h_max.unwrap_or(f64::INFINITY).min((t_end - t0).abs());
        let mut scal: Vec<f64> = x.iter().map(|v| atol + rtol * v.abs()).collect();
        let mut h = initial_step(self.h0, &x, &f0, &scal, h_max);

        let mut it = Iteration::new(n);
        let mut st = Stages::new(n);
        let mut prev = Previous::new(n);
        let (mut q, mut x_new) = (vec![0.0; 3 * n], vec![0.0; n]);
        let mut gustafsson = Gustafsson::new();
        let mut steps = 0usize;
        // The last step was rejected; a non-finite value was why.
        let (mut rejected, mut non_finite) = (false, false);

        loop {
            if steps >= self.max_steps {
                return Err(IntegrateError::TooManySteps { t, steps });
            }
            let last;
            (h, last) = next_step(0.0, t, t_end, h, non_finite)?;
            steps += 1;
            let hs = dir * h;
            let t_new = if last { t_end } else { t + hs };

            it.refresh(&mut jac_fn, t, &x, &mut stats)?;
            let outcome = if it.prepare(hs, &mut stats) {
                prev.extrapolate(hs, &x, &mut st.z);
                let nit = self.newton_max_iter;
                st.newton(&it, &mut f, t, hs, &x, &scal, fnewt, nit, &mut stats)?
            } else {
                Newton::SINGULAR
            };
            let (theta, iterations) = match outcome {
                Newton::Converged { theta, iterations } => (theta, iterations),
                Newton::Failed {
                    factor,
                    non_finite: nf,
                } => {
                    stats.newton_failures += 1;
                    stats.rejected += 1;
                    h *= factor;
                    it.after_rejection();
                    (rejected, non_finite) = (true, nf);
                    continue;
                }
            };

            st.end_state(&x, &mut x_new);
            let refine = stats.accepted == 0 || rejected;
            let ends = (x.as_slice(), f0.as_slice(), x_new.as_slice());
            let err = st.error(&it, &mut f, (t, hs), ends, (atol, rtol), refine, &mut stats)?;
            let fac = step_factor(err, iterations, self.newton_max_iter);
            if !(err < 1.0 && all_finite(&x_new)) {
                stats.rejected += 1;
                (rejected, non_finite) = (true, !err.is_finite() || !all_finite(&x_new));
                h *= rejected_factor(non_finite, stats.accepted, fac);
                // A Jacobian under which Newton converged fast is kept.
                if theta > reuse {
                    it.after_rejection();
                }
                continue;
            }
            stats.accepted += 1;
            let grown = (h * gustafsson.accepted(h, err, fac)).min(h_max);
            let h_new = if rejected { grown.min(h) } else { grown };

            coefficients(&st.z, &mut q, n);
            let dense = Collocation::between((t, &x), (t_new, &x_new), hs, &q);
            if let Some((te, xe)) = hooks.end_of_step(&dense, dir)? {
                return Ok(solution(te, xe, stats, h_new, true, hooks.next_out));
            }

            // f at the new state for the next error estimate, from the
            // polynomial (evaluated instead when a projection moves it).
            end_derivative(&q, hs, &mut f0);
            // The step's polynomial starts the next one.
            prev.keep(&mut x, &mut q, &x_new, hs);
            t = t_new;
            hooks.project(&mut f, (t, &mut x), &mut f0, &mut stats.rhs_calls)?;
            error_scale(&mut scal, &x, atol, rtol);
            it.after_acceptance(theta > reuse);
            (rejected, non_finite) = (false, false);
            if last {
                return Ok(solution(t, x, stats, h_new, false, hooks.next_out));
            }
            if !keeps_step(theta, reuse, h_new / h) {
                h = h_new;
            }
        }
    }
}

/// The factor of the step size after a rejected step whose controller
/// proposed `fac`: small after a non-finite value, the first step's
/// before any step was accepted.
fn rejected_factor(non_finite: bool, accepted: usize, fac: f64) -> f64 {
    if non_finite {
        FAC_FAIL
    } else if accepted == 0 {
        FAC_FIRST
    } else {
        fac
    }
}

/// The result of an integration ending at `t` in state `x`.
fn solution(
    t: f64,
    x: Vec<f64>,
    stats: Radau5Stats,
    h_next: f64,
    event: bool,
    outputs: usize,
) -> Radau5Solution {
    Radau5Solution {
        t,
        x,
        stats,
        h_next,
        event,
        outputs,
    }
}
