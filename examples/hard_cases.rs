//! The hard-case catalogue at the published horizons: one row per check,
//! with its criterion, the measured figure and pass or fail. The same cases
//! run at shorter horizons in `cargo test --test hard_cases`.
//!
//! Run: `cargo run --release --example hard_cases`.

#[path = "../tests/hard_cases/cases.rs"]
mod cases;
#[path = "../tests/hard_cases/precision.rs"]
mod precision;

use std::process::ExitCode;
use std::time::Instant;

fn main() -> ExitCode {
    let started = Instant::now();
    let mut rows = Vec::new();
    rows.extend(cases::a01_long_horizon(2000.0));
    let two = cases::FourBar2 {
        a: 1.0,
        m: 1.0,
        g: 9.81,
    };
    rows.extend(cases::four_bar_singular_positions(&two, 2, 10.0, 1e-3));
    let forty = cases::FourBar40 {
        a: 1.0,
        m: 1.0,
        g: 9.81,
    };
    rows.extend(cases::four_bar_singular_positions(&forty, 40, 20.0, 5e-3));
    rows.extend(cases::four_bar_condition_warning(1e3));
    rows.extend(cases::singular_dependent_block());
    rows.extend(cases::disc_steady_circle());
    rows.extend(cases::bicycle_self_stability(10.0));
    rows.extend(cases::bicycle_pitch_drift(10_000));
    rows.extend(cases::four_bar_drift(10_000));
    rows.extend(cases::stiff_spring(1.0));
    rows.extend(cases::mass_ratio_chain());
    rows.extend(cases::bad_states());
    rows.extend(cases::andrews_squeezer());
    rows.extend(cases::andrews_gamma_dead_centres(1e3, 1e-5, false));
    rows.extend(cases::andrews_gamma_dead_centres(1e3, 1e-5, true));
    rows.extend(cases::pivot_estimate_against_svd(4.0));
    rows.extend(precision::round_off_all(10_000));
    rows.extend(precision::double_pendulum_chaos(1000.0));
    println!("| case | criterion | measured | result |");
    println!("| --- | --- | --- | --- |");
    for r in &rows {
        println!(
            "| {} | {} | {} | {} |",
            r.case,
            r.criterion,
            r.measured,
            if r.pass { "pass" } else { "FAIL" }
        );
    }
    let failed = rows.iter().filter(|r| !r.pass).count();
    println!(
        "\n{} checks, {} failed, {:.1} s",
        rows.len(),
        failed,
        started.elapsed().as_secs_f64()
    );
    if failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}
