//! The Whipple bicycle benchmark (Meijaard et al. 2007) in Moore's 2012
//! geometry, derived at compile time. The default action prints the lean and
//! steer eigenvalues against speed and the two critical speeds found by root
//! finding; `-- eigen` prints them as JSON; the model command line
//! (`eval`, `info`, `equations`, `bench`) comes with it.

#[path = "models/whipple_bicycle.rs"]
mod model;

use std::error::Error;
use std::process::ExitCode;
use std::time::Instant;

use appell::Model;
use model::WhippleBicycle;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().collect();
    if args.get(1).map(String::as_str) == Some("eigen") {
        return match eigen_json(&WhippleBicycle::default()) {
            Ok(s) => {
                println!("{s}");
                ExitCode::SUCCESS
            }
            Err(e) => {
                println!("{{\"error\": {:?}}}", e.to_string());
                ExitCode::FAILURE
            }
        };
    }
    appell::cli::run(WhippleBicycle::default(), demonstrate)
}

/// `{"v": [...], "eigenvalues": [[[re, im], ...], ...], "weave_speed": x, "capsize_speed": y}`
/// for v = 0, 0.5, ..., 10 m/s.
fn eigen_json(p: &WhippleBicycle) -> Result<String, Box<dyn Error>> {
    let speeds: Vec<f64> = (0..=20).map(|k| 0.5 * k as f64).collect();
    let mut rows = Vec::new();
    for &v in &speeds {
        let ev = model::eigenvalues(p, v)?;
        let pairs: Vec<String> = ev
            .iter()
            .map(|(re, im)| format!("[{re:?}, {im:?}]"))
            .collect();
        rows.push(format!("[{}]", pairs.join(", ")));
    }
    let (weave, capsize) = model::critical_speeds(p)?;
    let vs: Vec<String> = speeds.iter().map(|v| format!("{v:?}")).collect();
    Ok(format!(
        "{{\"v\": [{}], \"eigenvalues\": [{}], \"weave_speed\": {weave:?}, \"capsize_speed\": {capsize:?}}}",
        vs.join(", "),
        rows.join(", ")
    ))
}

fn demonstrate(p: &WhippleBicycle) -> Result<(), Box<dyn Error>> {
    let info = WhippleBicycle::info();
    println!(
        "Whipple bicycle: reduced state ({}), {} operations per rhs call",
        {
            let mut s: Vec<String> = info.retained.iter().map(|c| c.to_string()).collect();
            s.extend(info.speeds.iter().map(|c| format!("{c}_dot")));
            s.join(", ")
        },
        info.rhs_ops.total
    );
    println!(
        "cyclic: {:?}, ignorable: {:?}\n",
        info.cyclic, info.ignorable
    );
    println!("{:>5}  lean/steer eigenvalues (re ± im)", "v");
    for k in 0..=20 {
        let v = 0.5 * k as f64;
        let ev = model::eigenvalues(p, v)?;
        let text: Vec<String> = ev
            .iter()
            .map(|(re, im)| {
                if im.abs() > 1e-12 {
                    format!("{re:+.4}{im:+.4}i")
                } else {
                    format!("{re:+.4}")
                }
            })
            .collect();
        println!("{v:>5.1}  {}", text.join("  "));
    }
    let t = Instant::now();
    let (weave, capsize) = model::critical_speeds(p)?;
    println!("\nweave speed   {weave:.14} m/s (published 4.29238253634111)");
    println!("capsize speed {capsize:.14} m/s (published 6.02426201538837)");
    println!(
        "self-stable between them; root finding took {:.1} ms",
        t.elapsed().as_secs_f64() * 1e3
    );
    let t = Instant::now();
    let reps = 200;
    for _ in 0..reps {
        std::hint::black_box(model::eigenvalues(p, std::hint::black_box(5.0))?);
    }
    println!(
        "linearization + eigenvalues at one speed: {:.1} µs",
        t.elapsed().as_secs_f64() * 1e6 / reps as f64
    );
    Ok(())
}
