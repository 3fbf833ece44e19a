//! The coefficients of TR-BDF2 and of its embedded error estimate.

// TR-BDF2 coefficients.
pub(super) const GAMMA: f64 = 2.0 - core::f64::consts::SQRT_2;
pub(super) const D: f64 = GAMMA / 2.0;
pub(super) const W: f64 = core::f64::consts::SQRT_2 / 4.0;
// Error weights (b̂ − b) of the three stage derivatives.
pub(super) const E1: f64 = (1.0 - 4.0 * W) / 3.0;
pub(super) const E2: f64 = 1.0 / 3.0;
pub(super) const E3: f64 = -2.0 * D / 3.0;
