//! [`Settings`]: the settings shared by the adaptive explicit integrators,
//! their defaults, validation and error weights.

use crate::solution::IntegrateError;

/// The settings of an adaptive explicit integrator (see the builders).
#[derive(Clone, Copy, PartialEq)]
pub(crate) struct Settings {
    pub(crate) rtol: f64,
    pub(crate) atol: f64,
    pub(crate) max_steps: usize,
    pub(crate) h_init: Option<f64>,
    pub(crate) h_min: f64,
    pub(crate) h_max: Option<f64>,
    pub(crate) beta: f64,
    pub(crate) event_tol: f64,
    pub(crate) adaptive: bool,
    pub(crate) contact_watch: bool,
}

impl Settings {
    /// The common defaults with the controller's `beta`.
    pub(crate) const fn new(beta: f64) -> Self {
        Settings {
            rtol: 1e-6,
            atol: 1e-9,
            max_steps: 100_000,
            h_init: None,
            h_min: 0.0,
            h_max: None,
            beta,
            event_tol: 1e-12,
            adaptive: true,
            contact_watch: true,
        }
    }

    /// `Debug` of the integrator `name` as if its settings were its fields.
    pub(crate) fn debug(&self, name: &str, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct(name)
            .field("rtol", &self.rtol)
            .field("atol", &self.atol)
            .field("max_steps", &self.max_steps)
            .field("h_init", &self.h_init)
            .field("h_min", &self.h_min)
            .field("h_max", &self.h_max)
            .field("beta", &self.beta)
            .field("event_tol", &self.event_tol)
            .field("adaptive", &self.adaptive)
            .field("contact_watch", &self.contact_watch)
            .finish()
    }

    /// Validation; `beta` must be in `[0, 0.2]`, or `[0, 0.2)` unless
    /// `beta_closed`.
    pub(super) fn check(&self, beta_closed: bool) -> Result<(), IntegrateError> {
        let bad = |what| Err(IntegrateError::InvalidInput { what });
        if !(self.rtol >= 0.0 && self.rtol.is_finite()) {
            return bad("rtol must be finite and >= 0");
        }
        if !(self.atol >= 0.0 && self.atol.is_finite()) {
            return bad("atol must be finite and >= 0");
        }
        if self.rtol == 0.0 && self.atol == 0.0 {
            return bad("rtol and atol are both 0");
        }
        if !(self.h_min >= 0.0 && self.h_min.is_finite()) {
            return bad("h_min must be finite and >= 0");
        }
        if let Some(h) = self.h_init {
            if !(h.is_finite() && h != 0.0) {
                return bad("h_init must be finite and nonzero");
            }
        }
        if !self.adaptive && self.h_init.is_none() {
            return bad("fixed steps (adaptive(false)) need h_init");
        }
        if let Some(h) = self.h_max {
            if h.is_nan() || h <= 0.0 {
                return bad("h_max must be > 0");
            }
        }
        if beta_closed {
            if !(0.0..=0.2).contains(&self.beta) {
                return bad("beta must be in [0, 0.2]");
            }
        } else if !(0.0..0.2).contains(&self.beta) {
            return bad("beta must be in [0, 0.2)");
        }
        if self.event_tol.is_nan() || self.event_tol < 0.0 {
            return bad("event_tol must be >= 0");
        }
        Ok(())
    }

    /// The weight `atol + rtol |x|`, kept positive.
    #[inline]
    pub(crate) fn scale(&self, a: f64, b: f64) -> f64 {
        let sk = self.atol + self.rtol * a.abs().max(b.abs());
        sk.max(f64::MIN_POSITIVE)
    }
}
