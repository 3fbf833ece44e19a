//! The UR5 on a differential-drive base: the reduced state, the multiplier
//! oracle, the limit of a very heavy base (the fixed-base UR5, itself
//! checked against Pinocchio in `tests/pinocchio.rs`), and energy.

mod common;
#[path = "../examples/models/mobile_manipulator.rs"]
mod mobile_manipulator;
#[path = "../examples/models/ur5.rs"]
mod ur5;

use appell::integrate::Dop853;
use appell::Model;
use common::Rng;
use mobile_manipulator::MobileManipulator;
use ur5::Ur5;

const ARM: [&str; 6] = [
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
];

#[test]
fn the_base_leaves_the_state_and_the_contacts_are_eliminated_in_closed_form() {
    let info = MobileManipulator::info();
    println!(
        "retained {:?}, speeds {:?}, cyclic {:?}, ignorable {:?}, {} ops",
        info.retained, info.speeds, info.cyclic, info.ignorable, info.rhs_ops.total
    );
    for base in ["base_x", "base_y", "base_angle", "left", "right"] {
        assert!(!info.retained.contains(&base), "{base}");
    }
    assert_eq!(info.speeds.len(), 8);
    assert!(info.symbolic_elimination);
    assert_eq!(info.dependent, ["base_x", "base_y", "base_angle"]);
    // The arm's M and f come from the tree's recursions, projected onto the
    // eight speeds: cheaper than the closed form.
    assert!(info.form.starts_with("structured"), "{}", info.form);
}

#[test]
fn it_agrees_with_the_oracle() {
    let worst = common::agree(&MobileManipulator::default(), &mut Rng(21), 1000, 3.0);
    assert!(worst < 1e-9, "{worst:e}");
}

/// The largest relative difference between the arm's accelerations on a
/// base of mass (and inertias) `heavy` and on the fixed-base UR5.
fn heavy_base_difference(heavy: f64) -> f64 {
    let heavy = MobileManipulator {
        m_chassis: heavy,
        ixx: heavy,
        iyy: heavy,
        izz: heavy,
        m_wheel: heavy,
        i_wheel: heavy,
        ..MobileManipulator::default()
    };
    let (mi, ui) = (MobileManipulator::info(), Ur5::info());
    let arm = Ur5;
    let (pm, pu) = (heavy.prepare::<f64>(), arm.prepare::<f64>());
    let mut rng = Rng(22);
    let mut worst: f64 = 0.0;
    for _ in 0..200 {
        let angles: Vec<f64> = ARM.iter().map(|_| rng.uniform(-3.0, 3.0)).collect();
        let rates: Vec<f64> = ARM.iter().map(|_| rng.uniform(-2.0, 2.0)).collect();
        let torques: Vec<f64> = ARM.iter().map(|_| rng.uniform(-20.0, 20.0)).collect();
        // Each model's state and inputs, by name; the base at rest.
        let fill = |info: &appell::ModelInfo| {
            let at = |name: &str, values: &[f64]| {
                ARM.iter()
                    .position(|j| *j == name)
                    .map_or(0.0, |k| values[k])
            };
            let mut s: Vec<f64> = info.retained.iter().map(|c| at(c, &angles)).collect();
            s.extend(info.speeds.iter().map(|c| at(c, &rates)));
            let i: Vec<f64> = info
                .inputs
                .iter()
                .map(|name| at(name.trim_start_matches("tau_"), &torques))
                .collect();
            (s, i)
        };
        let ((sm, im), (su, iu)) = (fill(mi), fill(ui));
        let (mut dm, mut du) = (vec![0.0; sm.len()], vec![0.0; su.len()]);
        heavy
            .rhs(&pm, 0.0, &sm, &im, &mut dm)
            .map_err(|e| e.to_string())
            .unwrap();
        arm.rhs(&pu, 0.0, &su, &iu, &mut du).unwrap();
        let accel = |info: &appell::ModelInfo, d: &[f64], j: &str| {
            d[info.retained.len() + info.speeds.iter().position(|s| *s == j).unwrap()]
        };
        for j in ARM {
            let (a, b) = (accel(mi, &dm, j), accel(ui, &du, j));
            worst = worst.max((a - b).abs() / (1.0 + b.abs()));
        }
    }
    worst
}

#[test]
fn on_a_very_heavy_base_the_arm_moves_as_the_fixed_base_ur5() {
    // The base's reaction on the arm scales as (arm mass) / (base mass).
    let (a, b) = (heavy_base_difference(1e7), heavy_base_difference(1e9));
    println!("heavy base against the fixed-base UR5: {a:.2e} at 1e7 kg, {b:.2e} at 1e9 kg");
    assert!(b < 1e-6, "{b:e}");
    assert!(b < a / 30.0, "{a:e} {b:e}");
}

#[test]
fn rolling_freely_it_keeps_its_energy() {
    let model = MobileManipulator::default();
    let info = MobileManipulator::info();
    const S: usize = 6 + 8;
    assert_eq!(info.state_len(), S);
    let mut x0 = [0.0; S];
    for (k, c) in info.retained.iter().enumerate() {
        x0[k] = if *c == "shoulder_lift_joint" {
            -1.0
        } else {
            0.4
        };
    }
    x0[info.retained.len() + info.speeds.iter().position(|s| *s == "left").unwrap()] = 5.0;
    let inputs = vec![0.0; info.inputs.len()];
    let energy = |x: &[f64; S]| {
        let q: Vec<f64> = info
            .coordinates
            .iter()
            .map(|c| {
                info.retained
                    .iter()
                    .position(|r| r == c)
                    .map_or(0.0, |k| x[k])
            })
            .collect();
        let e =
            appell::energy::energies(&model, 0.0, &q, &x[info.retained.len()..], &inputs).unwrap();
        e.kinetic + e.potential
    };
    let solution = Dop853::new()
        .rtol(1e-12)
        .atol(1e-12)
        .solve_model(&model, &inputs, 0.0, &x0, 2.0)
        .unwrap();
    let (e0, e1) = (energy(&x0), energy(&solution.x));
    println!(
        "2 s rolling freely: energy {e0:.6} J, change {:.1e} J",
        e1 - e0
    );
    assert!(((e1 - e0) / e0.abs().max(1.0)).abs() < 1e-9);
}

/// Closed form with inputs on the wheels and the arm, and the arm's own
/// structured controller functions.
#[test]
fn controller_functions_agree_with_the_equations() {
    let mut rng = Rng(53);
    let worst = common::controller_agrees(&MobileManipulator::default(), &mut rng, 50, 3.0);
    assert!(worst < 1e-11, "{worst:.2e}");
    let worst = common::controller_agrees(&Ur5, &mut rng, 50, 3.0);
    assert!(worst < 1e-11, "{worst:.2e}");
}
