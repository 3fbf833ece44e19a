//! Adaptive Dormand–Prince 5(4) integration with dense output and event
//! location, on fixed-size arrays and without allocation.

use super::check_model;
use super::explicit::{
    self, all_finite, CallbackSink, DenseOutput, EmbeddedPair, Settings, Sink, SliceSink,
};
use super::solution::{EventFn, IntegrateError, ProjectFn, Solution, Stats};
use appell_core::Scalar;
use appell_core::{Model, ModelError};

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
/// use appell_integrate::Dopri5;
/// use appell_core::ModelError;
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
#[derive(Clone, Copy, PartialEq)]
pub struct Dopri5 {
    set: Settings,
}

impl core::fmt::Debug for Dopri5 {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        self.set.debug("Dopri5", f)
    }
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

/// The continuous extension of one accepted step.
struct Dense<T, const S: usize> {
    t: f64,
    h: f64,
    r: [[T; S]; 5],
}

impl<T: Scalar, const S: usize> DenseOutput<T, S> for Dense<T, S> {
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

/// The seven stages of a Dormand–Prince 5(4) step (`k[6]` is the FSAL
/// stage at the new state).
struct Stages<T, const S: usize> {
    k: [[T; S]; 7],
}

impl<T: Scalar, const S: usize> EmbeddedPair<T, S> for Stages<T, S> {
    const EXPO: f64 = 0.2;
    const BETA_WEIGHT: f64 = 0.75;
    const FAC_MIN: f64 = 0.2;
    const FAC_MAX: f64 = 10.0;
    const BETA_CLOSED: bool = false;
    type Dense = Dense<T, S>;

    fn new(k1: [T; S]) -> Self {
        Stages { k: [k1; 7] }
    }

    fn k1(&self) -> &[T; S] {
        &self.k[0]
    }

    #[inline]
    fn step<F>(
        &mut self,
        f: &mut F,
        set: &Settings,
        t: f64,
        hs: f64,
        t_new: f64,
        x: &[T; S],
        stats: &mut Stats,
    ) -> Result<Option<([T; S], f64)>, ModelError>
    where
        F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
    {
        let c = T::from_f64;
        let hh = c(hs);
        let [k1, k2, k3, k4, k5, k6, k7] = &mut self.k;
        // Fresh stages, as if `f` may leave components unwritten.
        for k in [&mut *k2, &mut *k3, &mut *k4, &mut *k5, &mut *k6, &mut *k7] {
            *k = [T::zero(); S];
        }
        let mut y = *x;
        for i in 0..S {
            y[i] = x[i] + hh * (c(A21) * k1[i]);
        }
        f(c(t + C2 * hs), &y, k2)?;
        for i in 0..S {
            y[i] = x[i] + hh * (c(A31) * k1[i] + c(A32) * k2[i]);
        }
        f(c(t + C3 * hs), &y, k3)?;
        for i in 0..S {
            y[i] = x[i] + hh * (c(A41) * k1[i] + c(A42) * k2[i] + c(A43) * k3[i]);
        }
        f(c(t + C4 * hs), &y, k4)?;
        for i in 0..S {
            y[i] = x[i] + hh * (c(A51) * k1[i] + c(A52) * k2[i] + c(A53) * k3[i] + c(A54) * k4[i]);
        }
        f(c(t + C5 * hs), &y, k5)?;
        for i in 0..S {
            y[i] = x[i]
                + hh * (c(A61) * k1[i]
                    + c(A62) * k2[i]
                    + c(A63) * k3[i]
                    + c(A64) * k4[i]
                    + c(A65) * k5[i]);
        }
        f(c(t + hs), &y, k6)?;
        let mut x_new = *x;
        for i in 0..S {
            x_new[i] = x[i]
                + hh * (c(A71) * k1[i]
                    + c(A73) * k3[i]
                    + c(A74) * k4[i]
                    + c(A75) * k5[i]
                    + c(A76) * k6[i]);
        }
        if !all_finite(&x_new) {
            stats.rhs_calls += 5;
            return Ok(None);
        }
        // The FSAL stage, needed by the error estimate.
        f(c(t_new), &x_new, k7)?;
        stats.rhs_calls += 6;

        let mut err = 0.0;
        for i in 0..S {
            let e = hs
                * (E1 * k1[i].re()
                    + E3 * k3[i].re()
                    + E4 * k4[i].re()
                    + E5 * k5[i].re()
                    + E6 * k6[i].re()
                    + E7 * k7[i].re());
            let sk = set.scale(x[i].re(), x_new[i].re());
            err += (e / sk) * (e / sk);
        }
        let err = if S == 0 || !set.adaptive {
            0.0
        } else {
            explicit::sqrt(err / S as f64)
        };
        if !err.is_finite() || !all_finite(k7) {
            return Ok(None);
        }
        Ok(Some((x_new, err)))
    }

    fn accept(&mut self) {
        self.k[0] = self.k[6];
    }

    /// The free fourth-order continuous extension (no rhs calls).
    fn dense<F>(
        &mut self,
        _f: &mut F,
        t: f64,
        hs: f64,
        x: &[T; S],
        x_new: &[T; S],
        _stats: &mut Stats,
    ) -> Result<Dense<T, S>, IntegrateError>
    where
        F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
    {
        let c = T::from_f64;
        let hh = c(hs);
        let [k1, _, k3, k4, k5, k6, k7] = &self.k;
        let mut r = [*x; 5];
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
        Ok(Dense { t, h: hs, r })
    }
}

impl Dopri5 {
    /// The integrator with the documented defaults ([`Dopri5`]).
    pub const fn new() -> Self {
        Dopri5 {
            set: Settings::new(0.04),
        }
    }

    /// The first step size (magnitude), or `None` (default) for Hairer's
    /// automatic choice.
    pub const fn h_init(mut self, h_init: Option<f64>) -> Self {
        self.set.h_init = h_init;
        self
    }

    /// The PI controller's β (default `0.04`; `0` is the elementary
    /// controller; must be in `[0, 0.2)`).
    pub const fn beta(mut self, beta: f64) -> Self {
        self.set.beta = beta;
        self
    }

    explicit::explicit_api!(Dopri5, Stages);
}
