//! Step-size control: the Newton tolerance, the step factor with its
//! Newton-dependent safety factor, Gustafsson's predictive controller and
//! the rule that keeps the Jacobian and the step.

/// The contraction rate up to which the Jacobian is kept when the caller
/// gives it (RADAU5's default `THET`).
pub(super) const REUSE_GIVEN: f64 = 0.001;
/// The same when it is computed by dual numbers, at the cost of one
/// evaluation per state component (RADAU5's advice for costly Jacobians).
pub(super) const REUSE_DUAL: f64 = 0.1;
const SAFETY: f64 = 0.9;
/// Bounds of `h_new/h`.
const FAC_MIN: f64 = 0.2;
const FAC_MAX: f64 = 8.0;
/// A factor in `[1, HOLD_MAX]` keeps the step (and its factorizations).
const HOLD_MAX: f64 = 1.2;
/// The step factor after a rejected first step.
pub(super) const FAC_FIRST: f64 = 0.1;
/// The step factor after a singular iteration matrix or a non-finite value.
pub(super) const FAC_FAIL: f64 = 0.5;

/// The Newton tolerance κ for the internal relative tolerance `rtol`
/// (RADAU5's `FNEWT`): `max(10 ε/rtol, min(0.03, √rtol))`.
pub(super) fn newton_tolerance(rtol: f64) -> f64 {
    if rtol > 0.0 {
        (10.0 * f64::EPSILON / rtol).max(0.03_f64.min(rtol.sqrt()))
    } else {
        0.03
    }
}

/// `h_new/h` for the error norm `err` of a step solved in `iterations`
/// Newton iterations (of at most `max_iter`): `fac · err^(−1/4)` within
/// `[0.2, 8]`, with the safety factor `fac = 0.9 (2 k_max + 1)/(2 k_max +
/// k)` lower for slow Newton convergence. A non-finite `err` gives 0.5.
pub(super) fn step_factor(err: f64, iterations: usize, max_iter: usize) -> f64 {
    if !err.is_finite() {
        return FAC_FAIL;
    }
    let k_max = max_iter as f64;
    let fac = SAFETY.min(SAFETY * (2.0 * k_max + 1.0) / (2.0 * k_max + iterations as f64));
    (fac * err.max(1e-10).powf(-0.25)).clamp(FAC_MIN, FAC_MAX)
}

/// Gustafsson's predictive controller: the step and error of the last
/// accepted step.
pub(super) struct Gustafsson {
    last: Option<(f64, f64)>,
}

impl Gustafsson {
    pub(super) fn new() -> Self {
        Gustafsson { last: None }
    }

    /// After an accepted step of size `h` with error norm `err` and the
    /// classical factor `fac`: the smaller of `fac` and the predictive
    /// factor `0.9 (h/h_acc) (err_acc/err²)^(1/4)` (within `[0.2, 8]`).
    pub(super) fn accepted(&mut self, h: f64, err: f64, fac: f64) -> f64 {
        let err = err.max(1e-10);
        let out = match self.last {
            Some((h_acc, err_acc)) => {
                let g = SAFETY * (h / h_acc) * (err_acc / (err * err)).powf(0.25);
                fac.min(g.clamp(FAC_MIN, FAC_MAX))
            }
            None => fac,
        };
        self.last = Some((h, err.max(1e-2)));
        out
    }
}

/// Whether the next step keeps the step size and both factorizations: the
/// Jacobian is kept (the contraction rate `theta` is at most `reuse`) and
/// the proposed factor is in `[1, 1.2]`.
pub(super) fn keeps_step(theta: f64, reuse: f64, fac: f64) -> bool {
    theta <= reuse && (1.0..=HOLD_MAX).contains(&fac)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn factors_are_bounded_and_safe() {
        assert_eq!(step_factor(0.0, 1, 7), FAC_MAX);
        assert_eq!(step_factor(1e12, 1, 7), FAC_MIN);
        assert_eq!(step_factor(f64::NAN, 1, 7), FAC_FAIL);
        // err = 1 with one iteration: the safety factor 0.9.
        assert!((step_factor(1.0, 1, 7) - 0.9).abs() < 1e-15);
        // Slower Newton convergence, smaller steps.
        assert!(step_factor(1.0, 7, 7) < step_factor(1.0, 2, 7));
        assert_eq!(newton_tolerance(1e-4), 0.01);
        assert_eq!(newton_tolerance(1e-1), 0.03);
        assert!(newton_tolerance(1e-17) > 1.0);
    }

    #[test]
    fn gustafsson_shrinks_when_the_error_grows() {
        let mut g = Gustafsson::new();
        assert_eq!(g.accepted(0.1, 0.5, 1.1), 1.1);
        // Same step, error grew from 0.5 to 0.9: the predictive factor
        // 0.9 (0.5/0.81)^(1/4) ≈ 0.80 wins over the classical one.
        let f = g.accepted(0.1, 0.9, 1.0);
        assert!((f - 0.9 * (0.5_f64 / 0.81).powf(0.25)).abs() < 1e-12, "{f}");
        assert!(keeps_step(0.0, 1e-3, 1.1) && !keeps_step(0.01, 1e-3, 1.1));
        assert!(!keeps_step(0.0, 1e-3, 1.3) && keeps_step(0.01, 0.1, 1.1));
    }
}
