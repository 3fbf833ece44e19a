//! The Chaplygin sleigh, derived at compile time: its turning decays and it
//! settles into straight-line motion. The model command line (`eval`,
//! `info`, `equations`, `bench`) comes with it.

#[path = "models/chaplygin_sleigh.rs"]
mod model;

use std::error::Error;
use std::process::ExitCode;

use appell::Model;
use model::ChaplyginSleigh;

fn main() -> ExitCode {
    appell::cli::run(ChaplyginSleigh::default(), demonstrate)
}

fn demonstrate(p: &ChaplyginSleigh) -> Result<(), Box<dyn Error>> {
    println!("{}", ChaplyginSleigh::info().equations);
    let prepared = p.prepare::<f64>();
    // State (theta, x_dot, theta_dot): heading 0, moving forward, turning.
    let mut s = [0.0f64, 1.0, 1.0];
    println!("{:>6} {:>10} {:>10} {:>10}", "t", "theta", "v", "omega");
    for k in 0..=10 {
        let v = s[1] / s[0].cos();
        println!(
            "{:>6.1} {:>10.6} {:>10.6} {:>10.6}",
            k as f64 * 2.0,
            s[0],
            v,
            s[2]
        );
        s = appell::integrate::rk4(p, &prepared, k as f64 * 2.0, &s, 1e-3, 2000, &[])?;
    }
    Ok(())
}
