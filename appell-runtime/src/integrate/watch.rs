//! The contact watch every `solve_model*` runs on a model with contacts
//! (see [`crate::contact_watch`]): a stopping watch checked on the initial
//! state and, as a projection that never moves the state, after every
//! accepted step; its stop becomes [`IntegrateError::Contact`].

use super::solution::{IntegrateError, ProjectionFailed};
use crate::model::Model;
use crate::scalar::Scalar;

/// The check the integrators compose after a caller's projection: the
/// reduced state in `f64` (the real parts, for dual numbers).
pub(in crate::integrate) type WatchFn<'a> =
    dyn FnMut(f64, &[f64]) -> Result<(), ProjectionFailed> + 'a;

/// Runs `solve` with the model's contact watch when `on` and the model has
/// contacts (and `None` otherwise), after checking the initial state `x0`
/// at `t0`; a stop of the watch is [`IntegrateError::Contact`], a failure
/// to evaluate the forces [`IntegrateError::Model`].
#[cfg(feature = "std")]
pub(in crate::integrate) fn watched<M: Model, T: Scalar, R>(
    model: &M,
    inputs: &[T],
    on: bool,
    t0: f64,
    x0: &[T],
    solve: impl FnOnce(Option<&mut WatchFn<'_>>) -> Result<R, IntegrateError>,
) -> Result<R, IntegrateError> {
    use crate::contact_watch::ContactWatch;
    if !on || M::info().contacts.is_empty() {
        return solve(None);
    }
    let real = |x: &[T]| -> Vec<f64> { x.iter().map(|v| v.re()).collect() };
    let mut watch = ContactWatch::new(model).inputs(&real(inputs));
    let result = match watch.check(t0, &real(x0)) {
        Ok(()) => {
            let mut check = |t: f64, x: &[f64]| watch.check(t, x);
            solve(Some(&mut check))
        }
        Err(failed) => Err(IntegrateError::Projection {
            t: t0,
            reason: failed.reason,
        }),
    };
    match result {
        Err(IntegrateError::Projection { .. }) => match (watch.stopped(), watch.failure()) {
            (Some(event), _) => Err(IntegrateError::Contact(event)),
            (None, Some(e)) => Err(IntegrateError::Model(e)),
            (None, None) => result,
        },
        other => other,
    }
}

/// Without `std` there are no contact forces to watch: `solve` runs as it
/// is.
#[cfg(not(feature = "std"))]
pub(in crate::integrate) fn watched<M: Model, T: Scalar, R>(
    _model: &M,
    _inputs: &[T],
    _on: bool,
    _t0: f64,
    _x0: &[T],
    solve: impl FnOnce(Option<&mut WatchFn<'_>>) -> Result<R, IntegrateError>,
) -> Result<R, IntegrateError> {
    solve(None)
}

/// A projection of the slice-based integrators ([`TrBdf2`](super::TrBdf2),
/// [`Radau5`](super::Radau5)).
#[cfg(feature = "std")]
pub(in crate::integrate) type SliceProject<'a> =
    dyn FnMut(f64, &mut [f64]) -> Result<(), ProjectionFailed> + 'a;

/// [`watched`] for the slice-based integrators: `solve` gets the caller's
/// `project` followed by the watch, as one projection.
#[cfg(feature = "std")]
pub(in crate::integrate) fn watched_slices<M: Model, R>(
    model: &M,
    inputs: &[f64],
    on: bool,
    t0: f64,
    x0: &[f64],
    project: Option<&mut SliceProject<'_>>,
    solve: impl FnOnce(Option<&mut SliceProject<'_>>) -> Result<R, IntegrateError>,
) -> Result<R, IntegrateError> {
    watched(model, inputs, on, t0, x0, |watch| {
        let Some(watch) = watch else {
            return solve(project);
        };
        let mut project = project;
        let mut both = |t: f64, x: &mut [f64]| -> Result<(), ProjectionFailed> {
            if let Some(p) = project.as_mut() {
                p(t, x)?;
            }
            watch(t, x)
        };
        solve(Some(&mut both))
    })
}
