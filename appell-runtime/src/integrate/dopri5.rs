//! Adaptive Dormand–Prince 5(4) integration with dense output and event
//! location, on fixed-size arrays and without allocation.

use super::check_state_len;
use crate::model::{Model, ModelError};
use crate::scalar::Scalar;

/// Why an adaptive integration stopped without reaching its end.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum IntegrateError {
    /// The step size the error control asked for fell below the minimum
    /// (`h_min` of the integrator, and never below 16 ulp of `t`): the problem is
    /// too stiff or singular near `t` for the tolerances.
    StepSizeTooSmall {
        /// Time reached.
        t: f64,
        /// The step size that was too small (magnitude).
        h: f64,
    },
    /// `max_steps` steps (accepted and rejected) were taken.
    TooManySteps {
        /// Time reached.
        t: f64,
        /// Steps taken.
        steps: usize,
    },
    /// The state, the rhs or the event function became NaN or infinite at
    /// `t` (and shrinking the step did not help).
    NonFinite {
        /// Time reached (the start of the failing step).
        t: f64,
    },
    /// A setting or an argument is invalid (non-finite times, negative
    /// tolerances, output times out of order or outside the interval).
    InvalidInput {
        /// What was wrong.
        what: &'static str,
    },
    /// The right-hand side returned an error.
    Model(ModelError),
}

impl From<ModelError> for IntegrateError {
    fn from(e: ModelError) -> Self {
        IntegrateError::Model(e)
    }
}

impl core::fmt::Display for IntegrateError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            IntegrateError::StepSizeTooSmall { t, h } => {
                write!(f, "step size {h:e} too small at t = {t}")
            }
            IntegrateError::TooManySteps { t, steps } => {
                write!(f, "{steps} steps taken, stopped at t = {t}")
            }
            IntegrateError::NonFinite { t } => write!(f, "non-finite value at t = {t}"),
            IntegrateError::InvalidInput { what } => write!(f, "invalid input: {what}"),
            IntegrateError::Model(e) => write!(f, "model error: {e}"),
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for IntegrateError {}

/// An event function `g(t, x)` as passed to [`Dopri5::solve_with`]: the
/// integration stops where its sign changes.
pub type EventFn<'a, T, const S: usize> = dyn FnMut(f64, &[T; S]) -> f64 + 'a;

/// Work counts of an adaptive integration.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Evaluations of the right-hand side (including the initial-step
    /// estimate; dense output and event location cost none).
    pub rhs_calls: usize,
    /// Accepted steps.
    pub accepted: usize,
    /// Rejected steps (error too large, or a non-finite stage).
    pub rejected: usize,
}

/// The result of an adaptive integration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Solution<T, const S: usize> {
    /// The final time: the end of the interval, or the event time.
    pub t: f64,
    /// The state at [`Solution::t`].
    pub x: [T; S],
    /// Work counts.
    pub stats: Stats,
    /// True when the integration stopped at a sign change of the event
    /// function (then `t` is the located event time).
    pub event: bool,
    /// How many of the requested output times were reached and written.
    pub outputs: usize,
    /// The size (magnitude) of the last step the error control proposed,
    /// a good initial step for continuing.
    pub h_next: f64,
}

/// Adaptive Dormand–Prince 5(4) integrator (Hairer, Nørsett & Wanner,
/// *Solving ODEs I*, the `DOPRI5` scheme), configured by a builder.
///
/// The fifth-order solution is propagated (local extrapolation) and the
/// embedded fourth-order one gives the error estimate; the last stage is the
/// first of the next step (FSAL), so an accepted step costs 6 rhs calls.
///
/// * **Error norm**: RMS over the components of `err_i / sk_i` with
///   `sk_i = atol + rtol · max(|x_i|, |x_new_i|)`; a step is accepted when
///   the norm is at most 1.
/// * **Step control**: the PI controller of `DOPRI5`,
///   `h_new = h · clamp(0.9 · err^(−α) · err_prev^β, 0.2, 10)` with
///   `α = 1/5 − 0.75 β`, `β = 0.04` by default ([`Dopri5::beta`]; `β = 0`
///   is the elementary controller). After a rejection the step shrinks by
///   `clamp(0.9 err^(−1/5), 0.2, 1)` and may not grow on the next accepted
///   step.
/// * **Initial step**: Hairer's `HINIT` algorithm (one extra rhs call)
///   unless [`Dopri5::h_init`] gives one.
/// * **Dense output**: the free fourth-order continuous extension of
///   `DOPRI5` (no extra rhs calls) gives the state at requested output times
///   and at events.
/// * **Events**: with an event function `g(t, x)`, after every accepted step
///   whose end has `g` of the other sign than its start (or zero), the root
///   is located on the dense output by the Illinois method to
///   [`Dopri5::event_tol`] and the integration stops there.
/// * **Failures** are typed [`IntegrateError`]s, never a panic or a NaN: a
///   non-finite stage rejects the step and retries 5× smaller, and is
///   reported as [`IntegrateError::NonFinite`] once the step would fall
///   below the minimum.
///
/// Time and step sizes are `f64`; the state is any [`Scalar`] (for dual
/// numbers the step-size decisions use the real parts, so derivatives are
/// those of the discrete trajectory with the same steps).
///
/// Defaults: `rtol = 1e-6`, `atol = 1e-9`, `max_steps = 100_000`,
/// `h_init = None` (automatic), `h_min = 0` (only the 16-ulp floor),
/// `h_max = None` (the interval length), `beta = 0.04`,
/// `event_tol = 1e-12`.
///
/// ```
/// use appell_runtime::integrate::Dopri5;
/// use appell_runtime::ModelError;
///
/// // Harmonic oscillator x'' = -x over one period, x(0) = 1, x'(0) = 0.
/// let f = |_t: f64, x: &[f64; 2], dx: &mut [f64; 2]| -> Result<(), ModelError> {
///     dx[0] = x[1];
///     dx[1] = -x[0];
///     Ok(())
/// };
/// let tau = 2.0 * std::f64::consts::PI;
/// let sol = Dopri5::new().rtol(1e-10).atol(1e-12).solve(f, 0.0, &[1.0, 0.0], tau).unwrap();
/// assert_eq!(sol.t, tau);
/// assert!((sol.x[0] - 1.0).abs() < 1e-9 && sol.x[1].abs() < 1e-9);
/// assert!(sol.stats.rhs_calls < 1500);
///
/// // The time the oscillator first crosses x = 0 (t = π/2), by an event.
/// let sol = Dopri5::new()
///     .rtol(1e-10)
///     .solve_until(f, |_t, x: &[f64; 2]| x[0], 0.0, &[1.0, 0.0], tau)
///     .unwrap();
/// assert!(sol.event);
/// assert!((sol.t - std::f64::consts::FRAC_PI_2).abs() < 1e-9);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dopri5 {
    rtol: f64,
    atol: f64,
    max_steps: usize,
    h_init: Option<f64>,
    h_min: f64,
    h_max: Option<f64>,
    beta: f64,
    event_tol: f64,
}

impl Default for Dopri5 {
    fn default() -> Self {
        Self::new()
    }
}

// Dormand–Prince 5(4) coefficients.
const C2: f64 = 1.0 / 5.0;
const C3: f64 = 3.0 / 10.0;
const C4: f64 = 4.0 / 5.0;
const C5: f64 = 8.0 / 9.0;
const A21: f64 = 1.0 / 5.0;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
const A71: f64 = 35.0 / 384.0;
const A73: f64 = 500.0 / 1113.0;
const A74: f64 = 125.0 / 192.0;
const A75: f64 = -2187.0 / 6784.0;
const A76: f64 = 11.0 / 84.0;
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;
const D1: f64 = -12715105075.0 / 11282082432.0;
const D3: f64 = 87487479700.0 / 32700410799.0;
const D4: f64 = -10690763975.0 / 1880347072.0;
const D5: f64 = 701980252875.0 / 199316789632.0;
const D6: f64 = -1453857185.0 / 822651844.0;
const D7: f64 = 69997945.0 / 29380423.0;

const SAFETY: f64 = 0.9;
const FAC_MIN: f64 = 0.2;
const FAC_MAX: f64 = 10.0;
const EVENT_MAX_ITER: usize = 200;

/// Where requested outputs go.
trait Sink<T, const S: usize> {
    fn len(&self) -> usize;
    fn time(&self, i: usize) -> f64;
    fn put(&mut self, i: usize, x: &[T; S]);
}

struct SliceSink<'a, T, const S: usize>(&'a mut [(f64, [T; S])]);

impl<T: Copy, const S: usize> Sink<T, S> for SliceSink<'_, T, S> {
    fn len(&self) -> usize {
        self.0.len()
    }
    fn time(&self, i: usize) -> f64 {
        self.0[i].0
    }
    fn put(&mut self, i: usize, x: &[T; S]) {
        self.0[i].1 = *x;
    }
}

struct CallbackSink<'a, 'b, T, const S: usize> {
    times: &'a [f64],
    cb: &'b mut dyn FnMut(f64, &[T; S]),
}

impl<T, const S: usize> Sink<T, S> for CallbackSink<'_, '_, T, S> {
    fn len(&self) -> usize {
        self.times.len()
    }
    fn time(&self, i: usize) -> f64 {
        self.times[i]
    }
    fn put(&mut self, i: usize, x: &[T; S]) {
        (self.cb)(self.times[i], x)
    }
}

/// The continuous extension of one accepted step.
struct Dense<T, const S: usize> {
    t: f64,
    h: f64,
    r: [[T; S]; 5],
}

impl<T: Scalar, const S: usize> Dense<T, S> {
    fn at(&self, t: f64) -> [T; S] {
        let th = (t - self.t) / self.h;
        let th1 = 1.0 - th;
        let (th, th1) = (T::from_f64(th), T::from_f64(th1));
        let r = &self.r;
        let mut out = r[0];
        for (i, o) in out.iter_mut().enumerate() {
            *o = r[0][i] + th * (r[1][i] + th1 * (r[2][i] + th * (r[3][i] + th1 * r[4][i])));
        }
        out
    }
}

fn all_finite<T: Scalar, const S: usize>(x: &[T; S]) -> bool {
    x.iter().all(|v| v.re().is_finite())
}

impl Dopri5 {
    /// The integrator with the documented defaults ([`Dopri5`]).
    pub const fn new() -> Self {
        Dopri5 {
            rtol: 1e-6,
            atol: 1e-9,
            max_steps: 100_000,
            h_init: None,
            h_min: 0.0,
            h_max: None,
            beta: 0.04,
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

    /// The first step size (magnitude), or `None` (default) for Hairer's
    /// automatic choice.
    pub const fn h_init(mut self, h_init: Option<f64>) -> Self {
        self.h_init = h_init;
        self
    }

    /// Minimum step size (default `0`: only the floor of 16 ulp of `t`); a
    /// smaller proposed step is [`IntegrateError::StepSizeTooSmall`]. The
    /// last step, cut to end exactly at `t_end`, may be smaller.
    pub const fn h_min(mut self, h_min: f64) -> Self {
        self.h_min = h_min;
        self
    }

    /// Maximum step size, or `None` (default) for the interval length.
    pub const fn h_max(mut self, h_max: Option<f64>) -> Self {
        self.h_max = h_max;
        self
    }

    /// The PI controller's β (default `0.04`; `0` is the elementary
    /// controller; must be in `[0, 0.2)`).
    pub const fn beta(mut self, beta: f64) -> Self {
        self.beta = beta;
        self
    }

    /// Absolute time tolerance of event location (default `1e-12`, never
    /// below 4 ulp of the event time).
    pub const fn event_tol(mut self, event_tol: f64) -> Self {
        self.event_tol = event_tol;
        self
    }

    /// Integrates `dx/dt = f(t, x)` from `(t0, x0)` to `t_end` (which may
    /// be before `t0`). `f(t, x, dx)` writes the derivative into `dx`.
    ///
    /// See [`Dopri5`] for an example.
    pub fn solve<T, F, const S: usize>(
        &self,
        f: F,
        t0: f64,
        x0: &[T; S],
        t_end: f64,
    ) -> Result<Solution<T, S>, IntegrateError>
    where
        T: Scalar,
        F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
    {
        let mut sink = CallbackSink {
            times: &[],
            cb: &mut |_, _| {},
        };
        self.run(f, t0, x0, t_end, &mut sink, None)
    }

    /// As [`Dopri5::solve`], stopping at the first sign change of the event
    /// function `g(t, x)` (see [`Dopri5`]); [`Solution::event`] tells
    /// whether it happened. A zero of `g` at `t0` is not an event.
    ///
    /// The reported time is the end of the final bracket on the far side of
    /// the crossing (where `g` has its new sign or is zero), within
    /// [`Dopri5::event_tol`] of the root of `g` on the dense output; the
    /// state there comes from the dense output.
    pub fn solve_until<T, F, G, const S: usize>(
        &self,
        f: F,
        mut g: G,
        t0: f64,
        x0: &[T; S],
        t_end: f64,
    ) -> Result<Solution<T, S>, IntegrateError>
    where
        T: Scalar,
        F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
        G: FnMut(f64, &[T; S]) -> f64,
    {
        let mut sink = CallbackSink {
            times: &[],
            cb: &mut |_, _| {},
        };
        self.run(f, t0, x0, t_end, &mut sink, Some(&mut g))
    }

    /// Integrates from `(t0, x0)` to the last time of `out` and writes the
    /// state at each `out[i].0` (set by the caller, ordered in the
    /// direction of integration) into `out[i].1`, from the dense output.
    ///
    /// ```
    /// use appell_runtime::integrate::Dopri5;
    /// use appell_runtime::ModelError;
    ///
    /// let f = |_t: f64, x: &[f64; 1], dx: &mut [f64; 1]| -> Result<(), ModelError> {
    ///     dx[0] = -x[0];
    ///     Ok(())
    /// };
    /// let mut out = [(0.5, [0.0]), (1.0, [0.0]), (2.0, [0.0])];
    /// let sol = Dopri5::new().rtol(1e-9).atol(1e-12).solve_at(f, 0.0, &[1.0], &mut out).unwrap();
    /// assert_eq!(sol.outputs, 3);
    /// for (t, x) in out {
    ///     assert!((x[0] - (-t).exp()).abs() < 1e-8);
    /// }
    /// ```
    pub fn solve_at<T, F, const S: usize>(
        &self,
        f: F,
        t0: f64,
        x0: &[T; S],
        out: &mut [(f64, [T; S])],
    ) -> Result<Solution<T, S>, IntegrateError>
    where
        T: Scalar,
        F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
    {
        let t_end = out.last().map_or(t0, |o| o.0);
        self.run(f, t0, x0, t_end, &mut SliceSink(out), None)
    }

    /// The general form: integrates from `(t0, x0)` to `t_end`, calls
    /// `on_output(t, x)` at each of `times` (ordered in the direction of
    /// integration and within the interval), and stops at an event of `g`
    /// when one is given (as [`Dopri5::solve_until`]); output times past the
    /// event are not reached.
    #[allow(clippy::too_many_arguments)]
    pub fn solve_with<T, F, const S: usize>(
        &self,
        f: F,
        t0: f64,
        x0: &[T; S],
        t_end: f64,
        times: &[f64],
        on_output: &mut dyn FnMut(f64, &[T; S]),
        event: Option<&mut EventFn<'_, T, S>>,
    ) -> Result<Solution<T, S>, IntegrateError>
    where
        T: Scalar,
        F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
    {
        let mut sink = CallbackSink {
            times,
            cb: on_output,
        };
        self.run(f, t0, x0, t_end, &mut sink, event)
    }

    /// [`Dopri5::solve`] of a model's reduced equations ([`Model::rhs`],
    /// after one [`Model::prepare`]) with `inputs` held constant. The array
    /// length `S` must be the reduced state length.
    pub fn solve_model<M: Model, T: Scalar, const S: usize>(
        &self,
        model: &M,
        inputs: &[T],
        t0: f64,
        x0: &[T; S],
        t_end: f64,
    ) -> Result<Solution<T, S>, IntegrateError> {
        check_state_len::<M>(S)?;
        let p = model.prepare::<T>();
        let f = |t: T, x: &[T; S], dx: &mut [T; S]| model.rhs(&p, t, x, inputs, dx);
        self.solve(f, t0, x0, t_end)
    }

    /// [`Dopri5::solve_at`] of a model's reduced equations, as
    /// [`Dopri5::solve_model`].
    pub fn solve_model_at<M: Model, T: Scalar, const S: usize>(
        &self,
        model: &M,
        inputs: &[T],
        t0: f64,
        x0: &[T; S],
        out: &mut [(f64, [T; S])],
    ) -> Result<Solution<T, S>, IntegrateError> {
        check_state_len::<M>(S)?;
        let p = model.prepare::<T>();
        let f = |t: T, x: &[T; S], dx: &mut [T; S]| model.rhs(&p, t, x, inputs, dx);
        self.solve_at(f, t0, x0, out)
    }

    /// [`Dopri5::solve_until`] of a model's reduced equations, as
    /// [`Dopri5::solve_model`].
    pub fn solve_model_until<M: Model, T: Scalar, G, const S: usize>(
        &self,
        model: &M,
        inputs: &[T],
        g: G,
        t0: f64,
        x0: &[T; S],
        t_end: f64,
    ) -> Result<Solution<T, S>, IntegrateError>
    where
        G: FnMut(f64, &[T; S]) -> f64,
    {
        check_state_len::<M>(S)?;
        let p = model.prepare::<T>();
        let f = |t: T, x: &[T; S], dx: &mut [T; S]| model.rhs(&p, t, x, inputs, dx);
        self.solve_until(f, g, t0, x0, t_end)
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
        if !(0.0..0.2).contains(&self.beta) {
            return bad("beta must be in [0, 0.2)");
        }
        if self.event_tol.is_nan() || self.event_tol < 0.0 {
            return bad("event_tol must be >= 0");
        }
        Ok(())
    }

    /// The weight `atol + rtol |x|`, kept positive.
    fn scale(&self, a: f64, b: f64) -> f64 {
        let sk = self.atol + self.rtol * a.abs().max(b.abs());
        sk.max(f64::MIN_POSITIVE)
    }

    /// Hairer's `HINIT`: a first step from the size of `x`, `f` and an
    /// estimate of the second derivative (one rhs call).
    #[allow(clippy::too_many_arguments)]
    fn initial_step<T, F, const S: usize>(
        &self,
        f: &mut F,
        t: f64,
        x: &[T; S],
        k1: &[T; S],
        dir: f64,
        h_max: f64,
        stats: &mut Stats,
    ) -> Result<f64, IntegrateError>
    where
        T: Scalar,
        F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
    {
        let (mut dnf, mut dny) = (0.0, 0.0);
        for i in 0..S {
            let sk = self.scale(x[i].re(), 0.0);
            dnf += (k1[i].re() / sk) * (k1[i].re() / sk);
            dny += (x[i].re() / sk) * (x[i].re() / sk);
        }
        let mut h = if dnf <= 1e-10 || dny <= 1e-10 {
            1e-6
        } else {
            libm::sqrt(dny / dnf) * 0.01
        };
        h = h.min(h_max);
        let mut x1 = *x;
        let hs = T::from_f64(dir * h);
        for i in 0..S {
            x1[i] = x[i] + hs * k1[i];
        }
        let mut f1 = [T::zero(); S];
        stats.rhs_calls += 1;
        f(T::from_f64(t + dir * h), &x1, &mut f1)?;
        if !all_finite(&f1) {
            // Let the main loop shrink the step.
            return Ok(h);
        }
        let mut der2 = 0.0;
        for i in 0..S {
            let sk = self.scale(x[i].re(), 0.0);
            let d = (f1[i].re() - k1[i].re()) / sk;
            der2 += d * d;
        }
        let der2 = libm::sqrt(der2) / h;
        let der12 = der2.max(libm::sqrt(dnf));
        let h1 = if der12 <= 1e-15 {
            (h * 1e-3).max(1e-6)
        } else {
            libm::pow(0.01 / der12, 0.2)
        };
        Ok((100.0 * h).min(h1).min(h_max))
    }

    /// The integration loop behind every `solve*`.
    fn run<T, F, K, const S: usize>(
        &self,
        mut f: F,
        t0: f64,
        x0: &[T; S],
        t_end: f64,
        sink: &mut K,
        mut event: Option<&mut EventFn<'_, T, S>>,
    ) -> Result<Solution<T, S>, IntegrateError>
    where
        T: Scalar,
        F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
        K: Sink<T, S>,
    {
        self.check_settings()?;
        if !t0.is_finite() || !t_end.is_finite() {
            return Err(IntegrateError::InvalidInput {
                what: "t0 and t_end must be finite",
            });
        }
        let dir = if t_end >= t0 { 1.0 } else { -1.0 };
        // Output times: finite, ordered, inside [t0, t_end].
        let n_out = sink.len();
        let mut prev = t0;
        for i in 0..n_out {
            let ti = sink.time(i);
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

        let mut stats = Stats::default();
        let mut t = t0;
        let mut x = *x0;
        let mut next_out = 0;
        while next_out < n_out && sink.time(next_out) == t0 {
            sink.put(next_out, &x);
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
        let finish = |t, x, stats, event, outputs, h_next| {
            Ok(Solution {
                t,
                x,
                stats,
                event,
                outputs,
                h_next,
            })
        };
        if t_end == t0 {
            return finish(t, x, stats, false, next_out, 0.0);
        }

        let mut k1 = [T::zero(); S];
        stats.rhs_calls += 1;
        f(T::from_f64(t), &x, &mut k1)?;
        if !all_finite(&k1) {
            return Err(IntegrateError::NonFinite { t });
        }
        let h_max = self.h_max.unwrap_or(f64::INFINITY).min((t_end - t0).abs());
        let mut h = match self.h_init {
            Some(h) => h.abs().min(h_max),
            None => self.initial_step(&mut f, t, &x, &k1, dir, h_max, &mut stats)?,
        };
        let expo1 = 0.2 - 0.75 * self.beta;
        let mut fac_old: f64 = 1e-4;
        let mut last_rejected = false;
        let mut steps = 0usize;
        let c = T::from_f64;

        loop {
            if steps >= self.max_steps {
                return Err(IntegrateError::TooManySteps { t, steps });
            }
            let h_floor = self
                .h_min
                .max(16.0 * f64::EPSILON * t.abs())
                .max(f64::MIN_POSITIVE);
            let remaining = (t_end - t).abs();
            let last = 1.01 * h >= remaining;
            if !last && h < h_floor {
                return Err(IntegrateError::StepSizeTooSmall { t, h });
            }
            if last {
                h = remaining;
            }
            steps += 1;
            let hs = dir * h;
            let hh = c(hs);

            // Stages.
            let mut y = x;
            let mut k2 = [T::zero(); S];
            let mut k3 = [T::zero(); S];
            let mut k4 = [T::zero(); S];
            let mut k5 = [T::zero(); S];
            let mut k6 = [T::zero(); S];
            let mut k7 = [T::zero(); S];
            for i in 0..S {
                y[i] = x[i] + hh * (c(A21) * k1[i]);
            }
            f(c(t + C2 * hs), &y, &mut k2)?;
            for i in 0..S {
                y[i] = x[i] + hh * (c(A31) * k1[i] + c(A32) * k2[i]);
            }
            f(c(t + C3 * hs), &y, &mut k3)?;
            for i in 0..S {
                y[i] = x[i] + hh * (c(A41) * k1[i] + c(A42) * k2[i] + c(A43) * k3[i]);
            }
            f(c(t + C4 * hs), &y, &mut k4)?;
            for i in 0..S {
                y[i] =
                    x[i] + hh * (c(A51) * k1[i] + c(A52) * k2[i] + c(A53) * k3[i] + c(A54) * k4[i]);
            }
            f(c(t + C5 * hs), &y, &mut k5)?;
            for i in 0..S {
                y[i] = x[i]
                    + hh * (c(A61) * k1[i]
                        + c(A62) * k2[i]
                        + c(A63) * k3[i]
                        + c(A64) * k4[i]
                        + c(A65) * k5[i]);
            }
            let t_new = if last { t_end } else { t + hs };
            f(c(t + hs), &y, &mut k6)?;
            let mut x_new = x;
            for i in 0..S {
                x_new[i] = x[i]
                    + hh * (c(A71) * k1[i]
                        + c(A73) * k3[i]
                        + c(A74) * k4[i]
                        + c(A75) * k5[i]
                        + c(A76) * k6[i]);
            }
            let finite_so_far = all_finite(&x_new);
            if finite_so_far {
                f(c(t_new), &x_new, &mut k7)?;
                stats.rhs_calls += 6;
            } else {
                stats.rhs_calls += 5;
            }

            // Error estimate.
            let mut err = 0.0;
            for i in 0..S {
                let e = hs
                    * (E1 * k1[i].re()
                        + E3 * k3[i].re()
                        + E4 * k4[i].re()
                        + E5 * k5[i].re()
                        + E6 * k6[i].re()
                        + E7 * k7[i].re());
                let sk = self.scale(x[i].re(), x_new[i].re());
                err += (e / sk) * (e / sk);
            }
            let err = if S == 0 {
                0.0
            } else {
                libm::sqrt(err / S as f64)
            };
            if !finite_so_far || !err.is_finite() || !all_finite(&k7) {
                // A non-finite stage: retry with a much smaller step.
                stats.rejected += 1;
                last_rejected = true;
                h *= FAC_MIN;
                if h < h_floor {
                    return Err(IntegrateError::NonFinite { t });
                }
                continue;
            }

            let fac11 = libm::pow(err, expo1);
            if err <= 1.0 {
                // Accepted.
                stats.accepted += 1;
                let fac = fac11 / libm::pow(fac_old, self.beta);
                let fac = (fac / SAFETY).clamp(1.0 / FAC_MAX, 1.0 / FAC_MIN);
                let mut h_new = h / fac;
                fac_old = err.max(1e-4);
                if last_rejected {
                    h_new = h_new.min(h);
                }
                last_rejected = false;

                let need_dense = event.is_some()
                    || (next_out < n_out && (sink.time(next_out) - t_new) * dir <= 0.0);
                let dense = if need_dense {
                    let mut r = [x, x, x, x, x];
                    for i in 0..S {
                        let ydiff = x_new[i] - x[i];
                        let bspl = hh * k1[i] - ydiff;
                        r[1][i] = ydiff;
                        r[2][i] = bspl;
                        r[3][i] = ydiff - hh * k7[i] - bspl;
                        r[4][i] = hh
                            * (c(D1) * k1[i]
                                + c(D3) * k3[i]
                                + c(D4) * k4[i]
                                + c(D5) * k5[i]
                                + c(D6) * k6[i]
                                + c(D7) * k7[i]);
                    }
                    Some(Dense { t, h: hs, r })
                } else {
                    None
                };

                // Event.
                let mut stop: Option<(f64, [T; S])> = None;
                if let (Some(g), Some(d)) = (event.as_mut(), dense.as_ref()) {
                    let g_new = g(t_new, &x_new);
                    if !g_new.is_finite() {
                        return Err(IntegrateError::NonFinite { t });
                    }
                    let crossed = g_old != 0.0 && (g_new == 0.0 || (g_new > 0.0) != (g_old > 0.0));
                    if crossed {
                        stop = Some(self.locate(&mut **g, d, t, g_old, t_new, g_new, &x_new)?);
                    }
                    g_old = g_new;
                }

                // Outputs up to the end of the step (or the event).
                let t_stop = stop.as_ref().map_or(t_new, |s| s.0);
                while next_out < n_out && (sink.time(next_out) - t_stop) * dir <= 0.0 {
                    let to = sink.time(next_out);
                    let xo = if to == t_new {
                        x_new
                    } else if let Some(d) = dense.as_ref() {
                        d.at(to)
                    } else {
                        x_new
                    };
                    if !all_finite(&xo) {
                        return Err(IntegrateError::NonFinite { t });
                    }
                    sink.put(next_out, &xo);
                    next_out += 1;
                }
                if let Some((te, xe)) = stop {
                    return finish(te, xe, stats, true, next_out, h_new.min(h_max));
                }

                t = t_new;
                x = x_new;
                k1 = k7;
                h = h_new.min(h_max);
                if last {
                    return finish(t, x, stats, false, next_out, h);
                }
            } else {
                // Rejected.
                stats.rejected += 1;
                last_rejected = true;
                h /= (fac11 / SAFETY).min(1.0 / FAC_MIN);
            }
        }
    }

    /// Illinois root finding of `g` on the dense output over `[a, b]` (in
    /// the direction of integration), `g(a) = ga`, `g(b) = gb` of opposite
    /// signs or `gb = 0`. Returns the far end of the final bracket.
    #[allow(clippy::too_many_arguments)]
    fn locate<T: Scalar, const S: usize>(
        &self,
        g: &mut dyn FnMut(f64, &[T; S]) -> f64,
        dense: &Dense<T, S>,
        a: f64,
        ga: f64,
        b: f64,
        gb: f64,
        xb: &[T; S],
    ) -> Result<(f64, [T; S]), IntegrateError> {
        let (mut lo, mut glo) = (a, ga);
        let (mut hi, mut ghi, mut xhi) = (b, gb, *xb);
        if ghi == 0.0 {
            return Ok((hi, xhi));
        }
        let mut side = 0i8;
        for _ in 0..EVENT_MAX_ITER {
            let tol = self
                .event_tol
                .max(4.0 * f64::EPSILON * lo.abs().max(hi.abs()));
            if (hi - lo).abs() <= tol {
                break;
            }
            let mut tc = (lo * ghi - hi * glo) / (ghi - glo);
            let (mn, mx) = (lo.min(hi), lo.max(hi));
            if !(tc > mn && tc < mx) {
                tc = 0.5 * (lo + hi);
                if !(tc > mn && tc < mx) {
                    break;
                }
            }
            let xc = dense.at(tc);
            let gc = g(tc, &xc);
            if !gc.is_finite() {
                return Err(IntegrateError::NonFinite { t: tc });
            }
            if gc == 0.0 {
                return Ok((tc, xc));
            }
            if (gc > 0.0) == (ghi > 0.0) {
                hi = tc;
                ghi = gc;
                xhi = xc;
                if side == -1 {
                    glo *= 0.5;
                }
                side = -1;
            } else {
                lo = tc;
                glo = gc;
                if side == 1 {
                    ghi *= 0.5;
                }
                side = 1;
            }
        }
        Ok((hi, xhi))
    }
}
