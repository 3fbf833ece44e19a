//! The hard-case catalogue, as tests (`cargo run --release --example
//! hard_cases` prints the same checks as a table).

mod cases;
mod precision;

fn check(rows: Vec<cases::CaseResult>) {
    for r in &rows {
        println!(
            "{} | {} | {} | {}",
            r.case,
            r.criterion,
            r.measured,
            if r.pass { "pass" } else { "FAIL" }
        );
    }
    for r in &rows {
        assert!(
            r.pass,
            "{}: {} — measured {}",
            r.case, r.criterion, r.measured
        );
    }
}

#[test]
fn a01_pendulum_2000_s() {
    // The published horizon: about a million rhs calls, well under a
    // second even in the test profile.
    check(cases::a01_long_horizon(2000.0));
}

#[test]
fn singular_dependent_blocks_are_typed_errors() {
    check(cases::singular_dependent_block());
}

#[test]
fn disc_rolls_a_steady_circle() {
    check(cases::disc_steady_circle());
}

#[test]
fn bicycle_self_stability_matches_its_eigenvalues() {
    check(cases::bicycle_self_stability(10.0));
}

#[test]
fn bicycle_pitch_drift_is_removed_by_projection() {
    check(cases::bicycle_pitch_drift(10_000));
}

#[test]
fn stiff_spring_pendulum_completes() {
    check(cases::stiff_spring(1.0));
}

#[test]
fn mass_ratio_chain_factorization_stays_accurate() {
    check(cases::mass_ratio_chain());
}

#[test]
fn four_bar_passes_its_singular_positions() {
    let p = cases::FourBar2 {
        a: 1.0,
        m: 1.0,
        g: 9.81,
    };
    check(cases::four_bar_singular_positions(&p, 2, 10.0, 1e-3));
}

#[test]
#[ignore = "N = 40 over 20 s: about a minute in release; run with --ignored or the example"]
fn four_bar_40_passes_its_singular_positions() {
    let p = cases::FourBar40 {
        a: 1.0,
        m: 1.0,
        g: 9.81,
    };
    check(cases::four_bar_singular_positions(&p, 40, 20.0, 5e-3));
}

#[test]
fn four_bar_drift_is_removed_by_projection() {
    check(cases::four_bar_drift(10_000));
}

#[test]
fn bad_states_are_named() {
    check(cases::bad_states());
}

#[test]
fn elliptic_functions_match_known_values() {
    // K(0) = π/2; sn(u | 0) = sin u; sn(u | 1) = tanh u (up to the
    // AGM's limit); K(1/2) = 1.854074677301372.
    assert!((cases::elliptic_k(0.0) - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    assert!((cases::elliptic_k(0.5) - 1.854074677301372).abs() < 1e-14);
    for u in [0.1, 0.7, 2.0, 5.0] {
        assert!((cases::jacobi_sn(u, 0.0) - f64::sin(u)).abs() < 1e-14);
    }
    // The small-amplitude pendulum is harmonic.
    let t = 1.3;
    let th = cases::pendulum_exact(1e-4, 9.81, 1.0, t);
    assert!((th - 1e-4 * (9.81f64.sqrt() * t).cos()).abs() < 1e-12);
}

#[test]
fn generated_code_round_off_is_bounded() {
    // Item 7 on 10,000 random states per model.
    check(precision::round_off_all(10_000));
}

#[test]
fn double_pendulum_separates_when_its_lyapunov_exponent_says() {
    // Item 8 with the exponent averaged over 200 s (1,000 s in the
    // example).
    check(precision::double_pendulum_chaos(200.0));
}

#[test]
fn the_condition_watch_warns_before_the_four_bars_dead_centre() {
    check(cases::four_bar_condition_warning(1e3));
}

#[test]
fn andrews_squeezer_matches_the_ivp_test_set() {
    check(cases::andrews_squeezer());
}

#[test]
fn the_condition_watch_warns_before_each_of_the_squeezers_dead_centres() {
    check(cases::andrews_gamma_dead_centres(1e3, 1e-5, false));
    check(cases::andrews_gamma_dead_centres(1e3, 1e-5, true));
}

#[test]
fn the_pivot_estimate_of_the_condition_follows_the_svd() {
    check(cases::pivot_estimate_against_svd(4.0));
}
