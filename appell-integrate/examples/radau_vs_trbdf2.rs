//! Work–precision of the two implicit integrators, [`Radau5`] (order 5) and
//! [`TrBdf2`] (order 2), on two stiff problems: wall time (median of 5
//! runs) and relative error at the end against a tight Radau5 reference,
//! over a sweep of tolerances (to 1e-11 for Radau5, 1e-14 for TR-BDF2,
//! which needs them), and the time each needs to reach a relative error of
//! 1e-6 and 1e-8 (interpolated log-log between the two runs of the sweep
//! around it).
//!
//! Run with `cargo run --release -p appell-integrate --example radau_vs_trbdf2`.
//!
//! * Van der Pol with μ = 1000 in Hairer & Wanner's scaling (time divided
//!   by μ, ε = 1/μ² = 1e-6): `y1' = y2`, `ε y2' = (1 − y1²) y2 − y1` from
//!   `(2, −0.66)` over `[0, 2]`, i.e. μ = 1000 over `[0, 2000]` of the
//!   unscaled time, with the relaxation jump near `t = 0.8`.
//! * Robertson's chemical kinetics from `(1, 0, 0)` over `[0, 1e5]`,
//!   `atol = 1e-6 rtol` (y2 is of order 1e-5 … 1e-8).

use appell_core::ModelError;
use appell_integrate::{IntegrateError, Radau5, TrBdf2};
use std::time::Instant;

type R = Result<(), ModelError>;

const EPS: f64 = 1e-6;

fn vdp(_t: f64, y: &[f64], dy: &mut [f64]) -> R {
    dy[0] = y[1];
    dy[1] = ((1.0 - y[0] * y[0]) * y[1] - y[0]) / EPS;
    Ok(())
}

fn vdp_jac(_t: f64, y: &[f64], j: &mut [f64]) -> R {
    j.copy_from_slice(&[
        0.0,
        1.0,
        (-2.0 * y[0] * y[1] - 1.0) / EPS,
        (1.0 - y[0] * y[0]) / EPS,
    ]);
    Ok(())
}

fn robertson(_t: f64, y: &[f64], dy: &mut [f64]) -> R {
    let (a, b, c) = (0.04 * y[0], 1e4 * y[1] * y[2], 3e7 * y[1] * y[1]);
    dy[0] = -a + b;
    dy[1] = a - b - c;
    dy[2] = c;
    Ok(())
}

fn robertson_jac(_t: f64, y: &[f64], j: &mut [f64]) -> R {
    j.copy_from_slice(&[
        -0.04,
        1e4 * y[2],
        1e4 * y[1],
        0.04,
        -1e4 * y[2] - 6e7 * y[1],
        -1e4 * y[1],
        0.0,
        6e7 * y[1],
        0.0,
    ]);
    Ok(())
}

/// A stiff test problem.
struct Problem {
    name: &'static str,
    f: fn(f64, &[f64], &mut [f64]) -> R,
    jac: fn(f64, &[f64], &mut [f64]) -> R,
    x0: &'static [f64],
    t_end: f64,
    /// `atol = atol_ratio · rtol`.
    atol_ratio: f64,
}

#[derive(Clone, Copy)]
enum Method {
    Radau5,
    TrBdf2,
}

impl Method {
    fn name(self) -> &'static str {
        match self {
            Method::Radau5 => "Radau5",
            Method::TrBdf2 => "TrBdf2",
        }
    }
}

/// One integration: the end state and the number of steps.
fn run(p: &Problem, m: Method, tol: f64) -> Result<(Vec<f64>, usize), IntegrateError> {
    let atol = tol * p.atol_ratio;
    Ok(match m {
        Method::Radau5 => {
            let s = Radau5::new()
                .rtol(tol)
                .atol(atol)
                .max_steps(10_000_000)
                .solve(p.f, p.jac, 0.0, p.x0, p.t_end)?;
            (s.x, s.stats.accepted + s.stats.rejected)
        }
        Method::TrBdf2 => {
            let s = TrBdf2::new()
                .rtol(tol)
                .atol(atol)
                .max_steps(10_000_000)
                .solve(p.f, p.jac, 0.0, p.x0, p.t_end)?;
            (s.x, s.stats.accepted + s.stats.rejected)
        }
    })
}

/// Median wall time (s) of 5 runs, the relative error against `reference`
/// (largest over the components) and the steps.
fn measure(p: &Problem, m: Method, tol: f64, reference: &[f64]) -> Option<(f64, f64, usize)> {
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..5 {
        let start = Instant::now();
        let r = run(p, m, tol);
        times.push(start.elapsed().as_secs_f64());
        match r {
            Ok(v) => last = Some(v),
            Err(e) => {
                println!("  {} rtol {tol:.0e}: {e}", m.name());
                return None;
            }
        }
        // Runs of over 2 s are measured once.
        if times[0] > 2.0 {
            break;
        }
    }
    times.sort_by(f64::total_cmp);
    let (x, steps) = last?;
    let err = x
        .iter()
        .zip(reference)
        .map(|(a, b)| ((a - b) / b).abs())
        .fold(0.0, f64::max);
    Some((times[times.len() / 2], err, steps))
}

/// The time to reach the relative error `target` from the runs `(time,
/// error)` of a sweep of tightening tolerances: interpolated log-log
/// between the first run at or below it and the one before.
fn time_to_reach(runs: &[(f64, f64)], target: f64) -> f64 {
    let Some(i) = runs.iter().position(|r| r.1 <= target) else {
        return f64::INFINITY;
    };
    if i == 0 || runs[i - 1].1 <= runs[i].1 {
        return runs[i].0;
    }
    let ((t0, e0), (t1, e1)) = (runs[i - 1], runs[i]);
    let s = (target.ln() - e0.ln()) / (e1.ln() - e0.ln());
    (t0.ln() + s * (t1.ln() - t0.ln())).exp()
}

fn main() {
    let problems = [
        Problem {
            name: "Van der Pol, mu = 1000 (eps = 1e-6), t in [0, 2]",
            f: vdp,
            jac: vdp_jac,
            x0: &[2.0, -0.66],
            t_end: 2.0,
            atol_ratio: 1.0,
        },
        Problem {
            name: "Robertson, t in [0, 1e5]",
            f: robertson,
            jac: robertson_jac,
            x0: &[1.0, 0.0, 0.0],
            t_end: 1e5,
            atol_ratio: 1e-6,
        },
    ];
    let sweep =
        |last: i32| -> Vec<f64> { (6..=last).map(|k| 10f64.powf(-k as f64 / 2.0)).collect() };
    for p in &problems {
        let reference = run(p, Method::Radau5, 1e-13).expect("reference").0;
        let check = run(p, Method::Radau5, 1e-12).expect("check").0;
        let spread = check
            .iter()
            .zip(&reference)
            .map(|(a, b)| ((a - b) / b).abs())
            .fold(0.0, f64::max);
        println!(
            "\n{}: reference {reference:?} (rtol 1e-13; vs rtol 1e-12: {spread:.1e})",
            p.name
        );
        println!("  method  rtol     time [ms]   rel. error   steps");
        let mut best = [[f64::INFINITY; 2]; 2];
        for (mi, m) in [Method::Radau5, Method::TrBdf2].into_iter().enumerate() {
            let mut runs: Vec<(f64, f64)> = Vec::new();
            for tol in sweep(if mi == 0 { 22 } else { 28 }) {
                let Some((time, err, steps)) = measure(p, m, tol, &reference) else {
                    continue;
                };
                println!(
                    "  {:6}  {tol:.0e}  {:10.3}  {err:10.2e}  {steps:7}",
                    m.name(),
                    time * 1e3
                );
                runs.push((time, err));
            }
            for (k, target) in [1e-6, 1e-8].into_iter().enumerate() {
                best[mi][k] = time_to_reach(&runs, target);
            }
        }
        for (k, target) in [1e-6, 1e-8].into_iter().enumerate() {
            let (r, t) = (best[0][k], best[1][k]);
            println!(
                "  time to relative error {target:.0e}: Radau5 {:.3} ms, TrBdf2 {:.3} ms, ratio {:.1}",
                r * 1e3,
                t * 1e3,
                t / r
            );
        }
    }
}
