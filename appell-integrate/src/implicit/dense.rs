//! Dense output and events: the cubic Hermite interpolant of a step and
//! event location on it.

use super::control::all_finite;
use crate::explicit::illinois;
use crate::solution::IntegrateError;

/// An event function `g(t, x)`.
pub(crate) type EventG<'a> = dyn FnMut(f64, &[f64]) -> f64 + 'a;

/// Overwrites `slot` with `x`.
pub(super) fn put(slot: &mut Vec<f64>, x: &[f64]) {
    slot.clear();
    slot.extend_from_slice(x);
}

/// The cubic Hermite interpolant of one accepted step from `(t, x0)` with
/// derivative `f0` to `(t + h, x1)` with derivative `f1` (`h` signed).
pub(super) struct Hermite<'a> {
    pub(super) t: f64,
    /// The end of the step (exactly).
    pub(super) t1: f64,
    pub(super) h: f64,
    pub(super) x0: &'a [f64],
    pub(super) f0: &'a [f64],
    pub(super) x1: &'a [f64],
    pub(super) f1: &'a [f64],
}

impl<'a> Hermite<'a> {
    /// The cubic from `(x0, f0)` at `t` to `(x1, f1)` at `t1`.
    pub(super) fn between(
        t: f64,
        t1: f64,
        (x0, f0): (&'a [f64], &'a [f64]),
        (x1, f1): (&'a [f64], &'a [f64]),
    ) -> Self {
        Hermite {
            t,
            t1,
            h: t1 - t,
            x0,
            f0,
            x1,
            f1,
        }
    }
}

/// The dense output of one accepted step, as the end of a step needs it
/// (events and outputs). Shared by the implicit integrators.
pub(crate) trait Dense {
    /// The start of the step.
    fn start(&self) -> f64;
    /// The end of the step (exactly).
    fn end(&self) -> f64;
    /// The state at the end of the step.
    fn end_state(&self) -> &[f64];
    /// The interpolated state at `tau` into `slot` (resized).
    fn at(&self, tau: f64, slot: &mut Vec<f64>);
}

impl Dense for Hermite<'_> {
    fn start(&self) -> f64 {
        self.t
    }

    fn end(&self) -> f64 {
        self.t1
    }

    fn end_state(&self) -> &[f64] {
        self.x1
    }

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
/// [`illinois`] on the dense output: the far end of the final bracket and
/// the state there (the step's end state exactly when the bracket did not
/// move).
pub(crate) fn locate<D: Dense>(
    event_tol: f64,
    g: &mut EventG<'_>,
    dense: &D,
    ga: f64,
    gb: f64,
) -> Result<(f64, Vec<f64>), IntegrateError> {
    let n = dense.end_state().len();
    let mut xc = Vec::with_capacity(n);
    let on_dense = |tc: f64| {
        dense.at(tc, &mut xc);
        if all_finite(&xc) {
            Ok(g(tc, &xc))
        } else {
            Err(IntegrateError::NonFinite { t: tc })
        }
    };
    let te = illinois(event_tol, on_dense, dense.start(), ga, dense.end(), gb)?;
    if te == dense.end() {
        Ok((te, dense.end_state().to_vec()))
    } else {
        let mut xe = Vec::with_capacity(n);
        dense.at(te, &mut xe);
        Ok((te, xe))
    }
}
