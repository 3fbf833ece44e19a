//! The elementary functions of [`DoubleDouble`], and its [`Scalar`]
//! implementation, which is made of them: each starts from the `f64`
//! function (or a reduction to a small argument) and adds the missing 53
//! bits by one Newton step or a Taylor series evaluated in double-double.

use super::{fp, two_prod, DoubleDouble};
use crate::Scalar;

/// `x` as a double-double.
#[inline]
fn dd(x: f64) -> DoubleDouble {
    DoubleDouble::from(x)
}

/// The third words of π/2 and ln 2 (the first two are
/// [`DoubleDouble::FRAC_PI_2`] and [`DoubleDouble::LN_2`]), so that the
/// argument reductions stay accurate for reduction multiples k in the
/// thousands: k times the error of a two-word constant would be
/// k · 1e-33.
const FRAC_PI_2_LO2: f64 = -1.4973849048591698e-33;
const LN_2_LO2: f64 = 5.707708438416212e-34;

/// a − k c for an integer-valued `k`, with c = `c` + `c_lo2` to about 160
/// bits: the products k · c.hi and k · c.lo are formed exactly, so only the
/// final subtractions round.
fn sub_multiple(a: DoubleDouble, k: f64, c: DoubleDouble, c_lo2: f64) -> DoubleDouble {
    let (p1, e1) = two_prod(k, c.hi);
    let (p2, e2) = two_prod(k, c.lo);
    a - DoubleDouble { hi: p1, lo: e1 } - DoubleDouble::new(p2, e2) - dd(k * c_lo2)
}

/// Square root: the f64 root `s`, corrected by one Newton step
/// `s + (a − s²) / (2 s)` whose remainder `a − s²` is formed in
/// double-double.
fn sqrt(a: DoubleDouble) -> DoubleDouble {
    if a.hi <= 0.0 {
        // √0 = 0 (keeping the sign of zero), √(negative) = NaN.
        return if a.hi == 0.0 {
            a
        } else {
            DoubleDouble::special(f64::NAN)
        };
    }
    if !a.hi.is_finite() {
        return DoubleDouble::special(a.hi);
    }
    let s = fp::sqrt(a.hi);
    let r = a - dd(s).sqr();
    let correction = r.hi / (2.0 * s);
    DoubleDouble::new(s, correction)
}

/// eˣ: x = k ln 2 + r with |r| ≤ ln 2 / 2; r scaled by 2⁻⁸; e^(r/256) − 1 by
/// its Taylor series; eight squarings in the form (1 + e)² − 1 = 2e + e²,
/// which keeps the relative error of e from growing; then · 2ᵏ.
fn exp(a: DoubleDouble) -> DoubleDouble {
    if a.hi.is_nan() {
        return a;
    }
    if a.hi > 709.79 {
        return DoubleDouble::special(f64::INFINITY);
    }
    if a.hi < -745.2 {
        return DoubleDouble::default();
    }
    if a.hi == 0.0 {
        return dd(1.0);
    }
    const SQUARINGS: i32 = 8;
    let k = fp::round(a.hi / DoubleDouble::LN_2.hi);
    let r = sub_multiple(a, k, DoubleDouble::LN_2, LN_2_LO2);
    let s = r.ldexp(-SQUARINGS);
    // |s| ≤ 1.36e-3: the term sⁿ/n! falls below 1e-34 |s| by n = 11.
    let mut sum = s;
    let mut term = s;
    for n in 2..=14 {
        term = (term * s).div_f64(n as f64);
        sum += term;
        if term.hi.abs() <= 1e-35 * s.hi.abs() {
            break;
        }
    }
    for _ in 0..SQUARINGS {
        sum = sum.mul_f64(2.0) + sum.sqr();
    }
    (sum + dd(1.0)).ldexp(k as i32)
}

/// ln x: near 1 (|x − 1| < 1/4), 2 atanh((x − 1)/(x + 1)) by its series,
/// which keeps the relative accuracy of a small result; elsewhere one Newton
/// step on eʸ = x from the f64 logarithm, y + x e⁻ʸ − 1.
fn ln(a: DoubleDouble) -> DoubleDouble {
    if a.hi.is_nan() {
        return a;
    }
    if a.hi <= 0.0 {
        return DoubleDouble::special(if a.hi == 0.0 {
            f64::NEG_INFINITY
        } else {
            f64::NAN
        });
    }
    if a.hi == f64::INFINITY {
        return a;
    }
    if (a.hi - 1.0).abs() < 0.25 {
        let z = (a - dd(1.0)) / (a + dd(1.0));
        let z2 = z.sqr();
        // |z| < 1/7: z^(2n)/(2n + 1) falls below 1e-34 by n = 20.
        let mut sum = z;
        let mut power = z;
        for n in 1..=24 {
            power *= z2;
            let term = power.div_f64((2 * n + 1) as f64);
            sum += term;
            if term.hi.abs() <= 1e-35 * z.hi.abs() {
                break;
            }
        }
        return sum.mul_f64(2.0);
    }
    let y = fp::ln(a.hi);
    dd(y) + (a * exp(dd(-y)) - dd(1.0))
}

/// (sin x, cos x): x = k π/2 + r with |r| ≤ π/4 (π/2 to three words, see
/// [`sub_multiple`]), both Taylor series of r, then the
/// quadrant k mod 4.
fn sin_cos(a: DoubleDouble) -> (DoubleDouble, DoubleDouble) {
    if !a.hi.is_finite() {
        let nan = DoubleDouble::special(f64::NAN);
        return (nan, nan);
    }
    let k = fp::round(a.hi / DoubleDouble::FRAC_PI_2.hi);
    let r = sub_multiple(a, k, DoubleDouble::FRAC_PI_2, FRAC_PI_2_LO2);
    let (s, c) = sin_cos_small(r);
    // k is an integer here; beyond 2^53 the reduction is meaningless anyway.
    match (k as i64).rem_euclid(4) {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// (sin r, cos r) for |r| ≤ π/4 + a little, by Taylor series to 1e-34.
fn sin_cos_small(r: DoubleDouble) -> (DoubleDouble, DoubleDouble) {
    if r.hi == 0.0 {
        return (r, dd(1.0));
    }
    let r2 = r.sqr();
    let neg_r2 = -r2;
    // sin r = r − r³/3! + …; (π/4)^(2n+1)/(2n+1)! < 1e-34 by 2n + 1 = 29.
    let mut sin = r;
    let mut term = r;
    let mut n = 1.0;
    while n < 40.0 {
        term = (term * neg_r2).div_f64((n + 1.0) * (n + 2.0));
        sin += term;
        n += 2.0;
        if term.hi.abs() <= 1e-35 * r.hi.abs() {
            break;
        }
    }
    // cos r = 1 − r²/2! + …
    let mut cos = dd(1.0);
    let mut term = dd(1.0);
    let mut n = 0.0;
    while n < 40.0 {
        term = (term * neg_r2).div_f64((n + 1.0) * (n + 2.0));
        cos += term;
        n += 2.0;
        if term.hi.abs() <= 1e-35 {
            break;
        }
    }
    (sin, cos)
}

/// atan2(y, x): θ₀ from the f64 `atan2`, then one Newton step on
/// y cos θ − x sin θ = 0, θ₁ = θ₀ + (y cos θ₀ − x sin θ₀)/(x cos θ₀ + y sin θ₀),
/// which is θ₀ + tan(θ − θ₀): the error falls from 1e-16 to 1e-48.
fn atan2(y: DoubleDouble, x: DoubleDouble) -> DoubleDouble {
    let theta0 = fp::atan2(y.hi, x.hi);
    if !theta0.is_finite() || (y.hi == 0.0 && x.hi == 0.0) || !y.is_finite() || !x.is_finite() {
        return DoubleDouble::special(theta0);
    }
    let (s, c) = sin_cos(dd(theta0));
    let num = y * c - x * s;
    let den = x * c + y * s;
    dd(theta0) + num / den
}

/// xⁿ by binary powering; x⁻ⁿ = 1/xⁿ.
fn powi(a: DoubleDouble, n: i32) -> DoubleDouble {
    let mut m = n.unsigned_abs();
    let mut base = a;
    let mut result = dd(1.0);
    while m > 0 {
        if m & 1 == 1 {
            result *= base;
        }
        m >>= 1;
        if m > 0 {
            base = base.sqr();
        }
    }
    if n < 0 {
        dd(1.0) / result
    } else {
        result
    }
}

// The bare calls are to this module's functions above, not to the methods.
impl Scalar for DoubleDouble {
    #[inline]
    fn from_f64(x: f64) -> Self {
        DoubleDouble::from(x)
    }
    #[inline]
    fn re(self) -> f64 {
        self.to_f64()
    }
    fn sin(self) -> Self {
        sin_cos(self).0
    }
    fn cos(self) -> Self {
        sin_cos(self).1
    }
    fn tan(self) -> Self {
        let (s, c) = sin_cos(self);
        s / c
    }
    fn exp(self) -> Self {
        exp(self)
    }
    fn ln(self) -> Self {
        ln(self)
    }
    #[inline]
    fn abs(self) -> Self {
        if self.hi < 0.0 {
            -self
        } else {
            self
        }
    }
    fn sqrt(self) -> Self {
        sqrt(self)
    }
    fn powi(self, n: i32) -> Self {
        powi(self, n)
    }
    fn atan2(self, x: Self) -> Self {
        atan2(self, x)
    }
}
