//! Double-double: identities, known constants to 32+ digits, and agreement
//! with the correctly rounded f64 operations.

use super::DoubleDouble;
use crate::Scalar;

type Dd = DoubleDouble;

fn dd(x: f64) -> Dd {
    Dd::from(x)
}

fn parse(s: &str) -> Dd {
    s.parse().unwrap()
}

/// |a − b| ≤ rel · |b| (absolute when b = 0).
#[track_caller]
fn assert_close(a: Dd, b: Dd, rel: f64) {
    let diff = (a - b).abs().to_f64();
    let scale = b.abs().to_f64().max(if b.hi == 0.0 { 1.0 } else { 0.0 });
    assert!(
        diff <= rel * scale,
        "{a:?} vs {b:?}: difference {diff:e}, relative {:e}",
        diff / scale
    );
}

/// A deterministic xorshift generator, uniform in [lo, hi).
struct Rng(u64);

impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        lo + (hi - lo) * ((self.0 >> 11) as f64 / (1u64 << 53) as f64)
    }
}

#[test]
fn constants_match_their_decimal_expansions() {
    // Digits from the standard tables (π, e, ln 2 to 36 digits).
    assert_close(
        Dd::PI,
        parse("3.14159265358979323846264338327950288"),
        4e-32,
    );
    assert_close(
        Dd::FRAC_PI_2,
        parse("1.57079632679489661923132169163975144"),
        4e-32,
    );
    assert_close(Dd::E, parse("2.71828182845904523536028747135266250"), 4e-32);
    assert_close(
        Dd::LN_2,
        parse("0.693147180559945309417232121458176568"),
        4e-32,
    );
}

#[test]
fn parsing_handles_signs_points_and_exponents() {
    assert_eq!(parse("-2.5e3"), dd(-2500.0));
    assert_eq!(parse("+0.125"), dd(0.125));
    assert_eq!(parse("125E-3"), dd(0.125));
    // 0.1 is not an f64: the parsed value is 0.1 to 32 digits.
    assert_close(parse("0.1") * dd(10.0), dd(1.0), 2e-32);
    assert!(parse("0.1") != dd(0.1));
    assert_eq!(parse("7"), dd(7.0));
    assert_close(parse("1e-300"), dd(1e-300), 1e-16);
    for bad in ["", "-", ".", "1.2.3", "1e", "abc", "1 "] {
        assert!(bad.parse::<Dd>().is_err(), "{bad:?}");
    }
}

#[test]
fn elementary_functions_match_known_values() {
    // sin 1, cos 1, e^(1/2), √2, atan 2, π/4 to 36 digits.
    assert_close(
        dd(1.0).sin(),
        parse("0.841470984807896506652502321630298999"),
        1e-31,
    );
    assert_close(
        dd(1.0).cos(),
        parse("0.540302305868139717400936607442976604"),
        1e-31,
    );
    assert_close(dd(1.0).exp(), Dd::E, 1e-31);
    assert_close(
        dd(0.5).exp(),
        parse("1.64872127070012814684865078781416357"),
        1e-31,
    );
    assert_close(dd(2.0).ln(), Dd::LN_2, 1e-31);
    assert_close(
        dd(2.0).sqrt(),
        parse("1.41421356237309504880168872420969808"),
        1e-31,
    );
    assert_close(
        dd(2.0).atan2(dd(1.0)),
        parse("1.10714871779409050301706546017853704"),
        1e-31,
    );
    assert_close(dd(1.0).atan2(dd(1.0)), Dd::PI.div_f64(4.0), 1e-31);
    assert_close(Dd::PI.div_f64(4.0).tan(), dd(1.0), 1e-31);
    assert_close(Dd::PI.sin(), dd(0.0), 1e-31);
    assert_close(Dd::PI.cos(), dd(-1.0), 1e-31);
    assert_close(Dd::FRAC_PI_2.sin(), dd(1.0), 1e-31);
}

#[test]
fn sin_squared_plus_cos_squared_is_one() {
    let mut rng = Rng(7);
    for _ in 0..2000 {
        let x = Dd::new(rng.uniform(-100.0, 100.0), rng.uniform(-1e-15, 1e-15));
        let (s, c) = (x.sin(), x.cos());
        assert_close(s.sqr() + c.sqr(), dd(1.0), 1e-31);
        assert_close(x.tan(), s / c, 1e-31);
        // sin 2x = 2 sin x cos x.
        assert_close(
            (x + x).sin(),
            (s * c).mul_f64(2.0),
            1e-30 / (x + x).sin().hi.abs(),
        );
    }
}

#[test]
fn exp_and_ln_invert_each_other() {
    let mut rng = Rng(8);
    for _ in 0..2000 {
        let x = Dd::new(rng.uniform(-50.0, 50.0), rng.uniform(-1e-15, 1e-15));
        assert_close(x.exp().ln(), x, 1e-30 / x.hi.abs().min(1.0));
        let y = dd(rng.uniform(-30.0, 30.0)).exp();
        assert_close(y.ln().exp(), y, 1e-30);
        // e^(a + b) = e^a e^b.
        let z = dd(rng.uniform(-5.0, 5.0));
        // (The rounding of x + z alone moves e^(x+z) by |x + z| · 1e-32.)
        assert_close((x + z).exp(), x.exp() * z.exp(), 2e-31 * (1.0 + x.hi.abs()));
    }
    // Near 1 the logarithm keeps its relative accuracy: ln(1 + h) for
    // h = 1e-10 (the f64 nearest) by its series h − h²/2 + h³/3.
    let h = dd(1e-10);
    let series = h - h.sqr().div_f64(2.0) + h.sqr() * h.div_f64(3.0);
    assert_close((dd(1.0) + h).ln(), series, 1e-30);
    // The range ends.
    assert!(dd(710.0).exp().hi.is_infinite());
    assert_eq!(dd(-746.0).exp().hi, 0.0);
    assert_eq!(dd(0.0).ln().hi, f64::NEG_INFINITY);
    assert!(dd(-1.0).ln().hi.is_nan());
    assert_close(dd(709.0).exp(), dd(709.0f64.exp()), 2.3e-16);
}

#[test]
fn atan2_has_the_right_quadrant() {
    let pi = Dd::PI;
    let cases = [
        (1.0, 1.0, pi.div_f64(4.0)),
        (1.0, -1.0, pi.mul_f64(0.75)),
        (-1.0, -1.0, -pi.mul_f64(0.75)),
        (-1.0, 1.0, -pi.div_f64(4.0)),
        (1.0, 0.0, Dd::FRAC_PI_2),
        (-1.0, 0.0, -Dd::FRAC_PI_2),
        (0.0, -1.0, pi),
        (0.0, 1.0, dd(0.0)),
    ];
    for (y, x, expected) in cases {
        assert_close(dd(y).atan2(dd(x)), expected, 1e-31);
    }
    let mut rng = Rng(9);
    for _ in 0..2000 {
        let theta = Dd::new(rng.uniform(-3.1, 3.1), rng.uniform(-1e-16, 1e-16));
        let r = rng.uniform(0.01, 100.0);
        let (s, c) = (theta.sin(), theta.cos());
        assert_close(
            s.mul_f64(r).atan2(c.mul_f64(r)),
            theta,
            1e-30 / theta.hi.abs(),
        );
    }
}

#[test]
fn powi_and_sqrt_are_consistent() {
    let x = parse("1.1");
    assert_close(x.powi(5), x * x * x * x * x, 1e-31);
    assert_close(x.powi(-3), dd(1.0) / (x * x * x), 1e-31);
    assert_eq!(x.powi(0), dd(1.0));
    assert_close(x.powi(2).sqrt(), x, 1e-31);
    assert_eq!(dd(0.0).sqrt(), dd(0.0));
    assert!(dd(-1.0).sqrt().hi.is_nan());
    assert_close(dd(1e-300).sqrt(), dd(1e-150), 1e-16);
}

/// +, −, ×, ÷ and √ are correctly rounded in IEEE 754, so the f64 rounding
/// of the (much more accurate) double-double result must be the f64 result
/// itself, bit for bit.
#[test]
fn rounding_to_f64_agrees_with_the_correctly_rounded_operations() {
    let mut rng = Rng(10);
    for _ in 0..100_000 {
        let a = rng.uniform(-1.0, 1.0) * 2f64.powi(rng.uniform(-30.0, 30.0) as i32);
        let b = rng.uniform(-1.0, 1.0) * 2f64.powi(rng.uniform(-30.0, 30.0) as i32);
        assert_eq!((dd(a) + dd(b)).to_f64(), a + b, "{a} + {b}");
        assert_eq!((dd(a) - dd(b)).to_f64(), a - b, "{a} - {b}");
        assert_eq!((dd(a) * dd(b)).to_f64(), a * b, "{a} * {b}");
        assert_eq!((dd(a) / dd(b)).to_f64(), a / b, "{a} / {b}");
        assert_eq!(dd(a.abs()).sqrt().to_f64(), a.abs().sqrt(), "sqrt {a}");
    }
}

/// The f64 transcendental functions of the platform are faithful (within
/// an ulp) but not promised to be correctly rounded: the double-double
/// result, rounded, must be within one ulp of them, and equal in almost all
/// cases.
#[test]
fn transcendental_functions_are_within_an_ulp_of_f64() {
    let mut rng = Rng(11);
    let ulps = |a: f64, b: f64| (a.to_bits() as i64 - b.to_bits() as i64).abs();
    let mut differ = 0;
    let n = 20_000;
    for _ in 0..n {
        let x = rng.uniform(-10.0, 10.0);
        let y = rng.uniform(-10.0, 10.0);
        let pairs = [
            (dd(x).sin().to_f64(), x.sin()),
            (dd(x).cos().to_f64(), x.cos()),
            (dd(x).exp().to_f64(), x.exp()),
            (dd(x.abs()).ln().to_f64(), x.abs().ln()),
            (dd(y).atan2(dd(x)).to_f64(), y.atan2(x)),
        ];
        for (a, b) in pairs {
            assert!(ulps(a, b) <= 1, "{a} vs {b} at x = {x}, y = {y}");
            differ += usize::from(a != b);
        }
    }
    assert!(differ < n / 100, "{differ} of {} differ by an ulp", 5 * n);
}

#[test]
fn generic_code_runs_on_double_double() {
    fn poly<T: Scalar>(x: T) -> T {
        x * x.sin() + T::from_f64(2.0) * x.powi(3) - x.exp().ln()
            + x.abs().sqrt()
            + x.atan2(T::one())
    }
    let a = poly(0.7_f64);
    let b = poly(dd(0.7));
    assert!((a - b.re()).abs() < 1e-15);
    let mut c = dd(1.0);
    c += dd(2.0);
    c *= dd(3.0);
    c -= dd(1.0);
    c /= dd(4.0);
    assert_eq!(c, dd(2.0));
}
