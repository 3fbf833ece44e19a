//! Adaptive implicit integration for stiff models: TR-BDF2 (std only), and
//! the parts of its loop [`Radau5`](super::Radau5) shares.

mod coefficients;
mod control;
mod dense;
mod driver;
mod jacobian;
mod newton;
mod settings;
mod shared;
mod solve;
mod stages;
mod stats;

pub(super) use control::{all_finite, wrms};
pub(super) use dense::{Dense, EventG};
pub(super) use jacobian::dual_jacobian;
pub use settings::TrBdf2;
pub(super) use shared::{
    check_problem, derivative, error_scale, initial_step, next_step, Hooks, ProjectG,
};
pub use stats::{TrBdf2Solution, TrBdf2Stats};
