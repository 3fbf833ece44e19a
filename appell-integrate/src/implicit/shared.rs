//! The parts of the adaptive loop shared by the implicit integrators
//! ([`TrBdf2`](super::TrBdf2) and [`Radau5`](crate::Radau5)):
//! checking the problem, the first and the next step size, and the end of
//! an accepted step (events, outputs, projection).

use super::control::{all_finite, wrms};
use super::dense::{locate, put, Dense, EventG};
use crate::solution::{IntegrateError, ProjectionFailed};
use appell_core::ModelError;

/// A projection `p(t, x)` of a state in place back onto a constraint
/// manifold, as passed to the `solve_projected` of the implicit
/// integrators.
pub(crate) type ProjectG<'a> = dyn FnMut(f64, &mut [f64]) -> Result<(), ProjectionFailed> + 'a;

/// Checks the problem before the first step: finite `t0` and `t_end`, the
/// output times (finite, ordered, inside `[t0, t_end]`) and a finite `x0`.
/// Returns the direction of integration, `1` or `-1`.
pub(crate) fn check_problem(
    t0: f64,
    x0: &[f64],
    t_end: f64,
    out: &[(f64, Vec<f64>)],
) -> Result<f64, IntegrateError> {
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

/// What a run does at the end of every accepted step besides stepping:
/// the event function with its last value, the outputs with the next one
/// to write, and the projection.
pub(crate) struct Hooks<'a, 'e, 'p> {
    event: Option<&'a mut EventG<'e>>,
    /// The event function's value at the start of the next step.
    g_old: f64,
    event_tol: f64,
    out: &'a mut [(f64, Vec<f64>)],
    /// The first output not yet written.
    pub(crate) next_out: usize,
    project: Option<&'a mut ProjectG<'p>>,
    /// The state before a projection.
    before: Vec<f64>,
}

impl<'a, 'e, 'p> Hooks<'a, 'e, 'p> {
    /// The hooks at the start `(t0, x0)`: the outputs at `t0` written, the
    /// event function's first value.
    pub(crate) fn start(
        out: &'a mut [(f64, Vec<f64>)],
        mut event: Option<&'a mut EventG<'e>>,
        event_tol: f64,
        project: Option<&'a mut ProjectG<'p>>,
        (t0, x0): (f64, &[f64]),
    ) -> Result<Self, IntegrateError> {
        let next_out = initial_outputs(out, t0, x0);
        let g_old = match event.as_mut() {
            Some(g) => event_value(g, t0, x0, t0)?,
            None => 0.0,
        };
        Ok(Hooks {
            event,
            g_old,
            event_tol,
            out,
            next_out,
            project,
            before: Vec::with_capacity(x0.len()),
        })
    }

    /// [`end_of_step`] on the step's dense output: the event's time and
    /// state, if one stops the run in the step.
    pub(crate) fn end_of_step<D: Dense>(
        &mut self,
        dense: &D,
        dir: f64,
    ) -> Result<Option<(f64, Vec<f64>)>, IntegrateError> {
        let (tol, out) = (self.event_tol, &mut *self.out);
        end_of_step(
            tol,
            &mut self.event,
            dense,
            &mut self.g_old,
            out,
            &mut self.next_out,
            dir,
        )
    }

    /// After an accepted step to `(t, x)`: the projection, where there is
    /// one; where it moved the state, its derivative `f0` anew (one rhs call,
    /// counted in `rhs_calls`) and the event function's value.
    pub(crate) fn project<F>(
        &mut self,
        f: &mut F,
        (t, x): (f64, &mut [f64]),
        f0: &mut [f64],
        rhs_calls: &mut usize,
    ) -> Result<(), IntegrateError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
    {
        let Some(p) = self.project.as_mut() else {
            return Ok(());
        };
        if project_state(p, t, x, &mut self.before)? {
            derivative(f, t, x, f0, rhs_calls)?;
            if let Some(g) = self.event.as_mut() {
                self.g_old = event_value(g, t, x, t)?;
            }
        }
        Ok(())
    }
}

/// The derivative `f(t, x)` into `f0` (one rhs call, counted in
/// `rhs_calls`); a non-finite one is [`IntegrateError::NonFinite`].
pub(crate) fn derivative<F>(
    f: &mut F,
    t: f64,
    x: &[f64],
    f0: &mut [f64],
    rhs_calls: &mut usize,
) -> Result<(), IntegrateError>
where
    F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
{
    *rhs_calls += 1;
    f(t, x, f0)?;
    if !all_finite(f0) {
        return Err(IntegrateError::NonFinite { t });
    }
    Ok(())
}

/// The error scale `atol + rtol |x_i|` of every component of `x`, into
/// `scale`.
pub(crate) fn error_scale(scale: &mut [f64], x: &[f64], atol: f64, rtol: f64) {
    for (s, v) in scale.iter_mut().zip(x) {
        *s = atol + rtol * v.abs();
    }
}

/// Writes `x0` into the outputs at `t0` (the first ones) and returns the
/// index of the next output.
fn initial_outputs(out: &mut [(f64, Vec<f64>)], t0: f64, x0: &[f64]) -> usize {
    let mut next_out = 0;
    while next_out < out.len() && out[next_out].0 == t0 {
        put(&mut out[next_out].1, x0);
        next_out += 1;
    }
    next_out
}

/// The first step size: `h_init`, else `0.01 ‖x‖/‖f‖` in the error norm
/// weighted by `sk` (`1e-6` when either is tiny), at most `h_max`.
pub(crate) fn initial_step(
    h_init: Option<f64>,
    x: &[f64],
    f0: &[f64],
    sk: &[f64],
    h_max: f64,
) -> f64 {
    match h_init {
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

/// The size of the step from `t`: `h`, or the rest of the interval when
/// `h` (nearly) reaches `t_end` (then `last` is true). A step below the
/// floor (`h_min`, 16 ulp of `t`) that does not reach `t_end` is
/// [`IntegrateError::StepSizeTooSmall`], or [`IntegrateError::NonFinite`]
/// when the last failure was a non-finite value.
pub(crate) fn next_step(
    h_min: f64,
    t: f64,
    t_end: f64,
    h: f64,
    failure_non_finite: bool,
) -> Result<(f64, bool), IntegrateError> {
    let remaining = (t_end - t).abs();
    let floor = h_min.max(16.0 * f64::EPSILON * t.abs());
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

/// The end of an accepted step with the dense output `dense`: the event
/// function at its end (a sign change from `g_old`, or a zero when `g_old`
/// was nonzero, is an event, located on `dense` to `event_tol`), then the
/// outputs up to the end of the step or the event. Updates `g_old` and
/// `next_out`; returns the event's time and state, if any.
fn end_of_step<D: Dense>(
    event_tol: f64,
    event: &mut Option<&mut EventG<'_>>,
    dense: &D,
    g_old: &mut f64,
    out: &mut [(f64, Vec<f64>)],
    next_out: &mut usize,
    dir: f64,
) -> Result<Option<(f64, Vec<f64>)>, IntegrateError> {
    let (t, t_new) = (dense.start(), dense.end());
    // Event at the end of the step.
    let mut crossed = false;
    let mut g_new = 0.0;
    if let Some(g) = event.as_mut() {
        g_new = event_value(g, t_new, dense.end_state(), t)?;
        crossed = *g_old != 0.0 && (g_new == 0.0 || (g_new > 0.0) != (*g_old > 0.0));
    }
    let mut stop: Option<(f64, Vec<f64>)> = None;
    if crossed {
        if let Some(g) = event.as_mut() {
            stop = Some(locate(event_tol, &mut **g, dense, *g_old, g_new)?);
        }
    }
    *g_old = g_new;

    // Outputs up to the end of the step (or the event).
    let t_stop = stop.as_ref().map_or(t_new, |s| s.0);
    *next_out = put_outputs(out, *next_out, dense, t_stop, dir, t)?;
    Ok(stop)
}

/// The event function `g` at `(tg, x)`; a non-finite value is
/// [`IntegrateError::NonFinite`] at `t` (the start of the current step).
pub(crate) fn event_value(
    g: &mut EventG<'_>,
    tg: f64,
    x: &[f64],
    t: f64,
) -> Result<f64, IntegrateError> {
    let v = g(tg, x);
    if !v.is_finite() {
        return Err(IntegrateError::NonFinite { t });
    }
    Ok(v)
}

/// Writes the outputs at or before `t_stop` (from `next_out` on) on the
/// step's dense output (its end state exactly at its end) and returns the
/// index of the next output. A non-finite interpolated state is
/// [`IntegrateError::NonFinite`] at `t`.
fn put_outputs<D: Dense>(
    out: &mut [(f64, Vec<f64>)],
    mut next_out: usize,
    dense: &D,
    t_stop: f64,
    dir: f64,
    t: f64,
) -> Result<usize, IntegrateError> {
    while next_out < out.len() && (out[next_out].0 - t_stop) * dir <= 0.0 {
        let to = out[next_out].0;
        let slot = &mut out[next_out].1;
        if to == dense.end() {
            put(slot, dense.end_state());
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

/// Projects the state `x` at `t` with `p` (`before` is scratch). Returns
/// whether it moved; a failure, or a non-finite projected state, is
/// [`IntegrateError::Projection`].
fn project_state(
    p: &mut ProjectG<'_>,
    t: f64,
    x: &mut [f64],
    before: &mut Vec<f64>,
) -> Result<bool, IntegrateError> {
    put(before, x);
    if let Err(e) = p(t, x) {
        return Err(IntegrateError::Projection {
            t,
            reason: e.reason,
        });
    }
    if !all_finite(x) {
        return Err(IntegrateError::Projection {
            t,
            reason: "the projected state is not finite",
        });
    }
    Ok(x.iter().zip(before.iter()).any(|(a, b)| a != b))
}
