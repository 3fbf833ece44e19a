//! What an adaptive integration returns and takes besides the right-hand
//! side: its [`Solution`] and work counts ([`Stats`]), why it stopped early
//! ([`IntegrateError`]), and the event and projection callbacks
//! ([`EventFn`], [`ProjectFn`]). Shared by the embedded pairs
//! ([`Dopri5`](super::Dopri5), [`Dop853`](super::Dop853)), the adaptive loop
//! they run on, and the implicit integrator.

use appell_core::{ContactEvent, ModelError};

/// Why an adaptive integration stopped without reaching its end.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum IntegrateError {
    /// The step size the error control asked for fell below the minimum
    /// (`h_min` of the integrator, and never below 16 ulp of `t`): the problem is
    /// too stiff or singular near `t` for the tolerances.
    StepSizeTooSmall {
        /// Time reached.
        t: f64,
        /// The step size that was too small (magnitude).
        h: f64,
    },
    /// `max_steps` steps (accepted and rejected) were taken.
    TooManySteps {
        /// Time reached.
        t: f64,
        /// Steps taken.
        steps: usize,
    },
    /// The state, the rhs or the event function became NaN or infinite at
    /// `t` (and shrinking the step did not help).
    NonFinite {
        /// Time reached (the start of the failing step).
        t: f64,
    },
    /// The projection passed to `solve_projected` reported failure (or
    /// left a non-finite state) after the step ending at `t`.
    Projection {
        /// Time of the state that could not be projected.
        t: f64,
        /// Why: the [`ProjectionFailed::reason`] the projection gave, or
        /// what the integrator found wrong with its result.
        reason: &'static str,
    },
    /// A setting or an argument is invalid (non-finite times, negative
    /// tolerances, output times out of order or outside the interval).
    InvalidInput {
        /// What was wrong.
        what: &'static str,
    },
    /// A one-sided contact was lost at [`ContactEvent::t`]: its normal
    /// force turned negative or the body left the region where the model
    /// holds. Raised by the contact watch every `solve_model*` of a model
    /// with contacts runs (see [`contact_watch`](crate::contact_watch), with
    /// `std`), at the located event or the end of the step that lost it.
    Contact(ContactEvent),
    /// The right-hand side returned an error.
    Model(ModelError),
}

impl From<ModelError> for IntegrateError {
    fn from(e: ModelError) -> Self {
        IntegrateError::Model(e)
    }
}

impl core::fmt::Display for IntegrateError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            IntegrateError::StepSizeTooSmall { t, h } => {
                write!(f, "step size {h:e} too small at t = {t}")
            }
            IntegrateError::TooManySteps { t, steps } => {
                write!(f, "{steps} steps taken, stopped at t = {t}")
            }
            IntegrateError::NonFinite { t } => write!(f, "non-finite value at t = {t}"),
            IntegrateError::Projection { t, reason } => {
                write!(
                    f,
                    "projection onto the constraints failed at t = {t}: {reason}"
                )
            }
            IntegrateError::InvalidInput { what } => write!(f, "invalid input: {what}"),
            IntegrateError::Contact(event) => write!(f, "{event}"),
            IntegrateError::Model(e) => write!(f, "model error: {e}"),
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for IntegrateError {}

/// An event function `g(t, x)` as passed to
/// [`Dopri5::solve_with`](super::Dopri5::solve_with): the integration stops
/// where its sign changes.
pub type EventFn<'a, T, const S: usize> = dyn FnMut(f64, &[T; S]) -> f64 + 'a;

/// A projection `p(t, x)` as passed to
/// [`Dopri5::solve_projected`](super::Dopri5::solve_projected): moves `x` in
/// place back onto a constraint manifold (for a model, with
/// `appell::linearize::project_holonomic`) and returns
/// `false` if it could not.
pub type ProjectFn<'a, T, const S: usize> =
    dyn FnMut(f64, &mut [T; S]) -> Result<(), ProjectionFailed> + 'a;

/// Why a projection (as passed to the `solve_projected` of
/// [`TrBdf2`](super::TrBdf2) and [`Radau5`](super::Radau5), with `std`)
/// could not move the state onto its manifold; the integration stops with
/// [`IntegrateError::Projection`] carrying the reason.
///
/// ```
/// use appell_integrate::{IntegrateError, ProjectionFailed};
///
/// let fail = ProjectionFailed { reason: "Newton did not converge" };
/// let e = IntegrateError::Projection { t: 1.5, reason: fail.reason };
/// assert_eq!(
///     e.to_string(),
///     "projection onto the constraints failed at t = 1.5: Newton did not converge"
/// );
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ProjectionFailed {
    /// What went wrong.
    pub reason: &'static str,
}

/// Work counts of an adaptive integration.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Evaluations of the right-hand side (including the initial-step
    /// estimate; dense output and event location cost none).
    pub rhs_calls: usize,
    /// Accepted steps.
    pub accepted: usize,
    /// Rejected steps (error too large, or a non-finite stage).
    pub rejected: usize,
}

/// The result of an adaptive integration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Solution<T, const S: usize> {
    /// The final time: the end of the interval, or the event time.
    pub t: f64,
    /// The state at [`Solution::t`].
    pub x: [T; S],
    /// Work counts.
    pub stats: Stats,
    /// True when the integration stopped at a sign change of the event
    /// function (then `t` is the located event time).
    pub event: bool,
    /// How many of the requested output times were reached and written.
    pub outputs: usize,
    /// The size (magnitude) of the last step the error control proposed,
    /// a good initial step for continuing.
    pub h_next: f64,
}
