//! Double-double arithmetic: a reference precision for the generated code.
//!
//! A [`DoubleDouble`] is an unevaluated sum `hi + lo` of two `f64`s with
//! `|lo| ≤ ulp(hi) / 2`, which gives a 106-bit significand (relative
//! rounding unit 2⁻¹⁰⁶ ≈ 1.2e-32) with the exponent range of `f64`. The
//! arithmetic rests on the error-free transformations `TwoSum` (the exact
//! rounding error of an addition) and `TwoProd` (of a multiplication, by a
//! fused multiply-add). The elementary functions (sqrt, exp, ln, sin, cos,
//! tan, atan2, powi) are accurate to a few units of 2⁻¹⁰⁶ relative for
//! moderate arguments; see [`DoubleDouble`] for the range limits.
//!
//! It implements [`Scalar`], so the code `#[derive(Appell)]`
//! emits runs on it unchanged: evaluating the same generated function in
//! `f64` and in double-double measures the round-off of the `f64` run.
//!
//! ```
//! use appell_core::precision::DoubleDouble;
//! use appell_core::Scalar;
//!
//! // 0.1 + 0.2 - 0.3 is 5.55e-17 in f64; the exact value of the three
//! // f64 literals is 2.78e-17, which double-double gets right.
//! let x = DoubleDouble::from_f64(0.1) + DoubleDouble::from_f64(0.2)
//!     - DoubleDouble::from_f64(0.3);
//! assert_eq!(x.to_f64(), 2.0f64.powi(-55));
//! // π to 32 digits.
//! let pi: DoubleDouble = "3.14159265358979323846264338327950288".parse().unwrap();
//! assert!((pi - DoubleDouble::PI).abs().to_f64() < 1e-31);
//! ```

mod elementary;
#[cfg(test)]
mod tests;

use core::ops::{Add, AddAssign, Div, DivAssign, Mul, MulAssign, Neg, Sub, SubAssign};
use core::str::FromStr;

use crate::Scalar;

/// The plain-`f64` operations double-double needs, from `std` when it is
/// there and from `libm` otherwise (as for the `f64` [`Scalar`]).
pub(crate) mod fp {
    #[inline(always)]
    pub fn fma(a: f64, b: f64, c: f64) -> f64 {
        #[cfg(feature = "std")]
        {
            a.mul_add(b, c)
        }
        #[cfg(not(feature = "std"))]
        {
            libm::fma(a, b, c)
        }
    }
    macro_rules! unary {
        ($($name:ident => $std:ident, $libm:ident;)*) => {$(
            #[inline(always)]
            pub fn $name(x: f64) -> f64 {
                #[cfg(feature = "std")]
                {
                    x.$std()
                }
                #[cfg(not(feature = "std"))]
                {
                    libm::$libm(x)
                }
            }
        )*};
    }
    unary! {
        sqrt => sqrt, sqrt;
        ln => ln, log;
        round => round, round;
    }
    #[inline(always)]
    pub fn atan2(y: f64, x: f64) -> f64 {
        #[cfg(feature = "std")]
        {
            y.atan2(x)
        }
        #[cfg(not(feature = "std"))]
        {
            libm::atan2(y, x)
        }
    }
}

/// A real number `hi + lo` held as two `f64`s with `|lo| ≤ ulp(hi) / 2`:
/// about 32 significant decimal digits (unit round-off 2⁻¹⁰⁶ ≈ 1.2e-32)
/// over the exponent range of `f64`.
///
/// `+ − × ÷` and `sqrt` are accurate to a few units of 2⁻¹⁰⁶; `exp`, `ln`,
/// `sin`, `cos`, `tan`, `atan2` and `powi` (through [`Scalar`]) to about
/// 1e-31 relative. `sin`, `cos` and `tan` reduce the argument by multiples
/// of π/2 held in double-double, so their absolute error grows like
/// |x| · 1e-32 (fine for the angles of a simulation, not for 1e20 rad).
/// Below about 1e-292 the low word underflows and the precision falls to
/// that of `f64`. Comparisons are those of the value (`hi` first, then
/// `lo`).
///
/// ```
/// use appell_core::precision::DoubleDouble;
/// use appell_core::Scalar;
///
/// let x = DoubleDouble::from_f64(2.0);
/// let r = x.sqrt();
/// // √2 · √2 − 2 vanishes to about 1e-32, where f64 leaves 4.4e-16.
/// assert!((r * r - x).abs().to_f64() < 1e-31);
/// assert_eq!(2f64.sqrt() * 2f64.sqrt() - 2.0, 4.440892098500626e-16);
/// // Rounded to f64, it is the correctly rounded √2.
/// assert_eq!(r.to_f64(), 2f64.sqrt());
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, PartialOrd)]
pub struct DoubleDouble {
    hi: f64,
    lo: f64,
}

/// `s + e = a + b` exactly, `s = fl(a + b)` (Knuth's TwoSum).
#[inline(always)]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    let e = (a - (s - bb)) + (b - bb);
    (s, e)
}

/// `s + e = a + b` exactly when `|a| ≥ |b|` (or a = 0) (Dekker's
/// FastTwoSum).
#[inline(always)]
fn quick_two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let e = b - (s - a);
    (s, e)
}

/// `p + e = a · b` exactly (barring underflow), `p = fl(a · b)`.
#[inline(always)]
fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    let e = fp::fma(a, b, -p);
    (p, e)
}

impl DoubleDouble {
    /// π = 3.14159265358979323846264338327950288…
    ///
    /// ```
    /// use appell_core::precision::DoubleDouble;
    /// assert_eq!(DoubleDouble::PI.to_f64(), std::f64::consts::PI);
    /// ```
    pub const PI: DoubleDouble = DoubleDouble {
        hi: core::f64::consts::PI,
        lo: 1.2246467991473532e-16,
    };
    /// π/2 = 1.57079632679489661923132169163975144…
    ///
    /// ```
    /// use appell_core::precision::DoubleDouble;
    /// assert_eq!(DoubleDouble::FRAC_PI_2 * DoubleDouble::from(2.0), DoubleDouble::PI);
    /// ```
    pub const FRAC_PI_2: DoubleDouble = DoubleDouble {
        hi: core::f64::consts::FRAC_PI_2,
        lo: 6.123233995736766e-17,
    };
    /// e = 2.71828182845904523536028747135266250…
    ///
    /// ```
    /// use appell_core::precision::DoubleDouble;
    /// assert_eq!(DoubleDouble::E.to_f64(), std::f64::consts::E);
    /// ```
    pub const E: DoubleDouble = DoubleDouble {
        hi: core::f64::consts::E,
        lo: 1.4456468917292502e-16,
    };
    /// ln 2 = 0.693147180559945309417232121458176568…
    ///
    /// ```
    /// use appell_core::precision::DoubleDouble;
    /// assert_eq!(DoubleDouble::LN_2.to_f64(), std::f64::consts::LN_2);
    /// ```
    pub const LN_2: DoubleDouble = DoubleDouble {
        hi: core::f64::consts::LN_2,
        lo: 2.3190468138462996e-17,
    };
    /// The unit round-off 2⁻¹⁰⁶ ≈ 1.23e-32 (half the gap between 1 and
    /// the next double-double with a full 106-bit significand).
    ///
    /// ```
    /// use appell_core::precision::DoubleDouble;
    /// assert_eq!(DoubleDouble::EPSILON, 2f64.powi(-106));
    /// ```
    pub const EPSILON: f64 = 1.232595164407831e-32;

    /// `hi + lo`, renormalized (any two finite `f64`s are accepted; the sum
    /// is held exactly).
    ///
    /// ```
    /// use appell_core::precision::DoubleDouble;
    /// let x = DoubleDouble::new(1.0, 1e-20);
    /// assert_eq!((x.hi(), x.lo()), (1.0, 1e-20));
    /// let y = DoubleDouble::new(1e-20, 1.0); // swapped: renormalized
    /// assert_eq!(y, x);
    /// ```
    pub fn new(hi: f64, lo: f64) -> DoubleDouble {
        let (hi, lo) = two_sum(hi, lo);
        DoubleDouble { hi, lo }
    }

    /// The high word: the value rounded to the nearest `f64`.
    ///
    /// ```
    /// use appell_core::precision::DoubleDouble;
    /// assert_eq!(DoubleDouble::PI.hi(), std::f64::consts::PI);
    /// ```
    pub fn hi(self) -> f64 {
        self.hi
    }

    /// The low word: what the high word leaves out.
    ///
    /// ```
    /// use appell_core::precision::DoubleDouble;
    /// let third = DoubleDouble::from(1.0) / DoubleDouble::from(3.0);
    /// assert!(third.lo() != 0.0 && third.lo().abs() < 1e-16 * third.hi());
    /// ```
    pub fn lo(self) -> f64 {
        self.lo
    }

    /// The value rounded to the nearest `f64` (ties to even, as `hi` is the
    /// rounded sum by construction).
    ///
    /// ```
    /// use appell_core::precision::DoubleDouble;
    /// let x = DoubleDouble::from(1.0) / DoubleDouble::from(10.0);
    /// assert_eq!(x.to_f64(), 0.1);
    /// ```
    pub fn to_f64(self) -> f64 {
        self.hi + self.lo
    }

    /// Whether both words are finite.
    ///
    /// ```
    /// use appell_core::precision::DoubleDouble;
    /// assert!(DoubleDouble::PI.is_finite());
    /// assert!(!(DoubleDouble::from(1.0) / DoubleDouble::from(0.0)).is_finite());
    /// ```
    pub fn is_finite(self) -> bool {
        self.hi.is_finite() && self.lo.is_finite()
    }

    /// `self · 2^k` exactly (barring overflow and underflow).
    #[inline]
    pub(crate) fn ldexp(self, k: i32) -> DoubleDouble {
        // Two factors, each a normal power of two, so that 2^k itself need
        // not be representable (k = 1024 for exp(709.7)).
        let k1 = k / 2;
        let k2 = k - k1;
        let f1 = pow2(k1);
        let f2 = pow2(k2);
        DoubleDouble {
            hi: self.hi * f1 * f2,
            lo: self.lo * f1 * f2,
        }
    }

    /// `self · b` for an `f64` `b`.
    #[inline]
    pub(crate) fn mul_f64(self, b: f64) -> DoubleDouble {
        let (p, e) = two_prod(self.hi, b);
        let e = fp::fma(self.lo, b, e);
        let (hi, lo) = quick_two_sum(p, e);
        DoubleDouble { hi, lo }
    }

    /// `self / b` for an `f64` `b`.
    #[inline]
    pub(crate) fn div_f64(self, b: f64) -> DoubleDouble {
        let q1 = self.hi / b;
        let r = self - DoubleDouble::from(q1).mul_f64(b);
        let q2 = r.hi / b;
        let r = r - DoubleDouble::from(q2).mul_f64(b);
        let q3 = r.hi / b;
        let (q1, q2) = quick_two_sum(q1, q2);
        DoubleDouble { hi: q1, lo: q2 } + DoubleDouble::from(q3)
    }

    /// The square, a little cheaper than `self * self`.
    #[inline]
    pub(crate) fn sqr(self) -> DoubleDouble {
        let (p, e) = two_prod(self.hi, self.hi);
        let e = fp::fma(2.0 * self.hi, self.lo, e);
        let (hi, lo) = quick_two_sum(p, e);
        DoubleDouble { hi, lo }
    }

    /// Propagates a non-finite `f64` result into both words.
    #[inline]
    fn special(x: f64) -> DoubleDouble {
        DoubleDouble { hi: x, lo: 0.0 }
    }
}

/// 2^k for `k` in the normal range of `f64` (−1022 ..= 1023), clamped.
#[inline]
fn pow2(k: i32) -> f64 {
    let k = k.clamp(-1022, 1023);
    f64::from_bits(((k + 1023) as u64) << 52)
}

impl From<f64> for DoubleDouble {
    fn from(x: f64) -> DoubleDouble {
        DoubleDouble { hi: x, lo: 0.0 }
    }
}

impl Neg for DoubleDouble {
    type Output = DoubleDouble;
    #[inline]
    fn neg(self) -> DoubleDouble {
        DoubleDouble {
            hi: -self.hi,
            lo: -self.lo,
        }
    }
}

impl Add for DoubleDouble {
    type Output = DoubleDouble;
    /// The accurate ("IEEE") double-double sum: relative error a few units
    /// of 2⁻¹⁰⁶ even under cancellation.
    #[inline]
    fn add(self, b: DoubleDouble) -> DoubleDouble {
        let (s, e) = two_sum(self.hi, b.hi);
        if !s.is_finite() {
            return DoubleDouble::special(s);
        }
        let (t, f) = two_sum(self.lo, b.lo);
        let (s, e) = quick_two_sum(s, e + t);
        let (hi, lo) = quick_two_sum(s, e + f);
        DoubleDouble { hi, lo }
    }
}

impl Sub for DoubleDouble {
    type Output = DoubleDouble;
    #[inline]
    fn sub(self, b: DoubleDouble) -> DoubleDouble {
        self + (-b)
    }
}

impl Mul for DoubleDouble {
    type Output = DoubleDouble;
    #[inline]
    fn mul(self, b: DoubleDouble) -> DoubleDouble {
        let (p, e) = two_prod(self.hi, b.hi);
        if !p.is_finite() {
            return DoubleDouble::special(p);
        }
        let e = e + (self.hi * b.lo + self.lo * b.hi);
        let (hi, lo) = quick_two_sum(p, e);
        DoubleDouble { hi, lo }
    }
}

impl Div for DoubleDouble {
    type Output = DoubleDouble;
    /// Long division: three f64 quotient digits, each correcting the
    /// remainder of the previous ones.
    #[inline]
    fn div(self, b: DoubleDouble) -> DoubleDouble {
        let q1 = self.hi / b.hi;
        if !q1.is_finite() || q1 == 0.0 {
            return DoubleDouble::special(q1);
        }
        let r = self - b.mul_f64(q1);
        let q2 = r.hi / b.hi;
        let r = r - b.mul_f64(q2);
        let q3 = r.hi / b.hi;
        let (q1, q2) = quick_two_sum(q1, q2);
        DoubleDouble { hi: q1, lo: q2 } + DoubleDouble::from(q3)
    }
}

macro_rules! assign_op {
    ($($tr:ident $f:ident $op:tt;)*) => {$(
        impl $tr for DoubleDouble {
            #[inline]
            fn $f(&mut self, b: DoubleDouble) {
                *self = *self $op b;
            }
        }
    )*};
}
assign_op! {
    AddAssign add_assign +;
    SubAssign sub_assign -;
    MulAssign mul_assign *;
    DivAssign div_assign /;
}

/// Why a string is not a double-double.
///
/// ```
/// use appell_core::precision::{DoubleDouble, ParseDoubleDoubleError};
/// assert_eq!("1.2.3".parse::<DoubleDouble>(), Err(ParseDoubleDoubleError));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ParseDoubleDoubleError;

impl core::fmt::Display for ParseDoubleDoubleError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("not a decimal number (digits, one optional '.', optional exponent)")
    }
}

impl FromStr for DoubleDouble {
    type Err = ParseDoubleDoubleError;
    /// A decimal `[+-]digits[.digits][(e|E)[+-]digits]`, to about 1e-32
    /// relative (digits beyond the 34th are ignored).
    fn from_str(s: &str) -> Result<DoubleDouble, ParseDoubleDoubleError> {
        let (negative, s) = match s.as_bytes().first() {
            Some(b'-') => (true, &s[1..]),
            Some(b'+') => (false, &s[1..]),
            _ => (false, s),
        };
        let (mantissa, exponent) = match s.find(['e', 'E']) {
            Some(i) => (
                &s[..i],
                s[i + 1..]
                    .parse::<i32>()
                    .map_err(|_| ParseDoubleDoubleError)?,
            ),
            None => (s, 0),
        };
        let mut value = DoubleDouble::default();
        let mut scale = exponent;
        let mut digits = 0;
        let mut seen_point = false;
        let mut seen_digit = false;
        for c in mantissa.bytes() {
            match c {
                b'.' if !seen_point => seen_point = true,
                b'0'..=b'9' => {
                    seen_digit = true;
                    if digits < 34 {
                        value = value.mul_f64(10.0) + DoubleDouble::from(f64::from(c - b'0'));
                        if value.hi != 0.0 {
                            digits += 1;
                        }
                        if seen_point {
                            scale -= 1;
                        }
                    } else if !seen_point {
                        scale += 1;
                    }
                }
                _ => return Err(ParseDoubleDoubleError),
            }
        }
        if !seen_digit {
            return Err(ParseDoubleDoubleError);
        }
        let ten_to = Scalar::powi(DoubleDouble::from(10.0), scale.abs());
        let value = if scale < 0 {
            value / ten_to
        } else {
            value * ten_to
        };
        Ok(if negative { -value } else { value })
    }
}
