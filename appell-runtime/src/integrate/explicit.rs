//! The machinery shared by the adaptive explicit Runge–Kutta integrators
//! [`Dopri5`](super::Dopri5) and [`Dop853`](super::Dop853): settings and
//! their validation, output sinks, the adaptive loop with step-size control,
//! dense output, outputs and events, event location and the initial step.
//!
//! A method is an [`EmbeddedPair`]: its stages (with their error estimate
//! and FSAL handling) and its continuous extension. Everything is generic
//! and monomorphised per method, without allocation.

use super::solution::{EventFn, IntegrateError, ProjectFn, Solution, Stats};
use crate::model::ModelError;
use crate::scalar::Scalar;

const SAFETY: f64 = 0.9;
/// Factor of the retry after a non-finite stage.
const FAC_NON_FINITE: f64 = 0.2;
const EVENT_MAX_ITER: usize = 200;

/// The settings of an adaptive explicit integrator (see the builders).
#[derive(Clone, Copy, PartialEq)]
pub(super) struct Settings {
    pub(super) rtol: f64,
    pub(super) atol: f64,
    pub(super) max_steps: usize,
    pub(super) h_init: Option<f64>,
    pub(super) h_min: f64,
    pub(super) h_max: Option<f64>,
    pub(super) beta: f64,
    pub(super) event_tol: f64,
    pub(super) adaptive: bool,
}

impl Settings {
    /// The common defaults with the controller's `beta`.
    pub(super) const fn new(beta: f64) -> Self {
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
        }
    }

    /// `Debug` of the integrator `name` as if its settings were its fields.
    pub(super) fn debug(&self, name: &str, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
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
            .finish()
    }

    /// Validation; `beta` must be in `[0, 0.2]`, or `[0, 0.2)` unless
    /// `beta_closed`.
    fn check(&self, beta_closed: bool) -> Result<(), IntegrateError> {
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
    pub(super) fn scale(&self, a: f64, b: f64) -> f64 {
        let sk = self.atol + self.rtol * a.abs().max(b.abs());
        sk.max(f64::MIN_POSITIVE)
    }
}

/// `x^y` for the step-size controller: the platform's `pow` with `std`
/// (several times faster than the portable one), `libm` without.
#[inline]
pub(super) fn pow(x: f64, y: f64) -> f64 {
    #[cfg(feature = "std")]
    {
        x.powf(y)
    }
    #[cfg(not(feature = "std"))]
    {
        libm::pow(x, y)
    }
}

/// √x for the error norms, by the same rule as [`pow`].
#[inline]
pub(super) fn sqrt(x: f64) -> f64 {
    Scalar::sqrt(x)
}

pub(super) fn all_finite<T: Scalar, const S: usize>(x: &[T; S]) -> bool {
    x.iter().all(|v| v.re().is_finite())
}

/// The continuous extension of one accepted step.
pub(super) trait DenseOutput<T, const S: usize> {
    /// The state at `t` inside the step.
    fn at(&self, t: f64) -> [T; S];
}

/// An embedded Runge–Kutta pair: its stage storage, one step with its error
/// estimate, and its continuous extension.
pub(super) trait EmbeddedPair<T: Scalar, const S: usize> {
    /// `1/q` with `q` the order the error behaves like, plus one: the
    /// exponent of the step-size controller and of `HINIT`.
    const EXPO: f64;
    /// The controller's `α = EXPO − BETA_WEIGHT · β`.
    const BETA_WEIGHT: f64;
    /// Smallest factor `h_new / h`.
    const FAC_MIN: f64;
    /// Largest factor `h_new / h`.
    const FAC_MAX: f64;
    /// Whether `β = 0.2` is allowed.
    const BETA_CLOSED: bool;
    type Dense: DenseOutput<T, S>;

    /// The stages with `k1 = f(t0, x0)`.
    fn new(k1: [T; S]) -> Self;

    /// The first stage of the next step.
    fn k1(&self) -> &[T; S];

    /// One step of size `hs` from `(t, x)` ending at `t_new`, counting its
    /// rhs calls: the new state and the error norm (`0` without error
    /// control), with the FSAL stage at the new state evaluated at least
    /// when the step is accepted; `None` when a value is non-finite.
    #[allow(clippy::too_many_arguments)]
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
        F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>;

    /// After an accepted step: its FSAL stage becomes the first stage.
    fn accept(&mut self);

    /// The continuous extension of the accepted step from `(t, x)` to
    /// `x_new` (any extra rhs calls counted in `stats`).
    #[allow(clippy::too_many_arguments)]
    fn dense<F>(
        &mut self,
        f: &mut F,
        t: f64,
        hs: f64,
        x: &[T; S],
        x_new: &[T; S],
        stats: &mut Stats,
    ) -> Result<Self::Dense, IntegrateError>
    where
        F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>;
}

/// Where requested outputs go.
pub(super) trait Sink<T, const S: usize> {
    fn len(&self) -> usize;
    fn time(&self, i: usize) -> f64;
    fn put(&mut self, i: usize, x: &[T; S]);
}

pub(super) struct SliceSink<'a, T, const S: usize>(pub(super) &'a mut [(f64, [T; S])]);

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

pub(super) struct CallbackSink<'a, 'b, T, const S: usize> {
    pub(super) times: &'a [f64],
    pub(super) cb: &'b mut dyn FnMut(f64, &[T; S]),
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

/// Hairer's `HINIT`: a first step from the size of `x`, `f` and an estimate
/// of the second derivative (one rhs call), for a method with `expo = 1/q`.
#[allow(clippy::too_many_arguments)]
fn initial_step<T, F, const S: usize>(
    set: &Settings,
    expo: f64,
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
        let sk = set.scale(x[i].re(), 0.0);
        dnf += (k1[i].re() / sk) * (k1[i].re() / sk);
        dny += (x[i].re() / sk) * (x[i].re() / sk);
    }
    let mut h = if dnf <= 1e-10 || dny <= 1e-10 {
        1e-6
    } else {
        sqrt(dny / dnf) * 0.01
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
        let sk = set.scale(x[i].re(), 0.0);
        let d = (f1[i].re() - k1[i].re()) / sk;
        der2 += d * d;
    }
    let der2 = sqrt(der2) / h;
    let der12 = der2.max(sqrt(dnf));
    let h1 = if der12 <= 1e-15 {
        (h * 1e-3).max(1e-6)
    } else {
        pow(0.01 / der12, expo)
    };
    Ok((100.0 * h).min(h1).min(h_max))
}

/// The integration loop behind every `solve*` of the method `P`.
#[allow(clippy::too_many_arguments)] // the problem, the outputs and two optional hooks
pub(super) fn run<P, T, F, K, const S: usize>(
    set: &Settings,
    mut f: F,
    t0: f64,
    x0: &[T; S],
    t_end: f64,
    sink: &mut K,
    mut event: Option<&mut EventFn<'_, T, S>>,
    mut project: Option<&mut ProjectFn<'_, T, S>>,
) -> Result<Solution<T, S>, IntegrateError>
where
    P: EmbeddedPair<T, S>,
    T: Scalar,
    F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
    K: Sink<T, S>,
{
    set.check(P::BETA_CLOSED)?;
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
    let mut st = P::new(k1);
    let span = (t_end - t0).abs();
    let h_max = if set.adaptive {
        set.h_max.unwrap_or(f64::INFINITY).min(span)
    } else {
        span
    };
    let mut h = match set.h_init {
        Some(h) => h.abs().min(h_max),
        None => initial_step(set, P::EXPO, &mut f, t, &x, st.k1(), dir, h_max, &mut stats)?,
    };
    let h_fixed = h;
    let expo1 = P::EXPO - P::BETA_WEIGHT * set.beta;
    let mut fac_old: f64 = 1e-4;
    let mut last_rejected = false;
    let mut steps = 0usize;

    loop {
        if steps >= set.max_steps {
            return Err(IntegrateError::TooManySteps { t, steps });
        }
        let h_floor = set
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
        let t_new = if last { t_end } else { t + hs };

        let Some((x_new, err)) = st.step(&mut f, set, t, hs, t_new, &x, &mut stats)? else {
            // A non-finite stage: retry with a much smaller step.
            stats.rejected += 1;
            last_rejected = true;
            h *= FAC_NON_FINITE;
            if !set.adaptive || h < h_floor {
                return Err(IntegrateError::NonFinite { t });
            }
            continue;
        };

        let fac11 = pow(err, expo1);
        if err <= 1.0 {
            // Accepted.
            stats.accepted += 1;
            let mut h_new = if set.adaptive {
                let fac = fac11 / pow(fac_old, set.beta);
                let fac = (fac / SAFETY).clamp(1.0 / P::FAC_MAX, 1.0 / P::FAC_MIN);
                fac_old = err.max(1e-4);
                h / fac
            } else {
                h_fixed
            };
            if last_rejected {
                h_new = h_new.min(h);
            }
            last_rejected = false;

            // Event at the end of the step.
            let mut crossed = false;
            let mut g_new = 0.0;
            if let Some(g) = event.as_mut() {
                g_new = g(t_new, &x_new);
                if !g_new.is_finite() {
                    return Err(IntegrateError::NonFinite { t });
                }
                crossed = g_old != 0.0 && (g_new == 0.0 || (g_new > 0.0) != (g_old > 0.0));
            }
            // The dense output only when the step contains an output time
            // or a crossing strictly inside it.
            let need_dense = (crossed && g_new != 0.0)
                || (next_out < n_out && (sink.time(next_out) - t_new) * dir < 0.0);
            let dense = if need_dense {
                Some(st.dense(&mut f, t, hs, &x, &x_new, &mut stats)?)
            } else {
                None
            };

            let mut stop: Option<(f64, [T; S])> = None;
            if crossed {
                if let (Some(g), Some(d)) = (event.as_mut(), dense.as_ref()) {
                    let on_dense = |tc: f64| Ok(g(tc, &d.at(tc)));
                    let te = illinois(set.event_tol, on_dense, t, g_old, t_new, g_new)?;
                    stop = Some((te, if te == t_new { x_new } else { d.at(te) }));
                } else {
                    // g is exactly zero at the end of the step.
                    stop = Some((t_new, x_new));
                }
            }
            g_old = g_new;

            // Outputs up to the end of the step (or the event).
            let t_stop = stop.as_ref().map_or(t_new, |s| s.0);
            while next_out < n_out && (sink.time(next_out) - t_stop) * dir <= 0.0 {
                let to = sink.time(next_out);
                let xo = match dense.as_ref() {
                    Some(d) if to != t_new => d.at(to),
                    _ => x_new,
                };
                if !all_finite(&xo) {
                    return Err(IntegrateError::NonFinite { t });
                }
                sink.put(next_out, &xo);
                next_out += 1;
            }
            let h_next = if set.adaptive {
                h_new.min(h_max)
            } else {
                h_fixed
            };
            if let Some((te, xe)) = stop {
                return finish(te, xe, stats, true, next_out, h_next);
            }

            t = t_new;
            x = x_new;
            st.accept();
            if let Some(p) = project.as_mut() {
                // Back onto the manifold; a moved state needs its own first
                // stage (one rhs call) and event value.
                let before = x;
                if !p(t, &mut x) || !all_finite(&x) {
                    return Err(IntegrateError::Projection { t });
                }
                if x.iter().zip(&before).any(|(a, b)| a.re() != b.re()) {
                    let mut k1 = [T::zero(); S];
                    stats.rhs_calls += 1;
                    f(T::from_f64(t), &x, &mut k1)?;
                    if !all_finite(&k1) {
                        return Err(IntegrateError::NonFinite { t });
                    }
                    st = P::new(k1);
                    if let Some(g) = event.as_mut() {
                        g_old = g(t, &x);
                        if !g_old.is_finite() {
                            return Err(IntegrateError::NonFinite { t });
                        }
                    }
                }
            }
            h = h_next;
            if last {
                return finish(t, x, stats, false, next_out, h);
            }
        } else {
            // Rejected.
            stats.rejected += 1;
            last_rejected = true;
            h /= (fac11 / SAFETY).min(1.0 / P::FAC_MIN);
        }
    }
}

/// Illinois root finding of an event function `g(t)` (evaluated on a dense
/// output) over `[a, b]` (in the direction of integration), `g(a) = ga`,
/// `g(b) = gb` of opposite signs or `gb = 0`, to `event_tol` (never below 4
/// ulp). Returns the far end of the final bracket: where `g` has its new
/// sign or is zero. Shared by every integrator with events.
pub(super) fn illinois(
    event_tol: f64,
    mut g: impl FnMut(f64) -> Result<f64, IntegrateError>,
    a: f64,
    ga: f64,
    b: f64,
    gb: f64,
) -> Result<f64, IntegrateError> {
    let (mut lo, mut glo) = (a, ga);
    let (mut hi, mut ghi) = (b, gb);
    if ghi == 0.0 {
        return Ok(hi);
    }
    let mut side = 0i8;
    for _ in 0..EVENT_MAX_ITER {
        let tol = event_tol.max(4.0 * f64::EPSILON * lo.abs().max(hi.abs()));
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
        let gc = g(tc)?;
        if !gc.is_finite() {
            return Err(IntegrateError::NonFinite { t: tc });
        }
        if gc == 0.0 {
            return Ok(tc);
        }
        if (gc > 0.0) == (ghi > 0.0) {
            hi = tc;
            ghi = gc;
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
    Ok(hi)
}

/// The builder setters common to both integrators and the public `solve*`
/// methods of the integrator `$ty` (a struct with `set: Settings`) whose
/// method is `$pair<T, S>`.
macro_rules! explicit_api {
    ($ty:ident, $pair:ident) => {
        /// Error control on (default `true`). With `false`, every step has the
        #[doc = concat!("size [`", stringify!($ty), "::h_init`] (required; the last step is cut to end at")]
        #[doc = concat!("`t_end`, and [`", stringify!($ty), "::h_max`] is ignored) and is accepted without an")]
        /// error estimate (a fixed-step method with dense output, for
        /// convergence studies); a non-finite state is reported at once.
        pub const fn adaptive(mut self, adaptive: bool) -> Self {
            self.set.adaptive = adaptive;
            self
        }

        /// Relative tolerance (default `1e-6`; must be ≥ 0).
        pub const fn rtol(mut self, rtol: f64) -> Self {
            self.set.rtol = rtol;
            self
        }

        /// Absolute tolerance (default `1e-9`; must be ≥ 0, and `rtol` and
        /// `atol` not both 0).
        pub const fn atol(mut self, atol: f64) -> Self {
            self.set.atol = atol;
            self
        }

        /// Maximum number of steps, accepted and rejected (default `100_000`).
        pub const fn max_steps(mut self, max_steps: usize) -> Self {
            self.set.max_steps = max_steps;
            self
        }

        /// Minimum step size (default `0`: only the floor of 16 ulp of `t`); a
        /// smaller proposed step is [`IntegrateError::StepSizeTooSmall`]. The
        /// last step, cut to end exactly at `t_end`, may be smaller.
        pub const fn h_min(mut self, h_min: f64) -> Self {
            self.set.h_min = h_min;
            self
        }

        /// Maximum step size, or `None` (default) for the interval length.
        pub const fn h_max(mut self, h_max: Option<f64>) -> Self {
            self.set.h_max = h_max;
            self
        }

        /// Absolute time tolerance of event location (default `1e-12`, never
        /// below 4 ulp of the event time).
        pub const fn event_tol(mut self, event_tol: f64) -> Self {
            self.set.event_tol = event_tol;
            self
        }

        /// Integrates `dx/dt = f(t, x)` from `(t0, x0)` to `t_end` (which may
        /// be before `t0`). `f(t, x, dx)` writes the derivative into `dx`.
        ///
        #[doc = concat!("See [`", stringify!($ty), "`] for an example.")]
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
            explicit::run::<$pair<T, S>, _, _, _, S>(&self.set, f, t0, x0, t_end, &mut sink, None, None)
        }

        #[doc = concat!("As [`", stringify!($ty), "::solve`], stopping at the first sign change of the event")]
        #[doc = concat!("function `g(t, x)` (see [`", stringify!($ty), "`]); [`Solution::event`] tells")]
        /// whether it happened. A zero of `g` at `t0` is not an event.
        ///
        /// The reported time is the end of the final bracket on the far side of
        /// the crossing (where `g` has its new sign or is zero), within
        #[doc = concat!("[`", stringify!($ty), "::event_tol`] of the root of `g` on the dense output; the")]
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
            explicit::run::<$pair<T, S>, _, _, _, S>(
                &self.set,
                f,
                t0,
                x0,
                t_end,
                &mut sink,
                Some(&mut g),
                None,
            )
        }

        /// Integrates from `(t0, x0)` to the last time of `out` and writes the
        /// state at each `out[i].0` (set by the caller, ordered in the
        /// direction of integration) into `out[i].1`, from the dense output.
        ///
        /// ```
        #[doc = concat!("use appell_runtime::integrate::", stringify!($ty), ";")]
        /// use appell_runtime::ModelError;
        ///
        /// let f = |_t: f64, x: &[f64; 1], dx: &mut [f64; 1]| -> Result<(), ModelError> {
        ///     dx[0] = -x[0];
        ///     Ok(())
        /// };
        /// let mut out = [(0.5, [0.0]), (1.0, [0.0]), (2.0, [0.0])];
        #[doc = concat!("let sol = ", stringify!($ty), "::new().rtol(1e-9).atol(1e-12).solve_at(f, 0.0, &[1.0], &mut out).unwrap();")]
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
            explicit::run::<$pair<T, S>, _, _, _, S>(
                &self.set,
                f,
                t0,
                x0,
                t_end,
                &mut SliceSink(out),
                None,
                None,
            )
        }

        /// The general form: integrates from `(t0, x0)` to `t_end`, calls
        /// `on_output(t, x)` at each of `times` (ordered in the direction of
        /// integration and within the interval), and stops at an event of `g`
        #[doc = concat!("when one is given (as [`", stringify!($ty), "::solve_until`]); output times past the")]
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
            explicit::run::<$pair<T, S>, _, _, _, S>(&self.set, f, t0, x0, t_end, &mut sink, event, None)
        }

        #[doc = concat!("As [`", stringify!($ty), "::solve`], with `project(t, x)` applied to the state")]
        /// after every accepted step: it moves `x` back onto a constraint
        /// manifold (a holonomic constraint the integration drifts from, an
        /// invariant) and returns `false` if it cannot
        /// ([`IntegrateError::Projection`]). When it moves the state, the next
        /// step starts afresh from the projected state (one more rhs call,
        /// counted). The step's error control and dense output are those of the
        /// unprojected step.
        ///
        /// ```
        #[doc = concat!("use appell_runtime::integrate::", stringify!($ty), ";")]
        /// // The harmonic oscillator keeps x² + v² = 1; projecting onto that
        /// // circle removes the slow drift of a loose tolerance.
        /// let f = |_t: f64, x: &[f64; 2], dx: &mut [f64; 2]| {
        ///     dx[0] = x[1];
        ///     dx[1] = -x[0];
        ///     Ok(())
        /// };
        /// let mut onto_circle = |_t: f64, x: &mut [f64; 2]| {
        ///     let r = (x[0] * x[0] + x[1] * x[1]).sqrt();
        ///     x[0] /= r;
        ///     x[1] /= r;
        ///     r > 0.0
        /// };
        #[doc = concat!("let solver = ", stringify!($ty), "::new().rtol(1e-4).atol(1e-6);")]
        /// let free = solver.solve(f, 0.0, &[1.0, 0.0], 100.0).unwrap();
        /// let kept = solver.solve_projected(f, &mut onto_circle, 0.0, &[1.0, 0.0], 100.0).unwrap();
        /// let radius = |x: [f64; 2]| (x[0] * x[0] + x[1] * x[1]).sqrt();
        /// assert!((radius(kept.x) - 1.0).abs() < 1e-15);
        /// assert!((radius(free.x) - 1.0).abs() > (radius(kept.x) - 1.0).abs());
        /// ```
        pub fn solve_projected<T, F, const S: usize>(
            &self,
            f: F,
            project: &mut ProjectFn<'_, T, S>,
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
            explicit::run::<$pair<T, S>, _, _, _, S>(
                &self.set,
                f,
                t0,
                x0,
                t_end,
                &mut sink,
                None,
                Some(project),
            )
        }

        #[doc = concat!("[`", stringify!($ty), "::solve_projected`] of a model's reduced equations, as")]
        #[doc = concat!("[`", stringify!($ty), "::solve_model`]; with")]
        /// [`project_holonomic`](crate::linearize::project_holonomic) as the
        /// projection it keeps a model on its holonomic constraints.
        pub fn solve_model_projected<M: Model, T: Scalar, const S: usize>(
            &self,
            model: &M,
            inputs: &[T],
            project: &mut ProjectFn<'_, T, S>,
            t0: f64,
            x0: &[T; S],
            t_end: f64,
        ) -> Result<Solution<T, S>, IntegrateError> {
            check_state_len::<M>(S)?;
            let p = model.prepare::<T>();
            let f = |t: T, x: &[T; S], dx: &mut [T; S]| model.rhs(&p, t, x, inputs, dx);
            self.solve_projected(f, project, t0, x0, t_end)
        }

        #[doc = concat!("[`", stringify!($ty), "::solve`] of a model's reduced equations ([`Model::rhs`],")]
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

        #[doc = concat!("[`", stringify!($ty), "::solve_at`] of a model's reduced equations, as")]
        #[doc = concat!("[`", stringify!($ty), "::solve_model`].")]
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

        #[doc = concat!("[`", stringify!($ty), "::solve_until`] of a model's reduced equations, as")]
        #[doc = concat!("[`", stringify!($ty), "::solve_model`].")]
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
    };
}
pub(super) use explicit_api;
