//! Numeric constants: exact rationals, with IEEE doubles where a float literal
//! entered the expression.
//!
//! Integers and fractions stay exact through `+`, `*` and integer powers. An
//! operation that would overflow the 128-bit numerator or denominator, or that
//! mixes in a float, yields a [`Number::Float`]; the result is then exactly what
//! an IEEE evaluation of the same operation would give.

use std::cmp::Ordering;
use std::fmt;
use std::hash::{Hash, Hasher};

/// A constant: an exact rational `num / den` (`den > 0`, lowest terms) or a
/// finite float.
///
/// ```
/// use appell_symbolic::Number;
/// let half = Number::ratio(1, 2).unwrap();
/// let third = Number::ratio(1, 3).unwrap();
/// assert_eq!(half.add(third), Number::ratio(5, 6).unwrap());
/// assert_eq!(half.mul(Number::int(2)), Number::int(1));
/// assert!(Number::float(0.5).is_float());
/// ```
#[derive(Clone, Copy, Debug)]
pub enum Number {
    /// An exact rational `num / den`, `den > 0`, `gcd(num, den) = 1`.
    Rational {
        /// Numerator (carries the sign).
        num: i128,
        /// Denominator, always positive.
        den: i128,
    },
    /// A finite floating-point value (never NaN or infinite; `-0.0` is stored as `0.0`).
    Float(f64),
}

fn gcd(mut a: i128, mut b: i128) -> i128 {
    a = a.abs();
    b = b.abs();
    while b != 0 {
        let r = a % b;
        a = b;
        b = r;
    }
    a
}

impl Number {
    /// The integer `n`.
    pub const fn int(n: i64) -> Number {
        Number::Rational {
            num: n as i128,
            den: 1,
        }
    }

    /// Zero.
    pub const ZERO: Number = Number::int(0);
    /// One.
    pub const ONE: Number = Number::int(1);
    /// Minus one.
    pub const MINUS_ONE: Number = Number::int(-1);

    /// The fraction `num / den` in lowest terms; `None` when `den == 0`.
    pub fn ratio(num: i128, den: i128) -> Option<Number> {
        if den == 0 {
            return None;
        }
        Some(Self::normalize(num, den))
    }

    fn normalize(num: i128, den: i128) -> Number {
        let g = gcd(num, den).max(1);
        let (mut n, mut d) = (num / g, den / g);
        if d < 0 {
            // i128::MIN cannot occur here in practice; fall back to float if it does.
            match (n.checked_neg(), d.checked_neg()) {
                (Some(a), Some(b)) => {
                    n = a;
                    d = b;
                }
                _ => return Number::float(num as f64 / den as f64),
            }
        }
        Number::Rational { num: n, den: d }
    }

    /// A float constant. Integral floats stay floats (`2.0` is not `2`), so a
    /// float literal is never silently made exact, except for `0.0` and
    /// `±1.0`, the identities, which become exact (multiplying by them is
    /// exact in IEEE arithmetic too). Callers reject non-finite input first;
    /// see [`Number::try_float`].
    pub fn float(x: f64) -> Number {
        if x == 0.0 {
            Number::ZERO
        } else if x == 1.0 {
            Number::ONE
        } else if x == -1.0 {
            Number::MINUS_ONE
        } else {
            Number::Float(x)
        }
    }

    /// A float constant, or `None` when `x` is NaN or infinite.
    pub fn try_float(x: f64) -> Option<Number> {
        x.is_finite().then(|| Number::float(x))
    }

    /// Whether this constant is a float (inexact).
    pub fn is_float(&self) -> bool {
        matches!(self, Number::Float(_))
    }

    /// The value as `f64` (rounded for rationals).
    pub fn to_f64(&self) -> f64 {
        match *self {
            Number::Rational { num, den } => {
                if den == 1 {
                    num as f64
                } else {
                    num as f64 / den as f64
                }
            }
            Number::Float(x) => x,
        }
    }

    /// Exact zero or float zero.
    pub fn is_zero(&self) -> bool {
        match *self {
            Number::Rational { num, .. } => num == 0,
            Number::Float(x) => x == 0.0,
        }
    }

    /// Exactly one (a float `1.0` counts: multiplying by it is the identity).
    pub fn is_one(&self) -> bool {
        match *self {
            Number::Rational { num, den } => num == 1 && den == 1,
            Number::Float(x) => x == 1.0,
        }
    }

    /// Strictly negative.
    pub fn is_negative(&self) -> bool {
        match *self {
            Number::Rational { num, .. } => num < 0,
            Number::Float(x) => x < 0.0,
        }
    }

    /// The integer value when this is an exact integer.
    pub fn as_integer(&self) -> Option<i128> {
        match *self {
            Number::Rational { num, den: 1 } => Some(num),
            _ => None,
        }
    }

    /// `-self`.
    #[allow(clippy::should_implement_trait)] // called by name across the engine; the operator trait is implemented too
    pub fn neg(self) -> Number {
        match self {
            Number::Rational { num, den } => match num.checked_neg() {
                Some(n) => Number::Rational { num: n, den },
                None => Number::float(-(num as f64) / den as f64),
            },
            Number::Float(x) => Number::float(-x),
        }
    }

    /// `self + other`.
    #[allow(clippy::should_implement_trait)] // called by name across the engine; the operator trait is implemented too
    pub fn add(self, other: Number) -> Number {
        match (self, other) {
            (Number::Rational { num: a, den: b }, Number::Rational { num: c, den: d }) => {
                let exact = (|| {
                    let g = gcd(b, d);
                    let lcm = b.checked_mul(d / g)?;
                    let x = a.checked_mul(lcm / b)?;
                    let y = c.checked_mul(lcm / d)?;
                    Some(Self::normalize(x.checked_add(y)?, lcm))
                })();
                exact.unwrap_or_else(|| Number::float(self.to_f64() + other.to_f64()))
            }
            _ => Number::float(self.to_f64() + other.to_f64()),
        }
    }

    /// `self * other`.
    #[allow(clippy::should_implement_trait)] // called by name across the engine; the operator trait is implemented too
    pub fn mul(self, other: Number) -> Number {
        match (self, other) {
            (Number::Rational { num: a, den: b }, Number::Rational { num: c, den: d }) => {
                let exact = (|| {
                    let g1 = gcd(a, d).max(1);
                    let g2 = gcd(c, b).max(1);
                    let n = (a / g1).checked_mul(c / g2)?;
                    let m = (b / g2).checked_mul(d / g1)?;
                    Some(Self::normalize(n, m))
                })();
                exact.unwrap_or_else(|| Number::float(self.to_f64() * other.to_f64()))
            }
            _ => Number::float(self.to_f64() * other.to_f64()),
        }
    }

    /// `1 / self`; `None` for zero.
    pub fn recip(self) -> Option<Number> {
        if self.is_zero() {
            return None;
        }
        Some(match self {
            Number::Rational { num, den } => Self::normalize(den, num),
            Number::Float(x) => Number::float(1.0 / x),
        })
    }

    /// `self ^ n` for an integer exponent; `None` for `0 ^ n` with `n < 0`.
    pub fn powi(self, n: i64) -> Option<Number> {
        if n < 0 {
            return self.recip()?.powi(n.checked_neg()?);
        }
        let mut base = self;
        let mut acc = Number::ONE;
        let mut e = n as u64;
        while e > 0 {
            if e & 1 == 1 {
                acc = acc.mul(base);
            }
            e >>= 1;
            if e > 0 {
                base = base.mul(base);
            }
        }
        Some(acc)
    }

    /// The exact square root when this is the square of a rational.
    pub fn exact_sqrt(self) -> Option<Number> {
        match self {
            Number::Rational { num, den } if num >= 0 => {
                let a = isqrt(num)?;
                let b = isqrt(den)?;
                Some(Number::Rational { num: a, den: b })
            }
            _ => None,
        }
    }

    /// Absolute value.
    pub fn abs(self) -> Number {
        if self.is_negative() {
            self.neg()
        } else {
            self
        }
    }

    /// The content of exact rationals: the largest positive rational `c` such
    /// that every `x / c` is an integer and the integers are coprime. `None`
    /// when a float is among them or all are zero.
    pub fn content(values: &[Number]) -> Option<Number> {
        let mut g_num: i128 = 0;
        let mut l_den: i128 = 1;
        for v in values {
            match *v {
                Number::Rational { num, den } => {
                    if num == 0 {
                        continue;
                    }
                    g_num = gcd(g_num, num);
                    let g = gcd(l_den, den);
                    l_den = (l_den / g).checked_mul(den)?;
                }
                Number::Float(_) => return None,
            }
        }
        if g_num == 0 {
            return None;
        }
        Number::ratio(g_num, l_den)
    }

    /// Total order used for canonical sorting (by value, then exact before float).
    pub fn total_cmp(&self, other: &Number) -> Ordering {
        self.to_f64()
            .total_cmp(&other.to_f64())
            .then_with(|| self.is_float().cmp(&other.is_float()))
    }
}

fn isqrt(n: i128) -> Option<i128> {
    if n < 0 {
        return None;
    }
    let mut r = (n as f64).sqrt() as i128;
    while r > 0 && r.checked_mul(r).is_none_or(|s| s > n) {
        r -= 1;
    }
    while (r + 1).checked_mul(r + 1).is_some_and(|s| s <= n) {
        r += 1;
    }
    (r * r == n).then_some(r)
}

impl std::ops::Add for Number {
    type Output = Number;
    fn add(self, o: Number) -> Number {
        Number::add(self, o)
    }
}

impl std::ops::Mul for Number {
    type Output = Number;
    fn mul(self, o: Number) -> Number {
        Number::mul(self, o)
    }
}

impl std::ops::Neg for Number {
    type Output = Number;
    fn neg(self) -> Number {
        Number::neg(self)
    }
}

impl PartialEq for Number {
    fn eq(&self, other: &Number) -> bool {
        match (self, other) {
            (Number::Rational { num: a, den: b }, Number::Rational { num: c, den: d }) => {
                a == c && b == d
            }
            (Number::Float(x), Number::Float(y)) => x.to_bits() == y.to_bits(),
            _ => false,
        }
    }
}

impl Eq for Number {}

impl Hash for Number {
    fn hash<H: Hasher>(&self, state: &mut H) {
        match self {
            Number::Rational { num, den } => {
                0u8.hash(state);
                num.hash(state);
                den.hash(state);
            }
            Number::Float(x) => {
                1u8.hash(state);
                x.to_bits().hash(state);
            }
        }
    }
}

impl fmt::Display for Number {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Number::Rational { num, den: 1 } => write!(f, "{num}"),
            Number::Rational { num, den } => write!(f, "{num}/{den}"),
            Number::Float(x) => {
                // `{:?}` prints the shortest representation that round-trips,
                // always with a `.` or exponent so it reads back as a float.
                write!(f, "{x:?}")
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn r(n: i128, d: i128) -> Number {
        Number::ratio(n, d).unwrap()
    }

    #[test]
    fn ratio_in_lowest_terms() {
        assert_eq!(r(2, 4), r(1, 2));
    }
    #[test]
    fn negative_denominator_moves_sign() {
        assert_eq!(r(1, -2), r(-1, 2));
    }
    #[test]
    fn add_fractions() {
        assert_eq!(r(1, 6).add(r(1, 3)), r(1, 2));
    }
    #[test]
    fn mul_fractions() {
        assert_eq!(r(2, 3).mul(r(3, 4)), r(1, 2));
    }
    #[test]
    fn powi_negative() {
        assert_eq!(r(2, 3).powi(-2), Some(r(9, 4)));
    }
    #[test]
    fn zero_to_negative_power_is_none() {
        assert_eq!(Number::ZERO.powi(-1), None);
    }
    #[test]
    fn exact_sqrt_of_square() {
        assert_eq!(r(9, 4).exact_sqrt(), Some(r(3, 2)));
    }
    #[test]
    fn exact_sqrt_of_non_square() {
        assert_eq!(r(2, 1).exact_sqrt(), None);
    }
    #[test]
    fn float_contaminates() {
        assert!(r(1, 3).add(Number::float(1.5)).is_float());
    }
    #[test]
    fn overflow_falls_back_to_float() {
        let big = Number::Rational {
            num: i128::MAX / 2,
            den: 1,
        };
        assert!(big.mul(big).is_float());
    }
    #[test]
    fn negative_zero_is_zero() {
        assert_eq!(Number::float(-0.0), Number::float(0.0));
    }
    #[test]
    fn content_of_rationals() {
        assert_eq!(
            Number::content(&[r(4, 1), r(-2, 1), r(6, 1)]),
            Some(r(2, 1))
        );
        assert_eq!(Number::content(&[r(1, 2), r(1, 3)]), Some(r(1, 6)));
        assert_eq!(Number::content(&[r(1, 2), Number::float(0.3)]), None);
    }
    #[test]
    fn float_identities_are_exact() {
        assert_eq!(Number::float(1.0), Number::ONE);
        assert_eq!(Number::float(-1.0), Number::MINUS_ONE);
        assert!(Number::float(2.0).is_float());
    }
    #[test]
    fn display_roundtrip_forms() {
        assert_eq!(r(-3, 4).to_string(), "-3/4");
        assert_eq!(Number::float(2.0).to_string(), "2.0");
    }
}
