//! A planar double pendulum derived at compile time; the model command line
//! (`eval`, `info`, `equations`, `bench`) comes with it.
//!
//! Run `cargo run --release --example double_pendulum` for the equations and
//! a short simulation with its energy drift.

#[path = "models/double_pendulum.rs"]
mod model;

use std::error::Error;
use std::process::ExitCode;

use appell::integrate::rk4;
use appell::Model;
use model::DoublePendulum;

fn main() -> ExitCode {
    appell::cli::run(DoublePendulum::default(), demonstrate)
}

/// Total energy: kinetic from the model, potential from the geometry.
fn energy(p: &DoublePendulum, s: &[f64; 4]) -> Result<f64, appell::ModelError> {
    let t = p.kinetic_energy(0.0, &s[..2], &s[2..])?;
    let v = -p.g * ((p.m1 + p.m2) * p.l1 * s[0].cos() + p.m2 * p.l2 * s[1].cos());
    Ok(t + v)
}

fn demonstrate(p: &DoublePendulum) -> Result<(), Box<dyn Error>> {
    println!("{}", DoublePendulum::info().equations);
    let prepared = p.prepare::<f64>();
    let s0 = [1.2, -0.4, 0.0, 0.0];
    let e0 = energy(p, &s0)?;
    let s = rk4(p, &prepared, 0.0, &s0, 1e-3, 10_000, &[])?;
    let e1 = energy(p, &s)?;
    println!("10 s of RK4 at h = 1 ms from q = (1.2, -0.4) at rest:");
    println!(
        "  q = ({:.6}, {:.6}), relative energy drift {:.2e}",
        s[0],
        s[1],
        ((e1 - e0) / e0).abs()
    );
    Ok(())
}
