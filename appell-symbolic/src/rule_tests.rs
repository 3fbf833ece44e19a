//! One test per simplification rule, egg style: `rule!(name, before, after)`
//! asserts that both sides build the same node, and that `after` prints as
//! written (so the right-hand side is the canonical text, not just an equal
//! value).

use crate::Graph;

macro_rules! rule {
    ($name:ident, $lhs:expr, $rhs:expr) => {
        #[test]
        fn $name() {
            let mut g = Graph::new();
            let l = g.parse($lhs).unwrap();
            let r = g.parse($rhs).unwrap();
            assert_eq!(
                g.display(l).to_string(),
                $rhs,
                "{} should simplify to {}",
                $lhs,
                $rhs
            );
            assert_eq!(l, r, "{} and {} are different nodes", $lhs, $rhs);
        }
    };
}

// Constants fold exactly.
rule!(fold_integers, "2 + 3*4", "14");
rule!(fold_fractions, "1/2 + 1/3", "5/6");
rule!(fold_powers, "(2/3)^-2", "9/4");
rule!(fold_float_with_exact, "0.5 + 1/4", "0.75");
// Identities.
rule!(add_zero, "x + 0", "x");
rule!(mul_one, "x*1", "x");
rule!(mul_zero, "x*0", "0");
rule!(pow_zero, "x^0", "1");
rule!(pow_one, "x^1", "x");
rule!(sub_self, "x - x", "0");
rule!(div_self, "x/x", "1");
// Flattening and collection.
rule!(flatten_sum, "(x + y) + (z + x)", "2*x + y + z");
rule!(collect_terms, "x + 2*x - x/2", "5/2*x");
rule!(collect_factors, "x*x^3/x", "x^3");
rule!(commute_sum, "y + x", "x + y");
rule!(commute_product, "y*x", "x*y");
rule!(power_of_power, "(x^2)^3", "x^6");
rule!(power_of_product, "(2*x*y)^2", "4*x^2*y^2");
rule!(negative_power_of_product, "(2*x)^-1", "1/2/x");
// Coefficients and sums.
rule!(distribute_coefficient, "3*(x + 2*y)", "3*x + 6*y");
rule!(negate_sum, "-(x - y)", "y - x");
rule!(primitive_sum_factor, "(4*x + 2*y)/z", "2*(2*x + y)/z");
rule!(sign_of_sum_factor, "(-x + y)/z", "-(x - y)/z");
rule!(like_sum_factors_merge, "(x + 1)*(1 + x)", "(x + 1)^2");
rule!(sum_factor_cancels, "(x + y)^2/(x + y)", "x + y");
// Roots and absolute values.
rule!(sqrt_squared, "sqrt(x)^2", "x");
rule!(sqrt_cubed, "sqrt(x)^3", "x*sqrt(x)");
rule!(sqrt_inverse_squared, "1/sqrt(x)^2", "1/x");
rule!(sqrt_of_square, "sqrt(x^2)", "abs(x)");
rule!(sqrt_of_scaled_square, "sqrt(4*x^2*y^4)", "2*y^2*abs(x)");
rule!(sqrt_exact, "sqrt(9/4)", "3/2");
rule!(abs_squared, "abs(x)^2", "x^2");
rule!(abs_of_negation, "abs(-x)", "abs(x)");
rule!(abs_of_abs, "abs(abs(x))", "abs(x)");
rule!(abs_of_even_power, "abs(x^2)", "x^2");
rule!(abs_of_exp, "abs(exp(x))", "exp(x)");
rule!(abs_of_number, "abs(-3/2)", "3/2");
// Parity and special values.
rule!(sin_odd, "sin(-x)", "-sin(x)");
rule!(sin_odd_sum, "sin(y - x) + sin(x - y)", "0");
rule!(cos_even, "cos(-2*x)", "cos(2*x)");
rule!(tan_odd, "tan(-x)", "-tan(x)");
rule!(sin_zero, "sin(0)", "0");
rule!(cos_zero, "cos(0)", "1");
rule!(
    right_angle_as_double,
    "cos(1.5707963267948966) + sin(-1.5707963267948966) + sin(3.141592653589793) + cos(3.141592653589793)*x",
    "-x - 1"
);
rule!(
    rounded_right_angle_stays,
    "cos(1.57079632679)",
    "4.8965888601467475e-12"
);
rule!(exp_zero, "exp(0)", "1");
rule!(ln_one, "ln(1)", "0");
rule!(exp_ln, "exp(ln(x))", "x");
rule!(ln_exp, "ln(exp(x))", "x");
rule!(atan2_zero_over_positive, "atan2(0, x^2 + 1)", "0");
// Pythagoras inside a sum.
rule!(pythagoras, "sin(x)^2 + cos(x)^2", "1");
rule!(pythagoras_scaled, "3*y*sin(x)^2 + 3*y*cos(x)^2", "3*y");
rule!(
    pythagoras_higher_power,
    "sin(x)^2*cos(x)^2 + cos(x)^4",
    "cos(x)^2"
);
rule!(one_minus_sin_squared, "1 - sin(x)^2", "cos(x)^2");
rule!(
    scaled_minus_cos_squared,
    "2*y - 2*y*cos(x)^2",
    "2*y*sin(x)^2"
);
rule!(
    pythagoras_with_other_terms,
    "z + sin(2*x)^2 + cos(2*x)^2",
    "z + 1"
);
rule!(
    pythagoras_needs_equal_coefficients,
    "2*sin(x)^2 + cos(x)^2",
    "2*sin(x)^2 + cos(x)^2"
);

#[test]
fn rewrite_pass_limit_is_a_stop_reason_not_an_error() {
    let mut g = Graph::with_limits(crate::Limits {
        max_rewrite_passes: 1,
        ..crate::Limits::default()
    });
    let e = g
        .parse("sin(x)^2 + cos(x)^2 + sin(y)^2 + cos(y)^2")
        .unwrap();
    // One pass collapses one pair, then the limit stops the rewrite.
    assert_eq!(g.display(e).to_string(), "cos(y)^2 + sin(y)^2 + 1");
    assert!(g.stats().rewrite_limit_stops >= 1);
}

#[test]
fn term_limit_is_an_error() {
    let mut g = Graph::with_limits(crate::Limits {
        max_terms: 10,
        ..crate::Limits::default()
    });
    let e = g.parse("(a + b + c + d)*(e + f + h + i)").unwrap();
    assert_eq!(
        g.expand(e).unwrap_err(),
        crate::SymbolicError::TermLimit { limit: 10 }
    );
}

#[test]
fn ln_of_non_positive_constant_is_an_error() {
    let mut g = Graph::new();
    assert_eq!(
        g.parse("ln(0)").unwrap_err(),
        crate::SymbolicError::NonFiniteConstant
    );
    assert!(g.parse("sqrt(-4)").is_err());
}

#[test]
fn nan_float_is_rejected() {
    let mut g = Graph::new();
    assert_eq!(
        g.float(f64::NAN).unwrap_err(),
        crate::SymbolicError::NonFiniteConstant
    );
}

#[test]
fn zero_to_a_negative_power_is_a_division_by_zero() {
    let mut g = Graph::new();
    let z = g.int(0).unwrap();
    assert!(matches!(
        g.powi(z, -2),
        Err(crate::SymbolicError::DivisionByZero { .. })
    ));
}

#[test]
fn huge_exponent_overflows_cleanly() {
    let mut g = Graph::new();
    let x = g.parse("x^2000000000").unwrap();
    assert_eq!(
        g.powi(x, 2).unwrap_err(),
        crate::SymbolicError::ExponentOverflow
    );
}

// The functions of friction laws, drives and one-sided contacts.
rule!(sinh_odd, "sinh(-x)", "-sinh(x)");
rule!(cosh_even, "cosh(-x)", "cosh(x)");
rule!(tanh_odd, "tanh(-x)", "-tanh(x)");
rule!(asin_odd, "asin(-x)", "-asin(x)");
rule!(atan_odd, "atan(-x)", "-atan(x)");
rule!(sign_odd, "sign(-x)", "-sign(x)");
rule!(sign_idempotent, "sign(sign(x))", "sign(x)");
rule!(sign_of_positive, "sign(exp(x))", "1");
rule!(sign_of_constants, "sign(-3/2) + 2*sign(0)", "-1");
rule!(hyperbolic_at_zero, "sinh(0) + tanh(0) + cosh(0)", "1");
rule!(inverse_at_zero, "asin(0) + atan(0) + acos(1)", "0");
rule!(powf_integer_exponent, "powf(x, 3)", "x^3");
rule!(powf_integral_float_exponent, "powf(x, 2.0)", "x^2");
rule!(powf_half, "powf(x, 1/2)", "sqrt(x)");
rule!(powf_of_one, "powf(1, x)", "1");
rule!(select_equal_branches, "select(x, y, y)", "y");
rule!(
    select_known_sign,
    "select(exp(x), y, z) + select(-exp(x), y, z)",
    "y + z"
);
rule!(select_zero_condition, "select(0, y, z)", "z");
rule!(
    select_nested_same_condition,
    "select(x, select(x, y, w), z)",
    "select(x, y, z)"
);
rule!(min_of_equal, "min(x, x)", "x");
rule!(max_as_select, "max(x, y)", "select(x - y, x, y)");

#[test]
fn functions_fold_and_reject_constants_outside_their_domain() {
    let mut g = Graph::new();
    let e = g
        .parse("tanh(0.5) + powf(2.0, 0.5) + min(1.5, 2.5)")
        .unwrap();
    let expected = 0.5f64.tanh() + 2f64.sqrt() + 1.5;
    assert_eq!(g.display(e).to_string(), format!("{expected}"));
    for bad in ["asin(2.0)", "acos(-1.5)", "powf(-8.0, 0.3)"] {
        assert!(g.parse(bad).is_err(), "{bad}");
    }
}
