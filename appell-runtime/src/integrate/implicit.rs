//! Adaptive implicit integration for stiff models: TR-BDF2 (std only).

mod coefficients;
mod control;
mod dense;
mod driver;
mod newton;
mod settings;
mod solve;
mod stages;
mod stats;

pub use settings::TrBdf2;
pub use stats::{TrBdf2Solution, TrBdf2Stats};
