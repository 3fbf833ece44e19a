//! The adaptive loop behind every `solve*` of [`TrBdf2`].

use super::control::{accepted_factor, all_finite, rejected_factor, FAC_NEWTON};
use super::dense::{EventG, Hermite};
use super::newton::{newton_tolerance, Iteration, Newton, JAC_SLOW};
use super::settings::TrBdf2;
use super::shared::{
    check_problem, end_of_step, event_value, initial_outputs, initial_step, next_step,
    project_state, ProjectG,
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
        mut event: Option<&mut EventG<'_>>,
        mut project: Option<&mut ProjectG<'_>>,
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
        let mut next_out = initial_outputs(out, t0, &x);
        let mut g_old = match event.as_mut() {
            Some(g) => event_value(g, t, &x, t)?,
            None => 0.0,
        };
        if t_end == t0 {
            return Ok(solution(t, x, stats, 0.0, false, next_out));
        }

        let mut f0 = vec![0.0; n];
        stats.rhs_calls += 1;
        f(t, &x, &mut f0)?;
        if !all_finite(&f0) {
            return Err(IntegrateError::NonFinite { t });
        }
        let h_max = self.h_max.unwrap_or(f64::INFINITY).min((t_end - t0).abs());
        let mut sk: Vec<f64> = x.iter().map(|v| self.atol + self.rtol * v.abs()).collect();
        let mut h = initial_step(self.h_init, &x, &f0, &sk, h_max);

        let mut it = Iteration::new(n);
        let kappa = newton_tolerance(self.rtol);
        let mut steps = 0usize;
        let mut rejected_last = false;
        let mut failure_non_finite = false;
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
            if !all_finite(&st.y3) {
                stats.rejected += 1;
                rejected_last = true;
                failure_non_finite = true;
                h *= FAC_NEWTON;
                continue;
            }

            let accept = !self.adaptive || err <= 1.0;
            if !accept {
                stats.rejected += 1;
                rejected_last = true;
                failure_non_finite = !err.is_finite();
                h *= rejected_factor(err);
                continue;
            }
            stats.accepted += 1;

            let dense = Hermite {
                t,
                t1: t_new,
                h: t_new - t,
                x0: &x,
                f0: &f0,
                x1: &st.y3,
                f1: &st.f3,
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
                return Ok(solution(te, xe, stats, h, true, next_out));
            }

            t = t_new;
            x.copy_from_slice(&st.y3);
            f0.copy_from_slice(&st.f3);
            if let Some(p) = project.as_mut() {
                // Back onto the manifold; a moved state needs its own
                // derivative (one rhs call) and event value.
                if project_state(p, t, &mut x, &mut st.scratch)? {
                    stats.rhs_calls += 1;
                    f(t, &x, &mut f0)?;
                    if !all_finite(&f0) {
                        return Err(IntegrateError::NonFinite { t });
                    }
                    if let Some(g) = event.as_mut() {
                        g_old = event_value(g, t, &x, t)?;
                    }
                }
            }
            for i in 0..n {
                sk[i] = self.atol + self.rtol * x[i].abs();
            }
            it.fresh = false;
            if theta > JAC_SLOW {
                it.have_jac = false;
            }
            let fac = accepted_factor(err, rejected_last);
            rejected_last = false;
            failure_non_finite = false;
            let h_new = if self.adaptive {
                (h * fac).min(h_max)
            } else {
                self.h_init.map_or(h, f64::abs).min(h_max)
            };
            if last {
                return Ok(solution(t, x, stats, h_new, false, next_out));
            }
            h = h_new;
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
