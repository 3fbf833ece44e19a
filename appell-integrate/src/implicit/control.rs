//! Error control: the weighted RMS norm and the step-size factors.

const SAFETY: f64 = 0.9;
const FAC_MIN: f64 = 0.2;
const FAC_MAX: f64 = 5.0;
pub(super) const FAC_NEWTON: f64 = 0.25;
const HOLD_MAX: f64 = 1.2;

/// RMS of `v_i / sk_i`.
pub(crate) fn wrms(v: &[f64], sk: &[f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let s: f64 = v.iter().zip(sk).map(|(a, s)| (a / s) * (a / s)).sum();
    (s / v.len() as f64).sqrt()
}

pub(crate) fn all_finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// The step-size factor after an accepted step with error norm `err`:
/// `0.9 · err^(−1/3)` within `[0.2, 5]` (5 for a zero or non-finite norm),
/// at most 1 right after a rejection (`rejected_last`), and exactly 1 for a
/// growth below 20 % (to keep the factorization).
pub(super) fn accepted_factor(err: f64, rejected_last: bool) -> f64 {
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
    fac
}

/// The step-size factor after a step rejected with error norm `err`:
/// `0.9 · err^(−1/3)` within `[0.2, 1]`, or 1/4 for a non-finite norm.
pub(super) fn rejected_factor(err: f64) -> f64 {
    if err.is_finite() {
        (SAFETY * err.powf(-1.0 / 3.0)).clamp(FAC_MIN, 1.0)
    } else {
        FAC_NEWTON
    }
}
