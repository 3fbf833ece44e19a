//! The appell side of the Pinocchio comparison (`../README.md`): times the
//! generated functions of the repository's robot models on a batch of
//! random states drawn exactly as `../pinocchio_bench.cpp` draws them.
//!
//! ```text
//! appell_bench MODEL [--joints J1,J2,...] [--batch B] [--reps R] [--seed S] [--only F1,F2]
//! appell_bench list
//! ```
//!
//! MODEL is `ur5`, `panda`, `spatial_chain_2`, `_4`, `_8`, `_16` (and `_32`
//! with `--features large-models`). `--joints` gives the joint order in
//! which the random numbers are drawn (Pinocchio's, which `run.py` passes
//! on); without it the model's speed order is used. For each state: q_i
//! uniform in [-π, π), then v_i, then τ_i uniform in [-1, 1), per joint in
//! that order (SplitMix64, the C++ driver's generator). The values are then
//! placed by joint name: coordinates and speeds are the joints', inputs
//! `tau_<joint>`, and the reduced state of `rhs` is the retained
//! coordinates (`info().retained`) followed by the speeds. Functions that
//! take an acceleration get the τ vector (as Pinocchio's RNEA does here).
//!
//! Output: JSON lines, one describing the model, then one per timed
//! function with the per-call time (ns) of each repetition (one pass over
//! the batch) summarised as median, min and max over the repetitions, and a
//! checksum (the sum of the function's outputs over the batch, from an
//! untimed pass; for `rhs` only the accelerations) to compare with
//! Pinocchio's.
//!
//! Adding a function is one `t.run(...)` line in [`bench`].

#[path = "../../../../examples/models/panda.rs"]
mod panda;
#[path = "../../../../examples/models/spatial_chain.rs"]
mod spatial_chain;
#[path = "../../../../examples/models/ur5.rs"]
mod ur5;

use std::hint::black_box;
use std::process::ExitCode;
use std::time::Instant;

use appell::{Model, ModelError};

/// The models this build has, by the names `run.py` uses.
const MODELS: &[&str] = &[
    "ur5",
    "panda",
    "spatial_chain_2",
    "spatial_chain_4",
    "spatial_chain_8",
    "spatial_chain_16",
    "spatial_chain_32",
    #[cfg(feature = "large-models")]
    "spatial_chain_64",
];

/// SplitMix64, as in the C++ driver; `uniform` takes the top 53 bits.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        let u = (self.next() >> 11) as f64 * (1.0 / (1u64 << 53) as f64);
        lo + (hi - lo) * u
    }
}

/// Command-line options.
struct Options {
    model: String,
    joints: Option<Vec<String>>,
    batch: usize,
    reps: usize,
    seed: u64,
    only: Option<Vec<String>>,
}

/// The batch, one flat array per argument kind, `count` states each.
struct Batch {
    count: usize,
    /// Reduced state of `rhs`: retained coordinates, then speeds.
    state: Vec<f64>,
    state_len: usize,
    /// All coordinates, in `info().coordinates` order.
    q: Vec<f64>,
    n: usize,
    /// Speeds, in `info().speeds` order.
    u: Vec<f64>,
    /// Accelerations for inverse dynamics (the τ draws), in speed order.
    a: Vec<f64>,
    l: usize,
    /// Inputs, in `info().inputs` order.
    inputs: Vec<f64>,
    m: usize,
}

/// The arguments of state `k`.
struct State<'a> {
    state: &'a [f64],
    q: &'a [f64],
    u: &'a [f64],
    /// For the inverse dynamics the Model trait is gaining.
    #[allow(dead_code)]
    a: &'a [f64],
    inputs: &'a [f64],
}

impl Batch {
    fn at(&self, k: usize) -> State<'_> {
        State {
            state: &self.state[k * self.state_len..(k + 1) * self.state_len],
            q: &self.q[k * self.n..(k + 1) * self.n],
            u: &self.u[k * self.l..(k + 1) * self.l],
            a: &self.a[k * self.l..(k + 1) * self.l],
            inputs: &self.inputs[k * self.m..(k + 1) * self.m],
        }
    }
}

/// Where each of `names` is in `joints`, with `prefix` taken off first.
fn positions(joints: &[String], names: &[&str], prefix: &str) -> Result<Vec<usize>, String> {
    names
        .iter()
        .map(|name| {
            let joint = name.strip_prefix(prefix).unwrap_or(name);
            joints
                .iter()
                .position(|j| j == joint)
                .ok_or_else(|| format!("`{name}` is not one of the joints {joints:?}"))
        })
        .collect()
}

fn draw<M: Model>(opts: &Options) -> Result<Batch, String> {
    let info = M::info();
    let joints: Vec<String> = match &opts.joints {
        Some(j) => j.clone(),
        None => info.speeds.iter().map(|s| s.to_string()).collect(),
    };
    let nj = joints.len();
    if info.speeds.len() != nj || info.coordinates.len() != nj || info.inputs.len() != nj {
        return Err(format!(
            "{}: {} joints given, the model has {} coordinates, {} speeds, {} inputs",
            info.name,
            nj,
            info.coordinates.len(),
            info.speeds.len(),
            info.inputs.len()
        ));
    }
    let q_at = positions(&joints, info.coordinates, "")?;
    let u_at = positions(&joints, info.speeds, "")?;
    let in_at = positions(&joints, info.inputs, "tau_")?;
    let kept_at = positions(&joints, info.retained, "")?;
    let count = opts.batch;
    let mut b = Batch {
        count,
        state: Vec::with_capacity(count * info.state_len()),
        state_len: info.state_len(),
        q: Vec::with_capacity(count * nj),
        n: nj,
        u: Vec::with_capacity(count * nj),
        a: Vec::with_capacity(count * nj),
        l: nj,
        inputs: Vec::with_capacity(count * nj),
        m: nj,
    };
    let mut rng = SplitMix64(opts.seed);
    let pi = std::f64::consts::PI;
    for _ in 0..count {
        let q: Vec<f64> = (0..nj).map(|_| rng.uniform(-pi, pi)).collect();
        let v: Vec<f64> = (0..nj).map(|_| rng.uniform(-1.0, 1.0)).collect();
        let tau: Vec<f64> = (0..nj).map(|_| rng.uniform(-1.0, 1.0)).collect();
        b.state.extend(kept_at.iter().map(|&i| q[i]));
        b.state.extend(u_at.iter().map(|&i| v[i]));
        b.q.extend(q_at.iter().map(|&i| q[i]));
        b.u.extend(u_at.iter().map(|&i| v[i]));
        b.a.extend(u_at.iter().map(|&i| tau[i]));
        b.inputs.extend(in_at.iter().map(|&i| tau[i]));
    }
    Ok(b)
}

/// What the Rust compiler targeted, for the output.
fn build() -> String {
    let mut features = Vec::new();
    if cfg!(target_feature = "avx2") {
        features.push("avx2");
    }
    if cfg!(target_feature = "fma") {
        features.push("fma");
    }
    if cfg!(target_feature = "avx512f") {
        features.push("avx512f");
    }
    if features.is_empty() {
        "release, default target".to_string()
    } else {
        format!("release, target features {}", features.join("+"))
    }
}

fn json_list(items: &[&str]) -> String {
    let quoted: Vec<String> = items.iter().map(|s| format!("\"{s}\"")).collect();
    format!("[{}]", quoted.join(","))
}

/// Times functions over one batch and prints a JSON line for each.
struct Timer<'a> {
    name: &'a str,
    batch: &'a Batch,
    reps: usize,
    only: Option<&'a [String]>,
    build: String,
}

impl Timer<'_> {
    /// Times `f`, which writes `out_len` outputs for a state; the checksum
    /// sums `out[sum_from..]`.
    fn run<F>(&self, function: &str, out_len: usize, sum_from: usize, mut f: F)
    where
        F: FnMut(&State, &mut [f64]) -> Result<(), ModelError>,
    {
        if let Some(only) = self.only {
            if !only.iter().any(|o| o == function) {
                return;
            }
        }
        let b = self.batch;
        let mut out = vec![0.0; out_len];
        let mut acc = 0.0;
        let mut pass = |out: &mut [f64], acc: &mut f64| {
            for k in 0..b.count {
                if let Err(e) = f(&b.at(k), out) {
                    panic!("{} {function} at state {k}: {e}", self.name);
                }
                *acc += out[0];
            }
        };
        pass(&mut out, &mut acc); // warm-up
        let mut per_call: Vec<f64> = (0..self.reps)
            .map(|_| {
                let start = Instant::now();
                pass(&mut out, &mut acc);
                start.elapsed().as_secs_f64() * 1e9 / b.count as f64
            })
            .collect();
        black_box(acc);
        let mut checksum = 0.0;
        for k in 0..b.count {
            f(&b.at(k), &mut out).expect("evaluated above");
            checksum += out[sum_from..].iter().sum::<f64>();
        }
        per_call.sort_by(f64::total_cmp);
        let r = per_call.len();
        let median = if r % 2 == 1 {
            per_call[r / 2]
        } else {
            0.5 * (per_call[r / 2 - 1] + per_call[r / 2])
        };
        println!(
            "{{\"impl\":\"appell\",\"build\":\"{}\",\"model\":\"{}\",\"fn\":\"{function}\",\"batch\":{},\"reps\":{},\"median_ns\":{:.2},\"min_ns\":{:.2},\"max_ns\":{:.2},\"checksum\":{:e}}}",
            self.build, self.name, b.count, r, median, per_call[0], per_call[r - 1], checksum
        );
    }
}

/// Times every generated function of `model` that has a Pinocchio
/// counterpart (`run.py` pairs them by name).
fn bench<M: Model>(model: &M, opts: &Options) -> Result<(), String> {
    let info = M::info();
    let b = draw::<M>(opts)?;
    println!(
        "{{\"impl\":\"appell\",\"build\":\"{}\",\"model\":\"{}\",\"type\":\"{}\",\"nv\":{},\"joints\":{},\"retained\":{},\"rhs_ops\":{}}}",
        build(),
        opts.model,
        info.name,
        info.speeds.len(),
        json_list(info.speeds),
        json_list(info.retained),
        info.rhs_ops.total
    );
    let t = Timer {
        name: &opts.model,
        batch: &b,
        reps: opts.reps,
        only: opts.only.as_deref(),
        build: build(),
    };
    let (l, kept) = (info.speeds.len(), info.retained.len());
    // Parameter-only work is done once, as a simulation does.
    let prepared = model.prepare::<f64>();

    // Forward dynamics: the reduced state's rates (q̇ = u, then ü).
    t.run("rhs", info.state_len(), kept, |s, out| {
        model.rhs(&prepared, 0.0, s.state, s.inputs, out)
    });
    // M (l×l, row-major) and f of M ü = f.
    t.run("mass_matrix_and_forcing", l * l + l, 0, |s, out| {
        let (m, f) = out.split_at_mut(l * l);
        model.mass_matrix_and_forcing(0.0, s.q, s.u, s.inputs, m, f)
    });
    // The controller functions: inverse dynamics (RNEA), M alone (CRBA,
    // both triangles) and the gravity term.
    t.run("inverse_dynamics", l, 0, |s, out| {
        model.inverse_dynamics(0.0, s.q, s.u, s.a, out)
    });
    t.run("mass_matrix", l * l, 0, |s, out| model.mass_matrix(0.0, s.q, out));
    t.run("gravity", l, 0, |s, out| model.gravity_forces(0.0, s.q, out));
    Ok(())
}

fn parse(args: &[String]) -> Result<Options, String> {
    let mut it = args.iter();
    let model = it.next().ok_or("no model given")?.clone();
    let mut opts = Options {
        model,
        joints: None,
        batch: 1000,
        reps: 31,
        seed: 20240917,
        only: None,
    };
    let list = |s: &str| s.split(',').filter(|x| !x.is_empty()).map(String::from).collect();
    while let Some(arg) = it.next() {
        let mut value = || it.next().ok_or(format!("{arg} needs a value"));
        match arg.as_str() {
            "--joints" => opts.joints = Some(list(value()?)),
            "--only" => opts.only = Some(list(value()?)),
            "--batch" => opts.batch = value()?.parse().map_err(|e| format!("--batch: {e}"))?,
            "--reps" => opts.reps = value()?.parse().map_err(|e| format!("--reps: {e}"))?,
            "--seed" => opts.seed = value()?.parse().map_err(|e| format!("--seed: {e}"))?,
            other => return Err(format!("unknown argument {other}")),
        }
    }
    if opts.batch == 0 || opts.reps == 0 {
        return Err("--batch and --reps must be positive".into());
    }
    Ok(opts)
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("list") {
        println!("{}", MODELS.join(" "));
        return ExitCode::SUCCESS;
    }
    let opts = match parse(&args) {
        Ok(o) => o,
        Err(e) => {
            eprintln!("appell_bench: {e}\nusage: appell_bench MODEL [--joints J1,J2] [--batch B] [--reps R] [--seed S] [--only F1,F2]; models: {}", MODELS.join(" "));
            return ExitCode::from(2);
        }
    };
    let result = match opts.model.as_str() {
        "ur5" => bench(&ur5::Ur5, &opts),
        "panda" => bench(&panda::Panda, &opts),
        "spatial_chain_2" => bench(&spatial_chain::SpatialChain2, &opts),
        "spatial_chain_4" => bench(&spatial_chain::SpatialChain4, &opts),
        "spatial_chain_8" => bench(&spatial_chain::SpatialChain8, &opts),
        "spatial_chain_16" => bench(&spatial_chain::SpatialChain16, &opts),
        "spatial_chain_32" => bench(&spatial_chain::SpatialChain32, &opts),
        #[cfg(feature = "large-models")]
        "spatial_chain_64" => bench(&spatial_chain::SpatialChain64, &opts),
        other => Err(format!(
            "unknown model {other}; this build has {}",
            MODELS.join(" ")
        )),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("appell_bench: {e}");
            ExitCode::FAILURE
        }
    }
}
