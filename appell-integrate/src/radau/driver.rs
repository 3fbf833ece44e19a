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
    all_finite, check_problem, end_of_step, event_value, initial_outputs, initial_step, next_step,
    project_state, EventG, ProjectG,
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
        mut event: Option<&mut EventG<'_>>,
        mut project: Option<&mut ProjectG<'_>>,
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
        let mut next_out = initial_outputs(out, t0, &x);
        let mut g_old = match event.as_mut() {
            Some(g) => event_value(g, t, &x, t)?,
            None => 0.0,
        };
        if t_end == t0 {
            return Ok(solution(t, x, stats, 0.0, false, next_out));
        }

        let mut f0 = vec![0.0; n];
        derivative(&mut f, t, &x, &mut f0, &mut stats)?;
        let (rtol, atol) = self.internal_tolerances();
        let fnewt = newton_tolerance(rtol);
        let reuse = self.jacobian_reuse.unwrap_or(REUSE_GIVEN);
        let h_max = self.h_max.unwrap_or(f64::INFINITY).min((t_end - t0).abs());
        let mut scal: Vec<f64> = x.iter().map(|v| atol + rtol * v.abs()).collect();
        let mut h = initial_step(self.h0, &x, &f0, &scal, h_max);

        let mut it = Iteration::new(n);
        let mut st = Stages::new(n);
        let mut prev = Previous::new(n);
        let (mut q, mut x_new, mut buf) = (vec![0.0; 3 * n], vec![0.0; n], Vec::new());
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
                // A singular iteration matrix.
                Newton::Failed {
                    factor: FAC_FAIL,
                    non_finite: false,
                }
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
                h *= match () {
                    _ if non_finite => FAC_FAIL,
                    _ if stats.accepted == 0 => FAC_FIRST,
                    _ => fac,
                };
                // A Jacobian under which Newton converged fast is kept.
                if theta > reuse {
                    it.after_rejection();
                }
                continue;
            }
            stats.accepted += 1;
            let mut h_new = (h * gustafsson.accepted(h, err, fac)).min(h_max);
            if rejected {
                h_new = h_new.min(h);
            }

            coefficients(&st.z, &mut q, n);
            let dense = Collocation {
                t,
                t1: t_new,
                h: hs,
                x0: &x,
                q: &q,
                x1: &x_new,
            };
            let stop = end_of_step(
                self.event_tol,
                &mut event,
                &dense,
                &mut g_old,
                out,
                &mut next_out,
                dir,
            )?;
            if let Some((te, xe)) = stop {
                return Ok(solution(te, xe, stats, h_new, true, next_out));
            }

            // f at the new state for the next error estimate, from the
            // polynomial (evaluated instead when a projection moves it).
            end_derivative(&q, hs, &mut f0);
            // The step's polynomial starts the next one.
            prev.keep(&mut x, &mut q, &x_new, hs);
            t = t_new;
            if let Some(p) = project.as_mut() {
                if project_state(p, t, &mut x, &mut buf)? {
                    derivative(&mut f, t, &x, &mut f0, &mut stats)?;
                    if let Some(g) = event.as_mut() {
                        g_old = event_value(g, t, &x, t)?;
                    }
                }
            }
            for (s, v) in scal.iter_mut().zip(&x) {
                *s = atol + rtol * v.abs();
            }
            it.fresh = false;
            if theta > reuse {
                it.have_jac = false;
            }
            (rejected, non_finite) = (false, false);
            if last {
                return Ok(solution(t, x, stats, h_new, false, next_out));
            }
            if !keeps_step(theta, reuse, h_new / h) {
                h = h_new;
            }
        }
    }
}

/// The derivative `f(t, x)` into `f0` (one rhs call); a non-finite one is
/// [`IntegrateError::NonFinite`].
fn derivative<F>(
    f: &mut F,
    t: f64,
    x: &[f64],
    f0: &mut [f64],
    stats: &mut Radau5Stats,
) -> Result<(), IntegrateError>
where
    F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
{
    stats.rhs_calls += 1;
    f(t, x, f0)?;
    if !all_finite(f0) {
        return Err(IntegrateError::NonFinite { t });
    }
    Ok(())
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
