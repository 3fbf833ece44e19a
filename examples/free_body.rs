//! A free rigid body oriented by a unit quaternion, with the model command
//! line: `cargo run --release --example free_body -- info`. The default
//! action spins a T-handle about its intermediate axis for 40 s (DOP853,
//! projected onto the unit quaternion after every step) and reports its
//! flips and how well energy and angular momentum are kept.

#[allow(dead_code)] // the Chaplygin ball beside it serves tests/quaternions.rs
#[path = "models/free_body.rs"]
mod model;

use std::error::Error;
use std::process::ExitCode;

use appell::integrate::Dop853;
use appell::linearize::project_holonomic;
use model::FreeBody;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().collect();
    let stdin = std::io::stdin();
    let mut input = stdin.lock();
    let mut output = std::io::stdout().lock();
    match appell::cli::run_with(
        FreeBody::default(),
        &args,
        &mut input,
        &mut output,
        demonstrate,
    ) {
        Ok(()) => ExitCode::SUCCESS,
        Err(appell::cli::CliError::Usage(text)) => {
            eprint!("{text}");
            ExitCode::from(2)
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// The body axes' ω components and the quaternion's rotation of I ω.
fn momentum(p: &FreeBody, x: &[f64; 10]) -> [f64; 3] {
    let (w, a, b, c) = (x[0], x[1], x[2], x[3]);
    let r = [
        [
            w * w + a * a - b * b - c * c,
            2.0 * (a * b - w * c),
            2.0 * (a * c + w * b),
        ],
        [
            2.0 * (a * b + w * c),
            w * w - a * a + b * b - c * c,
            2.0 * (b * c - w * a),
        ],
        [
            2.0 * (a * c - w * b),
            2.0 * (b * c + w * a),
            w * w - a * a - b * b + c * c,
        ],
    ];
    let h = [p.i1 * x[4], p.i2 * x[5], p.i3 * x[6]];
    core::array::from_fn(|i| (0..3).map(|k| r[i][k] * h[k]).sum())
}

fn demonstrate(p: &FreeBody) -> Result<(), Box<dyn Error>> {
    // Identity orientation, spin 4 rad/s about B.y with a small wobble.
    let mut x = [1.0, 0.0, 0.0, 0.0, 0.01, 4.0, 0.01, 0.0, 0.0, 0.0];
    let energy =
        |x: &[f64; 10]| 0.5 * (p.i1 * x[4] * x[4] + p.i2 * x[5] * x[5] + p.i3 * x[6] * x[6]);
    let (e0, h0) = (energy(&x), momentum(p, &x));
    let mut onto = |t: f64, x: &mut [f64; 10]| {
        project_holonomic(p, t, x, 1e-15, 20)
            .map(|_| ())
            .map_err(Into::into)
    };
    let solver = Dop853::new().rtol(1e-13).atol(1e-13);
    let (mut flips, mut sign, mut worst_e, mut worst_h) = (0, 1.0, 0.0f64, 0.0f64);
    let start = std::time::Instant::now();
    for k in 0..400 {
        let t = k as f64 * 0.1;
        x = solver
            .solve_model_projected(p, &[], &mut onto, t, &x, t + 0.1)?
            .x;
        if x[5].signum() != sign {
            flips += 1;
            sign = x[5].signum();
            println!("t = {:5.1} s: flipped (ω_y = {:+.3} rad/s)", t + 0.1, x[5]);
        }
        worst_e = worst_e.max(((energy(&x) - e0) / e0).abs());
        let h = momentum(p, &x);
        worst_h = worst_h.max(
            (0..3).map(|i| (h[i] - h0[i]).abs()).fold(0.0, f64::max)
                / (h0.iter().map(|v| v * v).sum::<f64>().sqrt()),
        );
    }
    println!(
        "40 s in {:.1} ms: {flips} flips; relative energy error {worst_e:.1e}, angular momentum {worst_h:.1e}",
        start.elapsed().as_secs_f64() * 1e3
    );
    Ok(())
}
