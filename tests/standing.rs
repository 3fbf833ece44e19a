//! Legged robots standing on their feet: a `contact(foot, point)` per foot
//! and a scene per contact set, against Pinocchio 4.1.0's constrained
//! forward dynamics (`forwardDynamics` with the feet's Jacobians and
//! drifts) at 20 random states a set that keep the feet still
//! (`tests/reference/pinocchio/contacts/`, written by
//! `make_contacts_reference.py`).
//!
//! A scene holds its feet; the model itself is the robot in the air. The
//! scene's rhs gives the accelerations of its privileged speeds (the base's
//! and the free legs' joints: each stance foot makes its leg's three joints
//! dependent), `appell::constraint_forces` the multipliers, which are the
//! ground's forces on the feet in the world's axes, and the joint
//! accelerations of the stance legs. Both are compared with Pinocchio's
//! ddq and λ through `appell::pinocchio::PinocchioMap`.

use appell::constraint_forces::{contact_forces, FootForce, Friction};
use appell::pinocchio::PinocchioMap;
use appell::{Appell, Model, RowSource};
use serde_json::Value;

/// Solo12 on a free base with a point contact at each foot, standing on
/// all four or trotting on a diagonal pair.
#[allow(clippy::duplicated_attributes)] // the scenes name effects alike
#[derive(Appell, Clone, Debug, Default)]
#[appell(urdf("tests/robots/solo/solo12.urdf", base = free), gravity(-9.81 * N.z))]
#[appell(contact(FL_FOOT, point, effect = fl), contact(FR_FOOT, point, effect = fr))]
#[appell(contact(HL_FOOT, point, effect = hl), contact(HR_FOOT, point, effect = hr))]
#[appell(scene(standing, effects(gravity, actuation, fl, fr, hl, hr)))]
#[appell(scene(trotting, effects(gravity, actuation, fl, hr)))]
struct Solo12;

/// Unitree G1 (29 joints) on a free base with its two feet flat: in double
/// support or standing on its left foot.
#[allow(clippy::duplicated_attributes)] // the scenes name effects alike
#[derive(Appell, Clone, Debug, Default)]
#[appell(urdf("tests/robots/g1/g1_29dof_rev_1_0.urdf", base = free), gravity(-9.81 * N.z))]
#[appell(contact(left_ankle_roll_link, flat, effect = left))]
#[appell(contact(right_ankle_roll_link, flat, effect = right))]
#[appell(scene(double_support, effects(gravity, actuation, left, right)))]
#[appell(scene(left_support, effects(gravity, actuation, left)))]
struct G1;

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("a list")
        .iter()
        .map(|x| x.as_f64().expect("a number"))
        .collect()
}

/// max |a − b| / (1 + max |b|).
fn relative(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let scale = 1.0 + b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let worst = a
        .iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    worst / scale
}

/// The worst relative differences of the scene's accelerations and contact
/// forces to Pinocchio's, over the reference's states (`Full` is the robot
/// in the air, whose coordinates and speeds the scene's are among).
fn worst_difference<Full: Model, S: Model>(scene: &S, set: &str) -> (f64, f64) {
    let path = format!(
        "{}/tests/reference/pinocchio/contacts/{set}.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let data: Value =
        serde_json::from_str(&std::fs::read_to_string(path).expect("file")).expect("JSON");
    let joints: Vec<&str> = data["joints"].as_array().expect("joints")[1..]
        .iter()
        .map(|j| j["name"].as_str().expect("name"))
        .collect();
    let (full, info) = (Full::info(), S::info());
    let map = PinocchioMap::free("root_joint", full.coordinates, full.speeds, &joints).unwrap();
    let (n, l, nv) = (full.coordinates.len(), full.speeds.len(), map.nv());
    let prepared = scene.prepare::<f64>();
    let (mut worst_a, mut worst_f, mut worst_cop) = (0.0f64, 0.0f64, 0.0f64);
    let (mut centres, mut flat) = (0, false);
    for s in data["states"].as_array().expect("states") {
        let (q_pin, v_pin, tau) = (numbers(&s["q"]), numbers(&s["v"]), numbers(&s["tau"]));
        let (mut q, mut u) = (vec![0.0; n], vec![0.0; l]);
        map.q_from_pinocchio(&q_pin, &mut q).unwrap();
        map.v_from_pinocchio(&q, &v_pin, &mut u).unwrap();
        let speed = |name: &str| full.speeds.iter().position(|s| *s == name).unwrap();
        let scene_u: Vec<f64> = info.speeds.iter().map(|s| u[speed(s)]).collect();
        let inputs: Vec<f64> = info
            .inputs
            .iter()
            .map(|i| {
                let j = joints
                    .iter()
                    .position(|j| Some(*j) == i.strip_prefix("tau_"));
                tau[6 + j.expect("an actuated joint")]
            })
            .collect();
        // The scene's rhs on its reduced state.
        let mut state: Vec<f64> = info
            .retained
            .iter()
            .map(|c| q[info.coordinate_index(c).unwrap()])
            .collect();
        let k = state.len();
        state.extend(&scene_u);
        let mut d = vec![0.0; state.len()];
        scene.rhs(&prepared, 0.0, &state, &inputs, &mut d).unwrap();
        // The multipliers and the stance joints' accelerations.
        let forces = contact_forces(scene, 0.0, &q, &scene_u, &inputs).unwrap();
        let u_dot: Vec<f64> = full
            .speeds
            .iter()
            .map(|s| match info.speeds.iter().position(|x| x == s) {
                Some(k_s) => d[k + k_s],
                None => forces.qddot[full.coordinate_index(s).expect("a joint's rate")],
            })
            .collect();
        let mut a = vec![0.0; nv];
        map.a_to_pinocchio(&q, &u, &u_dot, &mut a).unwrap();
        worst_a = worst_a.max(relative(&a, &numbers(&s["ddq"])));
        // The feet's rows (the base's unit quaternion has a row too).
        let feet: Vec<f64> = info
            .row_sources
            .iter()
            .zip(&forces.multipliers)
            .filter(|(r, _)| matches!(r, RowSource::Contact { .. }))
            .map(|(_, m)| *m)
            .collect();
        worst_f = worst_f.max(relative(&feet, &numbers(&s["lambda"])));
        // The same multipliers gathered by foot: the force at the link's
        // origin, then a flat foot's moment about it, foot after foot.
        let links: Vec<&str> = forces.feet.iter().map(|f| f.link).collect();
        let by_foot: Vec<f64> = forces
            .feet
            .iter()
            .flat_map(|f| f.force.iter().chain(f.moment.iter().flatten()).copied())
            .collect();
        assert_eq!(by_foot, feet, "{set}: the feet {links:?}");
        let (residual, pressed) = center_of_pressure_residual(&forces.feet);
        worst_cop = worst_cop.max(residual);
        centres += pressed;
        flat |= forces.feet.iter().any(|f| f.moment.is_some());
    }
    assert!(
        worst_cop < 1e-12,
        "{set}: moment about the centre of pressure {worst_cop:.1e}"
    );
    assert!(!flat || centres > 0, "{set}: no flat foot pressed down");
    println!(
        "{set}: {} speeds, {} operations per rhs call; worst relative difference to Pinocchio: accelerations {worst_a:.1e}, contact forces {worst_f:.1e}; {centres} centres of pressure, worst moment along the ground {worst_cop:.1e}",
        info.speeds.len(),
        info.rhs_ops.total
    );
    (worst_a, worst_f)
}

/// The largest component along the ground of the feet's moments about
/// their centres of pressure on the plane z = 0 (zero by definition),
/// relative to the force times the origin's height.
fn center_of_pressure_residual(feet: &[FootForce]) -> (f64, usize) {
    let (mut worst, mut pressed) = (0.0f64, 0);
    for foot in feet {
        let (Some(m), Some(p)) = (foot.moment, foot.center_of_pressure(0.0)) else {
            assert!(foot.moment.is_none() || foot.force[2] <= 0.0, "{foot:?}");
            continue;
        };
        let (f, o) = (foot.force, foot.position);
        let r = [o[0] - p[0], o[1] - p[1], o[2] - p[2]];
        let about = [
            m[0] + r[1] * f[2] - r[2] * f[1],
            m[1] + r[2] * f[0] - r[0] * f[2],
        ];
        let scale = f.iter().map(|x| x.abs()).sum::<f64>() * (1.0 + o[2].abs());
        worst = worst.max(about[0].abs().max(about[1].abs()) / scale);
        pressed += 1;
        // The friction the foot needs is the horizontal force over F_z.
        let Friction::Required { mu, normal, .. } = foot.friction() else {
            panic!("{foot:?} pushes down")
        };
        assert_eq!(normal, f[2]);
        assert!((mu - f[0].hypot(f[1]) / f[2]).abs() <= 1e-15 * (1.0 + mu));
    }
    (worst, pressed)
}

#[test]
fn a_stance_foot_makes_its_legs_joints_dependent() {
    let four = Solo12Standing::info();
    assert_eq!(
        four.speeds,
        [
            "root_joint_wx",
            "root_joint_wy",
            "root_joint_wz",
            "root_joint_x",
            "root_joint_y",
            "root_joint_z"
        ]
    );
    assert!(
        four.form
            .starts_with("structured: M by the composite-rigid-body algorithm")
            && four.form.contains("projected onto the scene's"),
        "{}",
        four.form
    );
    let trot = Solo12Trotting::info();
    assert_eq!(trot.speeds.len(), 12);
    for leg in ["FR", "HL"] {
        for joint in ["HAA", "HFE", "KFE"] {
            assert!(trot.speeds.contains(&format!("{leg}_{joint}").as_str()));
        }
    }
    // The model itself is the robot in the air, in its structured form.
    let info = Solo12::info();
    assert_eq!(info.speeds.len(), 18);
    // Its one row is the base quaternion's unit norm.
    assert_eq!((info.holonomic, info.constraints), (1, 1));
    assert!(info.form.starts_with("structured"), "{}", info.form);
}

#[test]
fn solo12_on_its_feet_agrees_with_pinocchio() {
    let robot = Solo12;
    let four = worst_difference::<Solo12, _>(Solo12Standing::from_ref(&robot), "solo12_four_feet");
    let trot = worst_difference::<Solo12, _>(Solo12Trotting::from_ref(&robot), "solo12_trot_fl_hr");
    for (set, (a, f)) in [("four feet", four), ("trot", trot)] {
        assert!(
            a < 1e-9 && f < 1e-9,
            "{set}: accelerations {a:.1e}, forces {f:.1e}"
        );
    }
}

#[test]
fn g1_on_its_flat_feet_agrees_with_pinocchio() {
    let robot = G1;
    let double = worst_difference::<G1, _>(G1DoubleSupport::from_ref(&robot), "g1_double_support");
    let left = worst_difference::<G1, _>(G1LeftSupport::from_ref(&robot), "g1_left_support");
    for (set, (a, f)) in [("double support", double), ("left support", left)] {
        assert!(
            a < 1e-9 && f < 1e-9,
            "{set}: accelerations {a:.1e}, forces {f:.1e}"
        );
    }
}

/// A body on one leg (`tests/data/one_leg.urdf`), in the air or standing.
#[derive(Appell, Clone, Debug, Default)]
#[appell(urdf("tests/data/one_leg.urdf", base = free), gravity(-9.81 * N.z))]
#[appell(contact(foot, point, effect = stance))]
#[appell(scene(standing, effects(gravity, actuation, stance)))]
struct OneLeg;

/// The one-legged robot upright at height `z` with its hip pitched by
/// `hip` and its knee bent by `knee` (full coordinates; the model and its
/// scene have the same ones).
fn upright(z: f64, hip: f64, knee: f64) -> Vec<f64> {
    let info = OneLeg::info();
    let at = |name: &str| info.coordinate_index(name).unwrap();
    let mut q = vec![0.0; info.coordinates.len()];
    q[at("root_joint_qw")] = 1.0;
    q[at("root_joint_z")] = z;
    q[at("hip_pitch")] = hip;
    q[at("knee")] = knee;
    q
}

#[test]
fn a_falling_robot_lands_on_its_foot_with_the_impulse_that_stops_it() {
    use appell::hybrid::{Guard, Hybrid, Phase};
    let robot = OneLeg;
    let standing = OneLegStanding::from_ref(&robot);
    assert_eq!(OneLeg::contact_links(), ["foot"]);
    let phases = vec![
        Phase::new("flight", &robot).guard(Guard::touchdown(1, &robot, 0).impact(standing, 0.0)),
        Phase::new("standing", standing),
    ];
    // Upright, the knee bent, 0.5 m up and at rest: it falls as one body
    // (no torque turns a joint in free fall) until the foot reaches the
    // ground.
    let q = upright(0.5, 0.3, -0.6);
    let mut feet = [[0.0; 3]];
    robot.contact_points(0.0, &q, &mut feet).unwrap();
    let height = feet[0][2];
    assert!((height - (0.5 - 0.05 - 0.2 * 0.3f64.cos() - 0.2 * 0.3f64.cos())).abs() < 1e-12);
    let run = Hybrid::new(phases)
        .run::<19>(0, 0.0, &q, &[0.0; 9], 0.2)
        .expect("a landing");
    assert_eq!(run.switches.len(), 1);
    let landing = &run.switches[0];
    assert_eq!(
        (landing.reason, landing.from, landing.to),
        ("touchdown", 0, 1)
    );
    // The free fall's time and speed at the ground.
    let t = (2.0 * height / 9.81).sqrt();
    assert!((landing.t - t).abs() < 1e-6, "{} against {t}", landing.t);
    // The ground's impulse on the foot pushes up, at most what stops the
    // whole robot (4 kg at g t), and the plastic landing loses energy.
    let row = OneLegStanding::info()
        .row_sources
        .iter()
        .position(|r| {
            *r == RowSource::Contact {
                contact: 0,
                axis: 2,
            }
        })
        .unwrap();
    let up = landing.impulses[row];
    assert!(up > 0.0 && up < 4.0 * 9.81 * t, "impulse {up}");
    assert!(landing.energy_lost > 0.0);
    // Standing, the foot stays where it landed.
    let mut after = [[0.0; 3]];
    robot.contact_points(0.0, &run.end.q, &mut after).unwrap();
    let mut at_landing = [[0.0; 3]];
    let sample = run
        .samples
        .iter()
        .find(|s| s.phase == 1)
        .expect("a standing sample");
    robot
        .contact_points(0.0, &sample.q, &mut at_landing)
        .unwrap();
    for k in 0..3 {
        assert!(
            (after[0][k] - at_landing[0][k]).abs() < 1e-9,
            "{after:?} {at_landing:?}"
        );
    }
    assert!(after[0][2].abs() < 1e-6);
}

#[test]
fn the_lift_off_guard_is_the_grounds_push_along_n_z() {
    use appell::constraint_forces::contact_forces;
    use appell::hybrid::Guard;
    let robot = OneLeg;
    let standing = OneLegStanding::from_ref(&robot);
    let info = OneLegStanding::info();
    let q = upright(0.4, 0.3, -0.6);
    let u = [0.1, -0.2, 0.05, 0.3, 0.0, -0.1];
    let inputs = [0.5, -1.0, 2.0];
    let guard = Guard::contact_lift_off(0, standing, 0, &inputs);
    let push = (guard.value)(0.0, &q, &u).unwrap();
    let forces = contact_forces(standing, 0.0, &q, &u, &inputs).unwrap();
    let row = info
        .row_sources
        .iter()
        .position(|r| {
            *r == RowSource::Contact {
                contact: 0,
                axis: 2,
            }
        })
        .unwrap();
    assert_eq!(push, forces.multipliers[row]);
    assert!(push > 0.0);
    // The model in the air holds no contact: the guard says so.
    let in_the_air = Guard::contact_lift_off(0, &robot, 0, &inputs);
    assert!(matches!(
        (in_the_air.value)(0.0, &q, &[0.0; 9]),
        Err(appell::ModelError::Contact { .. })
    ));
    // A touchdown guard past the declared contacts says so too.
    let nowhere = Guard::touchdown(0, &robot, 3);
    assert!(matches!(
        (nowhere.value)(0.0, &q, &[0.0; 9]),
        Err(appell::ModelError::Contact { .. })
    ));
}

#[test]
fn the_urdfs_joint_limits_are_kept() {
    let limits = OneLeg::joint_limits();
    let joints: Vec<&str> = limits.iter().map(|l| l.joint).collect();
    assert_eq!(joints, ["hip_roll", "hip_pitch", "knee"]);
    let knee = limits[2];
    assert_eq!(
        (knee.lower, knee.upper, knee.velocity, knee.effort),
        (-2.5, 0.0, 10.0, 10.0)
    );
    // A scene has the model's.
    assert_eq!(OneLegStanding::joint_limits(), limits);
    // Solo12's knees, as its URDF gives them (`<limit effort="1000"
    // lower="-10" upper="10" velocity="1000"/>`).
    let kfe = Solo12::joint_limits()
        .iter()
        .find(|l| l.joint == "FL_KFE")
        .expect("FL_KFE");
    assert_eq!(
        (kfe.lower, kfe.upper, kfe.velocity, kfe.effort),
        (-10.0, 10.0, 1000.0, 1000.0)
    );
}

#[test]
fn a_stance_leg_stretched_straight_is_a_typed_error_not_a_nan() {
    // Knee straight: the hip pitch and the knee move the foot the same
    // way, and the stance leg's rates are not determined.
    let robot = OneLeg;
    let standing = OneLegStanding::from_ref(&robot);
    let info = OneLegStanding::info();
    let q = upright(0.45, 0.0, 0.0);
    let at = |name: &str| info.coordinate_index(name).unwrap();
    let mut x: Vec<f64> = info.retained.iter().map(|c| q[at(c)]).collect();
    x.extend([0.0; 6]);
    let mut rates = vec![0.0; x.len()];
    let result = standing.rhs(&standing.prepare::<f64>(), 0.0, &x, &[0.0; 3], &mut rates);
    assert!(result.is_err(), "{result:?}: {rates:?}");
}

#[test]
fn the_command_line_reports_each_foots_force() {
    let robot = OneLeg;
    let standing = OneLegStanding::from_ref(&robot);
    let info = OneLegStanding::info();
    let q = upright(0.4, 0.3, -0.6);
    let u: Vec<f64> = (0..info.speeds.len())
        .map(|k| 0.1 * k as f64 - 0.3)
        .collect();
    let inputs: Vec<f64> = (0..info.inputs.len())
        .map(|k| 0.5 - 0.2 * k as f64)
        .collect();
    let object = |names: &[&str], values: &[f64]| {
        let map: serde_json::Map<String, Value> = names
            .iter()
            .zip(values)
            .map(|(n, v)| (n.to_string(), serde_json::json!(v)))
            .collect();
        Value::Object(map)
    };
    let line = serde_json::json!({
        "q": object(info.coordinates, &q),
        "u": object(info.speeds, &u),
        "inputs": object(info.inputs, &inputs),
    })
    .to_string();
    let args: Vec<String> = ["one_leg", "contacts", "--scene", "standing"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let mut out = Vec::new();
    appell::cli::run_with(robot.clone(), &args, &mut line.as_bytes(), &mut out, |_| {
        Ok(())
    })
    .unwrap();
    let answer: Value = serde_json::from_slice(&out).unwrap();
    let forces = contact_forces(standing, 0.0, &q, &u, &inputs).unwrap();
    let [foot] = &forces.feet[..] else {
        panic!("{:?}", forces.feet)
    };
    let mut at = [[0.0; 3]];
    robot.contact_points(0.0, &q, &mut at).unwrap();
    assert_eq!((foot.link, foot.contact, foot.position), ("foot", 0, at[0]));
    assert_eq!(foot.moment, None);
    let json = &answer["feet"][0];
    assert_eq!(json["link"], "foot");
    assert_eq!(numbers(&json["force"]), foot.force.to_vec());
    assert_eq!(numbers(&json["position"]), foot.position.to_vec());
    assert_eq!(json["moment"], Value::Null);
    // The foot's force is the multipliers of its three rows, by axis.
    for (axis, force) in foot.force.iter().enumerate() {
        let row = info
            .row_sources
            .iter()
            .position(|r| *r == RowSource::Contact { contact: 0, axis })
            .unwrap();
        assert_eq!(*force, forces.multipliers[row]);
    }
    match foot.friction() {
        Friction::Required { mu, .. } => assert_eq!(json["friction"]["mu"], serde_json::json!(mu)),
        Friction::LiftOff { normal } => {
            assert_eq!(json["friction"]["lift_off"], serde_json::json!(normal))
        }
        other => panic!("{other:?}"),
    }
}
