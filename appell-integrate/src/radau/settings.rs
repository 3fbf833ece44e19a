//! [`Radau5`]: the integrator's settings, builder and their validation.

use crate::solution::IntegrateError;

// Items the documentation links to.
#[cfg(doc)]
use super::Radau5Stats;

/// Adaptive Radau IIA integrator of order 5 for stiff problems (Hairer &
/// Wanner's RADAU5, *Solving ODEs II*, §IV.8), configured by a builder.
/// Requires the `std` feature.
///
/// The three-stage Radau IIA method is the collocation method at the nodes
/// `c = ((4 − √6)/10, (4 + √6)/10, 1)`: order 5, L-stable and stiffly
/// accurate, so a stiff component decays as fast as the exact one however
/// large the step.
///
/// * **Newton**: the stage increments `z` solve `z = h (A ⊗ I) F(x + z)`
///   by simplified Newton. Transformed by the eigenvectors of `A⁻¹`, the
///   3n×3n system splits into one real n×n system with `γ/h − J` and one
///   complex n×n system with `(α − iβ)/h − J` (`J = ∂f/∂x`), each factored
///   by LU once per step size. The first iterate is the previous step's
///   collocation polynomial extrapolated. Iterations stop when
///   `η ‖Δ‖ ≤ κ` (`η = θ/(1 − θ)`, θ the contraction rate, κ from the
///   tolerance), at most [`Radau5::newton_max_iter`]; a contraction rate
///   above 0.99, or one too slow to converge in the iterations left,
///   rejects the step and shrinks it.
/// * **Jacobian reuse** (as RADAU5): after an accepted step the Jacobian is
///   kept when Newton converged fast (θ ≤ [`Radau5::jacobian_reuse`], or
///   in one iteration); then, when the proposed step changes by a factor
///   in `[1, 1.2]`, the step size and both factorizations are kept too. A
///   Newton failure with a stale Jacobian gets a new one for the retry, and
///   so does a step rejected by the error estimate unless its Newton
///   iteration converged fast (RADAU5 renews it after every rejection).
/// * **Error estimate**: the embedded estimate of order 3,
///   `(γ/h − J)⁻¹ (f(t, x) + Σ e_i z_i / h)`; the filter by `(I − h J/γ)⁻¹`
///   keeps it bounded on stiff components. On the first step and after a
///   rejection, an estimate above 1 is refined once by `f` at `x + err`.
///   After an accepted step, `f(t, x)` is the derivative of its
///   collocation polynomial at its end (equal to `f` there up to the
///   residual of the converged Newton iteration, and free), unless a
///   projection moved the state. Norm: RMS of `err_i / sk_i`, `sk_i =
///   atol' + rtol' · max(|x_i|, |x_new_i|)`; a step is accepted when the
///   norm is below 1.
/// * **Tolerances**: as RADAU5, the given tolerances are mapped to
///   `rtol' = 0.1 rtol^(2/3)`, `atol' = atol · rtol'/rtol` (for `rtol = 0`:
///   `atol' = 0.1 atol^(2/3)`), which makes the global error follow the
///   requested tolerance closely on problems where the method has its
///   full order. Where it does not (the order reduction of stiff problems
///   driven by a time-dependent forcing), the error can approach the
///   looser `rtol'`.
/// * **Step control**: `h_new = h · clamp(fac · err^(−1/4), 1/5, 8)` with
///   the safety factor `fac = 0.9 (2 k_max + 1)/(2 k_max + k)` (`k` Newton
///   iterations), combined with Gustafsson's predictive controller
///   (`h_new` the smaller of the two); no growth right after a rejection;
///   a rejected first step is retried 10× smaller.
/// * **Initial step**: `0.01 ‖x0‖/‖f(t0, x0)‖` in the error norm (`1e-6`
///   when either is tiny) unless [`Radau5::h0`] gives one.
/// * **Dense output**: the collocation polynomial of each accepted step
///   (degree 3, through `x` and the three stages), at no extra cost. It
///   serves [`Radau5::solve_at`] and [`Radau5::solve_until`]. It is of
///   local order 4 where the step ends superconverge to order 6: between
///   steps the error is at the level of the tolerance, above that of the
///   step ends.
/// * **Events** ([`Radau5::solve_until`]): a sign change of `g(t, x)` over
///   an accepted step (or a zero at its end, `g` nonzero at its start) is
///   located on the dense output by the Illinois method to
///   [`Radau5::event_tol`]; the integration stops there. A zero of `g` at
///   `t0` is not an event.
/// * **Failures** are typed [`IntegrateError`]s, never a panic or a NaN.
///
/// Defaults: `rtol = 1e-6`, `atol = 1e-9`, `max_steps = 100_000`,
/// `h0 = None` (automatic), `h_max = None` (the interval length),
/// `newton_max_iter = 7`, `event_tol = 1e-12`, `jacobian_reuse` 0.001
/// with a given Jacobian and 0.1 with a model's.
///
/// ```
/// use appell_integrate::Radau5;
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
/// let sol = Radau5::new().rtol(1e-6).atol(1e-9).solve(f, jac, 0.0, &[0.0], 5.0).unwrap();
/// assert_eq!(sol.t, 5.0);
/// // Exact: x = λ (λ cos t + sin t)/(λ² + 1) − e^(−λt) λ²/(λ² + 1), λ = 1000.
/// let exact = 1e3 * (1e3 * 5.0_f64.cos() + 5.0_f64.sin()) / (1e6 + 1.0);
/// assert!((sol.x[0] - exact).abs() < 1e-6);
/// assert!(sol.stats.accepted < 100);
/// // A constant Jacobian converges Newton in one iteration: computed once.
/// assert_eq!(sol.stats.jacobians, 1);
///
/// // Invalid settings are reported, not acted on.
/// assert!(Radau5::new().rtol(-1.0).solve(f, jac, 0.0, &[0.0], 1.0).is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Radau5 {
    pub(super) rtol: f64,
    pub(super) atol: f64,
    pub(super) h0: Option<f64>,
    pub(super) h_max: Option<f64>,
    pub(super) max_steps: usize,
    pub(super) newton_max_iter: usize,
    pub(super) jacobian_reuse: Option<f64>,
    pub(super) event_tol: f64,
    pub(super) contact_watch: bool,
    pub(super) jacobian_by_duals: bool,
}

impl Default for Radau5 {
    fn default() -> Self {
        Self::new()
    }
}

impl Radau5 {
    /// The integrator with the documented defaults ([`Radau5`]).
    ///
    /// ```
    /// use appell_integrate::Radau5;
    /// assert_eq!(Radau5::new(), Radau5::default());
    /// ```
    pub const fn new() -> Self {
        Radau5 {
            rtol: 1e-6,
            atol: 1e-9,
            h0: None,
            h_max: None,
            max_steps: 100_000,
            newton_max_iter: 7,
            jacobian_reuse: None,
            event_tol: 1e-12,
            contact_watch: true,
            jacobian_by_duals: false,
        }
    }

    /// Relative tolerance (default `1e-6`; must be finite and ≥ 0).
    ///
    /// ```
    /// use appell_integrate::{IntegrateError, Radau5};
    /// use appell_core::ModelError;
    ///
    /// let f = |_t: f64, x: &[f64], dx: &mut [f64]| -> Result<(), ModelError> {
    ///     dx[0] = -x[0];
    ///     Ok(())
    /// };
    /// let jac = |_t: f64, _x: &[f64], j: &mut [f64]| -> Result<(), ModelError> {
    ///     j[0] = -1.0;
    ///     Ok(())
    /// };
    /// let loose = Radau5::new().rtol(1e-3).solve(f, jac, 0.0, &[1.0], 1.0).unwrap();
    /// let tight = Radau5::new().rtol(1e-10).solve(f, jac, 0.0, &[1.0], 1.0).unwrap();
    /// let exact = (-1.0_f64).exp();
    /// assert!((tight.x[0] - exact).abs() < (loose.x[0] - exact).abs());
    /// assert!(matches!(
    ///     Radau5::new().rtol(f64::NAN).solve(f, jac, 0.0, &[1.0], 1.0),
    ///     Err(IntegrateError::InvalidInput { .. })
    /// ));
    /// ```
    pub const fn rtol(mut self, rtol: f64) -> Self {
        self.rtol = rtol;
        self
    }

    /// Absolute tolerance (default `1e-9`; must be finite and ≥ 0, and
    /// `rtol` and `atol` not both 0).
    ///
    /// ```
    /// use appell_integrate::{IntegrateError, Radau5};
    /// use appell_core::ModelError;
    ///
    /// let f = |_t: f64, x: &[f64], dx: &mut [f64]| -> Result<(), ModelError> {
    ///     dx[0] = -x[0];
    ///     Ok(())
    /// };
    /// let jac = |_t: f64, _x: &[f64], j: &mut [f64]| -> Result<(), ModelError> {
    ///     j[0] = -1.0;
    ///     Ok(())
    /// };
    /// // A pure absolute tolerance is allowed...
    /// assert!(Radau5::new().rtol(0.0).atol(1e-8).solve(f, jac, 0.0, &[1.0], 1.0).is_ok());
    /// // ...but not no tolerance at all.
    /// assert!(matches!(
    ///     Radau5::new().rtol(0.0).atol(0.0).solve(f, jac, 0.0, &[1.0], 1.0),
    ///     Err(IntegrateError::InvalidInput { .. })
    /// ));
    /// ```
    pub const fn atol(mut self, atol: f64) -> Self {
        self.atol = atol;
        self
    }

    /// The first step size (magnitude), or `None` (default) for the
    /// automatic choice; must be finite and nonzero.
    ///
    /// ```
    /// use appell_integrate::Radau5;
    /// use appell_core::ModelError;
    ///
    /// let f = |_t: f64, x: &[f64], dx: &mut [f64]| -> Result<(), ModelError> {
    ///     dx[0] = -x[0];
    ///     Ok(())
    /// };
    /// let jac = |_t: f64, _x: &[f64], j: &mut [f64]| -> Result<(), ModelError> {
    ///     j[0] = -1.0;
    ///     Ok(())
    /// };
    /// let sol = Radau5::new().h0(Some(1e-3)).solve(f, jac, 0.0, &[1.0], 1.0).unwrap();
    /// assert!((sol.x[0] - (-1.0_f64).exp()).abs() < 1e-6);
    /// assert!(Radau5::new().h0(Some(0.0)).solve(f, jac, 0.0, &[1.0], 1.0).is_err());
    /// ```
    pub const fn h0(mut self, h0: Option<f64>) -> Self {
        self.h0 = h0;
        self
    }

    /// Maximum step size, or `None` (default) for the interval length;
    /// must be > 0.
    ///
    /// ```
    /// use appell_integrate::Radau5;
    /// use appell_core::ModelError;
    ///
    /// let f = |_t: f64, _x: &[f64], dx: &mut [f64]| -> Result<(), ModelError> {
    ///     dx[0] = 1.0;
    ///     Ok(())
    /// };
    /// let jac = |_t: f64, _x: &[f64], j: &mut [f64]| -> Result<(), ModelError> {
    ///     j[0] = 0.0;
    ///     Ok(())
    /// };
    /// let sol = Radau5::new().h_max(Some(0.1)).solve(f, jac, 0.0, &[0.0], 1.0).unwrap();
    /// assert!(sol.stats.accepted >= 10);
    /// assert!(Radau5::new().h_max(Some(-1.0)).solve(f, jac, 0.0, &[0.0], 1.0).is_err());
    /// ```
    pub const fn h_max(mut self, h_max: Option<f64>) -> Self {
        self.h_max = h_max;
        self
    }

    /// Maximum number of steps, accepted and rejected (default `100_000`);
    /// more is [`IntegrateError::TooManySteps`].
    ///
    /// ```
    /// use appell_integrate::{IntegrateError, Radau5};
    /// use appell_core::ModelError;
    ///
    /// let f = |t: f64, _x: &[f64], dx: &mut [f64]| -> Result<(), ModelError> {
    ///     dx[0] = (10.0 * t).cos();
    ///     Ok(())
    /// };
    /// let jac = |_t: f64, _x: &[f64], j: &mut [f64]| -> Result<(), ModelError> {
    ///     j[0] = 0.0;
    ///     Ok(())
    /// };
    /// let r = Radau5::new().max_steps(3).solve(f, jac, 0.0, &[0.0], 100.0);
    /// assert!(matches!(r, Err(IntegrateError::TooManySteps { steps: 3, .. })));
    /// ```
    pub const fn max_steps(mut self, max_steps: usize) -> Self {
        self.max_steps = max_steps;
        self
    }

    /// Maximum Newton iterations per step (default `7`; at least 1). It also
    /// sets the safety factor of the step control ([`Radau5`]).
    ///
    /// ```
    /// use appell_integrate::{IntegrateError, Radau5};
    /// use appell_core::ModelError;
    ///
    /// let f = |_t: f64, x: &[f64], dx: &mut [f64]| -> Result<(), ModelError> {
    ///     dx[0] = -x[0] * x[0];
    ///     Ok(())
    /// };
    /// let jac = |_t: f64, x: &[f64], j: &mut [f64]| -> Result<(), ModelError> {
    ///     j[0] = -2.0 * x[0];
    ///     Ok(())
    /// };
    /// let sol = Radau5::new().newton_max_iter(10).solve(f, jac, 0.0, &[1.0], 1.0).unwrap();
    /// assert!((sol.x[0] - 0.5).abs() < 1e-7);
    /// assert!(matches!(
    ///     Radau5::new().newton_max_iter(0).solve(f, jac, 0.0, &[1.0], 1.0),
    ///     Err(IntegrateError::InvalidInput { .. })
    /// ));
    /// ```
    pub const fn newton_max_iter(mut self, newton_max_iter: usize) -> Self {
        self.newton_max_iter = newton_max_iter;
        self
    }

    /// The Newton contraction rate up to which an accepted step's Jacobian
    /// is kept for the next step (RADAU5's `THET`; must be in `[0, 1)`).
    /// Larger values trade Newton iterations for Jacobians: worth it when a
    /// Jacobian costs many rhs calls. A Newton solve that converged in one
    /// iteration keeps the Jacobian at any setting. Default: `0.001` (as
    /// RADAU5) where the Jacobian is given, `0.1` (RADAU5's advice for
    /// costly Jacobians) for the `solve_model*` methods, whose Jacobian
    /// (the model's generated one, or by dual numbers at one evaluation of
    /// the equations per state component) costs several evaluations of the
    /// equations.
    ///
    /// ```
    /// use appell_integrate::{IntegrateError, Radau5};
    /// use appell_core::ModelError;
    ///
    /// // x' = −x²: a Jacobian that changes with the state.
    /// let f = |_t: f64, x: &[f64], dx: &mut [f64]| -> Result<(), ModelError> {
    ///     dx[0] = -x[0] * x[0];
    ///     Ok(())
    /// };
    /// let jac = |_t: f64, x: &[f64], j: &mut [f64]| -> Result<(), ModelError> {
    ///     j[0] = -2.0 * x[0];
    ///     Ok(())
    /// };
    /// let fresh = Radau5::new().rtol(1e-8).solve(f, jac, 0.0, &[1.0], 10.0).unwrap();
    /// let kept = Radau5::new()
    ///     .rtol(1e-8)
    ///     .jacobian_reuse(0.1)
    ///     .solve(f, jac, 0.0, &[1.0], 10.0)
    ///     .unwrap();
    /// assert!(kept.stats.jacobians <= fresh.stats.jacobians);
    /// assert!((kept.x[0] - 1.0 / 11.0).abs() < 1e-8);
    /// assert!(matches!(
    ///     Radau5::new().jacobian_reuse(1.0).solve(f, jac, 0.0, &[1.0], 1.0),
    ///     Err(IntegrateError::InvalidInput { .. })
    /// ));
    /// ```
    pub const fn jacobian_reuse(mut self, theta: f64) -> Self {
        self.jacobian_reuse = Some(theta);
        self
    }

    /// Absolute time tolerance of event location (default `1e-12`; must be
    /// ≥ 0; never tighter than 4 ulp of the event time), see
    /// [`Radau5::solve_until`].
    ///
    /// ```
    /// use appell_integrate::Radau5;
    /// use appell_core::ModelError;
    ///
    /// let f = |_t: f64, _x: &[f64], dx: &mut [f64]| -> Result<(), ModelError> {
    ///     dx[0] = 1.0;
    ///     Ok(())
    /// };
    /// let jac = |_t: f64, _x: &[f64], j: &mut [f64]| -> Result<(), ModelError> {
    ///     j[0] = 0.0;
    ///     Ok(())
    /// };
    /// let g = |_t: f64, x: &[f64]| x[0] - 0.3;
    /// let sol = Radau5::new().event_tol(1e-3).solve_until(f, jac, g, 0.0, &[0.0], 1.0).unwrap();
    /// assert!(sol.event && (sol.t - 0.3).abs() <= 1e-3);
    /// assert!(Radau5::new().event_tol(-1.0).solve_until(f, jac, g, 0.0, &[0.0], 1.0).is_err());
    /// ```
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
    /// use appell_integrate::Radau5;
    /// assert_ne!(Radau5::new().contact_watch(false), Radau5::new());
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
    /// use appell_integrate::Radau5;
    /// use appell_core::__doc_model::Pendulum;
    ///
    /// let model = Pendulum { g_over_l: 9.81 };
    /// let x0 = [1.0, 0.0];
    /// let generated = Radau5::new().solve_model(&model, &[0.5], 0.0, &x0, 2.0).unwrap();
    /// let duals = Radau5::new()
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

    /// Whether [`Radau5::jacobian_by_duals`] is set: for drivers that pass
    /// their own Jacobian (the hybrid driver's phases).
    // Shared with the hybrid driver; not part of the API.
    #[doc(hidden)]
    pub const fn wants_duals(&self) -> bool {
        self.jacobian_by_duals
    }

    /// The settings checked, or [`IntegrateError::InvalidInput`] saying
    /// what is wrong.
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
        if let Some(h) = self.h0 {
            if !(h.is_finite() && h != 0.0) {
                return bad("h0 must be finite and nonzero");
            }
        }
        if let Some(h) = self.h_max {
            if h.is_nan() || h <= 0.0 {
                return bad("h_max must be > 0");
            }
        }
        if self.newton_max_iter == 0 {
            return bad("newton_max_iter must be at least 1");
        }
        if let Some(theta) = self.jacobian_reuse {
            if !(0.0..1.0).contains(&theta) {
                return bad("jacobian_reuse must be in [0, 1)");
            }
        }
        if self.max_steps == 0 {
            return bad("max_steps must be at least 1");
        }
        if self.event_tol.is_nan() || self.event_tol < 0.0 {
            return bad("event_tol must be >= 0");
        }
        Ok(())
    }

    /// The internal tolerances `(rtol', atol')` of RADAU5 (see [`Radau5`]).
    pub(super) fn internal_tolerances(&self) -> (f64, f64) {
        if self.rtol > 0.0 {
            let r = 0.1 * self.rtol.powf(2.0 / 3.0);
            (r, self.atol * r / self.rtol)
        } else {
            (0.0, 0.1 * self.atol.powf(2.0 / 3.0))
        }
    }
}
