//! The appell side of the Pinocchio comparison (`../README.md`): times the
//! generated functions of the repository's robot models on a batch of
//! random states drawn exactly as `../pinocchio_bench.cpp` draws them.
//!
//! ```text
//! appell_bench MODEL [--joints J1,J2,...] [--batch B] [--reps R] [--seed S] [--only F1,F2]
//!              [--dump-jacobian]
//! appell_bench list
//! ```
//!
//! MODEL is `ur5`, `ur5_right_angles` (`arms.rs`), `panda`, `spatial_chain_2`, `_4`, `_8`, `_16`, `_32` (and
//! `_64` with `--features large-models`), or a floating-base robot:
//! `solo12`, `anymal_b`, `go1`, `hyq`, `hyq_right_angles`, `g1` (`floating.rs`). `--joints` gives the
//! joint order in which the random numbers are drawn (Pinocchio's, which
//! `run.py` passes on); without it the model's speed order is used.
//!
//! Fixed base: for each state, q_i uniform in [-π, π), then v_i, then τ_i
//! uniform in [-1, 1), per joint in that order (SplitMix64, the C++
//! driver's generator). The values are then placed by joint name:
//! coordinates and speeds are the joints', inputs `tau_<joint>`, and the
//! reduced state of `rhs` is the retained coordinates (`info().retained`)
//! followed by the speeds. Functions that take an acceleration get the τ
//! vector (as Pinocchio's RNEA does here).
//!
//! Free base (`root_joint` first in `--joints`): Pinocchio's q, v and w are
//! drawn as `bench::draw` in `../bench_common.hpp` draws them (the base's
//! position uniform in [-1, 1)³, its quaternion x, y, z, w from four
//! uniforms in [-1, 1) divided by their norm, the joints' angles in
//! [-π, π); v and w uniform in [-1, 1) over all nv entries; Pinocchio's
//! ABA gets τ = w with the base's six entries zeroed, its RNEA a = w), then
//! converted to appell's coordinates, speeds and accelerations by
//! [`PinocchioMap`] (untimed); the inputs `tau_<joint>` are w's joint
//! entries.
//!
//! Output: JSON lines, one describing the model, then one per timed
//! function with the per-call time (ns) of each repetition (one pass over
//! the batch) summarised as median, min and max over the repetitions, and a
//! checksum (the sum of the function's outputs over the batch, from an
//! untimed pass; for `rhs` only the accelerations) to compare with
//! Pinocchio's. For a free base the checksum pass first converts each
//! output to Pinocchio's conventions (accelerations by `a_to_pinocchio`,
//! forces by `tau_to_pinocchio`, M by `mass_to_pinocchio`), so that it
//! sums the same numbers as Pinocchio's; the timed loop calls appell's
//! function alone. Two more timed functions measure the conversion itself:
//! `map_in` (Pinocchio's q and v to appell's reduced state) and `map_out`
//! (appell's accelerations to Pinocchio's `a`).
//!
//! Forward-dynamics derivatives (fixed bases): where the model has a
//! generated Jacobian (`info().jacobian`), or a twin with `jacobian(on)` in
//! `jacobian.rs` (the Panda, the 8- to 64-link chains, Solo12), [`jacobians`] times
//! `rhs_jacobian` (the generated rhs, A = ∂rhs/∂state and B = ∂rhs/∂inputs
//! in one call) and `rhs_jacobian_dual` (the same three outputs by one
//! `Dual64` evaluation of the rhs per state and input column, what
//! `linearize` did before `rhs_jacobian`). `--dump-jacobian` times nothing
//! and prints, per state of the batch, ∂q̈/∂q, ∂q̈/∂v and ∂q̈/∂τ in
//! Pinocchio's joint order, for `run.py`'s entry-by-entry check against
//! `pinocchio_bench --dump-derivatives`.
//!
//! Adding a function is one `t.run(...)` line in [`bench`].

mod arms;
mod floating;
mod jacobian;
#[path = "../../../../examples/models/panda.rs"]
mod panda;
#[path = "../../../../examples/models/spatial_chain.rs"]
mod spatial_chain;
#[path = "../../../../examples/models/ur5.rs"]
mod ur5;

use std::hint::black_box;
use std::process::ExitCode;
use std::time::Instant;

use appell::num_dual::Dual64;
use appell::pinocchio::PinocchioMap;
use appell::{Model, ModelError};

/// The models this build has, by the names `run.py` uses.
const MODELS: &[&str] = &[
    "ur5",
    "ur5_right_angles",
    "panda",
    "spatial_chain_2",
    "spatial_chain_4",
    "spatial_chain_8",
    "spatial_chain_16",
    "spatial_chain_32",
    #[cfg(feature = "large-models")]
    "spatial_chain_64",
    "solo12",
    "anymal_b",
    "go1",
    "hyq",
    "hyq_right_angles",
    "g1",
];

/// The name `urdf(..., base = free)` gives the free joint (Pinocchio's
/// `JointModelFreeFlyer` in `buildModel` has the same).
const ROOT: &str = "root_joint";

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
    /// `--dump-jacobian`: print the Jacobians instead of timing.
    dump_jacobian: bool,
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
    /// A free base: Pinocchio's q (nq per state) and v (nv per state) as
    /// drawn, and the map between the conventions. Empty and `None` for a
    /// fixed base.
    q_pin: Vec<f64>,
    nq_pin: usize,
    v_pin: Vec<f64>,
    nv_pin: usize,
    map: Option<PinocchioMap>,
}

/// The arguments of state `k`.
struct State<'a> {
    state: &'a [f64],
    q: &'a [f64],
    u: &'a [f64],
    /// Accelerations (speed order) for the inverse dynamics.
    a: &'a [f64],
    inputs: &'a [f64],
    q_pin: &'a [f64],
    v_pin: &'a [f64],
}

impl Batch {
    fn at(&self, k: usize) -> State<'_> {
        State {
            state: &self.state[k * self.state_len..(k + 1) * self.state_len],
            q: &self.q[k * self.n..(k + 1) * self.n],
            u: &self.u[k * self.l..(k + 1) * self.l],
            a: &self.a[k * self.l..(k + 1) * self.l],
            inputs: &self.inputs[k * self.m..(k + 1) * self.m],
            q_pin: &self.q_pin[k * self.nq_pin..(k + 1) * self.nq_pin],
            v_pin: &self.v_pin[k * self.nv_pin..(k + 1) * self.nv_pin],
        }
    }
}

/// A URDF joint name as the URDF reader names the model's coordinate
/// (every character other than an ASCII letter, digit or `_` becomes `_`),
/// so that Pinocchio's names from `--joints` can be looked up.
fn rust_name(urdf: &str) -> String {
    urdf.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
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
    if info.coordinate_index(&format!("{ROOT}_qw")).is_some() {
        return draw_free::<M>(opts);
    }
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
        q_pin: Vec::new(),
        nq_pin: 0,
        v_pin: Vec::new(),
        nv_pin: 0,
        map: None,
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

/// The batch of a floating-base model: Pinocchio's states drawn as the C++
/// driver draws them (`bench::draw`), converted to appell's by
/// [`PinocchioMap`].
fn draw_free<M: Model>(opts: &Options) -> Result<Batch, String> {
    let info = M::info();
    let joints: Vec<String> = match &opts.joints {
        Some(j) => j.iter().filter(|j| *j != ROOT).cloned().collect(),
        None => info.speeds[6..].iter().map(|s| s.to_string()).collect(),
    };
    let names: Vec<&str> = joints.iter().map(String::as_str).collect();
    let map = PinocchioMap::free(ROOT, info.coordinates, info.speeds, &names)
        .map_err(|e| format!("{}: {e}", info.name))?;
    let in_at = positions(&joints, info.inputs, "tau_")?;
    let kept_at: Vec<usize> = info
        .retained
        .iter()
        .map(|c| info.coordinate_index(c).expect("a retained coordinate"))
        .collect();
    let (n, l, m) = (info.coordinates.len(), info.speeds.len(), info.inputs.len());
    let (nq, nv) = (map.nq(), map.nv());
    let count = opts.batch;
    let mut b = Batch {
        count,
        state: Vec::with_capacity(count * info.state_len()),
        state_len: info.state_len(),
        q: vec![0.0; count * n],
        n,
        u: vec![0.0; count * l],
        a: vec![0.0; count * l],
        l,
        inputs: Vec::with_capacity(count * m),
        m,
        q_pin: Vec::with_capacity(count * nq),
        nq_pin: nq,
        v_pin: Vec::with_capacity(count * nv),
        nv_pin: nv,
        map: None,
    };
    let mut rng = SplitMix64(opts.seed);
    let pi = std::f64::consts::PI;
    for k in 0..count {
        let mut q_pin: Vec<f64> = (0..7).map(|_| rng.uniform(-1.0, 1.0)).collect();
        let norm =
            (q_pin[3] * q_pin[3] + q_pin[4] * q_pin[4] + q_pin[5] * q_pin[5] + q_pin[6] * q_pin[6])
                .sqrt();
        q_pin[3..7].iter_mut().for_each(|x| *x /= norm);
        q_pin.extend((7..nq).map(|_| rng.uniform(-pi, pi)));
        let v_pin: Vec<f64> = (0..nv).map(|_| rng.uniform(-1.0, 1.0)).collect();
        let w: Vec<f64> = (0..nv).map(|_| rng.uniform(-1.0, 1.0)).collect();
        let q = &mut b.q[k * n..(k + 1) * n];
        let u = &mut b.u[k * l..(k + 1) * l];
        let a = &mut b.a[k * l..(k + 1) * l];
        let bad = |e: ModelError| format!("converting state {k}: {e}");
        map.q_from_pinocchio(&q_pin, q).map_err(bad)?;
        map.v_from_pinocchio(q, &v_pin, u).map_err(bad)?;
        map.a_from_pinocchio(q, &v_pin, &w, a).map_err(bad)?;
        b.state.extend(kept_at.iter().map(|&i| q[i]));
        b.state.extend_from_slice(u);
        // Pinocchio's w after the base's six entries, joint by joint.
        b.inputs.extend(in_at.iter().map(|&i| w[6 + i]));
        b.q_pin.extend(q_pin);
        b.v_pin.extend(v_pin);
    }
    b.map = Some(map);
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
    let quoted: Vec<String> = items.iter().map(|s| json_string(s)).collect();
    format!("[{}]", quoted.join(","))
}

fn json_string(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' | '\\' => {
                out.push('\\');
                out.push(c);
            }
            c if (c as u32) < 0x20 => out.push_str(&format!("\\u{:04x}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
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
    fn wants(&self, function: &str) -> bool {
        self.only
            .is_none_or(|only| only.iter().any(|o| o == function))
    }

    /// Times `f`, which writes `out_len` outputs for a state; the checksum
    /// adds `sum(state, out)` over the batch (untimed).
    fn run<F, G>(&self, function: &str, out_len: usize, mut f: F, sum: G)
    where
        F: FnMut(&State, &mut [f64]) -> Result<(), ModelError>,
        G: Fn(&State, &[f64]) -> Result<f64, ModelError>,
    {
        if !self.wants(function) {
            return;
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
            let s = b.at(k);
            f(&s, &mut out).expect("evaluated above");
            checksum += sum(&s, &out).expect("a conversion to Pinocchio's conventions");
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
        "{{\"impl\":\"appell\",\"build\":\"{}\",\"model\":\"{}\",\"type\":\"{}\",\"nv\":{},\"joints\":{},\"retained\":{},\"rhs_ops\":{},\"form\":{}{}}}",
        build(),
        opts.model,
        info.name,
        info.speeds.len(),
        json_list(info.speeds),
        json_list(info.retained),
        info.rhs_ops.total,
        json_string(info.form),
        jacobian_fields::<M>()
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

    let map = b.map.as_ref();
    // The checksums: the sum of the outputs, in Pinocchio's conventions
    // (converted here, untimed, for a free base).
    let plain = |from: usize| move |_: &State, out: &[f64]| Ok(out[from..].iter().sum::<f64>());
    let nv = map.map_or(l, PinocchioMap::nv);
    let accelerations = |s: &State, out: &[f64]| -> Result<f64, ModelError> {
        let Some(map) = map else {
            return Ok(out[kept..].iter().sum());
        };
        let mut a = vec![0.0; nv];
        map.a_to_pinocchio(s.q, s.u, &out[kept..], &mut a)?;
        Ok(a.iter().sum())
    };
    let forces = |s: &State, out: &[f64]| -> Result<f64, ModelError> {
        let Some(map) = map else {
            return Ok(out.iter().sum());
        };
        let mut tau = vec![0.0; nv];
        map.tau_to_pinocchio(s.q, out, &mut tau)?;
        Ok(tau.iter().sum())
    };
    let mass = |s: &State, out: &[f64]| -> Result<f64, ModelError> {
        let Some(map) = map else {
            return Ok(out[..l * l].iter().sum());
        };
        let mut m = vec![0.0; nv * nv];
        map.mass_to_pinocchio(s.q, &out[..l * l], &mut m)?;
        Ok(m.iter().sum())
    };
    // M ü = f in Pinocchio's terms: with u = T v and u̇ = T a + u̇₀ (u̇₀ the
    // accelerations at a = 0), Tᵀ M T a = Tᵀ (f − M u̇₀).
    let mass_and_forcing = |s: &State, out: &[f64]| -> Result<f64, ModelError> {
        let Some(map) = map else {
            return Ok(out.iter().sum());
        };
        let (m, f) = out.split_at(l * l);
        let mut u_dot0 = vec![0.0; l];
        map.a_from_pinocchio(s.q, s.v_pin, &vec![0.0; nv], &mut u_dot0)?;
        let g: Vec<f64> = (0..l)
            .map(|i| f[i] - (0..l).map(|j| m[i * l + j] * u_dot0[j]).sum::<f64>())
            .collect();
        let mut f_pin = vec![0.0; nv];
        map.tau_to_pinocchio(s.q, &g, &mut f_pin)?;
        Ok(mass(s, m)? + f_pin.iter().sum::<f64>())
    };

    // Forward dynamics: the reduced state's rates (q̇ = u, then ü).
    t.run(
        "rhs",
        info.state_len(),
        |s, out| model.rhs(&prepared, 0.0, s.state, s.inputs, out),
        accelerations,
    );
    // M (l×l, row-major) and f of M ü = f.
    t.run(
        "mass_matrix_and_forcing",
        l * l + l,
        |s, out| {
            let (m, f) = out.split_at_mut(l * l);
            model.mass_matrix_and_forcing(0.0, s.q, s.u, s.inputs, m, f)
        },
        mass_and_forcing,
    );
    // The controller functions: inverse dynamics (RNEA), M alone (CRBA,
    // both triangles) and the gravity term.
    t.run(
        "inverse_dynamics",
        l,
        |s, out| model.inverse_dynamics(0.0, s.q, s.u, s.a, out),
        forces,
    );
    t.run(
        "mass_matrix",
        l * l,
        |s, out| model.mass_matrix(0.0, s.q, out),
        mass,
    );
    t.run(
        "gravity",
        l,
        |s, out| model.gravity_forces(0.0, s.q, out),
        forces,
    );
    // What converting costs a Pinocchio user who keeps Pinocchio's state:
    // its q and v to appell's reduced state, and appell's accelerations to
    // Pinocchio's a (the checksum of map_out is the sum of the drawn w).
    if let Some(map) = map {
        let kept_at: Vec<usize> = info
            .retained
            .iter()
            .map(|c| info.coordinate_index(c).expect("a retained coordinate"))
            .collect();
        let n = info.coordinates.len();
        let mut q = vec![0.0; n];
        t.run(
            "map_in",
            info.state_len(),
            |s, out| {
                map.q_from_pinocchio(s.q_pin, &mut q)?;
                map.v_from_pinocchio(&q, s.v_pin, &mut out[kept..])?;
                for (x, &i) in out[..kept].iter_mut().zip(&kept_at) {
                    *x = q[i];
                }
                Ok(())
            },
            plain(0),
        );
        t.run(
            "map_out",
            nv,
            |s, out| map.a_to_pinocchio(s.q, s.u, s.a, out),
            plain(0),
        );
    }
    if map.is_none() && info.jacobian.is_some() {
        jacobians(model, &t, opts)?;
    }
    Ok(())
}

/// The `"jacobian_ops"` and `"jacobian_form"` fields of a head line.
fn jacobian_fields<M: Model>() -> String {
    match &M::info().jacobian {
        Some(j) => format!(
            ",\"jacobian_ops\":{},\"jacobian_form\":{}",
            j.ops.total,
            json_string(j.form)
        ),
        None => ",\"jacobian_ops\":null,\"jacobian_form\":null".to_string(),
    }
}

/// [`bench`] of `model`, then, if its generated Jacobian is the rhs in
/// dual numbers (or it has none), the symbolic Jacobians of its twin
/// `with` ([`twin`]).
fn with_twin<P: Model, M: Model>(model: &P, with: &M, opts: &Options) -> Result<(), String> {
    bench(model, opts)?;
    let by_duals = P::info()
        .jacobian
        .is_none_or(|j| j.form.starts_with("dual numbers"));
    if by_duals {
        twin(with, opts)?;
    }
    Ok(())
}

/// The Jacobians of a twin of the model (`jacobian.rs`: the same robot
/// with `jacobian(on)`), on the same batch (same joints, same draws), under
/// the model's name: a head line naming the twin, then [`jacobians`].
fn twin<M: Model>(model: &M, opts: &Options) -> Result<(), String> {
    let info = M::info();
    if info.jacobian.is_none() {
        return Err(format!("{} has no generated Jacobian", info.name));
    }
    let b = draw::<M>(opts)?;
    if !opts.dump_jacobian {
        println!(
            "{{\"impl\":\"appell\",\"build\":\"{}\",\"model\":\"{}\",\"jacobian_type\":\"{}\"{}}}",
            build(),
            opts.model,
            info.name,
            jacobian_fields::<M>()
        );
    }
    let t = Timer {
        name: &opts.model,
        batch: &b,
        reps: opts.reps,
        only: opts.only.as_deref(),
        build: build(),
    };
    jacobians(model, &t, opts)
}

/// `dstate`, A (s×s) and B (s×i), row-major, one after the other in `out`
/// (the layout of both Jacobian functions' outputs), by one [`Dual64`]
/// evaluation of the rhs per column of A and of B, seeded on that state
/// component or input, as `appell::linearize` computed them before the
/// generated `rhs_jacobian` (`dual_columns` in
/// `appell-linearize/src/jacobian.rs`); the buffers `x`, `w`, `y`
/// are allocated by the caller and `prepared` made once.
// `prepared` and the dual buffers x, w, y are made once by `jacobians` and reused for every
// state of the timed batch; the rest: rhs_jacobian's state, inputs and its three outputs in `out`
#[allow(clippy::too_many_arguments)]
fn dual_jacobian<M: Model>(
    model: &M,
    prepared: &M::Prepared<Dual64>,
    state: &[f64],
    inputs: &[f64],
    x: &mut [Dual64],
    w: &mut [Dual64],
    y: &mut [Dual64],
    out: &mut [f64],
) -> Result<(), ModelError> {
    let (s, ni) = (state.len(), inputs.len());
    for (xi, &v) in x.iter_mut().zip(state) {
        *xi = Dual64::from_re(v);
    }
    for (wi, &v) in w.iter_mut().zip(inputs) {
        *wi = Dual64::from_re(v);
    }
    let (dstate, rest) = out.split_at_mut(s);
    let (a, b) = rest.split_at_mut(s * s);
    for j in 0..s + ni {
        if j < s {
            x[j].eps = 1.0;
        } else {
            w[j - s].eps = 1.0;
        }
        let r = model.rhs(prepared, Dual64::from_re(0.0), x, w, y);
        if j < s {
            x[j].eps = 0.0;
        } else {
            w[j - s].eps = 0.0;
        }
        r?;
        if j < s {
            for (i, yi) in y.iter().enumerate() {
                a[i * s + j] = yi.eps;
            }
        } else {
            for (i, yi) in y.iter().enumerate() {
                b[i * ni + j - s] = yi.eps;
            }
        }
    }
    for (d, yi) in dstate.iter_mut().zip(y.iter()) {
        *d = yi.re;
    }
    Ok(())
}

/// Times the forward-dynamics derivatives of a fixed-base model with a
/// generated Jacobian: `rhs_jacobian` (generated) and `rhs_jacobian_dual`
/// (dual numbers, [`dual_jacobian`]), both writing `dstate`, A and B. Their
/// checksum is the sum over the batch of the rows of A and B that are ü's
/// (the rows after the retained coordinates' q̇ = u): ∂ü/∂q (retained
/// coordinates), ∂ü/∂u and ∂ü/∂τ, the same numbers as the sum of
/// Pinocchio's `ddq_dq`, `ddq_dv` and `Minv` (whose column of the left-out
/// cyclic coordinate is zero). With `--dump-jacobian`, prints them instead
/// ([`dump_jacobian`]).
fn jacobians<M: Model>(model: &M, t: &Timer, opts: &Options) -> Result<(), String> {
    let info = M::info();
    let (s, ni, kept) = (info.state_len(), info.inputs.len(), info.retained.len());
    let len = s + s * s + s * ni;
    let prepared = model.prepare::<Dual64>();
    let zero = Dual64::from_re(0.0);
    let (mut x, mut w, mut y) = (vec![zero; s], vec![zero; ni], vec![zero; s]);
    if opts.dump_jacobian {
        return dump_jacobian(model, t.batch, opts, |st, out| {
            dual_jacobian(
                model, &prepared, st.state, st.inputs, &mut x, &mut w, &mut y, out,
            )
        });
    }
    let derivatives = move |_: &State, out: &[f64]| -> Result<f64, ModelError> {
        let (a, b) = out[s..].split_at(s * s);
        Ok(a[kept * s..].iter().sum::<f64>() + b[kept * ni..].iter().sum::<f64>())
    };
    t.run(
        "rhs_jacobian",
        len,
        |st, out| {
            let (dstate, rest) = out.split_at_mut(s);
            let (a, b) = rest.split_at_mut(s * s);
            model.rhs_jacobian(0.0, st.state, st.inputs, dstate, a, b)
        },
        derivatives,
    );
    t.run(
        "rhs_jacobian_dual",
        len,
        |st, out| {
            dual_jacobian(
                model, &prepared, st.state, st.inputs, &mut x, &mut w, &mut y, out,
            )
        },
        derivatives,
    );
    Ok(())
}

/// `--dump-jacobian`: for each state of the batch, one JSON line with the
/// generated ∂q̈/∂q (nv×nq, `null` at a coordinate the reduced state leaves
/// out), ∂q̈/∂v, ∂q̈/∂τ and q̈ in Pinocchio's joint order (`--joints`),
/// and the largest difference of the generated [A | B] from the dual
/// numbers' (`dual`).
fn dump_jacobian<M: Model>(
    model: &M,
    b: &Batch,
    opts: &Options,
    mut dual: impl FnMut(&State, &mut [f64]) -> Result<(), ModelError>,
) -> Result<(), String> {
    let info = M::info();
    let (s, ni, kept) = (info.state_len(), info.inputs.len(), info.retained.len());
    let joints: Vec<String> = match &opts.joints {
        Some(j) => j.clone(),
        None => info.speeds.iter().map(|s| s.to_string()).collect(),
    };
    let find = |names: &[&str], name: &str| names.iter().position(|n| *n == name);
    let speed: Vec<usize> = joints
        .iter()
        .map(|j| find(info.speeds, j).ok_or(format!("no speed {j}")))
        .collect::<Result<_, _>>()?;
    let input: Vec<usize> = joints
        .iter()
        .map(|j| find(info.inputs, &format!("tau_{j}")).ok_or(format!("no input tau_{j}")))
        .collect::<Result<_, _>>()?;
    let retained: Vec<Option<usize>> = joints.iter().map(|j| find(info.retained, j)).collect();
    let (mut generated, mut dual_out) =
        (vec![0.0; s + s * s + s * ni], vec![0.0; s + s * s + s * ni]);
    let number = |x: f64| format!("{x:e}");
    let matrix = |rows: Vec<Vec<String>>| {
        let rows: Vec<String> = rows.iter().map(|r| format!("[{}]", r.join(","))).collect();
        format!("[{}]", rows.join(","))
    };
    for k in 0..b.count {
        let st = b.at(k);
        {
            let (dstate, rest) = generated.split_at_mut(s);
            let (a, bm) = rest.split_at_mut(s * s);
            model
                .rhs_jacobian(0.0, st.state, st.inputs, dstate, a, bm)
                .map_err(|e| format!("rhs_jacobian at state {k}: {e}"))?;
        }
        dual(&st, &mut dual_out).map_err(|e| format!("dual Jacobian at state {k}: {e}"))?;
        let dual_diff = generated[s..]
            .iter()
            .zip(&dual_out[s..])
            .map(|(g, d)| (g - d).abs())
            .fold(0.0, f64::max);
        let (a, bm) = generated[s..].split_at(s * s);
        let row = |p: usize| kept + speed[p];
        let nj = joints.len();
        let dq = (0..nj)
            .map(|p| {
                (0..nj)
                    .map(|r| match retained[r] {
                        Some(c) => number(a[row(p) * s + c]),
                        None => "null".to_string(),
                    })
                    .collect()
            })
            .collect();
        let dv = (0..nj)
            .map(|p| {
                (0..nj)
                    .map(|r| number(a[row(p) * s + kept + speed[r]]))
                    .collect()
            })
            .collect();
        let dtau = (0..nj)
            .map(|p| {
                (0..nj)
                    .map(|r| number(bm[row(p) * ni + input[r]]))
                    .collect()
            })
            .collect();
        let ddq: Vec<String> = (0..nj).map(|p| number(generated[row(p)])).collect();
        println!(
            "{{\"model\":\"{}\",\"type\":\"{}\",\"state\":{k},\"ddq\":[{}],\"ddq_dq\":{},\"ddq_dv\":{},\"ddq_dtau\":{},\"dual_max_diff\":{:e}}}",
            opts.model,
            info.name,
            ddq.join(","),
            matrix(dq),
            matrix(dv),
            matrix(dtau),
            dual_diff
        );
    }
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
        dump_jacobian: false,
    };
    let list = |s: &str| -> Vec<String> {
        s.split(',')
            .filter(|x| !x.is_empty())
            .map(String::from)
            .collect()
    };
    while let Some(arg) = it.next() {
        let mut value = || it.next().ok_or(format!("{arg} needs a value"));
        match arg.as_str() {
            "--joints" => {
                opts.joints = Some(list(value()?).into_iter().map(|j| rust_name(&j)).collect())
            }
            "--only" => opts.only = Some(list(value()?)),
            "--dump-jacobian" => opts.dump_jacobian = true,
            "--batch" => opts.batch = value()?.parse().map_err(|e| format!("--batch: {e}"))?,
            "--reps" => opts.reps = value()?.parse().map_err(|e| format!("--reps: {e}"))?,
            "--seed" => opts.seed = value()?.parse().map_err(|e| format!("--seed: {e}"))?,
            other => return Err(format!("unknown argument {other}")),
        }
    }
    if opts.dump_jacobian {
        // Nothing is timed.
        opts.only = Some(Vec::new());
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
            eprintln!("appell_bench: {e}\nusage: appell_bench MODEL [--joints J1,J2] [--batch B] [--reps R] [--seed S] [--only F1,F2] [--dump-jacobian]; models: {}", MODELS.join(" "));
            return ExitCode::from(2);
        }
    };
    let result = match opts.model.as_str() {
        "ur5" => bench(&ur5::Ur5, &opts),
        "ur5_right_angles" => bench(&arms::Ur5RightAngles, &opts),
        "panda" => with_twin(&panda::Panda, &jacobian::PandaJacobian, &opts),
        "spatial_chain_2" => bench(&spatial_chain::SpatialChain2, &opts),
        "spatial_chain_4" => bench(&spatial_chain::SpatialChain4, &opts),
        "spatial_chain_8" => with_twin(
            &spatial_chain::SpatialChain8,
            &jacobian::SpatialChain8Jacobian,
            &opts,
        ),
        "spatial_chain_16" => with_twin(
            &spatial_chain::SpatialChain16,
            &jacobian::SpatialChain16Jacobian,
            &opts,
        ),
        "spatial_chain_32" => with_twin(
            &spatial_chain::SpatialChain32,
            &jacobian::SpatialChain32Jacobian,
            &opts,
        ),
        #[cfg(feature = "large-models")]
        "spatial_chain_64" => with_twin(
            &spatial_chain::SpatialChain64,
            &jacobian::SpatialChain64Jacobian,
            &opts,
        ),
        "solo12" => with_twin(&floating::Solo12, &jacobian::Solo12Jacobian, &opts),
        "anymal_b" => bench(&floating::AnymalB, &opts),
        "go1" => bench(&floating::Go1, &opts),
        "hyq" => bench(&floating::Hyq, &opts),
        "hyq_right_angles" => bench(&floating::HyqRightAngles, &opts),
        "g1" => bench(&floating::G1, &opts),
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
