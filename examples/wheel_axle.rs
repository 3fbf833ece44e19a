//! The paper's wheel-axle assemblage (Wang & Pao 2003, Sec. IV C), derived at
//! compile time by `#[derive(Appell)]`.
//!
//! Run `cargo run --release --example wheel_axle` for the derived equations
//! beside the paper's eq. 64 and a short simulation; `-- eval`, `-- info`,
//! `-- equations` and `-- bench` give the model command line.

#[path = "models/wheel_axle.rs"]
mod model;

use std::error::Error;
use std::process::ExitCode;
use std::time::Instant;

use appell::integrate::rk4;
use appell::Model;
use model::WheelAxle;

fn main() -> ExitCode {
    appell::cli::run(WheelAxle::default(), demonstrate)
}

fn demonstrate(p: &WheelAxle) -> Result<(), Box<dyn Error>> {
    let info = WheelAxle::info();
    println!("{}", info.equations);
    println!("The paper's eq. (64), with the drive torque tau added to (64a):");
    println!(
        "  2a(M+m') psi1_ddot - l(M+m') phi_ddot              = 2 M g sin(alpha) cos(phi) + tau/a"
    );
    println!(
        "  a l (M+m') psi1_ddot - (M l^2 + m' l^2 + m' a^2) phi_ddot = M g l sin(alpha) cos(phi)"
    );
    println!("(M = mass, m' = rim). Multiply the first by a and negate the second to get the");
    println!("derived rows above: the mass matrices and forcing terms agree term by term.\n");

    // Start heading across the slope and let gravity turn... nothing: with
    // gravity alone phi_ddot = 0, so the axle keeps its heading while the
    // wheels accelerate down the slope; then a drive torque turns it.
    let prepared = p.prepare::<f64>();
    let mut state = [0.3, 0.0, 0.0];
    let h = 1e-3;
    let start = Instant::now();
    state = rk4(p, &prepared, 0.0, &state, h, 2000, &[0.0])?;
    println!(
        "after 2 s of gravity alone: phi = {:.6} rad (unchanged), psi1_dot = {:.6} rad/s",
        state[0], state[2]
    );
    let expected = p.mass * p.g * p.alpha.sin() * 0.3f64.cos() / (p.a * (p.mass + p.rim)) * 2.0;
    println!("  closed form psi1_dot = {expected:.6} rad/s (constant acceleration, eq. 64)");
    state = rk4(p, &prepared, 2.0, &state, h, 2000, &[0.5])?;
    let elapsed = start.elapsed();
    println!(
        "after 2 s more with tau = 0.5 N m on wheel 1: phi = {:.6} rad, phi_dot = {:.6} rad/s",
        state[0], state[1]
    );
    println!(
        "4000 RK4 steps (16000 rhs calls) in {:.3} ms; the rhs costs {} operations",
        elapsed.as_secs_f64() * 1e3,
        info.rhs_ops.total
    );
    Ok(())
}
