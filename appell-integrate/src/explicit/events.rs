//! Event location: Illinois root finding on a dense output.

use crate::solution::IntegrateError;

const EVENT_MAX_ITER: usize = 200;

/// Illinois root finding of an event function `g(t)` (evaluated on a dense
/// output) over `[a, b]` (in the direction of integration), `g(a) = ga`,
/// `g(b) = gb` of opposite signs or `gb = 0`, to `event_tol` (never below 4
/// ulp). Returns the far end of the final bracket: where `g` has its new
/// sign or is zero. Shared by every integrator with events.
pub(crate) fn illinois(
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
