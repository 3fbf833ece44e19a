//! The n-link planar pendulum, n = 2, 4, 8 or 16 (`--n N`, default 4), with the
//! model command line: `cargo run --release --example n_link_pendulum --
//! --n 8 bench`. The default action integrates 10 s with RK4 and reports the
//! time it took.

#[path = "models/n_link_pendulum.rs"]
mod model;

use std::error::Error;
use std::process::ExitCode;

use appell::Model;
use model::{Pendulum16, Pendulum2, Pendulum4, Pendulum8};

fn main() -> ExitCode {
    let mut args: Vec<String> = std::env::args().collect();
    let mut n = 4;
    if let Some(i) = args.iter().position(|a| a == "--n") {
        match args.get(i + 1).and_then(|s| s.parse().ok()) {
            Some(v @ (2 | 4 | 8 | 16)) => n = v,
            _ => {
                eprintln!("--n takes 2, 4, 8 or 16");
                return ExitCode::from(2);
            }
        }
        args.drain(i..i + 2);
    }
    match n {
        2 => run(Pendulum2::default(), &args),
        8 => run(Pendulum8::default(), &args),
        16 => run(Pendulum16::default(), &args),
        _ => run(Pendulum4::default(), &args),
    }
}

fn run<M: Model>(model: M, args: &[String]) -> ExitCode {
    let stdin = std::io::stdin();
    let mut input = stdin.lock();
    let mut output = std::io::stdout().lock();
    match appell::cli::run_with(model, args, &mut input, &mut output, demonstrate) {
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

/// 10 s of RK4 at h = 1 ms from all links at 0.5 rad, at rest.
fn demonstrate<M: Model>(model: &M) -> Result<(), Box<dyn Error>> {
    let info = M::info();
    let n = info.coordinates.len();
    let prepared = model.prepare::<f64>();
    let mut state = vec![0.0; 2 * n];
    for x in state.iter_mut().take(n) {
        *x = 0.5;
    }
    let mut k = [
        vec![0.0; 2 * n],
        vec![0.0; 2 * n],
        vec![0.0; 2 * n],
        vec![0.0; 2 * n],
    ];
    let h = 1e-3;
    let start = std::time::Instant::now();
    for step in 0..10_000 {
        let t = step as f64 * h;
        model.rhs(&prepared, t, &state, &[], &mut k[0])?;
        let s1: Vec<f64> = state
            .iter()
            .zip(&k[0])
            .map(|(x, d)| x + 0.5 * h * d)
            .collect();
        model.rhs(&prepared, t + 0.5 * h, &s1, &[], &mut k[1])?;
        let s2: Vec<f64> = state
            .iter()
            .zip(&k[1])
            .map(|(x, d)| x + 0.5 * h * d)
            .collect();
        model.rhs(&prepared, t + 0.5 * h, &s2, &[], &mut k[2])?;
        let s3: Vec<f64> = state.iter().zip(&k[2]).map(|(x, d)| x + h * d).collect();
        model.rhs(&prepared, t + h, &s3, &[], &mut k[3])?;
        for i in 0..2 * n {
            state[i] += h / 6.0 * (k[0][i] + 2.0 * k[1][i] + 2.0 * k[2][i] + k[3][i]);
        }
    }
    println!(
        "{}: {} links, {} operations per rhs call; 10 s of RK4 (h = 1 ms) in {:.1} ms",
        info.name,
        n,
        info.rhs_ops.total,
        start.elapsed().as_secs_f64() * 1e3
    );
    println!(
        "final angles: {:?}",
        &state[..n]
            .iter()
            .map(|x| (x * 1e6).round() / 1e6)
            .collect::<Vec<_>>()
    );
    Ok(())
}
