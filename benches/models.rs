//! Generated reduced rhs against the multiplier oracle, and the expansion
//! time of `#[derive(Appell)]`, for each example model.
//!
//! Run: `cargo bench --bench models`.

// The shared model files carry items (other sizes, root finding) this
// benchmark does not use.
#![allow(dead_code)]

#[path = "../examples/models/chaplygin_sleigh.rs"]
mod chaplygin_sleigh;
#[path = "../examples/models/double_pendulum.rs"]
mod double_pendulum;
#[path = "../examples/models/free_body.rs"]
mod free_body;
#[path = "../examples/models/mobile_manipulator.rs"]
mod mobile_manipulator;
#[path = "../examples/models/n_link_pendulum.rs"]
mod n_link_pendulum;
#[path = "../examples/models/panda.rs"]
mod panda;
#[path = "../examples/models/rolling_disc.rs"]
mod rolling_disc;
#[path = "../examples/models/spatial_chain.rs"]
mod spatial_chain;
#[path = "../examples/models/ur5.rs"]
mod ur5;
#[path = "../examples/models/wheel_axle.rs"]
mod wheel_axle;
#[path = "../examples/models/whipple_bicycle.rs"]
mod whipple_bicycle;

use std::hint::black_box;
use std::time::Instant;

use appell::oracle::reduced_rhs;
use appell::Model;
use criterion::{criterion_group, criterion_main, Criterion};

/// The `#[derive(Appell)]` struct `name` of a model file, as a derive input.
fn derive_input(source: &str, name: &str) -> syn::DeriveInput {
    let unit = format!("pub struct {name};");
    let (at, end) = match source.find(&format!("pub struct {name} {{")) {
        Some(at) => (
            at,
            at + source[at..].find("\n}").expect("end of struct") + 2,
        ),
        None => {
            let at = source.find(&unit).expect("struct");
            (at, at + unit.len())
        }
    };
    let start = source[..at].rfind("#[derive(Appell").expect("derive");
    syn::parse_str(&source[start..end]).expect("struct")
}

/// Fixed states in [-1, 1] (deterministic) for the retained coordinates and
/// speeds, with full coordinates for the oracle; projected onto the
/// holonomic constraints (a quaternion's unit norm) where the model has
/// them.
fn states<M: Model>(model: &M, count: usize) -> Vec<(Vec<f64>, Vec<f64>, Vec<f64>)> {
    let info = M::info();
    let mut seed = 0x1234_5678_9abc_def0u64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    (0..count)
        .map(|_| {
            let q: Vec<f64> = info.coordinates.iter().map(|_| next()).collect();
            let u: Vec<f64> = info.speeds.iter().map(|_| next()).collect();
            let mut s: Vec<f64> = info
                .retained
                .iter()
                .map(|c| q[info.coordinate_index(c).unwrap()])
                .collect();
            s.extend(&u);
            let mut q = q;
            if info.holonomic > 0 {
                appell::linearize::project_holonomic(model, 0.0, &mut s, 1e-14, 30)
                    .expect("a consistent state");
                for (k, c) in info.retained.iter().enumerate() {
                    q[info.coordinate_index(c).unwrap()] = s[k];
                }
            }
            (s, q, u)
        })
        .collect()
}

fn bench_model<M: Model>(
    c: &mut Criterion,
    name: &str,
    model: &M,
    source: &str,
    struct_name: &str,
) {
    let info = M::info();
    let inputs = vec![0.1; info.inputs.len()];
    let prepared = model.prepare::<f64>();
    let set = states(model, 64);
    let mut d = vec![0.0; info.state_len()];
    let mut group = c.benchmark_group(name);
    group.bench_function("rhs generated (per call)", |b| {
        b.iter(|| {
            for (s, _, _) in &set {
                model
                    .rhs(&prepared, 0.0, black_box(s), &inputs, &mut d)
                    .unwrap();
            }
            black_box(&d);
        })
    });
    group.bench_function("rhs oracle (per call)", |b| {
        b.iter(|| {
            for (_, q, u) in &set {
                black_box(reduced_rhs(model, 0.0, black_box(q), u, &inputs).unwrap());
            }
        })
    });
    // The generated Jacobian (symbolic, or the rhs in W-wide dual numbers:
    // `info().jacobian`) against num-dual's column-by-column passes.
    let s = info.state_len();
    let (mut a, mut bm) = (vec![0.0; s * s], vec![0.0; s * info.inputs.len()]);
    group.bench_function("rhs_jacobian generated (per call)", |b| {
        b.iter(|| {
            for (x, _, _) in &set {
                model
                    .rhs_jacobian(0.0, black_box(x), &inputs, &mut d, &mut a, &mut bm)
                    .unwrap();
            }
            black_box(&a);
        })
    });
    group.bench_function("rhs_jacobian num-dual columns (per call)", |b| {
        b.iter(|| {
            for (x, _, _) in &set {
                let lin = appell::linearize::dual_linearize(model, 0.0, black_box(x), &inputs);
                black_box(lin.unwrap());
            }
        })
    });
    let input = derive_input(source, struct_name);
    group.bench_function("derive expansion", |b| {
        b.iter(|| appell_codegen::expand(black_box(&input)))
    });
    group.finish();
    // One summary line measured side by side (criterion's numbers above are
    // per batch of 64 states).
    let t = Instant::now();
    let reps = 2000;
    for _ in 0..reps {
        for (s, _, _) in &set {
            model
                .rhs(&prepared, 0.0, black_box(s), &inputs, &mut d)
                .unwrap();
        }
    }
    let rhs_ns = t.elapsed().as_secs_f64() * 1e9 / (reps * set.len()) as f64;
    let t = Instant::now();
    let reps = 20;
    for _ in 0..reps {
        for (_, q, u) in &set {
            black_box(reduced_rhs(model, 0.0, black_box(q), u, &inputs).unwrap());
        }
    }
    let oracle_ns = t.elapsed().as_secs_f64() * 1e9 / (reps * set.len()) as f64;
    let t = Instant::now();
    for _ in 0..20 {
        black_box(appell_codegen::expand(&input));
    }
    let expand_ms = t.elapsed().as_secs_f64() * 1e3 / 20.0;
    println!(
        "{name}: {} ops, rhs {rhs_ns:.1} ns, oracle {oracle_ns:.0} ns ({:.0}x), derive expansion {expand_ms:.2} ms",
        info.rhs_ops.total,
        oracle_ns / rhs_ns
    );
    // The Jacobians side by side: three alternating rounds, the medians.
    let (mut generated, mut columns) = (Vec::new(), Vec::new());
    for _ in 0..3 {
        let t = Instant::now();
        for _ in 0..50 {
            for (x, _, _) in &set {
                model
                    .rhs_jacobian(0.0, black_box(x), &inputs, &mut d, &mut a, &mut bm)
                    .unwrap();
            }
        }
        generated.push(t.elapsed().as_secs_f64() * 1e9 / (50 * set.len()) as f64);
        let t = Instant::now();
        for _ in 0..5 {
            for (x, _, _) in &set {
                black_box(
                    appell::linearize::dual_linearize(model, 0.0, black_box(x), &inputs).unwrap(),
                );
            }
        }
        columns.push(t.elapsed().as_secs_f64() * 1e9 / (5 * set.len()) as f64);
    }
    generated.sort_by(f64::total_cmp);
    columns.sort_by(f64::total_cmp);
    let form = info.jacobian.map_or("none", |j| j.form);
    let form = form.split(':').next().unwrap_or(form);
    println!(
        "{name}: rhs_jacobian ({form}) {:.0} ns, num-dual columns {:.0} ns ({:.1}x)",
        generated[1],
        columns[1],
        columns[1] / generated[1]
    );
}

/// ns per rhs call and op count of a scene, for the per-scene table.
fn scene_line<M: Model>(label: &str, model: &M) {
    let info = M::info();
    let inputs = vec![0.1; info.inputs.len()];
    let prepared = model.prepare::<f64>();
    let set = states(model, 64);
    let mut d = vec![0.0; info.state_len()];
    for (s, _, _) in &set {
        let _ = model.rhs(&prepared, 0.0, s, &inputs, &mut d);
    }
    let reps = 2000;
    let t = Instant::now();
    for _ in 0..reps {
        for (s, _, _) in &set {
            let _ = model.rhs(&prepared, 0.0, black_box(s), &inputs, &mut d);
        }
    }
    let ns = t.elapsed().as_secs_f64() * 1e9 / (reps * set.len()) as f64;
    println!(
        "{label}: state {}, {} ops, rhs {ns:.1} ns",
        info.state_len(),
        info.rhs_ops.total
    );
}

fn bench(c: &mut Criterion) {
    let axle = wheel_axle::WheelAxle::default();
    scene_line("scene wheel_axle (all effects)", &axle);
    scene_line(
        "scene wheel_axle::coasting",
        &wheel_axle::WheelAxleCoasting(axle.clone()),
    );
    scene_line(
        "scene wheel_axle::driven",
        &wheel_axle::WheelAxleDriven(axle.clone()),
    );
    scene_line(
        "scene wheel_axle::track",
        &wheel_axle::WheelAxleTrack(axle.clone()),
    );
    let bike = whipple_bicycle::WhippleBicycle::default();
    scene_line("scene whipple_bicycle (all effects)", &bike);
    scene_line(
        "scene whipple_bicycle::coasting",
        &whipple_bicycle::WhippleBicycleCoasting(bike.clone()),
    );
    scene_line(
        "scene whipple_bicycle::ridden",
        &whipple_bicycle::WhippleBicycleRidden(bike.clone()),
    );
    bench_model(
        c,
        "wheel_axle",
        &wheel_axle::WheelAxle::default(),
        include_str!("../examples/models/wheel_axle.rs"),
        "WheelAxle",
    );
    bench_model(
        c,
        "double_pendulum",
        &double_pendulum::DoublePendulum::default(),
        include_str!("../examples/models/double_pendulum.rs"),
        "DoublePendulum",
    );
    bench_model(
        c,
        "rolling_disc",
        &rolling_disc::RollingDisc::default(),
        include_str!("../examples/models/rolling_disc.rs"),
        "RollingDisc",
    );
    bench_model(
        c,
        "chaplygin_sleigh",
        &chaplygin_sleigh::ChaplyginSleigh::default(),
        include_str!("../examples/models/chaplygin_sleigh.rs"),
        "ChaplyginSleigh",
    );
    bench_model(
        c,
        "n_link_pendulum_8",
        &n_link_pendulum::Pendulum8::default(),
        include_str!("../examples/models/n_link_pendulum.rs"),
        "Pendulum8",
    );
    bench_model(
        c,
        "n_link_pendulum_16",
        &n_link_pendulum::Pendulum16::default(),
        include_str!("../examples/models/n_link_pendulum.rs"),
        "Pendulum16",
    );
    bench_model(
        c,
        "free_body",
        &free_body::FreeBody::default(),
        include_str!("../examples/models/free_body.rs"),
        "FreeBody",
    );
    bench_model(
        c,
        "chaplygin_ball",
        &free_body::ChaplyginBall::default(),
        include_str!("../examples/models/free_body.rs"),
        "ChaplyginBall",
    );
    bench_model(
        c,
        "ur5",
        &ur5::Ur5,
        include_str!("../examples/models/ur5.rs"),
        "Ur5",
    );
    bench_model(
        c,
        "panda",
        &panda::Panda,
        include_str!("../examples/models/panda.rs"),
        "Panda",
    );
    bench_model(
        c,
        "spatial_chain_8",
        &spatial_chain::SpatialChain8,
        include_str!("../examples/models/spatial_chain.rs"),
        "SpatialChain8",
    );
    bench_model(
        c,
        "mobile_manipulator",
        &mobile_manipulator::MobileManipulator::default(),
        include_str!("../examples/models/mobile_manipulator.rs"),
        "MobileManipulator",
    );
    bench_model(
        c,
        "whipple_bicycle",
        &bike,
        include_str!("../examples/models/whipple_bicycle.rs"),
        "WhippleBicycle",
    );
    c.bench_function("whipple_bicycle/linearize + eigenvalues at 5 m/s", |b| {
        b.iter(|| whipple_bicycle::eigenvalues(&bike, black_box(5.0)).unwrap())
    });
    let t = Instant::now();
    for _ in 0..200 {
        black_box(whipple_bicycle::eigenvalues(&bike, black_box(5.0)).unwrap());
    }
    println!(
        "whipple_bicycle: linearization and eigenvalues at one speed {:.1} µs",
        t.elapsed().as_secs_f64() * 1e6 / 200.0
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
