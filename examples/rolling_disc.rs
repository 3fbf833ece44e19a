//! A thin disc rolling without slip, derived at compile time: a steady turn
//! (Euler's equation about the centre) stays steady, and a slightly faster
//! spin makes the lean oscillate about it. The model command line (`eval`,
//! `contacts`, `info`, `equations`, `bench`, `accuracy`) comes with it.

#[path = "models/rolling_disc.rs"]
mod model;

use std::error::Error;
use std::process::ExitCode;

use appell::Model;
use model::RollingDisc;

fn main() -> ExitCode {
    appell::cli::run(RollingDisc::default(), demonstrate)
}

/// The state (lean, yaw rate, lean rate, spin rate) of a steady turn at
/// lean `theta` and yaw rate `omega`: from Euler's equation about the
/// centre, −(3/2) r Ω W cos θ + (1/4) r Ω² cos θ sin θ − g sin θ = 0 with
/// W = Ω sin θ + ω the disc's total axial rate.
fn steady_turn(p: &RollingDisc, theta: f64, omega: f64) -> [f64; 4] {
    let (s, c) = theta.sin_cos();
    let w = (0.25 * p.r * omega * omega * c * s - p.g * s) / (1.5 * p.r * omega * c);
    [theta, omega, 0.0, w - omega * s]
}

fn demonstrate(p: &RollingDisc) -> Result<(), Box<dyn Error>> {
    println!("{}", RollingDisc::info().equations);
    let prepared = p.prepare::<f64>();
    let steady = steady_turn(p, 0.3, 2.0);
    let mut nudged = steady;
    nudged[3] *= 1.02;
    let mut a = steady;
    let mut b = nudged;
    println!(
        "{:>5} {:>14} {:>14}",
        "t", "lean (steady)", "lean (+2% spin)"
    );
    for k in 0..=10 {
        let t = k as f64 * 0.5;
        println!("{t:>5.1} {:>14.10} {:>14.10}", a[0], b[0]);
        a = appell::integrate::rk4(p, &prepared, t, &a, 1e-4, 5000, &[])?;
        b = appell::integrate::rk4(p, &prepared, t, &b, 1e-4, 5000, &[])?;
    }
    Ok(())
}
