//! The adaptive loop behind every `solve*` of [`TrBdf2`].

use super::control::{accepted_factor, all_finite, rejected_factor, wrms, FAC_NEWTON};
use super::dense::{locate, put, EventG, Hermite};
use super::newton::{newton_tolerance, Iteration, Newton, JAC_SLOW};
use super::settings::TrBdf2;
use super::stages::Stages;
use super::stats::{TrBdf2Solution, TrBdf2Stats};
use crate::integrate::solution::IntegrateError;
use crate::model::ModelError;

impl TrBdf2 {
    /// The integration loop behind every `solve*`: `f` and its Jacobian
    /// `jac_fn` from `(t0, x0)` to `t_end`, with the outputs `out` (times
    /// given, states written) and an optional event function.
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
    ) -> Result<TrBdf2Solution, IntegrateError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
        J: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
    {
        let dir = self.check_problem(t0, x0, t_end, out)?;
        let n = x0.len();
        let mut stats = TrBdf2Stats::default();
        let mut t = t0;
        let mut x = x0.to_vec();
        let mut next_out = 0;
        while next_out < out.len() && out[next_out].0 == t0 {
            put(&mut out[next_out].1, &x);
            next_out += 1;
        }
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
        let mut h = self.initial_step(&x, &f0, &sk, h_max);

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
            (h, last) = self.next_step(t, t_end, h, failure_non_finite)?;
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
            let stop = self.end_of_step(&mut event, &dense, &mut g_old, out, &mut next_out, dir)?;
            if let Some((te, xe)) = stop {
                return Ok(solution(te, xe, stats, h, true, next_out));
            }

            t = t_new;
            x.copy_from_slice(&st.y3);
            f0.copy_from_slice(&st.f3);
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

    /// The end of an accepted step with the interpolant `dense`: the event
    /// function at its end (a sign change from `g_old`, or a zero when
    /// `g_old` was nonzero, is an event, located on `dense`), then the
    /// outputs up to the end of the step or the event. Updates `g_old` and
    /// `next_out`; returns the event's time and state, if any.
    fn end_of_step(
        &self,
        event: &mut Option<&mut EventG<'_>>,
        dense: &Hermite<'_>,
        g_old: &mut f64,
        out: &mut [(f64, Vec<f64>)],
        next_out: &mut usize,
        dir: f64,
    ) -> Result<Option<(f64, Vec<f64>)>, IntegrateError> {
        let (t, t_new) = (dense.t, dense.t1);
        // Event at the end of the step.
        let mut crossed = false;
        let mut g_new = 0.0;
        if let Some(g) = event.as_mut() {
            g_new = event_value(g, t_new, dense.x1, t)?;
            crossed = *g_old != 0.0 && (g_new == 0.0 || (g_new > 0.0) != (*g_old > 0.0));
        }
        let mut stop: Option<(f64, Vec<f64>)> = None;
        if crossed {
            if let Some(g) = event.as_mut() {
                stop = Some(locate(self.event_tol, &mut **g, dense, *g_old, g_new)?);
            }
        }
        *g_old = g_new;

        // Outputs up to the end of the step (or the event).
        let t_stop = stop.as_ref().map_or(t_new, |s| s.0);
        *next_out = put_outputs(out, *next_out, dense, t_stop, dir, t)?;
        Ok(stop)
    }

    /// The size of the step from `t`: `h`, or the rest of the interval when
    /// `h` (nearly) reaches `t_end` (then `last` is true). A step below the
    /// floor (`h_min`, 16 ulp of `t`) that does not reach `t_end` is
    /// [`IntegrateError::StepSizeTooSmall`], or
    /// [`IntegrateError::NonFinite`] when the last failure was a non-finite
    /// value.
    fn next_step(
        &self,
        t: f64,
        t_end: f64,
        h: f64,
        failure_non_finite: bool,
    ) -> Result<(f64, bool), IntegrateError> {
        let remaining = (t_end - t).abs();
        let floor = self.h_min.max(16.0 * f64::EPSILON * t.abs());
        if h < floor && h < remaining {
            return Err(if failure_non_finite {
                IntegrateError::NonFinite { t }
            } else {
                IntegrateError::StepSizeTooSmall { t, h }
            });
        }
        let last = h >= remaining * (1.0 - 1e-12);
        Ok(if last { (remaining, true) } else { (h, false) })
    }

    /// Checks the problem before the first step: the settings, finite `t0`
    /// and `t_end`, the output times (finite, ordered, inside
    /// `[t0, t_end]`) and a finite `x0`. Returns the direction of
    /// integration, `1` or `-1`.
    fn check_problem(
        &self,
        t0: f64,
        x0: &[f64],
        t_end: f64,
        out: &[(f64, Vec<f64>)],
    ) -> Result<f64, IntegrateError> {
        self.check_settings()?;
        if !t0.is_finite() || !t_end.is_finite() {
            return Err(IntegrateError::InvalidInput {
                what: "t0 and t_end must be finite",
            });
        }
        let dir = if t_end >= t0 { 1.0 } else { -1.0 };
        let mut prev = t0;
        for o in out.iter() {
            let ti = o.0;
            if !ti.is_finite() || (ti - prev) * dir < 0.0 || (ti - t_end) * dir > 0.0 {
                return Err(IntegrateError::InvalidInput {
                    what: "output times must be finite, ordered and within [t0, t_end]",
                });
            }
            prev = ti;
        }
        if !all_finite(x0) {
            return Err(IntegrateError::NonFinite { t: t0 });
        }
        Ok(dir)
    }

    /// The first step size: [`TrBdf2::h_init`], else `0.01 ‖x‖/‖f‖` in the
    /// error norm weighted by `sk` (`1e-6` when either is tiny), at most
    /// `h_max`.
    fn initial_step(&self, x: &[f64], f0: &[f64], sk: &[f64], h_max: f64) -> f64 {
        match self.h_init {
            Some(h) => h.abs().min(h_max),
            None => {
                let d0 = wrms(x, sk);
                let d1 = wrms(f0, sk);
                let h0 = if d0 < 1e-5 || d1 < 1e-5 {
                    1e-6
                } else {
                    0.01 * d0 / d1
                };
                h0.min(h_max)
            }
        }
    }
}

/// The event function `g` at `(tg, x)`; a non-finite value is
/// [`IntegrateError::NonFinite`] at `t` (the start of the current step).
fn event_value(g: &mut EventG<'_>, tg: f64, x: &[f64], t: f64) -> Result<f64, IntegrateError> {
    let v = g(tg, x);
    if !v.is_finite() {
        return Err(IntegrateError::NonFinite { t });
    }
    Ok(v)
}

/// Writes the outputs at or before `t_stop` (from `next_out` on) on the
/// step's interpolant `dense` (its end state exactly at its end) and
/// returns the index of the next output. A non-finite interpolated state
/// is [`IntegrateError::NonFinite`] at `t`.
fn put_outputs(
    out: &mut [(f64, Vec<f64>)],
    mut next_out: usize,
    dense: &Hermite<'_>,
    t_stop: f64,
    dir: f64,
    t: f64,
) -> Result<usize, IntegrateError> {
    while next_out < out.len() && (out[next_out].0 - t_stop) * dir <= 0.0 {
        let to = out[next_out].0;
        let slot = &mut out[next_out].1;
        if to == dense.t1 {
            put(slot, dense.x1);
        } else {
            dense.at(to, slot);
            if !all_finite(slot) {
                return Err(IntegrateError::NonFinite { t });
            }
        }
        next_out += 1;
    }
    Ok(next_out)
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
