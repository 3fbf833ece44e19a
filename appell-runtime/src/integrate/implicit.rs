//! Adaptive implicit integration for stiff models: TR-BDF2 (std only).

use super::explicit::illinois;
use super::solution::IntegrateError;
use crate::model::{check_len, Model, ModelError};
use nalgebra::{DMatrix, DVector};
use num_dual::Dual64;

/// Work counts of a [`TrBdf2`] integration.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TrBdf2Stats {
    /// Evaluations of the right-hand side in `f64` (the initial one and one
    /// per Newton iteration; the Jacobian's evaluations are not included).
    pub rhs_calls: usize,
    /// Evaluations of the right-hand side in dual numbers for Jacobians
    /// ([`TrBdf2::solve_model`]: one per state component and Jacobian; 0
    /// with a user Jacobian).
    pub jacobian_rhs_calls: usize,
    /// Accepted steps.
    pub accepted: usize,
    /// Rejected steps (error too large, or Newton failed).
    pub rejected: usize,
    /// Jacobian evaluations.
    pub jacobians: usize,
    /// LU factorizations of the iteration matrix `I − h d J`.
    pub lu_factorizations: usize,
    /// Newton iterations (over both implicit stages).
    pub newton_iterations: usize,
    /// Newton failures (divergence, slow convergence, a non-finite iterate or
    /// a singular iteration matrix); each rejects its step.
    pub newton_failures: usize,
}

/// The result of a [`TrBdf2`] integration.
#[derive(Clone, Debug, PartialEq)]
pub struct TrBdf2Solution {
    /// The final time (the end of the interval).
    pub t: f64,
    /// The state at [`TrBdf2Solution::t`].
    pub x: Vec<f64>,
    /// Work counts.
    pub stats: TrBdf2Stats,
    /// The size (magnitude) of the next step the error control proposed.
    pub h_next: f64,
    /// Whether the integration stopped at an event ([`TrBdf2::solve_until`]);
    /// [`TrBdf2Solution::t`] is then the event time, not the end of the
    /// interval.
    pub event: bool,
    /// How many output times were written ([`TrBdf2::solve_at`]).
    pub outputs: usize,
}

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
/// use appell_runtime::integrate::TrBdf2;
/// use appell_runtime::ModelError;
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
    rtol: f64,
    atol: f64,
    max_steps: usize,
    h_init: Option<f64>,
    h_min: f64,
    h_max: Option<f64>,
    max_newton: usize,
    adaptive: bool,
    event_tol: f64,
}

impl Default for TrBdf2 {
    fn default() -> Self {
        Self::new()
    }
}

// TR-BDF2 coefficients.
const GAMMA: f64 = 2.0 - core::f64::consts::SQRT_2;
const D: f64 = GAMMA / 2.0;
const W: f64 = core::f64::consts::SQRT_2 / 4.0;
// Error weights (b̂ − b) of the three stage derivatives.
const E1: f64 = (1.0 - 4.0 * W) / 3.0;
const E2: f64 = 1.0 / 3.0;
const E3: f64 = -2.0 * D / 3.0;

const SAFETY: f64 = 0.9;
const FAC_MIN: f64 = 0.2;
const FAC_MAX: f64 = 5.0;
const FAC_NEWTON: f64 = 0.25;
const HOLD_MAX: f64 = 1.2;
const NEWTON_KAPPA: f64 = 0.01;
const NEWTON_DIVERGE: f64 = 0.9;
const JAC_SLOW: f64 = 0.2;

/// RMS of `v_i / sk_i`.
fn wrms(v: &[f64], sk: &[f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let s: f64 = v.iter().zip(sk).map(|(a, s)| (a / s) * (a / s)).sum();
    (s / v.len() as f64).sqrt()
}

fn all_finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// An event function `g(t, x)`.
type EventG<'a> = dyn FnMut(f64, &[f64]) -> f64 + 'a;

/// Overwrites `slot` with `x`.
fn put(slot: &mut Vec<f64>, x: &[f64]) {
    slot.clear();
    slot.extend_from_slice(x);
}

/// The cubic Hermite interpolant of one accepted step from `(t, x0)` with
/// derivative `f0` to `(t + h, x1)` with derivative `f1` (`h` signed).
struct Hermite<'a> {
    t: f64,
    /// The end of the step (exactly).
    t1: f64,
    h: f64,
    x0: &'a [f64],
    f0: &'a [f64],
    x1: &'a [f64],
    f1: &'a [f64],
}

impl Hermite<'_> {
    /// The interpolated state at `tau` into `slot` (resized).
    fn at(&self, tau: f64, slot: &mut Vec<f64>) {
        let s = (tau - self.t) / self.h;
        let s2 = s * s;
        let s3 = s2 * s;
        let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
        let h10 = (s3 - 2.0 * s2 + s) * self.h;
        let h01 = 3.0 * s2 - 2.0 * s3;
        let h11 = (s3 - s2) * self.h;
        slot.clear();
        slot.extend(
            (0..self.x0.len())
                .map(|i| h00 * self.x0[i] + h10 * self.f0[i] + h01 * self.x1[i] + h11 * self.f1[i]),
        );
    }
}

/// The event of `g` inside the step of `dense` (`g` is `ga` at its start
/// and `gb` at its end, of opposite signs or `gb = 0`), located by
/// [`illinois`] on the interpolant: the far end of the final bracket and
/// the state there (the step's end state exactly when the bracket did not
/// move).
fn locate(
    event_tol: f64,
    g: &mut EventG<'_>,
    dense: &Hermite<'_>,
    ga: f64,
    gb: f64,
) -> Result<(f64, Vec<f64>), IntegrateError> {
    let mut xc = Vec::with_capacity(dense.x1.len());
    let on_dense = |tc: f64| {
        dense.at(tc, &mut xc);
        if all_finite(&xc) {
            Ok(g(tc, &xc))
        } else {
            Err(IntegrateError::NonFinite { t: tc })
        }
    };
    let te = illinois(event_tol, on_dense, dense.t, ga, dense.t1, gb)?;
    if te == dense.t1 {
        Ok((te, dense.x1.to_vec()))
    } else {
        let mut xe = Vec::with_capacity(dense.x1.len());
        dense.at(te, &mut xe);
        Ok((te, xe))
    }
}

/// How a Newton solve of a stage ended (model errors are passed on).
enum Newton {
    /// Converged, with the largest contraction rate seen.
    Converged { theta: f64 },
    /// Diverged, too slow, or a non-finite value (`true`).
    Failed { non_finite: bool },
}

/// The state of the iteration matrix and its factorization.
struct Iteration {
    n: usize,
    jac: Vec<f64>,
    /// A Jacobian has been computed (at some earlier point).
    have_jac: bool,
    /// The Jacobian was computed at the start of the current step.
    fresh: bool,
    lu: Option<nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>>,
    /// The signed step the factorization is for.
    lu_h: f64,
    /// The Newton rate estimate η carried between solves.
    eta: f64,
}

impl Iteration {
    /// Factors `I − h d J`; false when it is singular or not finite.
    fn factor(&mut self, h: f64, stats: &mut TrBdf2Stats) -> bool {
        let n = self.n;
        let hd = h * D;
        let jac = &self.jac;
        let m = DMatrix::from_fn(n, n, |i, j| {
            (if i == j { 1.0 } else { 0.0 }) - hd * jac[i * n + j]
        });
        stats.lu_factorizations += 1;
        let lu = m.lu();
        if !lu.is_invertible() {
            self.lu = None;
            return false;
        }
        self.lu = Some(lu);
        self.lu_h = h;
        true
    }

    /// Solves `(I − h d J) y = b` in place; false on failure.
    fn solve(&self, b: &mut [f64]) -> bool {
        let Some(lu) = &self.lu else { return false };
        let mut v = DVector::from_column_slice(b);
        if !lu.solve_mut(&mut v) {
            return false;
        }
        b.copy_from_slice(v.as_slice());
        all_finite(b)
    }

    /// Solves `y = psi + h d f(t, y)` for `y` (holding the predictor on
    /// entry), scaled by `sk`; on success `fy` is `(y − psi)/(h d)`.
    #[allow(clippy::too_many_arguments)]
    fn newton<F>(
        &mut self,
        f: &mut F,
        kappa: f64,
        max_newton: usize,
        t: f64,
        hd: f64,
        psi: &[f64],
        sk: &[f64],
        y: &mut [f64],
        fy: &mut [f64],
        stats: &mut TrBdf2Stats,
    ) -> Result<Newton, ModelError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
    {
        let n = self.n;
        let mut dy = vec![0.0; n];
        let mut norm_old = 0.0;
        let mut theta_max: f64 = 0.0;
        let mut eta = self.eta.max(f64::EPSILON).powf(0.8);
        for k in 0..max_newton {
            stats.rhs_calls += 1;
            f(t, y, fy)?;
            if !all_finite(fy) {
                return Ok(Newton::Failed { non_finite: true });
            }
            for i in 0..n {
                dy[i] = psi[i] + hd * fy[i] - y[i];
            }
            if !self.solve(&mut dy) {
                return Ok(Newton::Failed { non_finite: true });
            }
            stats.newton_iterations += 1;
            for i in 0..n {
                y[i] += dy[i];
            }
            let norm = wrms(&dy, sk);
            if !norm.is_finite() {
                return Ok(Newton::Failed { non_finite: true });
            }
            if k > 0 {
                let theta = norm / norm_old;
                theta_max = theta_max.max(theta);
                if theta >= NEWTON_DIVERGE {
                    return Ok(Newton::Failed { non_finite: false });
                }
                eta = theta / (1.0 - theta);
            }
            if eta * norm <= kappa || norm == 0.0 {
                self.eta = eta;
                for i in 0..n {
                    fy[i] = (y[i] - psi[i]) / hd;
                }
                return Ok(Newton::Converged { theta: theta_max });
            }
            norm_old = norm;
        }
        Ok(Newton::Failed { non_finite: false })
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

    fn check_settings(&self) -> Result<(), IntegrateError> {
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

    /// Integrates `dx/dt = f(t, x)` from `(t0, x0)` to `t_end` (which may be
    /// before `t0`). `f(t, x, dx)` writes the derivative into `dx`;
    /// `jac(t, x, j)` writes `∂f/∂x` into `j` (n×n, row-major). Both are
    /// called with slices of the length of `x0`.
    ///
    /// See [`TrBdf2`] for an example; [`TrBdf2::solve_model`] computes the
    /// Jacobian of a model by dual numbers.
    pub fn solve<F, J>(
        &self,
        f: F,
        jac: J,
        t0: f64,
        x0: &[f64],
        t_end: f64,
    ) -> Result<TrBdf2Solution, IntegrateError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
        J: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
    {
        self.run(f, jac, t0, x0, t_end, &mut [], None)
    }

    /// Integrates from `(t0, x0)` to the last time of `out` and writes the
    /// state at each `out[i].0` (set by the caller) into `out[i].1` (the
    /// vector is cleared and refilled with the `x0.len()` components), from
    /// the dense output ([`TrBdf2`]). The times must be finite and ordered in
    /// the direction of integration (which is that from `t0` to the last
    /// time; equal times are allowed), else [`IntegrateError::InvalidInput`].
    /// An empty `out` integrates nothing. [`TrBdf2Solution::outputs`] counts
    /// the written entries; the solution holds the state at the last time.
    ///
    /// ```
    /// use appell_runtime::integrate::TrBdf2;
    /// use appell_runtime::ModelError;
    ///
    /// let f = |_t: f64, x: &[f64], dx: &mut [f64]| -> Result<(), ModelError> {
    ///     dx[0] = -x[0];
    ///     Ok(())
    /// };
    /// let jac = |_t: f64, _x: &[f64], j: &mut [f64]| -> Result<(), ModelError> {
    ///     j[0] = -1.0;
    ///     Ok(())
    /// };
    /// let mut out = vec![(0.5, vec![]), (1.0, vec![]), (2.0, vec![])];
    /// let sol = TrBdf2::new()
    ///     .rtol(1e-8)
    ///     .atol(1e-10)
    ///     .solve_at(f, jac, 0.0, &[1.0], &mut out)
    ///     .unwrap();
    /// assert_eq!((sol.t, sol.outputs), (2.0, 3));
    /// for (t, x) in &out {
    ///     assert!((x[0] - (-t).exp()).abs() < 1e-5);
    /// }
    /// ```
    pub fn solve_at<F, J>(
        &self,
        f: F,
        jac: J,
        t0: f64,
        x0: &[f64],
        out: &mut [(f64, Vec<f64>)],
    ) -> Result<TrBdf2Solution, IntegrateError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
        J: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
    {
        let t_end = out.last().map_or(t0, |o| o.0);
        self.run(f, jac, t0, x0, t_end, out, None)
    }

    /// As [`TrBdf2::solve`], stopping at the first sign change of the event
    /// function `g(t, x)` (see [`TrBdf2`]); [`TrBdf2Solution::event`] tells
    /// whether it happened. A zero of `g` at `t0` is not an event; a
    /// non-finite value of `g` is [`IntegrateError::NonFinite`].
    ///
    /// The reported time is the end of the final bracket on the far side of
    /// the crossing (where `g` has its new sign or is zero), within
    /// [`TrBdf2::event_tol`] of the root of `g` on the dense output; the
    /// state there comes from the dense output.
    ///
    /// ```
    /// use appell_runtime::integrate::TrBdf2;
    /// use appell_runtime::ModelError;
    ///
    /// // x' = −x from 1: x = 1/2 at t = ln 2.
    /// let f = |_t: f64, x: &[f64], dx: &mut [f64]| -> Result<(), ModelError> {
    ///     dx[0] = -x[0];
    ///     Ok(())
    /// };
    /// let jac = |_t: f64, _x: &[f64], j: &mut [f64]| -> Result<(), ModelError> {
    ///     j[0] = -1.0;
    ///     Ok(())
    /// };
    /// let g = |_t: f64, x: &[f64]| x[0] - 0.5;
    /// let sol = TrBdf2::new()
    ///     .rtol(1e-9)
    ///     .atol(1e-12)
    ///     .solve_until(f, jac, g, 0.0, &[1.0], 5.0)
    ///     .unwrap();
    /// assert!(sol.event);
    /// assert!((sol.t - 2.0_f64.ln()).abs() < 1e-5);
    /// assert!(sol.x[0] <= 0.5);
    /// ```
    pub fn solve_until<F, J, G>(
        &self,
        f: F,
        jac: J,
        mut g: G,
        t0: f64,
        x0: &[f64],
        t_end: f64,
    ) -> Result<TrBdf2Solution, IntegrateError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
        J: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
        G: FnMut(f64, &[f64]) -> f64,
    {
        self.run(f, jac, t0, x0, t_end, &mut [], Some(&mut g))
    }

    /// Integrates a model's reduced equations ([`Model::rhs`]) from
    /// `(t0, x0)` to `t_end` with `inputs` held constant. The Jacobian is
    /// computed exactly by forward-mode dual numbers: one [`Dual64`]
    /// evaluation of the generated rhs per state component (counted in
    /// [`TrBdf2Stats::jacobian_rhs_calls`]).
    ///
    /// Errors: [`ModelError::Length`] (as [`IntegrateError::Model`]) when
    /// `x0` is not [`ModelInfo::state_len`](crate::ModelInfo::state_len)
    /// long, any error of [`Model::rhs`], and the integration errors of
    /// [`TrBdf2`].
    pub fn solve_model<M: Model>(
        &self,
        model: &M,
        t0: f64,
        x0: &[f64],
        t_end: f64,
        inputs: &[f64],
    ) -> Result<TrBdf2Solution, IntegrateError> {
        self.run_model(model, t0, x0, t_end, inputs, &mut [], None)
    }

    /// [`TrBdf2::solve_at`] of a model's reduced equations, as
    /// [`TrBdf2::solve_model`].
    ///
    /// ```
    /// use appell_runtime::integrate::TrBdf2;
    /// use appell_runtime::{Model, ModelError, ModelInfo, OpCounts, Scalar};
    /// # // A hand-written harmonic oscillator x'' = -w² x (what the derive would
    /// # // generate has the same shape). Only `info`, `prepare` and `rhs` matter
    /// # // to the integrator.
    /// # struct Oscillator { w: f64 }
    /// # static INFO: ModelInfo = ModelInfo {
    /// #     name: "Oscillator", parameters: &["w"], coordinates: &["x"], speeds: &["x"],
    /// #     dependent: &[], cyclic: &[], ignorable: &[], retained: &["x"], inputs: &[],
    /// #     effects: &[], outputs: &[], row_sources: &[], contacts: &[], holonomic: 0, constraints: 0, bodies: &[], force_points: 0,
    /// #     torques: 0, symbolic_elimination: true, rhs_ops: OpCounts {
    /// #         add: 0, mul: 2, div: 0, calls: 0, total: 3 },
    /// #     equations: "x'' = -w^2 x",
    /// # };
    /// # fn unused() -> Result<(), ModelError> { Err(ModelError::NonFinite { what: "unused" }) }
    /// # impl Model for Oscillator {
    /// #     type Prepared<T: Scalar> = T;
    /// #     fn info() -> &'static ModelInfo { &INFO }
    /// #     fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> { out[0] = self.w; Ok(()) }
    /// #     fn set_parameter(&mut self, _: &str, _: f64) -> bool { false }
    /// #     fn prepare<T: Scalar>(&self) -> T { let w = T::from_f64(self.w); -(w * w) }
    /// #     fn rhs<T: Scalar>(&self, p: &T, _t: T, s: &[T], _i: &[T], ds: &mut [T]) -> Result<(), ModelError> {
    /// #         appell_runtime::check_len("state", s, 2)?;
    /// #         appell_runtime::check_len("dstate", ds, 2)?;
    /// #         ds[0] = s[1]; ds[1] = *p * s[0]; Ok(())
    /// #     }
    /// #     fn mass_matrix_and_forcing<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
    /// #     fn speed_transform<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
    /// #     fn coordinate_rates<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { unused() }
    /// #     fn constraint_residuals<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
    /// #     fn kinetic_energy<T: Scalar>(&self, _: T, _: &[T], _: &[T]) -> Result<T, ModelError> { unused().map(|_| T::zero()) }
    /// #     fn mass_properties(&self, _: &mut [f64], _: &mut [[f64; 9]]) -> Result<(), ModelError> { unused() }
    /// #     fn body_poses<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
    /// #     fn constraint_rows<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
    /// #     fn load_geometry<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
    /// #     fn load_values<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [[T; 3]], _: &mut [[T; 3]]) -> Result<(), ModelError> { unused() }
    /// # }
    ///
    /// // x'' = −w² x, x(0) = 1, x'(0) = 0: x(t) = cos(w t).
    /// let model = Oscillator { w: 2.0 };
    /// let mut out: Vec<(f64, Vec<f64>)> = (1..=10).map(|k| (0.1 * k as f64, vec![])).collect();
    /// let sol = TrBdf2::new()
    ///     .rtol(1e-9)
    ///     .atol(1e-12)
    ///     .solve_model_at(&model, 0.0, &[1.0, 0.0], &mut out, &[])
    ///     .unwrap();
    /// assert_eq!(sol.outputs, 10);
    /// for (t, x) in &out {
    ///     assert!((x[0] - (2.0 * t).cos()).abs() < 1e-6);
    /// }
    /// // Output times out of order are invalid input.
    /// let mut bad = vec![(0.5, vec![]), (0.2, vec![])];
    /// assert!(TrBdf2::new().solve_model_at(&model, 0.0, &[1.0, 0.0], &mut bad, &[]).is_err());
    /// ```
    pub fn solve_model_at<M: Model>(
        &self,
        model: &M,
        t0: f64,
        x0: &[f64],
        out: &mut [(f64, Vec<f64>)],
        inputs: &[f64],
    ) -> Result<TrBdf2Solution, IntegrateError> {
        let t_end = out.last().map_or(t0, |o| o.0);
        self.run_model(model, t0, x0, t_end, inputs, out, None)
    }

    /// [`TrBdf2::solve_until`] of a model's reduced equations, as
    /// [`TrBdf2::solve_model`].
    ///
    /// ```
    /// use appell_runtime::integrate::TrBdf2;
    /// use appell_runtime::{Model, ModelError, ModelInfo, OpCounts, Scalar};
    /// # // A hand-written harmonic oscillator x'' = -w² x (what the derive would
    /// # // generate has the same shape). Only `info`, `prepare` and `rhs` matter
    /// # // to the integrator.
    /// # struct Oscillator { w: f64 }
    /// # static INFO: ModelInfo = ModelInfo {
    /// #     name: "Oscillator", parameters: &["w"], coordinates: &["x"], speeds: &["x"],
    /// #     dependent: &[], cyclic: &[], ignorable: &[], retained: &["x"], inputs: &[],
    /// #     effects: &[], outputs: &[], row_sources: &[], contacts: &[], holonomic: 0, constraints: 0, bodies: &[], force_points: 0,
    /// #     torques: 0, symbolic_elimination: true, rhs_ops: OpCounts {
    /// #         add: 0, mul: 2, div: 0, calls: 0, total: 3 },
    /// #     equations: "x'' = -w^2 x",
    /// # };
    /// # fn unused() -> Result<(), ModelError> { Err(ModelError::NonFinite { what: "unused" }) }
    /// # impl Model for Oscillator {
    /// #     type Prepared<T: Scalar> = T;
    /// #     fn info() -> &'static ModelInfo { &INFO }
    /// #     fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> { out[0] = self.w; Ok(()) }
    /// #     fn set_parameter(&mut self, _: &str, _: f64) -> bool { false }
    /// #     fn prepare<T: Scalar>(&self) -> T { let w = T::from_f64(self.w); -(w * w) }
    /// #     fn rhs<T: Scalar>(&self, p: &T, _t: T, s: &[T], _i: &[T], ds: &mut [T]) -> Result<(), ModelError> {
    /// #         appell_runtime::check_len("state", s, 2)?;
    /// #         appell_runtime::check_len("dstate", ds, 2)?;
    /// #         ds[0] = s[1]; ds[1] = *p * s[0]; Ok(())
    /// #     }
    /// #     fn mass_matrix_and_forcing<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
    /// #     fn speed_transform<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
    /// #     fn coordinate_rates<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { unused() }
    /// #     fn constraint_residuals<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
    /// #     fn kinetic_energy<T: Scalar>(&self, _: T, _: &[T], _: &[T]) -> Result<T, ModelError> { unused().map(|_| T::zero()) }
    /// #     fn mass_properties(&self, _: &mut [f64], _: &mut [[f64; 9]]) -> Result<(), ModelError> { unused() }
    /// #     fn body_poses<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
    /// #     fn constraint_rows<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
    /// #     fn load_geometry<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
    /// #     fn load_values<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [[T; 3]], _: &mut [[T; 3]]) -> Result<(), ModelError> { unused() }
    /// # }
    ///
    /// // x = cos(2t) first reaches 0 at t = π/4.
    /// let model = Oscillator { w: 2.0 };
    /// let sol = TrBdf2::new()
    ///     .rtol(1e-10)
    ///     .atol(1e-12)
    ///     .solve_model_until(&model, |_t, x: &[f64]| x[0], 0.0, &[1.0, 0.0], 10.0, &[])
    ///     .unwrap();
    /// assert!(sol.event);
    /// assert!((sol.t - core::f64::consts::FRAC_PI_4).abs() < 1e-6);
    /// ```
    pub fn solve_model_until<M: Model, G>(
        &self,
        model: &M,
        mut g: G,
        t0: f64,
        x0: &[f64],
        t_end: f64,
        inputs: &[f64],
    ) -> Result<TrBdf2Solution, IntegrateError>
    where
        G: FnMut(f64, &[f64]) -> f64,
    {
        self.run_model(model, t0, x0, t_end, inputs, &mut [], Some(&mut g))
    }

    #[allow(clippy::too_many_arguments)]
    fn run_model<M: Model>(
        &self,
        model: &M,
        t0: f64,
        x0: &[f64],
        t_end: f64,
        inputs: &[f64],
        out: &mut [(f64, Vec<f64>)],
        event: Option<&mut EventG<'_>>,
    ) -> Result<TrBdf2Solution, IntegrateError> {
        let n = M::info().state_len();
        check_len("state", x0, n)?;
        let p = model.prepare::<f64>();
        let pd = model.prepare::<Dual64>();
        let inputs_d: Vec<Dual64> = inputs.iter().map(|&v| Dual64::from_re(v)).collect();
        let mut xd = vec![Dual64::from_re(0.0); n];
        let mut outd = vec![Dual64::from_re(0.0); n];
        let f = |t: f64, x: &[f64], dx: &mut [f64]| model.rhs(&p, t, x, inputs, dx);
        let jac = |t: f64, x: &[f64], j: &mut [f64]| -> Result<(), ModelError> {
            let td = Dual64::from_re(t);
            for (d, &v) in xd.iter_mut().zip(x) {
                *d = Dual64::from_re(v);
            }
            for col in 0..n {
                xd[col].eps = 1.0;
                let r = model.rhs(&pd, td, &xd, &inputs_d, &mut outd);
                xd[col].eps = 0.0;
                r?;
                for (row, o) in outd.iter().enumerate() {
                    j[row * n + col] = o.eps;
                }
            }
            Ok(())
        };
        let mut sol = self.run(f, jac, t0, x0, t_end, out, event)?;
        sol.stats.jacobian_rhs_calls = sol.stats.jacobians * n;
        Ok(sol)
    }

    #[allow(clippy::too_many_arguments)]
    fn run<F, J>(
        &self,
        mut f: F,
        mut jac_fn: J,
        t0: f64,
        x0: &[f64],
        t_end: f64,
        out: &mut [(f64, Vec<f64>)],
        mut event: Option<&mut EventG<'_>>,
    ) -> Result<TrBdf2Solution, IntegrateError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
        J: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
    {
        self.check_settings()?;
        if !t0.is_finite() || !t_end.is_finite() {
            return Err(IntegrateError::InvalidInput {
                what: "t0 and t_end must be finite",
            });
        }
        let dir = if t_end >= t0 { 1.0 } else { -1.0 };
        // Output times: finite, ordered, inside [t0, t_end].
        let mut prev = t0;
        for o in out.iter() {
            let ti = o.0;
            if !ti.is_finite() || (ti - prev) * dir < 0.0 || (ti - t_end) * dir > 0.0 {
                return Err(IntegrateError::InvalidInput {
                    what: "output times must be finite, ordered and within [t0, t_end]",
                });
            }
            prev = ti;
        }
        if !all_finite(x0) {
            return Err(IntegrateError::NonFinite { t: t0 });
        }
        let n = x0.len();
        let mut stats = TrBdf2Stats::default();
        let mut t = t0;
        let mut x = x0.to_vec();
        let mut next_out = 0;
        while next_out < out.len() && out[next_out].0 == t0 {
            put(&mut out[next_out].1, &x);
            next_out += 1;
        }
        let mut g_old = match event.as_mut() {
            Some(g) => {
                let v = g(t, &x);
                if !v.is_finite() {
                    return Err(IntegrateError::NonFinite { t });
                }
                v
            }
            None => 0.0,
        };
        if t_end == t0 {
            return Ok(TrBdf2Solution {
                t,
                x,
                stats,
                h_next: 0.0,
                event: false,
                outputs: next_out,
            });
        }

        let mut f0 = vec![0.0; n];
        stats.rhs_calls += 1;
        f(t, &x, &mut f0)?;
        if !all_finite(&f0) {
            return Err(IntegrateError::NonFinite { t });
        }
        let h_max = self.h_max.unwrap_or(f64::INFINITY).min((t_end - t0).abs());
        let mut sk: Vec<f64> = x.iter().map(|v| self.atol + self.rtol * v.abs()).collect();
        let mut h = match self.h_init {
            Some(h) => h.abs().min(h_max),
            None => {
                let d0 = wrms(&x, &sk);
                let d1 = wrms(&f0, &sk);
                let h0 = if d0 < 1e-5 || d1 < 1e-5 {
                    1e-6
                } else {
                    0.01 * d0 / d1
                };
                h0.min(h_max)
            }
        };

        let mut it = Iteration {
            n,
            jac: vec![0.0; n * n],
            have_jac: false,
            fresh: false,
            lu: None,
            lu_h: 0.0,
            eta: 1.0,
        };
        // Newton tolerance, not below what rounding allows (as in RADAU5).
        let kappa = if self.rtol > 0.0 {
            NEWTON_KAPPA.max(10.0 * f64::EPSILON / self.rtol)
        } else {
            NEWTON_KAPPA
        };
        let mut steps = 0usize;
        let mut rejected_last = false;
        let mut failure_non_finite = false;
        let mut psi = vec![0.0; n];
        let mut y2 = vec![0.0; n];
        let mut f2 = vec![0.0; n];
        let mut y3 = vec![0.0; n];
        let mut f3 = vec![0.0; n];
        let mut est = vec![0.0; n];

        loop {
            if steps >= self.max_steps {
                return Err(IntegrateError::TooManySteps { t, steps });
            }
            let remaining = (t_end - t).abs();
            let floor = self.h_min.max(16.0 * f64::EPSILON * t.abs());
            if h < floor && h < remaining {
                return Err(if failure_non_finite {
                    IntegrateError::NonFinite { t }
                } else {
                    IntegrateError::StepSizeTooSmall { t, h }
                });
            }
            let last = h >= remaining * (1.0 - 1e-12);
            if last {
                h = remaining;
            }
            steps += 1;
            let hs = dir * h;

            if !it.have_jac {
                jac_fn(t, &x, &mut it.jac)?;
                stats.jacobians += 1;
                if !all_finite(&it.jac) {
                    return Err(IntegrateError::NonFinite { t });
                }
                it.have_jac = true;
                it.fresh = true;
                it.lu = None;
            }
            if (it.lu.is_none() || it.lu_h != hs) && !it.factor(hs, &mut stats) {
                // A singular iteration matrix: a new Jacobian, else a
                // smaller step.
                stats.newton_failures += 1;
                stats.rejected += 1;
                failure_non_finite = false;
                rejected_last = true;
                if it.fresh {
                    h *= FAC_NEWTON;
                } else {
                    it.have_jac = false;
                }
                continue;
            }

            // Stage 2 (trapezoidal rule to t + γh), Euler predictor.
            let hd = hs * D;
            for i in 0..n {
                psi[i] = x[i] + hd * f0[i];
                y2[i] = x[i] + GAMMA * hs * f0[i];
            }
            let mut outcome = it.newton(
                &mut f,
                kappa,
                self.max_newton,
                t + GAMMA * hs,
                hd,
                &psi,
                &sk,
                &mut y2,
                &mut f2,
                &mut stats,
            )?;
            let mut theta = 0.0_f64;
            if let Newton::Converged { theta: th } = outcome {
                theta = th;
                // Stage 3 (BDF2 to t + h), predictor extrapolating x and y2.
                for i in 0..n {
                    psi[i] = x[i] + hs * W * (f0[i] + f2[i]);
                    y3[i] = x[i] + (y2[i] - x[i]) / GAMMA;
                }
                outcome = it.newton(
                    &mut f,
                    kappa,
                    self.max_newton,
                    if last { t_end } else { t + hs },
                    hd,
                    &psi,
                    &sk,
                    &mut y3,
                    &mut f3,
                    &mut stats,
                )?;
            }
            match outcome {
                Newton::Converged { theta: th } => theta = theta.max(th),
                Newton::Failed { non_finite } => {
                    stats.newton_failures += 1;
                    stats.rejected += 1;
                    rejected_last = true;
                    failure_non_finite = non_finite;
                    it.eta = 1.0;
                    if it.fresh {
                        h *= FAC_NEWTON;
                    } else {
                        // Retry the same step with a new Jacobian.
                        it.have_jac = false;
                    }
                    continue;
                }
            }

            // Error estimate, filtered by the iteration matrix.
            for i in 0..n {
                est[i] = hs * (E1 * f0[i] + E2 * f2[i] + E3 * f3[i]);
            }
            let filtered = it.solve(&mut est);
            let scale: Vec<f64> = (0..n)
                .map(|i| self.atol + self.rtol * x[i].abs().max(y3[i].abs()))
                .collect();
            let err = if filtered {
                wrms(&est, &scale)
            } else {
                f64::NAN
            };
            if !all_finite(&y3) {
                stats.rejected += 1;
                rejected_last = true;
                failure_non_finite = true;
                h *= FAC_NEWTON;
                continue;
            }

            let accept = !self.adaptive || err <= 1.0;
            if accept {
                stats.accepted += 1;
                let t_new = if last { t_end } else { t + hs };

                // Event at the end of the step.
                let mut crossed = false;
                let mut g_new = 0.0;
                if let Some(g) = event.as_mut() {
                    g_new = g(t_new, &y3);
                    if !g_new.is_finite() {
                        return Err(IntegrateError::NonFinite { t });
                    }
                    crossed = g_old != 0.0 && (g_new == 0.0 || (g_new > 0.0) != (g_old > 0.0));
                }
                let dense = Hermite {
                    t,
                    t1: t_new,
                    h: t_new - t,
                    x0: &x,
                    f0: &f0,
                    x1: &y3,
                    f1: &f3,
                };
                let mut stop: Option<(f64, Vec<f64>)> = None;
                if crossed {
                    if let Some(g) = event.as_mut() {
                        stop = Some(locate(self.event_tol, &mut **g, &dense, g_old, g_new)?);
                    }
                }
                g_old = g_new;

                // Outputs up to the end of the step (or the event).
                let t_stop = stop.as_ref().map_or(t_new, |s| s.0);
                while next_out < out.len() && (out[next_out].0 - t_stop) * dir <= 0.0 {
                    let to = out[next_out].0;
                    let slot = &mut out[next_out].1;
                    if to == t_new {
                        put(slot, &y3);
                    } else {
                        dense.at(to, slot);
                        if !all_finite(slot) {
                            return Err(IntegrateError::NonFinite { t });
                        }
                    }
                    next_out += 1;
                }
                if let Some((te, xe)) = stop {
                    return Ok(TrBdf2Solution {
                        t: te,
                        x: xe,
                        stats,
                        h_next: h,
                        event: true,
                        outputs: next_out,
                    });
                }

                t = t_new;
                x.copy_from_slice(&y3);
                f0.copy_from_slice(&f3);
                for i in 0..n {
                    sk[i] = self.atol + self.rtol * x[i].abs();
                }
                it.fresh = false;
                if theta > JAC_SLOW {
                    it.have_jac = false;
                }
                let mut fac = if err.is_finite() && err > 0.0 {
                    (SAFETY * err.powf(-1.0 / 3.0)).clamp(FAC_MIN, FAC_MAX)
                } else {
                    FAC_MAX
                };
                if rejected_last {
                    fac = fac.min(1.0);
                }
                if (1.0..HOLD_MAX).contains(&fac) {
                    fac = 1.0;
                }
                rejected_last = false;
                failure_non_finite = false;
                let h_new = if self.adaptive {
                    (h * fac).min(h_max)
                } else {
                    self.h_init.map_or(h, f64::abs).min(h_max)
                };
                if last {
                    return Ok(TrBdf2Solution {
                        t,
                        x,
                        stats,
                        h_next: h_new,
                        event: false,
                        outputs: next_out,
                    });
                }
                h = h_new;
            } else {
                stats.rejected += 1;
                rejected_last = true;
                failure_non_finite = !err.is_finite();
                let fac = if err.is_finite() {
                    (SAFETY * err.powf(-1.0 / 3.0)).clamp(FAC_MIN, 1.0)
                } else {
                    FAC_NEWTON
                };
                h *= fac;
            }
        }
    }
}
