//! # appell-python-glue
//!
//! The native half of a model compiled by the `appell` Python package. The
//! package writes a small crate per model: the `#[derive(Appell)]` struct
//! and a `#[pymodule]` that calls [`register`]. Everything else (argument
//! checks, batches split over threads with the GIL released, the
//! integrators, the Jacobians) lives here, so it is compiled once into the
//! cache's shared target directory; only [`register`]'s small generic part
//! ([`Compiled`], one call of the model per function) is compiled per model.
//!
//! Layout of every function's arguments and results: [`Op`]. All values are
//! `f64`; a batch is a leading axis of N rows.
#![warn(missing_docs)]

mod ops;
mod python;
mod simulate;

pub use ops::{held_feet, Arg, Compiled, Evaluate, Failure, Op};
pub use python::{register, NativeModel};
pub use simulate::{Event, Feedback, Method, SimJob, DOP853_MAX_STATE};

/// The version of the interface between this crate and the Python package
/// (`appell._loader` checks it when it loads a model).
pub const ABI_VERSION: u32 = 1;
