//! Adaptive implicit integration of order 5 for stiff models: the
//! three-stage Radau IIA method as Hairer & Wanner's RADAU5 (std only).

mod coefficients;
mod control;
mod dense;
mod driver;
mod iteration;
mod linear;
mod settings;
mod solve;
mod stages;
mod stats;
#[cfg(test)]
mod tests;

pub use settings::Radau5;
pub use stats::{Radau5Solution, Radau5Stats};
