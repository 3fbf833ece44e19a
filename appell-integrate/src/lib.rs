//! # appell-integrate
//!
//! Integration of the reduced equations: fixed-step and adaptive explicit
//! methods without `std` and without allocation, and implicit methods for
//! stiff models (with `std`), which also watch a model's one-sided
//! contacts along the way ([`contact_watch`]); and, with `std`, a watch
//! over how near singular the dependent block of the constraints comes
//! ([`conditioning`]).
//!
//! The classical fourth-order Runge–Kutta method on fixed-size arrays, generic
//! over the [`Scalar`] so a trajectory can be integrated in `f32`, `f64` or
//! dual numbers (the last gives exact sensitivities of the discrete
//! trajectory to initial values or parameters).
//!
//! [`rk4_step`] and [`rk4`] integrate a [`Model`]'s reduced state (retained
//! coordinates then privileged speeds, see [`Model::rhs`]); [`rk4_step_fn`]
//! is the same step for any right-hand side given as a closure.
//!
//! [`heun_step_fn`] and [`midpoint_step_fn`] (with the model versions
//! [`heun_step`] and [`midpoint_step`]) are second-order steps of the same
//! shape. [`Dopri5`] is an adaptive Dormand–Prince 5(4) integrator with
//! error control, dense output and event location, also without allocation;
//! [`Dop853`] is its order-8 sibling (dense output of order 7), the choice
//! for tight tolerances. With `std`, `TrBdf2` is an L-stable implicit
//! method of order 2 whose Newton iterations use the Jacobian of the
//! generated rhs by dual numbers, for stiff models, and `Radau5` the
//! L-stable implicit method of order 5 (Radau IIA, as Hairer & Wanner's
//! RADAU5), the choice for stiff models at tight tolerances.
//!
//! Every step checks that the new state is finite (its real part, for dual
//! numbers) and reports [`ModelError::NonFinite`] with `what: "state"`
//! otherwise, so a blow-up never goes unnoticed as NaN.

#![cfg_attr(not(feature = "std"), no_std)]
#![warn(missing_docs)]

use appell_core::{Model, ModelError, Scalar};

#[cfg(feature = "std")]
pub mod conditioning;
#[cfg(feature = "std")]
pub mod contact_watch;
mod dop853;
pub use dop853::*;
mod dopri5;
mod explicit;
mod solution;
mod watch;
pub use dopri5::Dopri5;
pub use solution::{EventFn, IntegrateError, ProjectFn, ProjectionFailed, Solution, Stats};
#[cfg(feature = "std")]
mod implicit;
#[cfg(feature = "std")]
pub use implicit::*;
#[cfg(feature = "std")]
mod radau;
#[cfg(feature = "std")]
pub use radau::*;

/// Checks that an array length `found` (the `S` of a `[T; S]` state) is the
/// model's reduced state length ([`ModelInfo::state_len`](appell_core::ModelInfo::state_len)).
pub(crate) fn check_state_len<M: Model>(found: usize) -> Result<(), ModelError> {
    let expected = M::info().state_len();
    if found == expected {
        Ok(())
    } else {
        Err(ModelError::Length {
            argument: "state",
            expected,
            found,
        })
    }
}

/// [`check_state_len`], then [`Model::validate`]: what a simulation entry
/// point checks once before its first step.
pub(crate) fn check_model<M: Model>(model: &M, state_len: usize) -> Result<(), ModelError> {
    check_state_len::<M>(state_len)?;
    model.validate()
}

/// One step of Heun's method (the explicit trapezoidal rule, order 2) of
/// `dx/dt = f(t, x)` of size `h` from `(t, x)`: an Euler predictor
/// `x̃ = x + h f(t, x)`, then `x + h/2 (f(t, x) + f(t + h, x̃))`.
///
/// Two evaluations of `f`; its errors are passed on, and the new state is
/// checked to be finite ([`ModelError::NonFinite`] `{ what: "state" }`).
///
/// ```
/// use appell_integrate::heun_step_fn;
/// use appell_core::ModelError;
///
/// // dx/dt = x: one step of 0.1 has a local error of about h³/6.
/// let mut f = |_t: f64, x: &[f64; 1], dx: &mut [f64; 1]| -> Result<(), ModelError> {
///     dx[0] = x[0];
///     Ok(())
/// };
/// let x1 = heun_step_fn(&mut f, 0.0, 0.1, &[1.0]).unwrap();
/// assert_eq!(x1[0], 1.105); // 1 + h + h²/2
/// assert!((x1[0] - 0.1_f64.exp()).abs() < 2e-4);
/// ```
pub fn heun_step_fn<T, F, const S: usize>(
    f: &mut F,
    t: T,
    h: T,
    state: &[T; S],
) -> Result<[T; S], ModelError>
where
    T: Scalar,
    F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
{
    let half_h = h * T::from_f64(0.5);
    two_stage(f, t, h, h, state, |k1, k2| half_h * (k1 + k2))
}

/// One step of the explicit midpoint method (order 2) of `dx/dt = f(t, x)`
/// of size `h` from `(t, x)`: `x + h f(t + h/2, x + h/2 f(t, x))`.
///
/// Two evaluations of `f`; errors as for [`heun_step_fn`].
///
/// ```
/// use appell_integrate::midpoint_step_fn;
/// use appell_core::ModelError;
///
/// // dx/dt = t: the midpoint rule integrates a linear rate exactly.
/// let mut f = |t: f64, _x: &[f64; 1], dx: &mut [f64; 1]| -> Result<(), ModelError> {
///     dx[0] = t;
///     Ok(())
/// };
/// let x1 = midpoint_step_fn(&mut f, 1.0, 0.5, &[0.0]).unwrap();
/// assert!((x1[0] - (1.5_f64 * 1.5 - 1.0) / 2.0).abs() < 1e-15);
/// ```
pub fn midpoint_step_fn<T, F, const S: usize>(
    f: &mut F,
    t: T,
    h: T,
    state: &[T; S],
) -> Result<[T; S], ModelError>
where
    T: Scalar,
    F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
{
    let half_h = h * T::from_f64(0.5);
    two_stage(f, t, half_h, half_h, state, |_, k2| h * k2)
}

/// A two-stage explicit step: `k1 = f(t, x)`, `k2 = f(t + c, x + a k1)`,
/// then `x + increment(k1, k2)` componentwise, checked to be finite.
fn two_stage<T, F, const S: usize>(
    f: &mut F,
    t: T,
    c: T,
    a: T,
    state: &[T; S],
    increment: impl Fn(T, T) -> T,
) -> Result<[T; S], ModelError>
where
    T: Scalar,
    F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
{
    let mut k1 = [T::zero(); S];
    f(t, state, &mut k1)?;
    let mut x = *state;
    for i in 0..S {
        x[i] = state[i] + a * k1[i];
    }
    let mut k2 = [T::zero(); S];
    f(t + c, &x, &mut k2)?;
    let mut out = *state;
    for i in 0..S {
        out[i] = state[i] + increment(k1[i], k2[i]);
    }
    finite_state(out)
}

/// The state, or [`ModelError::NonFinite`] `{ what: "state" }`.
fn finite_state<T: Scalar, const S: usize>(x: [T; S]) -> Result<[T; S], ModelError> {
    if x.iter().all(|v| v.re().is_finite()) {
        Ok(x)
    } else {
        Err(ModelError::NonFinite { what: "state" })
    }
}

/// One step of Heun's method ([`heun_step_fn`]) of the model's reduced
/// equations; arguments and errors as for [`rk4_step`].
pub fn heun_step<M: Model, T: Scalar, const S: usize>(
    model: &M,
    prepared: &M::Prepared<T>,
    t: T,
    h: T,
    state: &[T; S],
    inputs: &[T],
) -> Result<[T; S], ModelError> {
    check_state_len::<M>(S)?;
    let mut f = |t: T, x: &[T; S], dx: &mut [T; S]| model.rhs(prepared, t, x, inputs, dx);
    heun_step_fn(&mut f, t, h, state)
}

/// One step of the explicit midpoint method ([`midpoint_step_fn`]) of the
/// model's reduced equations; arguments and errors as for [`rk4_step`].
pub fn midpoint_step<M: Model, T: Scalar, const S: usize>(
    model: &M,
    prepared: &M::Prepared<T>,
    t: T,
    h: T,
    state: &[T; S],
    inputs: &[T],
) -> Result<[T; S], ModelError> {
    check_state_len::<M>(S)?;
    let mut f = |t: T, x: &[T; S], dx: &mut [T; S]| model.rhs(prepared, t, x, inputs, dx);
    midpoint_step_fn(&mut f, t, h, state)
}

/// One classical RK4 step of `dx/dt = f(t, x)` of size `h` from `(t, x)`.
///
/// `f(t, x, dx)` writes the derivative into `dx`; its errors are passed on.
/// The new state is checked to be finite.
///
/// ```
/// use appell_integrate::rk4_step_fn;
/// use appell_core::ModelError;
///
/// // dx/dt = x, x(0) = 1: one step of 0.1 is accurate to ~1e-7.
/// let mut f = |_t: f64, x: &[f64; 1], dx: &mut [f64; 1]| -> Result<(), ModelError> {
///     dx[0] = x[0];
///     Ok(())
/// };
/// let x1 = rk4_step_fn(&mut f, 0.0, 0.1, &[1.0]).unwrap();
/// assert!((x1[0] - 0.1_f64.exp()).abs() < 1e-7);
///
/// // A right-hand side that overflows is reported, not returned as inf.
/// let mut g = |_t: f64, _x: &[f64; 1], dx: &mut [f64; 1]| -> Result<(), ModelError> {
///     dx[0] = f64::MAX;
///     Ok(())
/// };
/// assert_eq!(
///     rk4_step_fn(&mut g, 0.0, 10.0, &[0.0]),
///     Err(ModelError::NonFinite { what: "state" })
/// );
/// ```
pub fn rk4_step_fn<T, F, const S: usize>(
    f: &mut F,
    t: T,
    h: T,
    state: &[T; S],
) -> Result<[T; S], ModelError>
where
    T: Scalar,
    F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
{
    let half = T::from_f64(0.5);
    let sixth = T::from_f64(1.0 / 6.0);
    let two = T::from_f64(2.0);
    let half_h = h * half;
    let t_mid = t + half_h;

    let mut k1 = [T::zero(); S];
    f(t, state, &mut k1)?;

    let mut x = *state;
    for i in 0..S {
        x[i] = state[i] + half_h * k1[i];
    }
    let mut k2 = [T::zero(); S];
    f(t_mid, &x, &mut k2)?;

    for i in 0..S {
        x[i] = state[i] + half_h * k2[i];
    }
    let mut k3 = [T::zero(); S];
    f(t_mid, &x, &mut k3)?;

    for i in 0..S {
        x[i] = state[i] + h * k3[i];
    }
    let mut k4 = [T::zero(); S];
    f(t + h, &x, &mut k4)?;

    let mut out = *state;
    for i in 0..S {
        out[i] = state[i] + h * sixth * (k1[i] + two * (k2[i] + k3[i]) + k4[i]);
        if !out[i].re().is_finite() {
            return Err(ModelError::NonFinite { what: "state" });
        }
    }
    Ok(out)
}

/// One classical RK4 step of size `h` of the model's reduced equations
/// ([`Model::rhs`]) from time `t` and reduced state `state` (retained
/// coordinates then privileged speeds), with `inputs` held constant over the
/// step.
///
/// Errors: [`ModelError::Length`] when `S` is not
/// [`ModelInfo::state_len`](appell_core::ModelInfo::state_len) (or `inputs` has the
/// wrong length), any error of [`Model::rhs`], and
/// [`ModelError::NonFinite`] `{ what: "state" }` when the new state is not
/// finite.
///
/// See [`rk4`] for an example.
pub fn rk4_step<M: Model, T: Scalar, const S: usize>(
    model: &M,
    prepared: &M::Prepared<T>,
    t: T,
    h: T,
    state: &[T; S],
    inputs: &[T],
) -> Result<[T; S], ModelError> {
    check_state_len::<M>(S)?;
    let mut f = |t: T, x: &[T; S], dx: &mut [T; S]| model.rhs(prepared, t, x, inputs, dx);
    rk4_step_fn(&mut f, t, h, state)
}

/// Integrates the model's reduced equations with `steps` classical RK4 steps
/// of size `h` from `(t0, state0)` and returns the state at `t0 + steps·h`.
///
/// Step `k` starts at `t0 + k·h` (computed by multiplication, so no rounding
/// drift accumulates in the time). Errors as for [`rk4_step`]; the first
/// failing step stops the integration.
///
/// ```
/// use appell_core::Model;
/// use appell_integrate::{rk4, rk4_step};
/// # use appell_core::__doc_model::Oscillator;
///
/// // x'' = -w² x with x(0) = 1, x'(0) = 0: x(t) = cos(w t).
/// let model = Oscillator { w: 2.0 };
/// let prepared = model.prepare::<f64>();
/// let x = rk4(&model, &prepared, 0.0, &[1.0, 0.0], 1e-3, 1000, &[]).unwrap();
/// assert!((x[0] - 2.0_f64.cos()).abs() < 1e-10);
/// assert!((x[1] + 2.0 * 2.0_f64.sin()).abs() < 1e-10);
///
/// // One step is the same as `rk4_step`.
/// let a = rk4(&model, &prepared, 0.0, &[1.0, 0.0], 0.1, 1, &[]).unwrap();
/// let b = rk4_step(&model, &prepared, 0.0, 0.1, &[1.0, 0.0], &[]).unwrap();
/// assert_eq!(a, b);
///
/// // The array length must be the reduced state length (here 2).
/// assert!(rk4(&model, &prepared, 0.0, &[1.0, 0.0, 0.0], 0.1, 1, &[]).is_err());
/// ```
pub fn rk4<M: Model, T: Scalar, const S: usize>(
    model: &M,
    prepared: &M::Prepared<T>,
    t0: T,
    state0: &[T; S],
    h: T,
    steps: usize,
    inputs: &[T],
) -> Result<[T; S], ModelError> {
    check_model(model, S)?;
    if !state0.iter().all(|x| x.re().is_finite()) {
        return Err(ModelError::NonFinite { what: "state" });
    }
    let mut state = *state0;
    for k in 0..steps {
        let t = t0 + T::from_f64(k as f64) * h;
        state = rk4_step(model, prepared, t, h, &state, inputs)?;
    }
    Ok(state)
}
