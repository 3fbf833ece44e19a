//! What a method provides: an [`EmbeddedPair`] (its stages, error estimate
//! and FSAL handling) and its continuous extension, a [`DenseOutput`].

use super::settings::Settings;
use crate::solution::{IntegrateError, Stats};
use appell_core::ModelError;
use appell_core::Scalar;

pub(crate) fn all_finite<T: Scalar, const S: usize>(x: &[T; S]) -> bool {
    x.iter().all(|v| v.re().is_finite())
}

/// The continuous extension of one accepted step.
pub(crate) trait DenseOutput<T, const S: usize> {
    /// The state at `t` inside the step.
    fn at(&self, t: f64) -> [T; S];
}

/// An embedded Runge–Kutta pair: its stage storage, one step with its error
/// estimate, and its continuous extension.
pub(crate) trait EmbeddedPair<T: Scalar, const S: usize> {
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
    // once per step attempt in run's loop, #[inline] in both pairs: the step's times and state
    // are the loop's locals, the rhs, settings and counters its borrows
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
