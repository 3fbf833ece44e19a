//! What accuracy costs: every integrator over a sweep of step sizes or
//! tolerances on the wheel-axle (10 s, drive torque on), the rolling disc
//! (5 s) and the Whipple bicycle (5 s), error against a reference at much
//! higher accuracy, wall time as the median of repeated runs. Writes, under
//! `docs/work_precision/`, an SVG chart and a CSV per model, the f32-vs-f64
//! RK4 comparison, the cost of the multiplier oracle at equal accuracy, and
//! a markdown summary.
//!
//! `cargo run --release --example work_precision` (a few seconds);
//! `-- --quick` for a reduced sweep.

#[path = "models/rolling_disc.rs"]
mod rolling_disc;
#[path = "models/wheel_axle.rs"]
mod wheel_axle;
#[allow(dead_code)] // the model file's helpers serve other programs
#[path = "models/whipple_bicycle.rs"]
mod whipple_bicycle;

use std::error::Error;
use std::fmt::Write as _;
use std::time::Instant;

use appell::accuracy::{self, Method, Point, Problem};
use appell::Model;
use indicatif::{ProgressBar, ProgressStyle};

fn main() -> Result<(), Box<dyn Error>> {
    let quick = std::env::args().any(|a| a == "--quick");
    let dir = std::path::Path::new("docs/work_precision");
    std::fs::create_dir_all(dir)?;
    let (levels, repeats) = if quick { (4, 3) } else { (8, 7) };
    let mut summary =
        String::from("# What accuracy costs (measured by `examples/work_precision.rs`)\n\n");

    let axle = wheel_axle::WheelAxle::default();
    let axle_pb = Problem {
        model: &axle,
        x0: [0.3, 0.2, 1.0],
        t_end: 10.0,
        inputs: &[0.4],
        checkpoints: 10,
    };
    let axle_points = run(
        "wheel-axle, 10 s, τ = 0.4 N m",
        "wheel_axle",
        &axle_pb,
        levels,
        repeats,
        dir,
        &mut summary,
    )?;

    // Throughput: steps and rhs calls per second of wall time, per method,
    // at its most expensive setting on the wheel-axle (the benchmark the
    // issue asks for; compare ratios in one run only).
    writeln!(summary, "## Throughput on the wheel-axle (most expensive setting of each method)\n\n| method | setting | steps | rhs calls | time | steps/s | rhs calls/s |\n| --- | ---: | ---: | ---: | ---: | ---: | ---: |")?;
    for name in accuracy::method_names(&axle_points) {
        if let Some(p) = axle_points
            .iter()
            .filter(|p| p.method.name() == name)
            .max_by(|a, b| a.seconds.total_cmp(&b.seconds))
        {
            writeln!(
                summary,
                "| {name} | {:e} | {} | {} | {:.1} µs | {:.2e} | {:.2e} |",
                p.method.setting(),
                p.steps,
                p.rhs_calls,
                p.seconds * 1e6,
                p.steps as f64 / p.seconds,
                p.rhs_calls as f64 / p.seconds
            )?;
        }
    }
    writeln!(summary)?;

    let disc = rolling_disc::RollingDisc::default();
    let disc_pb = Problem {
        model: &disc,
        x0: [0.3, 1.5, 0.2, 12.0],
        t_end: 5.0,
        inputs: &[],
        checkpoints: 10,
    };
    run(
        "rolling disc, 5 s",
        "rolling_disc",
        &disc_pb,
        levels,
        repeats,
        dir,
        &mut summary,
    )?;

    // The benchmark bicycle at 4.6 m/s (self-stable), leaning 0.1 rad and
    // steering 0.05 rad, its pitch made consistent first.
    let bike = whipple_bicycle::WhippleBicycle::default();
    let mut bike_x0 = [
        0.1,
        std::f64::consts::PI / 10.0,
        0.05,
        0.3,
        -4.6 / bike.rr,
        0.0,
    ];
    appell::linearize::project_holonomic(&bike, 0.0, &mut bike_x0, 1e-14, 30)?;
    let bike_pb = Problem {
        model: &bike,
        x0: bike_x0,
        t_end: 5.0,
        inputs: &[0.0],
        checkpoints: 10,
    };
    run(
        "Whipple bicycle, 5 s at 4.6 m/s",
        "whipple_bicycle",
        &bike_pb,
        levels,
        repeats,
        dir,
        &mut summary,
    )?;

    // f32 against f64 with RK4 on the wheel-axle (the controller's choice).
    let (reference, _) = axle_pb.reference()?;
    let end = reference.last().copied().unwrap_or_default();
    let mut f32_rows = Vec::new();
    writeln!(summary, "\n## RK4 in f32 and f64 (wheel-axle)\n\n![RK4 in f32 and f64](rk4_f32_f64.svg)\n\n| steps | error f64 | error f32 |\n| ---: | ---: | ---: |")?;
    for k in 0..levels.min(8) {
        let n = 100usize << k;
        let h = 10.0 / n as f64;
        let x64 = appell::integrate::rk4(
            &axle,
            &axle.prepare::<f64>(),
            0.0,
            &axle_pb.x0,
            h,
            n,
            &[0.4],
        )?;
        let x32 = appell::integrate::rk4(
            &axle,
            &axle.prepare::<f32>(),
            0.0,
            &axle_pb.x0.map(|v| v as f32),
            h as f32,
            n,
            &[0.4f32],
        )?;
        let err = |x: [f64; 3]| {
            x.iter()
                .zip(&end)
                .map(|(a, b)| (a - b).abs() / (1.0 + b.abs()))
                .fold(0.0, f64::max)
        };
        let (e64, e32) = (err(x64), err(x32.map(|v| v as f64)));
        writeln!(summary, "| {n} | {e64:.2e} | {e32:.2e} |")?;
        f32_rows.push((n, e64, e32));
    }
    let mut csv32 = String::from("steps,error_f64,error_f32\n");
    for (n, a, b) in &f32_rows {
        writeln!(csv32, "{n},{a:e},{b:e}")?;
    }
    std::fs::write(dir.join("rk4_f32_f64.csv"), csv32)?;
    let line = |pick: fn(&(usize, f64, f64)) -> f64| -> Vec<(f64, f64)> {
        f32_rows.iter().map(|r| (r.0 as f64, pick(r))).collect()
    };
    std::fs::write(
        dir.join("rk4_f32_f64.svg"),
        accuracy::svg_loglog(
            "RK4 on the wheel-axle, 10 s: f64 and f32",
            "steps",
            "relative error at the final time",
            &[("f64", line(|r| r.1)), ("f32", line(|r| r.2))],
        ),
    )?;

    // The oracle (multiplier route) as the rhs of the same RK4, at equal steps.
    writeln!(summary, "\n## Generated code against the multiplier oracle (RK4, wheel-axle)\n\n| steps | error | generated | oracle | ratio |\n| ---: | ---: | ---: | ---: | ---: |")?;
    let oracle_steps: &[usize] = if quick { &[400, 800] } else { &[800, 3200] };
    for &n in oracle_steps {
        let gen = axle_points.iter().find(|p| p.method == Method::Rk4(n));
        let h = 10.0 / n as f64;
        let start = Instant::now();
        let mut x = axle_pb.x0;
        for k in 0..n {
            let t = k as f64 * h;
            let f = |x: &[f64; 3]| -> Result<[f64; 3], Box<dyn Error>> {
                let mut q = [0.0; 7];
                q[6] = x[0];
                let d = appell::oracle::reduced_rhs(&axle, t, &q, &x[1..], &[0.4])?;
                Ok([d[0], d[1], d[2]])
            };
            let add = |a: &[f64; 3], b: &[f64; 3], c: f64| -> [f64; 3] {
                std::array::from_fn(|i| a[i] + c * b[i])
            };
            let k1 = f(&x)?;
            let k2 = f(&add(&x, &k1, h / 2.0))?;
            let k3 = f(&add(&x, &k2, h / 2.0))?;
            let k4 = f(&add(&x, &k3, h))?;
            x = std::array::from_fn(|i| {
                x[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            });
        }
        let oracle_s = start.elapsed().as_secs_f64();
        let err = x
            .iter()
            .zip(&end)
            .map(|(a, b)| (a - b).abs() / (1.0 + b.abs()))
            .fold(0.0, f64::max);
        if let Some(g) = gen {
            writeln!(
                summary,
                "| {n} | {err:.2e} | {:.1} µs | {:.1} µs | {:.0}x |",
                g.seconds * 1e6,
                oracle_s * 1e6,
                oracle_s / g.seconds
            )?;
        }
    }
    std::fs::write(dir.join("README.md"), &summary)?;
    println!("{summary}");
    Ok(())
}

#[allow(clippy::too_many_arguments)] // a sweep's description, spelled out
fn run<M: Model, const S: usize>(
    title: &str,
    file: &str,
    pb: &Problem<'_, M, S>,
    levels: usize,
    repeats: usize,
    dir: &std::path::Path,
    summary: &mut String,
) -> Result<Vec<Point>, Box<dyn Error>> {
    let (reference, estimate) = pb.reference()?;
    let methods = accuracy::standard_methods(100, levels);
    let bar = ProgressBar::new(methods.len() as u64);
    bar.set_style(ProgressStyle::with_template(
        "{msg} [{bar:30}] {pos}/{len}",
    )?);
    bar.set_message(file.to_string());
    let start = Instant::now();
    let points = pb.sweep(&reference, &methods, repeats, |done, _| {
        // Only draw when the sweep is long enough to need it.
        if start.elapsed().as_secs_f64() > 1.0 {
            bar.set_position(done as u64);
        }
    });
    bar.finish_and_clear();
    std::fs::write(dir.join(format!("{file}.csv")), accuracy::csv(&points))?;
    std::fs::write(
        dir.join(format!("{file}.svg")),
        accuracy::svg_chart(title, &points),
    )?;
    writeln!(summary, "## {title}\n\nReference by DOP853 at rtol 1e-15 (estimated error {estimate:.1e}). Time to reach a relative error (largest over 10 checkpoints):\n")?;
    writeln!(
        summary,
        "| method | 1e-6 | 1e-9 | 1e-12 |\n| --- | ---: | ---: | ---: |"
    )?;
    for (name, times) in accuracy::time_to_reach(&points, &[1e-6, 1e-9, 1e-12]) {
        let cell =
            |t: &Option<f64>| t.map_or("not reached".to_string(), |s| format!("{:.1} µs", s * 1e6));
        writeln!(
            summary,
            "| {name} | {} | {} | {} |",
            cell(&times[0]),
            cell(&times[1]),
            cell(&times[2])
        )?;
    }
    writeln!(summary, "\n![{title}]({file}.svg)\n")?;
    Ok(points)
}
