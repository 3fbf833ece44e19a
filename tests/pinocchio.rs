//! The URDF robots (`examples/models/ur5.rs`, `panda.rs`) and the spatial
//! chains written with joints (`spatial_chain.rs`) against an independent
//! implementation: Pinocchio 4.1.0's ABA, CRBA and nonlinear effects at 20
//! random states per robot (`tests/reference/pinocchio/`, computed offline;
//! read here with serde_json), and against the multiplier oracle at 1,000
//! random states each.
//!
//! Pinocchio's vectors follow its joint order (`joints` in each file); the
//! model's are matched by name: coordinates and speeds are the joints',
//! inputs `tau_<joint>`. The reduced state leaves out the coordinates the
//! equations do not depend on (`info().retained`: the first joint, about
//! the vertical, of each arm), which the full-coordinate functions take at
//! any value.

mod common;
#[path = "../examples/models/panda.rs"]
mod panda;
#[path = "../examples/models/spatial_chain.rs"]
mod spatial_chain;
#[path = "../examples/models/ur5.rs"]
mod ur5;

use std::f64::consts::PI;

use appell::precision::DoubleDouble;
use appell::{Appell, Model};
use common::Rng;
use serde_json::Value;

/// The 4-link chain read from `make_urdf.py`'s file.
#[derive(Appell, Clone, Debug, Default)]
#[appell(urdf("examples/robots/spatial_chain/spatial_chain_4.urdf"))]
#[appell(gravity(-9.81 * N.z))]
struct UrdfChain4;

/// One state of a reference file, in Pinocchio's joint order.
struct State {
    q: Vec<f64>,
    v: Vec<f64>,
    tau: Vec<f64>,
    ddq: Vec<f64>,
    mass_matrix: Vec<Vec<f64>>,
    nle: Vec<f64>,
    /// Accelerations and the joint torques RNEA gives for them.
    a: Vec<f64>,
    rnea: Vec<f64>,
    gravity: Vec<f64>,
}

/// A reference file: Pinocchio's joint names and the states.
struct Reference {
    joints: Vec<String>,
    states: Vec<State>,
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("a list")
        .iter()
        .map(|x| x.as_f64().expect("a number"))
        .collect()
}

/// A reference file's JSON and its joint names, its gravity checked.
fn load(path: &str) -> (Value, Vec<String>) {
    let text = std::fs::read_to_string(path).expect("reference file");
    let data: Value = serde_json::from_str(&text).expect("JSON");
    assert_eq!(data["gravity"], serde_json::json!([0.0, 0.0, -9.81]));
    let joints = data["joints"]
        .as_array()
        .expect("joints")
        .iter()
        .map(|j| j.as_str().expect("name").to_string())
        .collect();
    (data, joints)
}

fn reference(robot: &str) -> Reference {
    let path = format!(
        "{}/tests/reference/pinocchio/{robot}.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let (data, joints) = load(&path);
    let states = data["states"]
        .as_array()
        .expect("states")
        .iter()
        .map(|s| State {
            q: numbers(&s["q"]),
            v: numbers(&s["v"]),
            tau: numbers(&s["tau"]),
            ddq: numbers(&s["ddq"]),
            mass_matrix: s["mass_matrix"]
                .as_array()
                .expect("rows")
                .iter()
                .map(numbers)
                .collect(),
            nle: numbers(&s["nle"]),
            a: numbers(&s["a"]),
            rnea: numbers(&s["rnea"]),
            gravity: numbers(&s["gravity_torque"]),
        })
        .collect();
    Reference { joints, states }
}

/// The index in Pinocchio's order of each of `names`, with `prefix` taken
/// off (`tau_`).
fn order(joints: &[String], names: &[&str], prefix: &str) -> Vec<usize> {
    names
        .iter()
        .map(|n| {
            let joint = n.strip_prefix(prefix).unwrap_or(n);
            joints
                .iter()
                .position(|j| j == joint)
                .unwrap_or_else(|| panic!("`{n}` is not a joint of the reference"))
        })
        .collect()
}

/// Where each of the model's coordinates, speeds, inputs and retained
/// coordinates sits in Pinocchio's joint order.
struct Orders {
    q_at: Vec<usize>,
    u_at: Vec<usize>,
    in_at: Vec<usize>,
    kept: Vec<usize>,
}

impl Orders {
    /// A reference state's q, u and inputs in the model's order, and its
    /// reduced state.
    fn state(&self, s: &State) -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
        let (q, u, inputs) = (
            pick(&self.q_at, &s.q),
            pick(&self.u_at, &s.v),
            pick(&self.in_at, &s.tau),
        );
        let mut state = pick(&self.kept, &s.q);
        state.extend(&u);
        (q, u, inputs, state)
    }
}

/// The entries of `from` at `at`.
fn pick(at: &[usize], from: &[f64]) -> Vec<f64> {
    at.iter().map(|&i| from[i]).collect()
}

fn orders(joints: &[String], info: &appell::ModelInfo) -> Orders {
    Orders {
        q_at: order(joints, info.coordinates, ""),
        u_at: order(joints, info.speeds, ""),
        in_at: order(joints, info.inputs, "tau_"),
        kept: order(joints, info.retained, ""),
    }
}

/// |a − b| / (1 + max |b|): the difference relative to the reference's
/// magnitude.
fn relative(a: &[f64], b: &[f64]) -> f64 {
    let scale = 1.0 + b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs() / scale))
}

/// The worst relative differences over the reference's states: the rhs's
/// accelerations against ABA's ddq, M against CRBA's, and the forcing f
/// against τ − nle.
struct Agreement {
    ddq: f64,
    mass_matrix: f64,
    forcing: f64,
    /// The controller functions against RNEA, CRBA, nle and
    /// computeGeneralizedGravity, and inverse dynamics of the rhs's ÿ
    /// against the inputs.
    controller: f64,
}

fn agreement<M: Model>(model: &M, robot: &str) -> Agreement {
    let info = M::info();
    let r = reference(robot);
    let orders = orders(&r.joints, info);
    let (u_at, kept) = (&orders.u_at, &orders.kept);
    assert_eq!(info.speeds.len(), r.joints.len(), "one speed per joint");
    let prepared = model.prepare::<f64>();
    let l = info.speeds.len();
    let mut worst = Agreement {
        ddq: 0.0,
        mass_matrix: 0.0,
        forcing: 0.0,
        controller: 0.0,
    };
    for s in &r.states {
        let (q, u, inputs, state) = orders.state(s);
        let mut d = vec![0.0; state.len()];
        model.rhs(&prepared, 0.0, &state, &inputs, &mut d).unwrap();
        assert_eq!(&d[..kept.len()], &pick(kept, &s.v)[..], "q̇ = u");
        worst.ddq = worst
            .ddq
            .max(relative(&d[kept.len()..], &pick(u_at, &s.ddq)));
        let (mut m, mut f) = (vec![0.0; l * l], vec![0.0; l]);
        model
            .mass_matrix_and_forcing(0.0, &q, &u, &inputs, &mut m, &mut f)
            .unwrap();
        let crba: Vec<f64> = (0..l * l)
            .map(|k| s.mass_matrix[u_at[k / l]][u_at[k % l]])
            .collect();
        worst.mass_matrix = worst.mass_matrix.max(relative(&m, &crba));
        let tau_minus_nle: Vec<f64> = u_at.iter().map(|&i| s.tau[i] - s.nle[i]).collect();
        worst.forcing = worst.forcing.max(relative(&f, &tau_minus_nle));
        worst.controller = worst.controller.max(controller(
            model,
            s,
            (&q, &u, &inputs),
            u_at,
            &d[kept.len()..],
        ));
    }
    println!("{robot}: {}", info.form);
    println!(
        "{robot}: inverse dynamics, M, h and gravity against RNEA, CRBA, nle and computeGeneralizedGravity, inverse dynamics of the rhs: {:.1e}",
        worst.controller
    );
    println!(
        "{robot} ({}): worst relative difference to Pinocchio over {} states: ddq {:.1e}, M {:.1e}, f = τ − nle {:.1e}",
        info.name,
        r.states.len(),
        worst.ddq,
        worst.mass_matrix,
        worst.forcing
    );
    worst
}

/// The worst relative difference of the controller functions at one state.
fn controller<M: Model>(
    model: &M,
    s: &State,
    (q, u, inputs): (&[f64], &[f64], &[f64]),
    u_at: &[usize],
    ydd: &[f64],
) -> f64 {
    let l = u.len();
    let pick = |from: &[f64]| -> Vec<f64> { u_at.iter().map(|&i| from[i]).collect() };
    let mut out = vec![0.0; l];
    let mut worst = 0.0f64;
    model
        .inverse_dynamics(0.0, q, u, &pick(&s.a), &mut out)
        .unwrap();
    worst = worst.max(relative(&out, &pick(&s.rnea)));
    model.inverse_dynamics(0.0, q, u, ydd, &mut out).unwrap();
    worst = worst.max(relative(&out, inputs));
    model.bias_forces(0.0, q, u, &mut out).unwrap();
    worst = worst.max(relative(&out, &pick(&s.nle)));
    model.gravity_forces(0.0, q, &mut out).unwrap();
    worst = worst.max(relative(&out, &pick(&s.gravity)));
    let mut m = vec![0.0; l * l];
    model.mass_matrix(0.0, q, &mut m).unwrap();
    let crba: Vec<f64> = (0..l * l)
        .map(|k| s.mass_matrix[u_at[k / l]][u_at[k % l]])
        .collect();
    worst.max(relative(&m, &crba))
}

fn assert_agrees<M: Model>(model: &M, robot: &str) {
    let w = agreement(model, robot);
    assert!(
        w.controller <= 1e-10,
        "{robot}: the controller functions differ by {:.2e}",
        w.controller
    );
    assert!(w.ddq <= 1e-10, "{robot}: ddq differs by {:.2e}", w.ddq);
    assert!(
        w.mass_matrix <= 1e-10,
        "{robot}: M differs by {:.2e}",
        w.mass_matrix
    );
    assert!(
        w.forcing <= 1e-10,
        "{robot}: f differs by {:.2e}",
        w.forcing
    );
}

/// Pinocchio's derivatives at a reference state (`derivatives/`), each
/// matrix a list of rows in its joint order.
struct Derivatives {
    q: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    tau: Vec<f64>,
    /// dtau_dq, dtau_dv, dtau_da, ddq_dq, ddq_dv, ddq_dtau.
    matrices: [Vec<Vec<f64>>; 6],
}

const DERIVATIVES: [&str; 6] = [
    "dtau_dq", "dtau_dv", "dtau_da", "ddq_dq", "ddq_dv", "ddq_dtau",
];

fn derivative_reference(robot: &str) -> (Vec<String>, Vec<Derivatives>) {
    let path = format!(
        "{}/tests/reference/pinocchio/derivatives/{robot}.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let (data, joints) = load(&path);
    let rows = |v: &Value| v.as_array().expect("rows").iter().map(numbers).collect();
    let states = data["states"]
        .as_array()
        .expect("states")
        .iter()
        .map(|s| Derivatives {
            q: numbers(&s["q"]),
            v: numbers(&s["v"]),
            a: numbers(&s["a"]),
            tau: numbers(&s["tau"]),
            matrices: DERIVATIVES.map(|k| rows(&s[k])),
        })
        .collect();
    (joints, states)
}

/// The worst relative difference of each generated derivative (row-major,
/// `rows` × `cols` in the model's order) from Pinocchio's, over the
/// reference's states: `inverse_dynamics_derivatives` against
/// computeRNEADerivatives and `forward_dynamics_derivatives` against
/// computeABADerivatives.
fn derivatives_agreement<M: Model>(model: &M, robot: &str) -> [f64; 6] {
    let info = M::info();
    let (joints, states) = derivative_reference(robot);
    let o = orders(&joints, info);
    let (n, l, ni) = (info.coordinates.len(), info.speeds.len(), info.inputs.len());
    let mut worst = [0.0f64; 6];
    let mut values = 0.0f64;
    // The values are in the states' own file (the same states, in order).
    let base = reference(robot);
    assert_eq!(base.states.len(), states.len());
    for (s, b) in states.iter().zip(&base.states) {
        assert_eq!((&s.q, &s.tau), (&b.q, &b.tau), "{robot}: the same states");
        let (q, u) = (pick(&o.q_at, &s.q), pick(&o.u_at, &s.v));
        let (a, tau) = (pick(&o.u_at, &s.a), pick(&o.in_at, &s.tau));
        let mut tau_out = vec![0.0; l];
        let (mut dq, mut du, mut m) = (vec![0.0; l * n], vec![0.0; l * l], vec![0.0; l * l]);
        model
            .inverse_dynamics_derivatives(0.0, &q, &u, &a, &mut tau_out, &mut dq, &mut du, &mut m)
            .unwrap();
        let mut accel = vec![0.0; l];
        let (mut fq, mut fu, mut ft) = (vec![0.0; l * n], vec![0.0; l * l], vec![0.0; l * ni]);
        model
            .forward_dynamics_derivatives(0.0, &q, &u, &tau, &mut accel, &mut fq, &mut fu, &mut ft)
            .unwrap();
        // The values beside the derivatives: RNEA's torques and ABA's ÿ.
        values = values
            .max(relative(&tau_out, &pick(&o.u_at, &b.rnea)))
            .max(relative(&accel, &pick(&o.u_at, &b.ddq)));
        // Each generated matrix, and where its columns are in Pinocchio's.
        let generated: [(&[f64], &[usize]); 6] = [
            (&dq, &o.q_at),
            (&du, &o.u_at),
            (&m, &o.u_at),
            (&fq, &o.q_at),
            (&fu, &o.u_at),
            (&ft, &o.in_at),
        ];
        for (k, (values, cols)) in generated.iter().enumerate() {
            let reference: Vec<f64> = o
                .u_at
                .iter()
                .flat_map(|&i| cols.iter().map(move |&j| (i, j)))
                .map(|(i, j)| s.matrices[k][i][j])
                .collect();
            worst[k] = worst[k].max(relative(values, &reference));
        }
    }
    assert!(values <= 1e-10, "{robot}: τ and ÿ differ by {values:.2e}");
    println!(
        "{robot}: derivatives against Pinocchio over {} states (τ and ÿ beside them {values:.1e}): {}",
        states.len(),
        DERIVATIVES
            .iter()
            .zip(worst)
            .map(|(k, w)| format!("{k} {w:.1e}"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    worst
}

/// The generated derivatives of the inverse and forward dynamics against
/// Pinocchio's analytical ones (`make_derivatives_reference.py`), to 1e-9
/// relative: the UR5 and the 8-link chain (dual numbers for the rhs's),
/// the Panda.
#[test]
fn the_derivatives_agree_with_pinocchio() {
    let cases = [
        ("ur5", derivatives_agreement(&ur5::Ur5, "ur5")),
        ("panda", derivatives_agreement(&panda::Panda, "panda")),
        (
            "spatial_chain_8",
            derivatives_agreement(&spatial_chain::SpatialChain8, "spatial_chain_8"),
        ),
    ];
    for (robot, worst) in cases {
        for (k, w) in DERIVATIVES.iter().zip(worst) {
            assert!(
                w <= 1e-9,
                "{robot}: {k} differs from Pinocchio's by {w:.2e}"
            );
        }
    }
}

#[test]
fn the_ur5_from_its_urdf_agrees_with_pinocchio() {
    assert_agrees(&ur5::Ur5, "ur5");
}

#[test]
fn the_panda_from_its_urdf_agrees_with_pinocchio() {
    assert_agrees(&panda::Panda, "panda");
}

#[test]
fn the_spatial_chains_written_with_joints_agree_with_pinocchio() {
    use spatial_chain::*;
    assert_agrees(&SpatialChain2, "spatial_chain_2");
    assert_agrees(&SpatialChain4, "spatial_chain_4");
    assert_agrees(&SpatialChain8, "spatial_chain_8");
    assert_agrees(&SpatialChain16, "spatial_chain_16");
    assert_agrees(&SpatialChain32, "spatial_chain_32");
}

/// Round-off at the reference's states: the generated rhs and inverse
/// dynamics in f64, and Pinocchio's ABA and RNEA (its f64 values in the
/// reference file), each against the same generated functions evaluated in
/// double-double (106-bit significand). Returns (appell, Pinocchio), each
/// the worst relative error over the states and over both functions.
fn round_off<M: Model>(model: &M, robot: &str) -> (f64, f64) {
    let info = M::info();
    let r = reference(robot);
    let orders = orders(&r.joints, info);
    let (u_at, kept) = (&orders.u_at, &orders.kept);
    let (pf, pd) = (model.prepare::<f64>(), model.prepare::<DoubleDouble>());
    let dd =
        |x: &[f64]| -> Vec<DoubleDouble> { x.iter().map(|&v| DoubleDouble::from(v)).collect() };
    let hi = |x: &[DoubleDouble]| -> Vec<f64> { x.iter().map(|v| v.to_f64()).collect() };
    let (mut ours, mut theirs) = (0.0f64, 0.0f64);
    for s in &r.states {
        let (q, u, inputs, state) = orders.state(s);
        let k = kept.len();
        let mut d = vec![0.0; state.len()];
        model.rhs(&pf, 0.0, &state, &inputs, &mut d).unwrap();
        let mut dd_d = vec![DoubleDouble::from(0.0); state.len()];
        model
            .rhs(
                &pd,
                DoubleDouble::from(0.0),
                &dd(&state),
                &dd(&inputs),
                &mut dd_d,
            )
            .unwrap();
        let exact = hi(&dd_d[k..]);
        ours = ours.max(relative(&d[k..], &exact));
        theirs = theirs.max(relative(&pick(u_at, &s.ddq), &exact));
        let a = pick(u_at, &s.a);
        let mut tau = vec![0.0; u.len()];
        model.inverse_dynamics(0.0, &q, &u, &a, &mut tau).unwrap();
        let mut dd_tau = vec![DoubleDouble::from(0.0); u.len()];
        model
            .inverse_dynamics(
                DoubleDouble::from(0.0),
                &dd(&q),
                &dd(&u),
                &dd(&a),
                &mut dd_tau,
            )
            .unwrap();
        let exact = hi(&dd_tau);
        ours = ours.max(relative(&tau, &exact));
        theirs = theirs.max(relative(&pick(u_at, &s.rnea), &exact));
    }
    println!(
        "{robot}: worst relative round-off against double-double over {} states (ABA's ÿ and RNEA's τ): appell {ours:.1e}, Pinocchio {theirs:.1e}",
        r.states.len()
    );
    (ours, theirs)
}

/// How much more the generated code may round off than Pinocchio: the
/// closed forms of the UR5 and the 4-link chain are within 8x of it
/// (3.1e-15 against 4.1e-16), the structured chains from 8 links on are
/// more accurate than it (5.1e-15 against 2.9e-14 at 32 links).
const ROUND_OFF_FACTOR: f64 = 10.0;

#[test]
fn the_generated_code_rounds_off_no_worse_than_pinocchio() {
    use spatial_chain::*;
    let cases = [
        round_off(&ur5::Ur5, "ur5"),
        round_off(&panda::Panda, "panda"),
        round_off(&SpatialChain2, "spatial_chain_2"),
        round_off(&SpatialChain4, "spatial_chain_4"),
        round_off(&SpatialChain8, "spatial_chain_8"),
        round_off(&SpatialChain16, "spatial_chain_16"),
        round_off(&SpatialChain32, "spatial_chain_32"),
    ];
    for (ours, theirs) in cases {
        assert!(
            ours <= ROUND_OFF_FACTOR * theirs.max(f64::EPSILON),
            "{ours:.2e} against Pinocchio's {theirs:.2e}"
        );
    }
}

/// The largest relative difference between the rhs and the multiplier
/// oracle (eqs. 69-70) over 1,000 random states: q in [−π, π], u in
/// [−2, 2], torques in [−20, 20].
fn oracle_agreement<M: Model>(model: &M, seed: u64) -> f64 {
    common::agree_with_inputs(model, &mut Rng(seed), 1000, PI, 20.0)
}

#[test]
fn the_robots_agree_with_the_oracle() {
    use spatial_chain::*;
    assert!(oracle_agreement(&ur5::Ur5, 1) < 1e-9);
    assert!(oracle_agreement(&panda::Panda, 2) < 1e-9);
    assert!(oracle_agreement(&SpatialChain2, 3) < 1e-9);
    assert!(oracle_agreement(&SpatialChain4, 4) < 1e-9);
    assert!(oracle_agreement(&SpatialChain8, 5) < 1e-9);
    assert!(oracle_agreement(&SpatialChain16, 6) < 1e-9);
}

#[test]
fn the_chain_read_from_its_urdf_is_the_chain_written_with_joints() {
    use spatial_chain::SpatialChain4;
    let (urdf, joints) = (UrdfChain4::info(), SpatialChain4::info());
    assert_eq!(urdf.coordinates, joints.coordinates);
    assert_eq!(urdf.retained, joints.retained);
    assert_eq!(urdf.speeds, joints.speeds);
    assert_eq!(urdf.inputs, joints.inputs);
    let names: Vec<&str> = urdf.bodies.iter().map(|b| b.name).collect();
    assert_eq!(names, ["link_1", "link_2", "link_3", "link_4"]);
    let (a, b) = (UrdfChain4, SpatialChain4);
    let (pa, pb) = (a.prepare::<f64>(), b.prepare::<f64>());
    let mut rng = Rng(11);
    let mut worst: f64 = 0.0;
    for _ in 0..1000 {
        let s: Vec<f64> = (0..urdf.state_len())
            .map(|k| {
                if k < urdf.retained.len() {
                    rng.uniform(-PI, PI)
                } else {
                    rng.uniform(-2.0, 2.0)
                }
            })
            .collect();
        let inputs: Vec<f64> = (0..4).map(|_| rng.uniform(-20.0, 20.0)).collect();
        let (mut da, mut db) = (vec![0.0; s.len()], vec![0.0; s.len()]);
        a.rhs(&pa, 0.0, &s, &inputs, &mut da).unwrap();
        b.rhs(&pb, 0.0, &s, &inputs, &mut db).unwrap();
        for (x, y) in da.iter().zip(&db) {
            worst = worst.max((x - y).abs() / (1.0 + y.abs()));
        }
    }
    println!("spatial chain 4, read from its URDF against written with joints: largest relative difference {worst:.1e} over 1,000 states");
    assert!(worst <= 1e-12, "{worst:.2e}");
}
