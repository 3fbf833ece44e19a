//! [`TrBdf2`]: the integrator's settings, builder and their validation.

use crate::solution::IntegrateError;

/// Adaptive TR-BDF2 integrator for stiff problems (Bank et al. 1985; the
/// formulation and error estimate of Hosea & Shampine 1996, as in MATLAB's
/// `ode23tb`), configured by a builder. Requires the `std` feature.
///
/// TR-BDF2 is the three-stage ESDIRK of order 2
///
/// ```text
///   0 |  0   0   0          γ = 2 − √2,  d = γ/2,  w = √2/4
///   γ |  d   d   0
///   1 |  w   w   d
///  ---+-------------
///     |  w   w   d          (order 2, L-stable, stiffly accurate)
///     | (1−w)/3 (3w+1)/3 d/3  (embedded order 3)
/// ```
///
/// a trapezoidal stage to `t + γh` followed by a BDF2 stage to `t + h`. The
/// first stage is the last of the previous step (FSAL), so a step costs one
/// rhs call per Newton iteration and nothing else.
///
/// * **Newton**: both implicit stages share the iteration matrix
///   `I − h d J`, `J = ∂f/∂x`. The Jacobian is reused across steps until a
///   Newton iteration converges slowly (contraction rate above 0.2) or fails
///   with a stale Jacobian; the LU factorization is reused while the step size
///   is unchanged (a proposed growth below 20 % is not taken, to keep it).
///   Iterations stop when `η ‖Δ‖ ≤ max(0.01, 10 ε / rtol)` (`η = θ/(1−θ)` from the contraction
///   rate θ, Hairer & Wanner's criterion), at most
///   [`TrBdf2::max_newton`] iterations; divergence (θ ≥ 0.9), a non-finite
///   iterate or a singular matrix is a Newton failure: the Jacobian is
///   recomputed if stale, else the step is rejected and shrunk 4×.
/// * **Error norm**: RMS over the components of `e_i / sk_i` with
///   `sk_i = atol + rtol · max(|x_i|, |x_new_i|)`, where `e` is the
///   difference of the embedded solutions filtered by `(I − h d J)⁻¹`
///   (Shampine's device, which keeps the estimate bounded on stiff
///   components); a step is accepted when the norm is at most 1.
/// * **Step control**: `h_new = h · clamp(0.9 · err^(−1/3), 0.2, 5)`, no
///   growth right after a rejection.
/// * **Initial step**: `0.01 ‖x0‖/‖f(t0, x0)‖` in the error norm (`1e-6`
///   when either is tiny) unless [`TrBdf2::h_init`] gives one.
/// * **Dense output**: on each accepted step from `(t, x)` to
///   `(t + h, x₁)`, the cubic Hermite interpolant of `x`, `f(t, x)`, `x₁`
///   and the last stage derivative `f₁ ≈ f(t + h, x₁)` (the FSAL first
///   stage of the next step, so no extra rhs call). It is locally of order 3,
///   one above the method, so interpolated states are as accurate as the
///   step ends. It serves [`TrBdf2::solve_at`] and [`TrBdf2::solve_until`].
/// * **Events** ([`TrBdf2::solve_until`]): after each accepted step the
///   event function `g(t, x)` is evaluated at its end; a sign change (or a
///   zero at the end, when `g` was nonzero at the start) is located on the
///   dense output by the Illinois method to [`TrBdf2::event_tol`] and the
///   integration stops there. A zero of `g` at `t0` is not an event.
/// * **Failures** are typed [`IntegrateError`]s, never a panic or a NaN.
///
/// Defaults: `rtol = 1e-6`, `atol = 1e-9`, `max_steps = 100_000`,
/// `h_init = None` (automatic), `h_min = 0` (only the floor of 16 ulp of
/// `t`), `h_max = None` (the interval length), `max_newton = 7`,
/// `adaptive = true`, `event_tol = 1e-12`.
///
/// ```
/// use appell_integrate::TrBdf2;
/// use appell_core::ModelError;
///
/// // x' = −1000 (x − cos t): stiff; x follows cos t after a short layer.
/// let f = |t: f64, x: &[f64], dx: &mut [f64]| -> Result<(), ModelError> {
///     dx[0] = -1000.0 * (x[0] - t.cos());
///     Ok(())
/// };
/// let jac = |_t: f64, _x: &[f64], j: &mut [f64]| -> Result<(), ModelError> {
///     j[0] = -1000.0;
///     Ok(())
/// };
/// let sol = TrBdf2::new().rtol(1e-6).atol(1e-9).solve(f, jac, 0.0, &[0.0], 5.0).unwrap();
/// assert_eq!(sol.t, 5.0);
/// // Exact: x = λ (λ cos t + sin t)/(λ² + 1) − e^(−λt) λ²/(λ² + 1), λ = 1000.
/// let exact = 1e3 * (1e3 * 5.0_f64.cos() + 5.0_f64.sin()) / (1e6 + 1.0);
/// assert!((sol.x[0] - exact).abs() < 1e-5);
/// assert!(sol.stats.accepted < 1000);
/// assert_eq!(sol.stats.jacobians, 1);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrBdf2 {
    pub(super) rtol: f64,
    pub(super) atol: f64,
    pub(super) max_steps: usize,
    pub(super) h_init: Option<f64>,
    pub(super) h_min: f64,
    pub(super) h_max: Option<f64>,
    pub(super) max_newton: usize,
    pub(super) adaptive: bool,
    pub(super) event_tol: f64,
    pub(super) contact_watch: bool,
    pub(super) jacobian_by_duals: bool,
}

impl Default for TrBdf2 {
    fn default() -> Self {
        Self::new()
    }
}

impl TrBdf2 {
    /// The integrator with the documented defaults ([`TrBdf2`]).
    pub const fn new() -> Self {
        TrBdf2 {
            rtol: 1e-6,
            atol: 1e-9,
            max_steps: 100_000,
            h_init: None,
            h_min: 0.0,
            h_max: None,
            max_newton: 7,
            adaptive: true,
            event_tol: 1e-12,
            contact_watch: true,
            jacobian_by_duals: false,
        }
    }

    /// Relative tolerance (default `1e-6`; must be ≥ 0).
    pub const fn rtol(mut self, rtol: f64) -> Self {
        self.rtol = rtol;
        self
    }

    /// Absolute tolerance (default `1e-9`; must be ≥ 0, and `rtol` and
    /// `atol` not both 0).
    pub const fn atol(mut self, atol: f64) -> Self {
        self.atol = atol;
        self
    }

    /// Maximum number of steps, accepted and rejected (default `100_000`).
    pub const fn max_steps(mut self, max_steps: usize) -> Self {
        self.max_steps = max_steps;
        self
    }

    /// The first step size (magnitude), or `None` (default) for the
    /// automatic choice.
    pub const fn h_init(mut self, h_init: Option<f64>) -> Self {
        self.h_init = h_init;
        self
    }

    /// Minimum step size (default `0`: only the floor of 16 ulp of `t`); a
    /// smaller proposed step is [`IntegrateError::StepSizeTooSmall`] (or
    /// [`IntegrateError::NonFinite`] when the last failure was a non-finite
    /// value). The last step, cut to end exactly at `t_end`, may be smaller.
    pub const fn h_min(mut self, h_min: f64) -> Self {
        self.h_min = h_min;
        self
    }

    /// Maximum step size, or `None` (default) for the interval length.
    pub const fn h_max(mut self, h_max: Option<f64>) -> Self {
        self.h_max = h_max;
        self
    }

    /// Maximum Newton iterations per stage (default `7`; at least 1).
    pub const fn max_newton(mut self, max_newton: usize) -> Self {
        self.max_newton = max_newton;
        self
    }

    /// With `false`, every step has the size [`TrBdf2::h_init`] (which must
    /// then be given; the last step is cut to end at `t_end`) and the error
    /// estimate never rejects a step; a Newton failure still retries the
    /// step 4× smaller. For convergence studies. Default `true`.
    pub const fn adaptive(mut self, adaptive: bool) -> Self {
        self.adaptive = adaptive;
        self
    }

    /// Absolute time tolerance of event location (default `1e-12`; must be
    /// ≥ 0; never tighter than 4 ulp of the event time), see
    /// [`TrBdf2::solve_until`].
    pub const fn event_tol(mut self, event_tol: f64) -> Self {
        self.event_tol = event_tol;
        self
    }

    /// Whether the `solve_model*` methods watch a model's one-sided
    /// contacts (default `true`): for a model with `rolls` contacts they
    /// check the initial state with a stopping
    /// [`ContactWatch`](crate::contact_watch::ContactWatch), locate where a
    /// normal force turns negative or the body leaves the region where the
    /// model holds as an event (or, for `solve_model_until`, check the end
    /// of each accepted step) and end there with
    /// [`IntegrateError::Contact`]. With `false`
    /// nothing is checked (give a warning watch as the projection of
    /// `solve_model_projected` to warn instead).
    ///
    /// ```
    /// use appell_integrate::TrBdf2;
    /// assert_ne!(TrBdf2::new().contact_watch(false), TrBdf2::new());
    /// ```
    pub const fn contact_watch(mut self, on: bool) -> Self {
        self.contact_watch = on;
        self
    }

    /// Whether the `solve_model*` methods compute the Newton Jacobian by
    /// forward-mode dual numbers (one evaluation of the rhs per state
    /// component, counted in the stats' `jacobian_rhs_calls`) even where
    /// the model has a generated [`Model::rhs_jacobian`](appell_core::Model::rhs_jacobian),
    /// which they use by default (default `false`). For checking or timing
    /// the generated Jacobian; a model without one always takes the dual
    /// numbers.
    ///
    /// ```
    /// use appell_integrate::TrBdf2;
    /// use appell_core::__doc_model::Pendulum;
    ///
    /// let model = Pendulum { g_over_l: 9.81 };
    /// let x0 = [1.0, 0.0];
    /// let generated = TrBdf2::new().solve_model(&model, &[0.5], 0.0, &x0, 2.0).unwrap();
    /// let duals = TrBdf2::new()
    ///     .jacobian_by_duals(true)
    ///     .solve_model(&model, &[0.5], 0.0, &x0, 2.0)
    ///     .unwrap();
    /// assert_eq!(generated.stats.jacobian_rhs_calls, 0);
    /// assert_eq!(duals.stats.jacobian_rhs_calls, 2 * duals.stats.jacobians);
    /// // The same Jacobians to rounding: the same steps and solution.
    /// assert_eq!(generated.stats.accepted, duals.stats.accepted);
    /// assert!((generated.x[0] - duals.x[0]).abs() < 1e-12);
    /// ```
    pub const fn jacobian_by_duals(mut self, on: bool) -> Self {
        self.jacobian_by_duals = on;
        self
    }

    pub(super) fn check_settings(&self) -> Result<(), IntegrateError> {
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
        if let Some(h) = self.h_max {
            if h.is_nan() || h <= 0.0 {
                return bad("h_max must be > 0");
            }
        }
        if self.max_newton == 0 {
            return bad("max_newton must be at least 1");
        }
        if !self.adaptive && self.h_init.is_none() {
            return bad("a fixed-step integration needs h_init");
        }
        if self.event_tol.is_nan() || self.event_tol < 0.0 {
            return bad("event_tol must be >= 0");
        }
        Ok(())
    }
}
