//! Models read from URDF files: the UR5's rounded right angles, measured;
//! numbers of the file promoted to struct fields; the Panda's mimic finger
//! joint as a constraint; `eval` on the command line with joint names;
//! links on fixed joints merged as Pinocchio merges them (an unphysical
//! dummy, a foot of zero mass with an inertia); `unchecked_inertia`;
//! `mimic = false`; a link named as a joint; a planar joint in the file.

mod common;
#[path = "../examples/models/ur5.rs"]
mod ur5;

use std::f64::consts::{FRAC_PI_2, PI};

use appell::{Appell, Model};
use common::Rng;

/// The UR5 with the pitches of its two joints written `1.57079632679` in
/// the file as parameters.
#[derive(Appell, Clone, Debug)]
#[appell(urdf(
    "examples/robots/ur5/ur5_robot.urdf",
    parameters(shoulder_lift_joint.rpy.pitch = lift_pitch, wrist_1_joint.rpy.pitch = wrist_pitch)
))]
#[appell(gravity(-9.81 * N.z))]
struct Ur5Pitches {
    lift_pitch: f64,
    wrist_pitch: f64,
}

/// The UR5 with a payload on its last link, the upper arm's length as a
/// parameter, and a point mass at the tool flange (a link the file gives no
/// mass).
#[derive(Appell, Clone, Debug)]
#[appell(urdf(
    "examples/robots/ur5/ur5_robot.urdf",
    parameters(wrist_3_link.mass = payload, elbow_joint.xyz.z = upper_arm, tool0.mass = tool)
))]
#[appell(gravity(-9.81 * N.z), positive(payload))]
struct Ur5Payload {
    payload: f64,
    upper_arm: f64,
    tool: f64,
}

/// The Panda with its fingers free: `panda_finger_joint2` mimics
/// `panda_finger_joint1`.
#[derive(Appell, Clone, Debug, Default)]
#[appell(urdf("examples/robots/panda/panda.urdf"), gravity(-9.81 * N.z))]
struct PandaWithFingers;

/// A link whose inertial frame is turned (rpy 0.3, -0.2, 0.5), and the same
/// link with the inertia written in the link frame (R I Rᵀ, computed
/// offline); the elbow's axis is not a unit axis.
#[derive(Appell, Clone, Debug, Default)]
#[appell(urdf("tests/fixtures/turned_inertial.urdf"), gravity(-9.81 * N.z))]
struct TurnedInertial;

#[derive(Appell, Clone, Debug, Default)]
#[appell(urdf("tests/fixtures/turned_inertial_written.urdf"), gravity(-9.81 * N.z))]
struct TurnedInertialWritten;

/// Links carrying parts on fixed joints (a dummy whose inertia breaks the
/// triangle inequality, a foot of zero mass with an inertia, a tool), and
/// the same arm with each link's parts merged into its inertial (NumPy).
#[derive(Appell, Clone, Debug, Default)]
#[appell(urdf("tests/fixtures/fixed_parts.urdf"), gravity(-9.81 * N.z))]
struct FixedParts;

#[derive(Appell, Clone, Debug, Default)]
#[appell(urdf("tests/fixtures/fixed_parts_merged.urdf"), gravity(-9.81 * N.z))]
struct FixedPartsMerged;

/// A link whose inertia breaks the triangle inequality, taken as written.
#[derive(Appell, Clone, Debug, Default)]
#[appell(
    urdf("tests/fixtures/lopsided.urdf", unchecked_inertia(arm)),
    gravity(-9.81 * N.z)
)]
struct Lopsided;

/// The Panda with its mimic tag ignored, as Pinocchio's default.
#[derive(Appell, Clone, Debug, Default)]
#[appell(
    urdf("examples/robots/panda/panda.urdf", mimic = false),
    gravity(-9.81 * N.z)
)]
struct PandaIndependentFingers;

/// A link and a joint both named `gripper`.
#[derive(Appell, Clone, Debug, Default)]
#[appell(urdf("tests/fixtures/named_alike.urdf"), gravity(-9.81 * N.z))]
struct NamedAlike;

/// A cart on a planar joint of the file, carrying a pendulum.
#[derive(Appell, Clone, Debug, Default)]
#[appell(urdf("tests/fixtures/planar_inside.urdf"), gravity(-9.81 * N.z))]
struct PlanarInside;

/// The rhs of two models at the same random states (the first coordinate,
/// ignorable in both, left out); the largest difference relative to
/// 1 + |b|.
fn largest_difference<A: Model, B: Model>(a: &A, b: &B, states: usize, seed: u64) -> f64 {
    let (ia, ib) = (A::info(), B::info());
    assert_eq!(ia.retained, ib.retained);
    assert_eq!(ia.speeds, ib.speeds);
    assert_eq!(ia.inputs, ib.inputs);
    let (pa, pb) = (a.prepare::<f64>(), b.prepare::<f64>());
    let mut rng = Rng(seed);
    let mut worst: f64 = 0.0;
    for _ in 0..states {
        let s: Vec<f64> = (0..ia.state_len())
            .map(|k| {
                if k < ia.retained.len() {
                    rng.uniform(-PI, PI)
                } else {
                    rng.uniform(-2.0, 2.0)
                }
            })
            .collect();
        let inputs: Vec<f64> = ia.inputs.iter().map(|_| rng.uniform(-20.0, 20.0)).collect();
        let (mut da, mut db) = (vec![0.0; s.len()], vec![0.0; s.len()]);
        a.rhs(&pa, 0.0, &s, &inputs, &mut da).unwrap();
        b.rhs(&pb, 0.0, &s, &inputs, &mut db).unwrap();
        for (x, y) in da.iter().zip(&db) {
            worst = worst.max((x - y).abs() / (1.0 + y.abs()));
        }
    }
    worst
}

/// π/2 as the UR5's file writes it.
// Not FRAC_PI_2 on purpose: the file's rounded value.
#[allow(clippy::approx_constant)]
const ROUNDED_RIGHT_ANGLE: f64 = 1.57079632679;

/// The UR5's file writes π/2 as 1.57079632679 (4.9e-12 below it); the
/// accelerations with exact right angles differ by about 2e-10 relative
/// (printed; the docs quote the figure).
#[test]
fn the_ur5s_rounded_right_angles_measured() {
    let rounded = Ur5Pitches {
        lift_pitch: ROUNDED_RIGHT_ANGLE,
        wrist_pitch: ROUNDED_RIGHT_ANGLE,
    };
    let same = largest_difference(&rounded, &ur5::Ur5, 200, 12);
    // Constants folded at compile time against the same numbers as
    // parameters: rounding apart.
    assert!(
        same <= 1e-13,
        "the parameters as the file's numbers: {same:.2e}"
    );
    let exact = Ur5Pitches {
        lift_pitch: FRAC_PI_2,
        wrist_pitch: FRAC_PI_2,
    };
    let d = largest_difference(&exact, &ur5::Ur5, 1000, 13);
    println!("UR5, exact right angles against the file's 1.57079632679: largest relative difference of the rhs {d:.2e} over 1,000 states");
    assert!((1e-11..1e-8).contains(&d), "{d:.2e}");
}

#[test]
fn a_turned_inertial_frame_is_the_inertia_turned() {
    let info = TurnedInertial::info();
    assert_eq!(info.coordinates, ["shoulder", "elbow"]);
    let d = largest_difference(&TurnedInertial, &TurnedInertialWritten, 500, 17);
    println!("turned inertial frame against the turned inertia written out: {d:.1e}");
    assert!(d <= 1e-13, "{d:.2e}");
}

#[test]
fn numbers_of_the_file_become_parameters() {
    let info = Ur5Payload::info();
    assert_eq!(info.parameters, ["payload", "upper_arm", "tool"]);
    let file = Ur5Payload {
        payload: 0.1879,
        upper_arm: 0.425,
        tool: 0.0,
    };
    let same = largest_difference(&file, &ur5::Ur5, 200, 14);
    assert!(same <= 1e-13, "{same:.2e}");
    // The tool flange is a body now, a point mass.
    let bodies: Vec<&str> = info.bodies.iter().map(|b| b.name).collect();
    assert!(bodies.contains(&"tool0"), "{bodies:?}");
    let mut masses = vec![0.0; info.bodies.len()];
    let mut inertias = vec![[0.0; 9]; info.bodies.len()];
    let loaded = Ur5Payload {
        payload: 2.5,
        upper_arm: 0.5,
        tool: 1.0,
    };
    loaded.mass_properties(&mut masses, &mut inertias).unwrap();
    let at = |name: &str| bodies.iter().position(|b| *b == name).unwrap();
    assert_eq!(masses[at("wrist_3_link")], 2.5);
    assert_eq!(
        (masses[at("tool0")], inertias[at("tool0")]),
        (1.0, [0.0; 9])
    );
    assert!(largest_difference(&loaded, &ur5::Ur5, 20, 15) > 1e-3);
    // `positive(payload)` is checked.
    let bad = Ur5Payload {
        payload: -1.0,
        ..loaded
    };
    let mut d = vec![0.0; info.state_len()];
    let err = bad.rhs(
        &bad.prepare::<f64>(),
        0.0,
        &vec![0.0; d.len()],
        &[0.0; 6],
        &mut d,
    );
    assert!(err.is_err());
}

#[test]
fn a_mimic_joint_is_a_dependent_coordinate_tied_by_a_constraint() {
    let info = PandaWithFingers::info();
    assert_eq!(info.holonomic, 1);
    assert_eq!(info.dependent, ["panda_finger_joint2"]);
    assert_eq!(info.speeds.len(), 8);
    assert!(info.inputs.contains(&"tau_panda_finger_joint1"));
    assert!(!info.inputs.contains(&"tau_panda_finger_joint2"));
    assert!(info.form.starts_with("structured"), "{}", info.form);
    // The rhs agrees with the multiplier oracle, which takes the
    // constraint's multiplier.
    let model = PandaWithFingers;
    let prepared = model.prepare::<f64>();
    let mut rng = Rng(16);
    let mut worst: f64 = 0.0;
    for _ in 0..200 {
        let mut q: Vec<f64> = info
            .coordinates
            .iter()
            .map(|_| rng.uniform(-3.0, 3.0))
            .collect();
        let finger = rng.uniform(0.0, 0.04);
        q[info.coordinate_index("panda_finger_joint1").unwrap()] = finger;
        q[info.coordinate_index("panda_finger_joint2").unwrap()] = finger;
        let u: Vec<f64> = info.speeds.iter().map(|_| rng.uniform(-2.0, 2.0)).collect();
        let inputs: Vec<f64> = info
            .inputs
            .iter()
            .map(|_| rng.uniform(-10.0, 10.0))
            .collect();
        let mut s: Vec<f64> = info
            .retained
            .iter()
            .map(|c| q[info.coordinate_index(c).unwrap()])
            .collect();
        s.extend(&u);
        let mut d = vec![0.0; s.len()];
        model.rhs(&prepared, 0.0, &s, &inputs, &mut d).unwrap();
        let o = appell::oracle::reduced_rhs(&model, 0.0, &q, &u, &inputs).unwrap();
        for (a, b) in d.iter().zip(&o) {
            worst = worst.max((a - b).abs() / (1.0 + a.abs().max(b.abs())));
        }
    }
    println!("Panda with mimic fingers: largest relative difference to the oracle {worst:.2e}");
    assert!(worst < 1e-9, "{worst:.2e}");
}

#[test]
fn eval_takes_the_joint_names() {
    let line = br#"{"q": {"shoulder_pan_joint": 0.0, "shoulder_lift_joint": -0.5, "elbow_joint": 1.0, "wrist_1_joint": 0.1, "wrist_2_joint": 0.2, "wrist_3_joint": 0.3},
        "u": {"shoulder_pan_joint": 0.3, "shoulder_lift_joint": 0.0, "elbow_joint": 0.0, "wrist_1_joint": 0.0, "wrist_2_joint": 0.0, "wrist_3_joint": 0.0},
        "inputs": {"tau_shoulder_pan_joint": 0.0, "tau_shoulder_lift_joint": 0.0, "tau_elbow_joint": 2.0, "tau_wrist_1_joint": 0.0, "tau_wrist_2_joint": 0.0, "tau_wrist_3_joint": 0.0}}"#;
    let line: Vec<u8> = line.iter().copied().filter(|c| *c != b'\n').collect();
    let mut out = Vec::new();
    let args: Vec<String> = ["ur5", "eval"].iter().map(|s| s.to_string()).collect();
    appell::cli::run_with(ur5::Ur5, &args, &mut &line[..], &mut out, |_| Ok(())).unwrap();
    let v: serde_json::Value = serde_json::from_slice(&out).unwrap();
    let info = ur5::Ur5::info();
    assert_eq!(info.retained[0], "shoulder_lift_joint");
    let mut s = vec![-0.5, 1.0, 0.1, 0.2, 0.3];
    s.extend([0.3, 0.0, 0.0, 0.0, 0.0, 0.0]);
    let inputs = [0.0, 0.0, 2.0, 0.0, 0.0, 0.0];
    let mut d = vec![0.0; s.len()];
    let model = ur5::Ur5;
    model
        .rhs(&model.prepare::<f64>(), 0.0, &s, &inputs, &mut d)
        .unwrap();
    assert_eq!(v["udot"]["elbow_joint"].as_f64(), Some(d[5 + 2]), "{v}");
}

#[test]
fn links_on_fixed_joints_are_one_body_with_their_parent() {
    // Bodies as the file has them (the dummy is one; the foot of zero mass
    // is not, its inertia is the forearm's).
    let names: Vec<&str> = FixedParts::info().bodies.iter().map(|b| b.name).collect();
    assert_eq!(names, ["arm", "dummy", "forearm", "tool"]);
    let d = largest_difference(&FixedParts, &FixedPartsMerged, 500, 21);
    println!("parts on fixed joints against their inertias merged by NumPy: {d:.1e}");
    assert!(d <= 1e-12, "{d:.2e}");
}

#[test]
fn an_unphysical_inertia_is_taken_as_written_when_asked() {
    let info = Lopsided::info();
    assert_eq!(info.coordinates, ["shoulder"]);
    // One pendulum: (τ − m g l cos q) / (I_yy + m l²) with l = 0.2 along
    // x, the axis y; at q = 0 the weight pulls with m g l.
    let model = Lopsided;
    let mut d = [0.0; 2];
    model
        .rhs(&model.prepare::<f64>(), 0.0, &[0.0, 0.0], &[0.0], &mut d)
        .unwrap();
    let want = 9.81 * 0.2 / (0.1 + 0.2 * 0.2);
    assert!((d[1] - want).abs() < 1e-12, "{} against {want}", d[1]);
}

#[test]
fn mimic_false_makes_mimic_joints_independent() {
    let info = PandaIndependentFingers::info();
    assert_eq!(info.holonomic, 0);
    assert!(info.dependent.is_empty());
    assert_eq!(info.speeds.len(), 9);
    assert!(info.inputs.contains(&"tau_panda_finger_joint2"));
}

#[test]
fn a_link_named_as_its_joint_gets_link_after_its_name() {
    let info = NamedAlike::info();
    assert_eq!(info.coordinates, ["gripper"]);
    assert_eq!(info.inputs, ["tau_gripper"]);
    let names: Vec<&str> = info.bodies.iter().map(|b| b.name).collect();
    assert_eq!(names, ["gripper_link"]);
}

#[test]
fn a_planar_joint_of_the_file_agrees_with_the_oracle() {
    let info = PlanarInside::info();
    assert_eq!(
        info.coordinates,
        ["slide_x", "slide_y", "slide_angle", "hinge"]
    );
    let worst = common::agree_with_inputs(&PlanarInside, &mut Rng(23), 300, PI, 20.0);
    println!("cart on a planar joint of its URDF against the oracle: {worst:.1e}");
    assert!(worst < 1e-9, "{worst:.2e}");
}
