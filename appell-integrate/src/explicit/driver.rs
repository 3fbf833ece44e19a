//! The adaptive loop behind every `solve*`: steps with step-size control,
//! outputs on the dense output, events and projection.

use super::controller::{grown_step, initial_step, pow, shrunk_step};
use super::events::illinois;
use super::pair::{all_finite, DenseOutput, EmbeddedPair};
use super::settings::Settings;
use super::sink::Sink;
use crate::solution::{EventFn, IntegrateError, ProjectFn, Solution, Stats};
use appell_core::ModelError;
use appell_core::Scalar;

/// Factor of the retry after a non-finite stage.
const FAC_NON_FINITE: f64 = 0.2;

/// The integration loop behind every `solve*` of the method `P`.
#[allow(clippy::too_many_arguments)] // the problem, the outputs and two optional hooks
pub(crate) fn run<P, T, F, K, const S: usize>(
    set: &Settings,
    mut f: F,
    t0: f64,
    x0: &[T; S],
    t_end: f64,
    sink: &mut K,
    mut event: Option<&mut EventFn<'_, T, S>>,
    mut project: Option<&mut ProjectFn<'_, T, S>>,
) -> Result<Solution<T, S>, IntegrateError>
where
    P: EmbeddedPair<T, S>,
    T: Scalar,
    F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
    K: Sink<T, S>,
{
    let dir = check_problem(set, P::BETA_CLOSED, t0, x0, t_end, sink)?;

    let mut stats = Stats::default();
    let mut t = t0;
    let mut x = *x0;
    let mut next_out = 0;
    while next_out < sink.len() && sink.time(next_out) == t0 {
        sink.put(next_out, &x);
        next_out += 1;
    }
    let mut g_old = match event.as_mut() {
        Some(g) => event_value(g, t, &x, t)?,
        None => 0.0,
    };
    if t_end == t0 {
        return finish(t, x, stats, false, next_out, 0.0);
    }

    let (mut st, h_max, mut h) =
        first_step::<P, T, F, S>(set, &mut f, t, &x, t_end, dir, &mut stats)?;
    let h_fixed = h;
    let expo1 = P::EXPO - P::BETA_WEIGHT * set.beta;
    let mut fac_old: f64 = 1e-4;
    let mut last_rejected = false;
    let mut steps = 0usize;

    loop {
        if steps >= set.max_steps {
            return Err(IntegrateError::TooManySteps { t, steps });
        }
        let (h_floor, last) = step_size(set, t, t_end, &mut h)?;
        steps += 1;
        let hs = dir * h;
        let t_new = if last { t_end } else { t + hs };

        let Some((x_new, err)) = st.step(&mut f, set, t, hs, t_new, &x, &mut stats)? else {
            // A non-finite stage: retry with a much smaller step.
            stats.rejected += 1;
            last_rejected = true;
            h *= FAC_NON_FINITE;
            if !set.adaptive || h < h_floor {
                return Err(IntegrateError::NonFinite { t });
            }
            continue;
        };

        let fac11 = pow(err, expo1);
        if err <= 1.0 {
            // Accepted.
            stats.accepted += 1;
            let mut h_new = if set.adaptive {
                grown_step::<P, T, S>(set, fac11, err, h, &mut fac_old)
            } else {
                h_fixed
            };
            if last_rejected {
                h_new = h_new.min(h);
            }
            last_rejected = false;

            let step = Accepted::new(t, hs, t_new, &x, x_new);
            let outputs = (&mut *sink, &mut next_out, dir);
            let (g_new, stop) = close_step(
                &mut st, &mut f, set, &mut event, outputs, step, g_old, &mut stats,
            )?;
            g_old = g_new;
            let h_next = if set.adaptive {
                h_new.min(h_max)
            } else {
                h_fixed
            };
            if let Some((te, xe)) = stop {
                return finish(te, xe, stats, true, next_out, h_next);
            }

            t = t_new;
            x = x_new;
            st.accept();
            if let Some(p) = project.as_mut() {
                // Back onto the manifold; a moved state needs its own first
                // stage (one rhs call) and event value.
                if let Some(k1) = project_state(p, &mut f, t, &mut x, &mut stats)? {
                    st = P::new(k1);
                    if let Some(g) = event.as_mut() {
                        g_old = event_value(g, t, &x, t)?;
                    }
                }
            }
            h = h_next;
            if last {
                return finish(t, x, stats, false, next_out, h);
            }
        } else {
            // Rejected.
            stats.rejected += 1;
            last_rejected = true;
            h = shrunk_step::<P, T, S>(fac11, h);
        }
    }
}

/// The size of the step from `t`: `h`, or what is left to `t_end` when
/// that is within 1% of it (the last step); with the smallest size allowed
/// at `t`, below which a step that is not the last is
/// [`IntegrateError::StepSizeTooSmall`]. Returns the floor and whether the
/// step is the last.
fn step_size(
    set: &Settings,
    t: f64,
    t_end: f64,
    h: &mut f64,
) -> Result<(f64, bool), IntegrateError> {
    let h_floor = set
        .h_min
        .max(16.0 * f64::EPSILON * t.abs())
        .max(f64::MIN_POSITIVE);
    let remaining = (t_end - t).abs();
    let last = 1.01 * *h >= remaining;
    if !last && *h < h_floor {
        return Err(IntegrateError::StepSizeTooSmall { t, h: *h });
    }
    if last {
        *h = remaining;
    }
    Ok((h_floor, last))
}

/// Where an event stopped the run: its time and state.
type Stop<T, const S: usize> = (f64, [T; S]);

/// A step accepted from `(t, x)` to `(t_new, x_new)`, of signed size `hs`.
struct Accepted<'a, T, const S: usize> {
    t: f64,
    hs: f64,
    t_new: f64,
    x: &'a [T; S],
    x_new: [T; S],
}

impl<'a, T, const S: usize> Accepted<'a, T, S> {
    fn new(t: f64, hs: f64, t_new: f64, x: &'a [T; S], x_new: [T; S]) -> Self {
        Accepted {
            t,
            hs,
            t_new,
            x,
            x_new,
        }
    }
}

/// After an accepted step: the event function at its end and, where it
/// changed sign from `g_old` in the step, where the event stops the run;
/// the outputs up to the end of the step (or the event) written into the
/// sink from its next output on. The dense output is built only when the
/// step holds an output time or a crossing strictly inside it.
#[allow(clippy::too_many_arguments)] // the stages, the rhs, the hooks and the step
fn close_step<P, T, F, K, const S: usize>(
    st: &mut P,
    f: &mut F,
    set: &Settings,
    event: &mut Option<&mut EventFn<'_, T, S>>,
    (sink, next_out, dir): (&mut K, &mut usize, f64),
    step: Accepted<'_, T, S>,
    g_old: f64,
    stats: &mut Stats,
) -> Result<(f64, Option<Stop<T, S>>), IntegrateError>
where
    P: EmbeddedPair<T, S>,
    T: Scalar,
    F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
    K: Sink<T, S>,
{
    let Accepted {
        t,
        hs,
        t_new,
        x,
        x_new,
    } = step;
    let mut crossed = false;
    let mut g_new = 0.0;
    if let Some(g) = event.as_mut() {
        g_new = event_value(g, t_new, &x_new, t)?;
        crossed = g_old != 0.0 && (g_new == 0.0 || (g_new > 0.0) != (g_old > 0.0));
    }
    let need_dense = (crossed && g_new != 0.0)
        || (*next_out < sink.len() && (sink.time(*next_out) - t_new) * dir < 0.0);
    let dense = if need_dense {
        Some(st.dense(f, t, hs, x, &x_new, stats)?)
    } else {
        None
    };
    let stop: Option<Stop<T, S>> = if crossed {
        let (g, d, tol) = (event.as_mut(), dense.as_ref(), set.event_tol);
        Some(event_stop(tol, g, d, (t, g_old), (t_new, g_new), x_new)?)
    } else {
        None
    };
    let t_stop = stop.as_ref().map_or(t_new, |s| s.0);
    put_outputs(
        sink,
        next_out,
        t,
        t_stop,
        t_new,
        &x_new,
        dense.as_ref(),
        dir,
    )?;
    Ok((g_new, stop))
}

/// Checks the problem before the first step: the settings (`beta_closed` as
/// in [`Settings::check`]), finite `t0` and `t_end`, the output times and a
/// finite `x0`. Returns the direction of integration, `1` or `-1`.
fn check_problem<T, K, const S: usize>(
    set: &Settings,
    beta_closed: bool,
    t0: f64,
    x0: &[T; S],
    t_end: f64,
    sink: &K,
) -> Result<f64, IntegrateError>
where
    T: Scalar,
    K: Sink<T, S>,
{
    set.check(beta_closed)?;
    if !t0.is_finite() || !t_end.is_finite() {
        return Err(IntegrateError::InvalidInput {
            what: "t0 and t_end must be finite",
        });
    }
    let dir = if t_end >= t0 { 1.0 } else { -1.0 };
    check_output_times(sink, t0, t_end, dir)?;
    if !all_finite(x0) {
        return Err(IntegrateError::NonFinite { t: t0 });
    }
    Ok(dir)
}

/// The integration's end: the state `x` at `t`, whether an event stopped
/// it, the number of outputs written and the step size to go on with.
fn finish<T, const S: usize>(
    t: f64,
    x: [T; S],
    stats: Stats,
    event: bool,
    outputs: usize,
    h_next: f64,
) -> Result<Solution<T, S>, IntegrateError> {
    Ok(Solution {
        t,
        x,
        stats,
        event,
        outputs,
        h_next,
    })
}

/// The method's stages with the first one at `(t, x)` (one rhs call), the
/// largest step size (the whole interval to `t_end` unless `h_max` limits
/// an adaptive run) and the first step size (`h_init`, or Hairer's
/// estimate).
fn first_step<P, T, F, const S: usize>(
    set: &Settings,
    f: &mut F,
    t: f64,
    x: &[T; S],
    t_end: f64,
    dir: f64,
    stats: &mut Stats,
) -> Result<(P, f64, f64), IntegrateError>
where
    P: EmbeddedPair<T, S>,
    T: Scalar,
    F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
{
    let mut k1 = [T::zero(); S];
    stats.rhs_calls += 1;
    f(T::from_f64(t), x, &mut k1)?;
    if !all_finite(&k1) {
        return Err(IntegrateError::NonFinite { t });
    }
    let st = P::new(k1);
    let span = (t_end - t).abs();
    let h_max = if set.adaptive {
        set.h_max.unwrap_or(f64::INFINITY).min(span)
    } else {
        span
    };
    let h = match set.h_init {
        Some(h) => h.abs().min(h_max),
        None => initial_step(set, P::EXPO, f, t, x, st.k1(), dir, h_max, stats)?,
    };
    Ok((st, h_max, h))
}

/// Checks that the output times of `sink` are finite, ordered in the
/// direction `dir` and inside `[t0, t_end]`.
fn check_output_times<T, K, const S: usize>(
    sink: &K,
    t0: f64,
    t_end: f64,
    dir: f64,
) -> Result<(), IntegrateError>
where
    K: Sink<T, S>,
{
    let mut prev = t0;
    for i in 0..sink.len() {
        let ti = sink.time(i);
        if !ti.is_finite() || (ti - prev) * dir < 0.0 || (ti - t_end) * dir > 0.0 {
            return Err(IntegrateError::InvalidInput {
                what: "output times must be finite, ordered and within [t0, t_end]",
            });
        }
        prev = ti;
    }
    Ok(())
}

/// The event function `g` at `(tg, x)`; a non-finite value is
/// [`IntegrateError::NonFinite`] at `t` (the start of the current step).
fn event_value<T, const S: usize>(
    g: &mut EventFn<'_, T, S>,
    tg: f64,
    x: &[T; S],
    t: f64,
) -> Result<f64, IntegrateError> {
    let v = g(tg, x);
    if !v.is_finite() {
        return Err(IntegrateError::NonFinite { t });
    }
    Ok(v)
}

/// Where a step from `t` to `t_new` in which the event function changed
/// sign (from `g_old` at `t` to `g_new` at `t_new`) stops: located on the dense output by
/// [`illinois`], or the end of the step when `g` is exactly zero there (no
/// dense output was needed).
fn event_stop<T, D, const S: usize>(
    event_tol: f64,
    event: Option<&mut &mut EventFn<'_, T, S>>,
    dense: Option<&D>,
    (t, g_old): (f64, f64),
    (t_new, g_new): (f64, f64),
    x_new: [T; S],
) -> Result<(f64, [T; S]), IntegrateError>
where
    T: Scalar,
    D: DenseOutput<T, S>,
{
    if let (Some(g), Some(d)) = (event, dense) {
        let on_dense = |tc: f64| Ok(g(tc, &d.at(tc)));
        let te = illinois(event_tol, on_dense, t, g_old, t_new, g_new)?;
        Ok((te, if te == t_new { x_new } else { d.at(te) }))
    } else {
        // g is exactly zero at the end of the step.
        Ok((t_new, x_new))
    }
}

/// Writes the outputs at or before `t_stop` (from `next_out` on) into
/// `sink`: on the dense output inside the step, `x_new` at its end `t_new`.
/// A non-finite output is [`IntegrateError::NonFinite`] at `t`.
#[allow(clippy::too_many_arguments)] // the sink, the step and its dense output
fn put_outputs<T, K, D, const S: usize>(
    sink: &mut K,
    next_out: &mut usize,
    t: f64,
    t_stop: f64,
    t_new: f64,
    x_new: &[T; S],
    dense: Option<&D>,
    dir: f64,
) -> Result<(), IntegrateError>
where
    T: Scalar,
    K: Sink<T, S>,
    D: DenseOutput<T, S>,
{
    let n_out = sink.len();
    while *next_out < n_out && (sink.time(*next_out) - t_stop) * dir <= 0.0 {
        let to = sink.time(*next_out);
        let xo = match dense {
            Some(d) if to != t_new => d.at(to),
            _ => *x_new,
        };
        if !all_finite(&xo) {
            return Err(IntegrateError::NonFinite { t });
        }
        sink.put(*next_out, &xo);
        *next_out += 1;
    }
    Ok(())
}

/// Projects the state `x` at `t` with `p`. When that moved it, returns the
/// first stage at the new state (one rhs call, counted in `stats`).
fn project_state<T, F, const S: usize>(
    p: &mut ProjectFn<'_, T, S>,
    f: &mut F,
    t: f64,
    x: &mut [T; S],
    stats: &mut Stats,
) -> Result<Option<[T; S]>, IntegrateError>
where
    T: Scalar,
    F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
{
    let before = *x;
    if let Err(failed) = p(t, x) {
        return Err(IntegrateError::Projection {
            t,
            reason: failed.reason,
        });
    }
    if !all_finite(x) {
        return Err(IntegrateError::Projection {
            t,
            reason: "the projection left a non-finite state",
        });
    }
    if x.iter().zip(&before).any(|(a, b)| a.re() != b.re()) {
        let mut k1 = [T::zero(); S];
        stats.rhs_calls += 1;
        f(T::from_f64(t), x, &mut k1)?;
        if !all_finite(&k1) {
            return Err(IntegrateError::NonFinite { t });
        }
        return Ok(Some(k1));
    }
    Ok(None)
}
