//! The contact watch every `solve_model*` runs on a model with contacts
//! (see [`crate::contact_watch`]): a stopping watch checked on the initial
//! state and, as a projection that never moves the state, after every
//! accepted step; its stop becomes [`IntegrateError::Contact`].

use super::solution::{IntegrateError, ProjectionFailed};
use appell_core::Model;
use appell_core::Scalar;

/// The check the integrators compose after a caller's projection: the
/// reduced state in `f64` (the real parts, for dual numbers).
pub(crate) type WatchFn<'a> = dyn FnMut(f64, &[f64]) -> Result<(), ProjectionFailed> + 'a;

/// The margin the integrators locate as an event (see
/// [`ContactWatch::margin`](crate::contact_watch::ContactWatch::margin)).
pub(crate) type MarginFn<'a> = dyn FnMut(f64, &[f64]) -> f64 + 'a;

/// Where a solution stopped at an event of its event function, if it did:
/// the time and the state.
#[cfg_attr(not(feature = "std"), allow(dead_code))] // no watch without std
pub(crate) trait EventEnd<T> {
    /// `(t, x)` at the event, or `None` when the run went to its end.
    fn event_end(&self) -> Option<(f64, &[T])>;
}

impl<T, const S: usize> EventEnd<T> for super::Solution<T, S> {
    fn event_end(&self) -> Option<(f64, &[T])> {
        self.event.then_some((self.t, &self.x[..]))
    }
}

#[cfg(feature = "std")]
impl EventEnd<f64> for super::TrBdf2Solution {
    fn event_end(&self) -> Option<(f64, &[f64])> {
        self.event.then_some((self.t, &self.x[..]))
    }
}

#[cfg(feature = "std")]
impl EventEnd<f64> for super::Radau5Solution {
    fn event_end(&self) -> Option<(f64, &[f64])> {
        self.event.then_some((self.t, &self.x[..]))
    }
}

/// How the watch joins an integration.
#[cfg_attr(not(feature = "std"), allow(dead_code))] // no watch without std
pub(crate) enum Hook<'h, 'a> {
    /// Not at all (switched off, no contacts, no `std`).
    None,
    /// A check after each accepted step, composed after the caller's
    /// projection: for a run with its own event function, which the
    /// integrators have room for only one of. A contact lost is seen at
    /// the end of the step that lost it.
    Project(&'h mut WatchFn<'a>),
    /// The margin as the event function: the integration stops where it
    /// comes down through zero, located on the dense output.
    Event(&'h mut MarginFn<'a>),
}

/// Runs `solve` with the model's contact watch when `on` and the model has
/// contacts, after checking the initial state `x0` at `t0`: as the event
/// function when the run has none of its own (`has_event` false; a
/// solution that ended at an event then ended at a contact lost), else as
/// a check after each step. A contact lost is
/// [`IntegrateError::Contact`], forces that cannot be evaluated
/// [`IntegrateError::Model`].
#[cfg(feature = "std")]
pub(crate) fn watched<M: Model, T: Scalar, R>(
    model: &M,
    inputs: &[T],
    on: bool,
    t0: f64,
    x0: &[T],
    has_event: bool,
    solve: impl FnOnce(Hook<'_, '_>) -> Result<R, IntegrateError>,
) -> Result<R, IntegrateError>
where
    R: EventEnd<T>,
{
    use crate::contact_watch::ContactWatch;
    if !on || M::info().contacts.is_empty() {
        return solve(Hook::None);
    }
    let real = |x: &[T]| -> Vec<f64> { x.iter().map(|v| v.re()).collect() };
    let mut watch = ContactWatch::new(model).inputs(&real(inputs));
    let result = match watch.check(t0, &real(x0)) {
        Err(failed) => Err(IntegrateError::Projection {
            t: t0,
            reason: failed.reason,
        }),
        Ok(()) if has_event => {
            let mut check = |t: f64, x: &[f64]| watch.check(t, x);
            solve(Hook::Project(&mut check))
        }
        Ok(()) => {
            let mut margin = |t: f64, x: &[f64]| watch.margin(t, x);
            solve(Hook::Event(&mut margin))
        }
    };
    match result {
        Ok(sol) => match sol.event_end() {
            Some((t, x)) if !has_event => match watch.lost_at(t, &real(x)) {
                Ok(event) => Err(IntegrateError::Contact(event)),
                Err(e) => Err(IntegrateError::Model(e)),
            },
            _ => Ok(sol),
        },
        Err(IntegrateError::Projection { .. } | IntegrateError::NonFinite { .. })
            if watch.stopped().is_some() || watch.failure().is_some() =>
        {
            match (watch.stopped(), watch.failure()) {
                (Some(event), _) => Err(IntegrateError::Contact(event)),
                (None, Some(e)) => Err(IntegrateError::Model(e)),
                (None, None) => result,
            }
        }
        other => other,
    }
}

/// Without `std` there are no contact forces to watch: `solve` runs as it
/// is.
#[cfg(not(feature = "std"))]
pub(crate) fn watched<M: Model, T: Scalar, R>(
    _model: &M,
    _inputs: &[T],
    _on: bool,
    _t0: f64,
    _x0: &[T],
    _has_event: bool,
    solve: impl FnOnce(Hook<'_, '_>) -> Result<R, IntegrateError>,
) -> Result<R, IntegrateError>
where
    R: EventEnd<T>,
{
    solve(Hook::None)
}

/// A projection of the slice-based integrators ([`TrBdf2`](super::TrBdf2),
/// [`Radau5`](super::Radau5)).
#[cfg(feature = "std")]
pub(crate) type SliceProject<'a> = dyn FnMut(f64, &mut [f64]) -> Result<(), ProjectionFailed> + 'a;

/// [`watched`] for the slice-based integrators ([`TrBdf2`](super::TrBdf2),
/// [`Radau5`](super::Radau5)): `solve` gets the event function (the
/// caller's, or the watch's margin) and the projection (the caller's,
/// followed by the watch's check when the caller has an event function).
#[cfg(feature = "std")]
#[allow(clippy::too_many_arguments)] // the problem's start and the hooks
pub(crate) fn watched_slices<M: Model, R>(
    model: &M,
    inputs: &[f64],
    on: bool,
    t0: f64,
    x0: &[f64],
    event: Option<&mut MarginFn<'_>>,
    project: Option<&mut SliceProject<'_>>,
    solve: impl FnOnce(
        Option<&mut MarginFn<'_>>,
        Option<&mut SliceProject<'_>>,
    ) -> Result<R, IntegrateError>,
) -> Result<R, IntegrateError>
where
    R: EventEnd<f64>,
{
    let has_event = event.is_some();
    watched(model, inputs, on, t0, x0, has_event, |hook| match hook {
        Hook::None => solve(event, project),
        Hook::Event(margin) => solve(Some(margin), project),
        Hook::Project(watch) => {
            let mut project = project;
            let mut both = |t: f64, x: &mut [f64]| -> Result<(), ProjectionFailed> {
                if let Some(p) = project.as_mut() {
                    p(t, x)?;
                }
                watch(t, x)
            };
            solve(event, Some(&mut both))
        }
    })
}
