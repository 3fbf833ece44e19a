//! Dense output and events: the cubic Hermite interpolant of a step and
//! event location on it.

use super::control::all_finite;
use crate::integrate::explicit::illinois;
use crate::integrate::solution::IntegrateError;

/// An event function `g(t, x)`.
pub(super) type EventG<'a> = dyn FnMut(f64, &[f64]) -> f64 + 'a;

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

impl Hermite<'_> {
    /// The interpolated state at `tau` into `slot` (resized).
    pub(super) fn at(&self, tau: f64, slot: &mut Vec<f64>) {
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
pub(super) fn locate(
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
