//! Our integrators against the `differential-equations` crate (0.7.0) on the
//! same generated right-hand side: the wheel-axle (10 s, drive torque on)
//! and the rolling disc (5 s). For each tolerance (rtol = tol, atol =
//! tol · 1e-2), the relative error at the final time against a tight
//! reference, the rhs calls and the median wall time of repeated runs.
//! Prints a markdown table and writes it to
//! `docs/work_precision/crate_comparison.md` when run from the repository
//! root.

#[path = "../../../examples/models/rolling_disc.rs"]
mod rolling_disc;
#[path = "../../../examples/models/wheel_axle.rs"]
mod wheel_axle;

use std::cell::Cell;
use std::fmt::Write as _;
use std::time::Instant;

use appell::integrate::{Dop853, Dopri5, TrBdf2};
use appell::Model;
use differential_equations::prelude::*;

/// The generated rhs as the crate's ODE; a model error turns the rates into
/// NaN (the crate then reports the failure) and is remembered.
struct Generated<'a, M: Model> {
    model: &'a M,
    prepared: M::Prepared<f64>,
    inputs: &'a [f64],
    failed: Cell<bool>,
}

impl<M: Model, const S: usize> ODE<f64, [f64; S]> for Generated<'_, M> {
    fn diff(&self, t: f64, y: &[f64; S], dydt: &mut [f64; S]) {
        if self
            .model
            .rhs(&self.prepared, t, y, self.inputs, dydt)
            .is_err()
        {
            self.failed.set(true);
            dydt.fill(f64::NAN);
        }
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn timed<R>(repeats: usize, mut f: impl FnMut() -> R) -> (R, f64) {
    let r = f();
    let times = (0..repeats)
        .map(|_| {
            let start = Instant::now();
            std::hint::black_box(f());
            start.elapsed().as_secs_f64()
        })
        .collect();
    (r, median(times))
}

fn relative_error<const S: usize>(x: &[f64; S], r: &[f64; S]) -> f64 {
    x.iter()
        .zip(r)
        .map(|(a, b)| (a - b).abs() / (1.0 + b.abs()))
        .fold(0.0, f64::max)
}

fn compare<M: Model, const S: usize>(
    title: &str,
    model: &M,
    x0: [f64; S],
    t_end: f64,
    inputs: &[f64],
    out: &mut String,
) -> Result<(), Box<dyn std::error::Error>> {
    let reference = Dop853::new()
        .rtol(1e-15)
        .atol(1e-17)
        .max_steps(10_000_000)
        .solve_model(model, inputs, 0.0, &x0, t_end)?
        .x;
    let ode = Generated {
        model,
        prepared: model.prepare::<f64>(),
        inputs,
        failed: Cell::new(false),
    };
    writeln!(out, "\n## {title}\n\n| tolerance | integrator | error | rhs calls | time |\n| ---: | --- | ---: | ---: | ---: |")?;
    let repeats = 15;
    for tol in [1e-6, 1e-9, 1e-12] {
        let mut row = |name: &str, x: Option<[f64; S]>, calls: usize, secs: f64| {
            let err = x.map_or(f64::NAN, |x| relative_error(&x, &reference));
            let _ = writeln!(
                out,
                "| {tol:.0e} | {name} | {err:.1e} | {calls} | {:.1} µs |",
                secs * 1e6
            );
        };
        // The integrators alone, as differential-equations' are: without
        // the contact watch a model with contacts gets (one contact-force
        // evaluation per step).
        let ours = Dopri5::new()
            .rtol(tol)
            .atol(tol * 1e-2)
            .max_steps(10_000_000)
            .contact_watch(false);
        let (r, s) = timed(repeats, || ours.solve_model(model, inputs, 0.0, &x0, t_end));
        let r = r?;
        row("appell Dopri5", Some(r.x), r.stats.rhs_calls, s);

        let ours = Dop853::new()
            .rtol(tol)
            .atol(tol * 1e-2)
            .max_steps(10_000_000)
            .contact_watch(false);
        let (r, s) = timed(repeats, || ours.solve_model(model, inputs, 0.0, &x0, t_end));
        let r = r?;
        row("appell DOP853", Some(r.x), r.stats.rhs_calls, s);

        let trbdf2 = TrBdf2::new()
            .rtol(tol)
            .atol(tol * 1e-2)
            .max_steps(10_000_000)
            .contact_watch(false);
        if tol >= 1e-9 {
            let (r, s) = timed(repeats.min(5), || {
                trbdf2.solve_model(model, inputs, 0.0, &x0, t_end)
            });
            let r = r?;
            let mut x = [0.0; S];
            x.copy_from_slice(&r.x);
            row(
                "appell TR-BDF2",
                Some(x),
                r.stats.rhs_calls + r.stats.jacobian_rhs_calls,
                s,
            );
        }

        // The crate's methods are built afresh for every run (Radau5 is not
        // Clone); building them costs nothing next to an integration.
        macro_rules! crate_run {
            ($name:expr, $reps:expr, $make:expr) => {{
                let (r, s) = timed($reps, || {
                    IVP::ode(&ode, 0.0, t_end, x0)
                        .method($make.rtol(tol).atol(tol * 1e-2))
                        .solve()
                });
                match r {
                    Ok(sol) => row($name, sol.y.last().copied(), sol.evals.function, s),
                    Err(e) => {
                        let msg = format!("failed: {e:?}").replace('|', "/");
                        row($name, None, 0, 0.0);
                        eprintln!("{} at {tol:e}: {msg}", $name);
                    }
                }
            }};
        }
        crate_run!("crate DOPRI5", repeats, ExplicitRungeKutta::dopri5());
        crate_run!("crate DOP853", repeats, ExplicitRungeKutta::dop853());
        if tol >= 1e-9 {
            crate_run!("crate Radau5", repeats.min(5), ImplicitRungeKutta::radau5());
        }
    }
    if ode.failed.get() {
        writeln!(out, "\n(the model reported an error during a crate run)")?;
    }
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut out = String::from(
        "# Our integrators against the differential-equations crate (0.7.0)\n\n\
         Same generated rhs, rtol = tol, atol = tol · 1e-2, relative error at the \
         final time against DOP853 at rtol 1e-15, median wall time of \
         repeated runs in one process (`comparisons/differential-equations`).\n",
    );
    let axle = wheel_axle::WheelAxle::default();
    compare(
        "wheel-axle, 10 s, τ = 0.4 N m",
        &axle,
        [0.3, 0.2, 1.0],
        10.0,
        &[0.4],
        &mut out,
    )?;
    let disc = rolling_disc::RollingDisc::default();
    compare(
        "rolling disc, 5 s",
        &disc,
        [0.3, 1.5, 0.2, 12.0],
        5.0,
        &[],
        &mut out,
    )?;
    println!("{out}");
    let docs = std::path::Path::new("docs/work_precision");
    if docs.is_dir() {
        std::fs::write(docs.join("crate_comparison.md"), &out)?;
    }
    Ok(())
}
