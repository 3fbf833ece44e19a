//! Fixed-base robots of example-robot-data (`tests/robots/`, copied by
//! `fetch_robots.py`) against Pinocchio 4.1.0 at 20 random states within
//! their joint limits each (`tests/reference/pinocchio/robots/`, written by
//! `make_robots_reference.py`): the rhs against ABA, the mass matrix and
//! forcing against CRBA and τ − nle, and the controller functions against
//! RNEA, CRBA, `nonLinearEffects` and `computeGeneralizedGravity`, each to
//! 1e-10 relative.
//!
//! Between them they take what the URDF reader does as Pinocchio does:
//! links on fixed joints merged into their parent's body (HyQ's feet are
//! dummies of 1e-6 kg whose inertia alone breaks the triangle inequality;
//! Bolt's feet have zero mass and an inertia; Talos's and the Allegro
//! hand's fingertips), continuous joints (Kinova, Tiago's wheels, the
//! double pendulum: Pinocchio's q is (cos θ, sin θ), the model's θ), mimic
//! tags on fixed joints (Talos's gripper), names that are no Rust names
//! (the Allegro hand's `joint_0.0` is `joint_0_0`), non-unit axes (Tiago,
//! Kinova).
//!
//! The floating-base robots (Solo12, ANYmal, Go1, HyQ on a free base; G1
//! and Talos with `large-models`) are compared through
//! `appell::pinocchio::PinocchioMap`: Pinocchio's q and v made the model's,
//! its M, RNEA, nle and gravity made of the model's functions and turned
//! into Pinocchio's terms. Pinocchio's τ acts on the base too, which the
//! model's inputs (the joints' torques) cannot, so the rhs is checked by
//! the residual of Pinocchio's own equations, M ddq + nle − τ, at the
//! model's accelerations with the base's part of τ left out; inverse
//! dynamics at Pinocchio's ddq gives all of its τ back.
//!
//! A joint of the model is matched with Pinocchio's by name: Pinocchio's
//! name made a Rust name as the reader makes it. Coordinates left out of
//! the reduced state (`info().retained`) are left out of the state given
//! to the rhs.
//!
//! The xArm 7 and the Tiago are compiled with `--features large-models`
//! only.

mod common;

use appell::{Appell, Model};
use serde_json::Value;

#[derive(Appell, Clone, Debug, Default)]
#[appell(urdf("tests/robots/z1/z1.urdf"), gravity(-9.81 * N.z))]
struct Z1;

/// Behind the feature `large-models` with the Tiago below: their
/// expansions are the largest of the set (2.4 and 2.8 MB of snapshot).
#[cfg(feature = "large-models")]
#[derive(Appell, Clone, Debug, Default)]
#[appell(urdf("tests/robots/xarm/xarm7.urdf"), gravity(-9.81 * N.z))]
struct XArm7;

#[derive(Appell, Clone, Debug, Default)]
#[appell(urdf("tests/robots/kinova/kinova.urdf"), gravity(-9.81 * N.z))]
struct Kinova;

#[derive(Appell, Clone, Debug, Default)]
#[appell(urdf("tests/robots/ur/ur10_robot.urdf"), gravity(-9.81 * N.z))]
struct Ur10;

#[derive(Appell, Clone, Debug, Default)]
#[appell(urdf("tests/robots/talos/talos_left_arm.urdf"), gravity(-9.81 * N.z))]
struct TalosLeftArm;

#[derive(Appell, Clone, Debug, Default)]
#[appell(
    urdf("tests/robots/allegro_hand/allegro_right_hand.urdf"),
    gravity(-9.81 * N.z)
)]
struct AllegroRightHand;

#[cfg(feature = "large-models")]
#[derive(Appell, Clone, Debug, Default)]
#[appell(urdf("tests/robots/tiago/tiago_no_hand.urdf"), gravity(-9.81 * N.z))]
struct TiagoNoHand;

#[derive(Appell, Clone, Debug, Default)]
#[appell(
    urdf("tests/robots/double_pendulum/double_pendulum_continuous.urdf"),
    gravity(-9.81 * N.z)
)]
struct DoublePendulumContinuous;

#[derive(Appell, Clone, Debug, Default)]
#[appell(urdf("tests/robots/hyq/hyq_no_sensors.urdf"), gravity(-9.81 * N.z))]
struct HyqFixed;

#[derive(Appell, Clone, Debug, Default)]
#[appell(urdf("tests/robots/bolt/bolt.urdf"), gravity(-9.81 * N.z))]
struct BoltFixed;

/// A joint of the reference: where its entries are in q and v.
struct Joint {
    /// The name as the model has it.
    name: String,
    /// Pinocchio's own name (the key of `angles`).
    urdf_name: String,
    nq: usize,
    idx_q: usize,
    idx_v: usize,
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("a list")
        .iter()
        .map(|x| x.as_f64().expect("a number"))
        .collect()
}

/// A name of the file as a Rust name, as the URDF reader makes it (the
/// names of this set need no more than this).
fn model_name(urdf: &str) -> String {
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

fn reference(robot: &str) -> (Vec<Joint>, Vec<Value>) {
    let path = format!(
        "{}/tests/reference/pinocchio/robots/{robot}.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let data: Value =
        serde_json::from_str(&std::fs::read_to_string(path).expect("file")).expect("JSON");
    assert_eq!(data["base"], "fixed");
    assert_eq!(data["gravity"], serde_json::json!([0.0, 0.0, -9.81]));
    let joints = data["joints"]
        .as_array()
        .expect("joints")
        .iter()
        .map(|j| {
            let urdf_name = j["name"].as_str().expect("name").to_string();
            let n = |k: &str| j[k].as_u64().expect("a count") as usize;
            assert_eq!(n("nv"), 1, "{urdf_name}: one speed");
            Joint {
                name: model_name(&urdf_name),
                urdf_name,
                nq: n("nq"),
                idx_q: n("idx_q"),
                idx_v: n("idx_v"),
            }
        })
        .collect();
    let states = data["states"].as_array().expect("states").clone();
    (joints, states)
}

#[derive(Appell, Clone, Debug, Default)]
#[appell(urdf("tests/robots/solo/solo12.urdf", base = free), gravity(-9.81 * N.z))]
struct Solo12;

#[derive(Appell, Clone, Debug, Default)]
#[appell(urdf("tests/robots/anymal_b_simple/anymal.urdf", base = free), gravity(-9.81 * N.z))]
struct Anymal;

#[derive(Appell, Clone, Debug, Default)]
#[appell(urdf("tests/robots/go1/go1.urdf", base = free), gravity(-9.81 * N.z))]
struct Go1;

#[derive(Appell, Clone, Debug, Default)]
#[appell(urdf("tests/robots/hyq/hyq_no_sensors.urdf", base = free), gravity(-9.81 * N.z))]
struct Hyq;

/// HyQ with its right angles exact: the file writes π/2 as 1.57079632679
/// (4.9e-12 short) and π as 3.14159265359.
#[derive(Appell, Clone, Debug, Default)]
#[appell(
    urdf("tests/robots/hyq/hyq_no_sensors.urdf", base = free, right_angles = 1e-10),
    gravity(-9.81 * N.z)
)]
struct HyqRightAngles;

#[cfg(feature = "large-models")]
#[derive(Appell, Clone, Debug, Default)]
#[appell(urdf("tests/robots/g1/g1_29dof_rev_1_0.urdf", base = free), gravity(-9.81 * N.z))]
struct G1;

/// A floating-base reference: its joints after the free flyer, in
/// Pinocchio's order and as the model names them, and its states.
fn free_reference(robot: &str) -> (Vec<String>, Vec<Value>) {
    let path = format!(
        "{}/tests/reference/pinocchio/robots/{robot}.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let data: Value =
        serde_json::from_str(&std::fs::read_to_string(path).expect("file")).expect("JSON");
    assert_eq!(data["base"], "free");
    assert_eq!(data["gravity"], serde_json::json!([0.0, 0.0, -9.81]));
    let joints = data["joints"].as_array().expect("joints");
    assert_eq!(joints[0]["type"], "JointModelFreeFlyer");
    let names = joints[1..]
        .iter()
        .map(|j| {
            assert_eq!(j["nq"], 1, "{robot}: one coordinate a joint");
            model_name(j["name"].as_str().expect("name"))
        })
        .collect();
    (names, data["states"].as_array().expect("states").clone())
}

/// The worst relative difference to a floating-base reference, through
/// the Pinocchio map.
fn worst_free_difference<M: Model + Default>(robot: &str) -> f64 {
    use appell::pinocchio::PinocchioMap;
    let model = M::default();
    let info = M::info();
    let (names, states) = free_reference(robot);
    let joints: Vec<&str> = names.iter().map(String::as_str).collect();
    let map = PinocchioMap::free("root_joint", info.coordinates, info.speeds, &joints)
        .unwrap_or_else(|e| panic!("{robot}: {e}"));
    let (n, l, nv) = (info.coordinates.len(), info.speeds.len(), map.nv());
    let prepared = model.prepare::<f64>();
    let to_pin = |q: &[f64], tau: &[f64]| {
        let mut out = vec![0.0; nv];
        map.tau_to_pinocchio(q, tau, &mut out).unwrap();
        out
    };
    let mut worst = 0.0f64;
    for s in &states {
        let (q_pin, v) = (numbers(&s["q"]), numbers(&s["v"]));
        let (tau, nle) = (numbers(&s["tau"]), numbers(&s["nle"]));
        let rows: Vec<Vec<f64>> = s["mass_matrix"]
            .as_array()
            .expect("rows")
            .iter()
            .map(numbers)
            .collect();
        let (mut q, mut u) = (vec![0.0; n], vec![0.0; l]);
        map.q_from_pinocchio(&q_pin, &mut q).unwrap();
        map.v_from_pinocchio(&q, &v, &mut u).unwrap();
        // M against CRBA.
        let (mut m, mut m_pin) = (vec![0.0; l * l], vec![0.0; nv * nv]);
        model.mass_matrix(0.0, &q, &mut m).unwrap();
        map.mass_to_pinocchio(&q, &m, &mut m_pin).unwrap();
        worst = worst.max(relative(&m_pin, &rows.concat()));
        // Inverse dynamics at Pinocchio's a and ddq: RNEA and all of τ.
        let mut u_dot = vec![0.0; l];
        let mut forces = vec![0.0; l];
        for (a, expected) in [("a", "rnea"), ("ddq", "tau")] {
            map.a_from_pinocchio(&q, &v, &numbers(&s[a]), &mut u_dot)
                .unwrap();
            model
                .inverse_dynamics(0.0, &q, &u, &u_dot, &mut forces)
                .unwrap();
            worst = worst.max(relative(&to_pin(&q, &forces), &numbers(&s[expected])));
        }
        // nle: inverse dynamics where Pinocchio's a is zero.
        map.a_from_pinocchio(&q, &v, &vec![0.0; nv], &mut u_dot)
            .unwrap();
        model
            .inverse_dynamics(0.0, &q, &u, &u_dot, &mut forces)
            .unwrap();
        worst = worst.max(relative(&to_pin(&q, &forces), &nle));
        model.gravity_forces(0.0, &q, &mut forces).unwrap();
        worst = worst.max(relative(
            &to_pin(&q, &forces),
            &numbers(&s["gravity_torque"]),
        ));
        // The rhs with the joints' torques: M ddq + nle = τ without the
        // base's part, in Pinocchio's own M and nle.
        let inputs: Vec<f64> = info
            .inputs
            .iter()
            .map(|i| {
                let k = joints
                    .iter()
                    .position(|j| Some(*j) == i.strip_prefix("tau_"));
                tau[6 + k.expect("an actuated joint")]
            })
            .collect();
        let mut state: Vec<f64> = info
            .retained
            .iter()
            .map(|c| q[info.coordinate_index(c).unwrap()])
            .collect();
        let k = state.len();
        state.extend(&u);
        let mut d = vec![0.0; state.len()];
        model.rhs(&prepared, 0.0, &state, &inputs, &mut d).unwrap();
        let mut a = vec![0.0; nv];
        map.a_to_pinocchio(&q, &u, &d[k..], &mut a).unwrap();
        let mut joint_tau = tau.clone();
        joint_tau[..6].iter_mut().for_each(|x| *x = 0.0);
        let residual: Vec<f64> = (0..nv)
            .map(|i| (0..nv).map(|j| rows[i][j] * a[j]).sum::<f64>() + nle[i] - joint_tau[i])
            .collect();
        let scale = 1.0 + joint_tau.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        worst = worst.max(residual.iter().fold(0.0f64, |m, r| m.max(r.abs())) / scale);
    }
    println!(
        "{robot} (free base, {} joints, {}): worst relative difference to Pinocchio over {} states {worst:.1e}",
        joints.len(),
        info.form.split(':').next().unwrap_or_default(),
        states.len()
    );
    worst
}

#[test]
fn floating_base_robots_agree_with_pinocchio() {
    for (robot, worst) in [
        ("solo12", worst_free_difference::<Solo12>("solo12")),
        ("anymal", worst_free_difference::<Anymal>("anymal")),
        ("go1", worst_free_difference::<Go1>("go1")),
        ("hyq", worst_free_difference::<Hyq>("hyq")),
        #[cfg(feature = "large-models")]
        ("g1", worst_free_difference::<G1>("g1")),
    ] {
        assert!(worst <= 1e-10, "{robot}: {worst:.2e}");
    }
}

/// HyQ's right angles read as exact (`right_angles = 1e-10`): Pinocchio
/// reads the file's numbers as written, 4.9e-12 off, so the two are
/// different robots by that much; the results differ by 6.6e-11 at most
/// over the reference's states.
#[test]
fn hyq_with_exact_right_angles_agrees_with_pinocchio() {
    let worst = worst_free_difference::<HyqRightAngles>("hyq");
    assert!(worst <= 2e-10, "{worst:.2e}");
}

/// The same right angles turn HyQ's joint frames by permutations, so its
/// rhs costs less.
#[test]
fn exact_right_angles_cost_less() {
    let (written, exact) = (Hyq::info(), HyqRightAngles::info());
    assert!(
        exact.rhs_ops.total * 10 < written.rhs_ops.total * 9,
        "rhs: {} operations with right angles exact, {} as written",
        exact.rhs_ops.total,
        written.rhs_ops.total
    );
}

/// |a − b| / (1 + max |b|).
fn relative(a: &[f64], b: &[f64]) -> f64 {
    let scale = 1.0 + b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs() / scale))
}

/// The worst relative difference to the reference over its states, of
/// every function compared.
fn worst_difference<M: Model + Default>(robot: &str) -> f64 {
    let model = M::default();
    let info = M::info();
    let (joints, states) = reference(robot);
    let joint = |name: &str| -> &Joint {
        let name = name.strip_prefix("tau_").unwrap_or(name);
        joints
            .iter()
            .find(|j| j.name == name)
            .unwrap_or_else(|| panic!("{robot}: `{name}` is not a joint of the reference"))
    };
    assert_eq!(
        info.speeds.len(),
        joints.len(),
        "{robot}: one speed a joint"
    );
    assert_eq!(
        info.coordinates.len(),
        joints.len(),
        "{robot}: one coordinate a joint"
    );
    let at: Vec<usize> = info.speeds.iter().map(|s| joint(s).idx_v).collect();
    let l = at.len();
    let prepared = model.prepare::<f64>();
    let mut worst = 0.0f64;
    for s in &states {
        let (q_ref, v, tau) = (numbers(&s["q"]), numbers(&s["v"]), numbers(&s["tau"]));
        let pick = |from: &[f64]| -> Vec<f64> { at.iter().map(|&i| from[i]).collect() };
        let coordinate = |c: &str| {
            let j = joint(c);
            match j.nq {
                1 => q_ref[j.idx_q],
                _ => s["angles"][&j.urdf_name].as_f64().expect("an angle"),
            }
        };
        let q: Vec<f64> = info.coordinates.iter().map(|c| coordinate(c)).collect();
        let u = pick(&v);
        let inputs: Vec<f64> = info.inputs.iter().map(|i| tau[joint(i).idx_v]).collect();
        let mut state: Vec<f64> = info.retained.iter().map(|c| coordinate(c)).collect();
        let k = state.len();
        state.extend(&u);
        // The rhs against ABA.
        let mut d = vec![0.0; state.len()];
        model.rhs(&prepared, 0.0, &state, &inputs, &mut d).unwrap();
        worst = worst.max(relative(&d[k..], &pick(&numbers(&s["ddq"]))));
        // M and f against CRBA and τ − nle.
        let rows: Vec<Vec<f64>> = s["mass_matrix"]
            .as_array()
            .expect("rows")
            .iter()
            .map(numbers)
            .collect();
        let crba: Vec<f64> = (0..l * l).map(|i| rows[at[i / l]][at[i % l]]).collect();
        let nle = pick(&numbers(&s["nle"]));
        let (mut m, mut f) = (vec![0.0; l * l], vec![0.0; l]);
        model
            .mass_matrix_and_forcing(0.0, &q, &u, &inputs, &mut m, &mut f)
            .unwrap();
        worst = worst.max(relative(&m, &crba));
        let tau_minus_nle: Vec<f64> = inputs.iter().zip(&nle).map(|(t, n)| t - n).collect();
        worst = worst.max(relative(&f, &tau_minus_nle));
        // The controller functions.
        let mut out = vec![0.0; l];
        model
            .inverse_dynamics(0.0, &q, &u, &pick(&numbers(&s["a"])), &mut out)
            .unwrap();
        worst = worst.max(relative(&out, &pick(&numbers(&s["rnea"]))));
        model.bias_forces(0.0, &q, &u, &mut out).unwrap();
        worst = worst.max(relative(&out, &nle));
        model.gravity_forces(0.0, &q, &mut out).unwrap();
        worst = worst.max(relative(&out, &pick(&numbers(&s["gravity_torque"]))));
        model.mass_matrix(0.0, &q, &mut m).unwrap();
        worst = worst.max(relative(&m, &crba));
    }
    println!(
        "{robot} ({} joints, {}): worst relative difference to Pinocchio over {} states {worst:.1e}",
        l,
        info.form.split(':').next().unwrap_or_default(),
        states.len()
    );
    worst
}

fn assert_agrees<M: Model + Default>(robot: &str) {
    let w = worst_difference::<M>(robot);
    assert!(w <= 1e-10, "{robot}: {w:.2e}");
}

#[test]
fn arms_agree_with_pinocchio() {
    assert_agrees::<Z1>("z1");
    #[cfg(feature = "large-models")]
    assert_agrees::<XArm7>("xarm7");
    assert_agrees::<Ur10>("ur10");
    assert_agrees::<TalosLeftArm>("talos_left_arm");
}

#[test]
fn continuous_joints_agree_with_pinocchio() {
    assert_agrees::<Kinova>("kinova");
    assert_agrees::<DoublePendulumContinuous>("double_pendulum_continuous");
    #[cfg(feature = "large-models")]
    assert_agrees::<TiagoNoHand>("tiago_no_hand");
}

#[test]
fn a_hand_agrees_with_pinocchio() {
    assert_agrees::<AllegroRightHand>("allegro_right_hand");
}

#[test]
fn legs_with_parts_on_fixed_joints_agree_with_pinocchio() {
    assert_agrees::<HyqFixed>("hyq_fixed");
    assert_agrees::<BoltFixed>("bolt_fixed");
}
