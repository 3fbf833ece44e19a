//! The n-link spatial chain, n = 2, 4, 8, 16 or 32 (64 with the cargo
//! feature `large-models`), chosen with `--n N` (default 4), with the model command
//! line: `cargo run --release --example spatial_chain -- --n 8 info`,
//! `eval`, `bench`. The mechanism is the one of
//! `examples/robots/spatial_chain/spatial_chain_N.urdf`, written here with
//! `joint(...)` and `repeat(...)` (see `models/spatial_chain.rs`). The
//! default action lets the chain fall for 2 s.

#[path = "common/robot_demo.rs"]
mod demo;
#[path = "models/spatial_chain.rs"]
mod model;

use std::process::ExitCode;

use appell::Model;
#[cfg(feature = "large-models")]
use model::SpatialChain64;
use model::{SpatialChain16, SpatialChain2, SpatialChain32, SpatialChain4, SpatialChain8};

/// The sizes this build has.
const SIZES: &[usize] = if cfg!(feature = "large-models") {
    &[2, 4, 8, 16, 32, 64]
} else {
    &[2, 4, 8, 16, 32]
};

fn main() -> ExitCode {
    let mut args: Vec<String> = std::env::args().collect();
    let mut n = 4;
    if let Some(i) = args.iter().position(|a| a == "--n") {
        match args.get(i + 1).and_then(|s| s.parse().ok()) {
            Some(v) if SIZES.contains(&v) => n = v,
            _ => {
                eprintln!("--n takes one of {SIZES:?} (64 needs `--features large-models`)");
                return ExitCode::from(2);
            }
        }
        args.drain(i..i + 2);
    }
    match n {
        2 => run(SpatialChain2, &args),
        8 => run(SpatialChain8, &args),
        16 => run(SpatialChain16, &args),
        32 => run(SpatialChain32, &args),
        #[cfg(feature = "large-models")]
        64 => run(SpatialChain64, &args),
        _ => run(SpatialChain4, &args),
    }
}

fn run<M: Model>(model: M, args: &[String]) -> ExitCode {
    let stdin = std::io::stdin();
    let mut input = stdin.lock();
    let mut output = std::io::stdout().lock();
    match appell::cli::run_with(model, args, &mut input, &mut output, demo::demonstrate) {
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
