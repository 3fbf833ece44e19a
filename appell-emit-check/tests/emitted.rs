//! The emitted code, compiled, against the engine's own numbers.

use appell_emit_check::*;
use num_dual::Dual64;

/// One generated case: its expression, the compiled functions, and the
/// values of (e, ∂e/∂x) the engine computed at fixed points of (a, b, x, y, z).
#[allow(dead_code)]
pub struct Case {
    pub text: &'static str,
    pub ops: usize,
    /// Whether the code calls `powi` (exponent above 64).
    pub powi: bool,
    pub joint_f64: fn(f64, f64, f64, f64, f64) -> [f64; 2],
    pub joint_f32: fn(f32, f32, f32, f32, f32) -> [f32; 2],
    pub joint_dual: fn(Dual64, Dual64, Dual64, Dual64, Dual64) -> [Dual64; 2],
    /// Whether the fused text uses `fma` (`Scalar::fused_mul_add`) at all.
    pub fused_text: bool,
    /// The same program written with `fma` (`Scalar::fused_mul_add`).
    pub fused_f64: fn(f64, f64, f64, f64, f64) -> [f64; 2],
    pub split: fn([f64; 2], [f64; 3]) -> [f64; 2],
    pub points: &'static [([f64; 5], [f64; 2])],
}

include!(concat!(env!("OUT_DIR"), "/cases.rs"));

/// Equal to within two units in the last place. The emitted code performs
/// the same IEEE operations in the same order as the engine's program, so the
/// results are identical except where the compiler folds a constant
/// subexpression (`sin(4)`) with its own libm at compile time, and `powi`,
/// whose rounding Rust leaves unspecified (a run-time call and a compile-time
/// fold may differ by a few ulps per multiplication).
fn same_bits(a: f64, b: f64, powi: bool) -> bool {
    if a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()) {
        return true;
    }
    let ulps = if powi { 256.0 } else { 2.0 };
    (a - b).abs() <= ulps * f64::EPSILON * a.abs().max(b.abs())
}

/// Runs `f` at every case's points and checks each output against the
/// engine's with `agree`; returns how many outputs were compared.
fn compare_all(
    what: &str,
    f: impl Fn(&Case) -> fn(f64, f64, f64, f64, f64) -> [f64; 2],
    agree: impl Fn(f64, f64, &Case) -> bool,
) -> usize {
    let mut checked = 0;
    for c in CASES {
        for (p, expected) in c.points {
            let got = f(c)(p[0], p[1], p[2], p[3], p[4]);
            for k in 0..2 {
                assert!(
                    agree(got[k], expected[k], c),
                    "output {k} of {}: {what} {} vs engine {}",
                    c.text,
                    got[k],
                    expected[k]
                );
                checked += 1;
            }
        }
    }
    checked
}

#[test]
fn emitted_code_equals_the_engine_bit_for_bit() {
    let checked = compare_all(
        "compiled",
        |c| c.joint_f64,
        |a, b, c| same_bits(a, b, c.powi),
    );
    assert_eq!(checked, CASES.len() * 6 * 2);
}

/// Written with `fma` (`Scalar::fused_mul_add`), the code gives the engine's values to the
/// bit on a target without FMA instructions (the default x86-64 target, as
/// in CI): a difference a − x·y is written (−x)·y + a, which IEEE arithmetic
/// gives exactly. With FMA each fused pair rounds once, so only closeness is
/// checked there.
#[test]
fn fused_code_equals_the_engine_without_fma() {
    compare_all(
        "fused",
        |c| c.fused_f64,
        |a, b, c| {
            if cfg!(target_feature = "fma") {
                (a - b).abs() <= 1e-6 * b.abs().max(1.0) || (a.is_nan() && b.is_nan())
            } else {
                same_bits(a, b, c.powi)
            }
        },
    );
    // The generator's expressions have products feeding sums in most cases.
    let fused = CASES.iter().filter(|c| c.fused_text).count();
    assert!(fused > CASES.len() / 2, "only {fused} cases were fused");
}

#[test]
fn hoisted_preparation_gives_the_same_numbers() {
    for c in CASES {
        for (p, expected) in c.points {
            let got = (c.split)([p[0], p[1]], [p[2], p[3], p[4]]);
            for k in 0..2 {
                assert!(
                    same_bits(got[k], expected[k], c.powi),
                    "{}: {} vs {}",
                    c.text,
                    got[k],
                    expected[k]
                );
            }
        }
    }
}

#[test]
fn dual_numbers_through_emitted_code_match_the_symbolic_derivative() {
    let mut compared = 0;
    for c in CASES {
        for (p, expected) in c.points {
            let d = |v: f64| Dual64::from(v);
            let got = (c.joint_dual)(d(p[0]), d(p[1]), Dual64::new(p[2], 1.0), d(p[3]), d(p[4]));
            // Real parts: num-dual computes some functions by other formulas
            // (tan from sin and cos, say), so they agree to rounding only.
            let re = got[0].re;
            assert!(
                (re - expected[0]).abs() <= 1e-12 * (1.0 + expected[0].abs()),
                "{}: {re} vs {}",
                c.text,
                expected[0]
            );
            // The dual part of e is ∂e/∂x computed by forward mode; output 1
            // is the symbolic derivative. They agree to rounding, relative to
            // the size of the terms (bounded here by a generous scale).
            let (ad, sym) = (got[0].eps, expected[1]);
            let scale = 1.0 + ad.abs().max(sym.abs());
            if ad.is_finite() && sym.is_finite() {
                assert!(
                    (ad - sym).abs() <= 1e-8 * scale,
                    "{}: dual {} vs symbolic {}",
                    c.text,
                    ad,
                    sym
                );
                compared += 1;
            }
        }
    }
    assert!(
        compared > CASES.len() * 5,
        "too few finite comparisons: {compared}"
    );
}

#[test]
fn f32_instantiation_tracks_f64_on_well_scaled_cases() {
    let mut close = 0;
    let mut total = 0;
    for c in CASES {
        for (p, expected) in c.points {
            let f = |i: usize| p[i] as f32;
            let got = (c.joint_f32)(f(0), f(1), f(2), f(3), f(4));
            if expected[0].is_finite() && expected[0].abs() < 1e3 {
                total += 1;
                if ((got[0] as f64) - expected[0]).abs() <= 1e-3 * (1.0 + expected[0].abs()) {
                    close += 1;
                }
            }
        }
    }
    // Random expressions include ill-conditioned ones; the bulk must agree.
    assert!(
        close as f64 >= 0.95 * total as f64,
        "{close} of {total} close"
    );
}

#[test]
fn operation_counts_are_reported() {
    let total: usize = CASES.iter().map(|c| c.ops).sum();
    assert!(
        total > CASES.len(),
        "{total} operations over {} cases",
        CASES.len()
    );
}
