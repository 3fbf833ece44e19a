//! Step-size control: the controller's power and square root, and the
//! initial step.

use super::pair::{all_finite, EmbeddedPair};
use super::settings::Settings;
use crate::solution::{IntegrateError, Stats};
use appell_core::ModelError;
use appell_core::Scalar;

/// Safety factor of the step-size controller.
const SAFETY: f64 = 0.9;

/// `x^y` for the step-size controller: the platform's `pow` with `std`
/// (several times faster than the portable one), `libm` without.
#[inline]
pub(crate) fn pow(x: f64, y: f64) -> f64 {
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
pub(crate) fn sqrt(x: f64) -> f64 {
    Scalar::sqrt(x)
}

/// Hairer's `HINIT`: a first step from the size of `x`, `f` and an estimate
/// of the second derivative (one rhs call), for a method with `expo = 1/q`.
// called once per run, from first_step: its own arguments (h_max for t_end) plus the
// method's exponent and the first stage k1 it has just evaluated
#[allow(clippy::too_many_arguments)]
pub(super) fn initial_step<T, F, const S: usize>(
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

/// The step after an accepted one of size `h` with error norm `err`
/// (`fac11 = err^α`): the PI controller's factor with the previous error
/// `fac_old`, limited to `[P::FAC_MIN, P::FAC_MAX]`. Updates `fac_old`.
pub(super) fn grown_step<P, T, const S: usize>(
    set: &Settings,
    fac11: f64,
    err: f64,
    h: f64,
    fac_old: &mut f64,
) -> f64
where
    P: EmbeddedPair<T, S>,
    T: Scalar,
{
    let fac = fac11 / pow(*fac_old, set.beta);
    let fac = (fac / SAFETY).clamp(1.0 / P::FAC_MAX, 1.0 / P::FAC_MIN);
    *fac_old = err.max(1e-4);
    h / fac
}

/// The retry after a rejected step of size `h` (`fac11 = err^α`), at most
/// `1/P::FAC_MIN` times smaller.
pub(super) fn shrunk_step<P, T, const S: usize>(fac11: f64, h: f64) -> f64
where
    P: EmbeddedPair<T, S>,
    T: Scalar,
{
    h / (fac11 / SAFETY).min(1.0 / P::FAC_MIN)
}
