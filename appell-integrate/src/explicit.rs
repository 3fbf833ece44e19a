//! The machinery shared by the adaptive explicit Runge–Kutta integrators
//! [`Dopri5`](super::Dopri5) and [`Dop853`](super::Dop853): settings and
//! their validation, output sinks, the adaptive loop with step-size control,
//! dense output, outputs and events, event location and the initial step.
//!
//! A method is an [`EmbeddedPair`]: its stages (with their error estimate
//! and FSAL handling) and its continuous extension. Everything is generic
//! and monomorphised per method, without allocation.

mod api;
mod controller;
mod driver;
mod events;
mod pair;
mod settings;
mod sink;

pub(super) use api::explicit_api;
pub(super) use controller::sqrt;
pub(super) use driver::run;
#[cfg(feature = "std")] // only the implicit method, std-only, needs it from outside
pub(super) use events::illinois;
pub(super) use pair::{all_finite, DenseOutput, EmbeddedPair};
pub(super) use settings::Settings;
pub(super) use sink::{CallbackSink, Sink, SliceSink};
