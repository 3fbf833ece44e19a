//! Scenes that leave constraints out: a constraint that belongs to an
//! effect (`effect = grip`) is kept only by the scenes that name it, and a
//! scene with fewer constraints names its own privileged speeds. Each such
//! scene is derived again with its own constraints, so it costs what a
//! model written with that constraint set alone costs, and moves as it.

mod common;
use appell::{Appell, Model};
use common::Rng;

/// The Chaplygin sleigh on an incline whose knife edge either grips (the
/// `grip` constraint: no sideways velocity at P) or skids sideways against
/// a viscous drag.
#[allow(clippy::duplicated_attributes)] // the scenes name effects alike
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(coordinates(x, y, theta), speeds(x, theta), positive(m, b))]
#[appell(frame(B = N.rotate_z(theta)))]
#[appell(point(P = O + x * N.x + y * N.y), point(C = P + b * B.x))]
#[appell(body(sleigh, center = C, frame = B, mass = m, inertia = principal(i0, i0, i0)))]
#[appell(nonholonomic(dt(y) * cos(theta) - dt(x) * sin(theta) == 0, effect = grip))]
#[appell(force(C, m * g * sin(alpha) * N.x, effect = gravity))]
#[appell(force(P, -c * dot(velocity(P), B.y) * B.y, effect = drag))]
#[appell(scene(gripping, effects(gravity, grip)))]
#[appell(scene(skidding, effects(gravity, drag), speeds(x, y, theta)))]
struct Sleigh {
    m: f64,
    i0: f64,
    b: f64,
    g: f64,
    alpha: f64,
    c: f64,
}

/// The skidding sleigh written on its own: no constraint, three speeds.
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(coordinates(x, y, theta), speeds(x, y, theta), positive(m, b))]
#[appell(frame(B = N.rotate_z(theta)))]
#[appell(point(P = O + x * N.x + y * N.y), point(C = P + b * B.x))]
#[appell(body(sleigh, center = C, frame = B, mass = m, inertia = principal(i0, i0, i0)))]
#[appell(force(C, m * g * sin(alpha) * N.x, effect = gravity))]
#[appell(force(P, -c * dot(velocity(P), B.y) * B.y, effect = drag))]
struct SkiddingSleigh {
    m: f64,
    i0: f64,
    b: f64,
    g: f64,
    alpha: f64,
    c: f64,
}

/// The gripping sleigh written on its own, with gravity only.
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(coordinates(x, y, theta), speeds(x, theta), positive(m, b))]
#[appell(frame(B = N.rotate_z(theta)))]
#[appell(point(P = O + x * N.x + y * N.y), point(C = P + b * B.x))]
#[appell(body(sleigh, center = C, frame = B, mass = m, inertia = principal(i0, i0, i0)))]
#[appell(nonholonomic(dt(y) * cos(theta) - dt(x) * sin(theta) == 0))]
#[appell(force(C, m * g * sin(alpha) * N.x, effect = gravity))]
struct GrippingSleigh {
    m: f64,
    i0: f64,
    b: f64,
    g: f64,
    alpha: f64,
}

fn sleigh(rng: &mut Rng) -> Sleigh {
    Sleigh {
        m: rng.uniform(0.5, 2.0),
        i0: rng.uniform(0.02, 0.2),
        b: rng.uniform(0.1, 0.5),
        g: 9.81,
        alpha: rng.uniform(0.05, 0.5),
        c: rng.uniform(0.5, 5.0),
    }
}

/// The reduced rhs of `model` at its reduced state `x`.
fn rhs<M: Model>(model: &M, x: &[f64]) -> Vec<f64> {
    let mut dx = vec![0.0; x.len()];
    model
        .rhs(&model.prepare::<f64>(), 0.0, x, &[], &mut dx)
        .expect("the rhs evaluates");
    dx
}

#[test]
fn a_scene_without_a_constraint_has_its_own_speeds_and_state() {
    let infos = Sleigh::scene_infos();
    let names: Vec<&str> = infos.iter().map(|i| i.name).collect();
    assert_eq!(names, ["Sleigh::gripping", "Sleigh::skidding"]);
    let (gripping, skidding) = (infos[0], infos[1]);
    assert_eq!(gripping.speeds, ["x", "theta"]);
    assert_eq!((gripping.constraints, gripping.dependent), (1, &["y"][..]));
    assert_eq!(skidding.speeds, ["x", "y", "theta"]);
    assert_eq!((skidding.constraints, skidding.dependent), (0, &[][..]));
    // Nothing depends on where the sleigh is: x and y leave the state.
    assert_eq!(skidding.retained, ["theta"]);
    assert_eq!(skidding.state_len(), 4);
    assert_eq!(Sleigh::info().effects, ["gravity", "drag", "grip"]);
    for info in [Sleigh::info(), gripping, skidding] {
        println!(
            "{}: state {:?} + {:?}, {} ops",
            info.name, info.retained, info.speeds, info.rhs_ops.total
        );
    }
}

#[test]
fn each_scene_costs_and_moves_as_the_model_written_with_its_constraints_alone() {
    // The same equations, lowered from a graph holding other expressions
    // too: the shared subexpressions may be grouped differently, by an
    // operation or two (as for the load-only scenes of tests/scene_costs.rs).
    let pairs = [
        ("skidding", SleighSkidding::info(), SkiddingSleigh::info()),
        ("gripping", SleighGripping::info(), GrippingSleigh::info()),
    ];
    for (label, scene, alone) in pairs {
        let (a, b) = (scene.rhs_ops.total, alone.rhs_ops.total);
        println!("{label}: scene {a} ops, written alone {b} ops");
        assert!(
            a.abs_diff(b) as f64 <= 0.05 * b as f64,
            "{label}: {a} against {b}"
        );
        assert_eq!(
            (scene.speeds, scene.retained),
            (alone.speeds, alone.retained)
        );
    }
    let mut rng = Rng(23);
    let mut worst = 0.0f64;
    for _ in 0..20 {
        let s = sleigh(&mut rng);
        let alone = SkiddingSleigh {
            m: s.m,
            i0: s.i0,
            b: s.b,
            g: s.g,
            alpha: s.alpha,
            c: s.c,
        };
        let x: Vec<f64> = (0..4).map(|_| rng.uniform(-2.0, 2.0)).collect();
        let (a, b) = (rhs(SleighSkidding::from_ref(&s), &x), rhs(&alone, &x));
        let gripping = GrippingSleigh {
            m: s.m,
            i0: s.i0,
            b: s.b,
            g: s.g,
            alpha: s.alpha,
        };
        let xg: Vec<f64> = (0..SleighGripping::info().state_len())
            .map(|_| rng.uniform(-2.0, 2.0))
            .collect();
        let (c, d) = (rhs(SleighGripping::from_ref(&s), &xg), rhs(&gripping, &xg));
        // The whole model grips too, and its drag, across a velocity that
        // the grip holds at zero, does nothing.
        let full = rhs(&s, &xg);
        for (p, q) in full.iter().zip(&c) {
            worst = worst.max((p - q).abs() / (1.0 + q.abs()));
        }
        for (p, q) in a.iter().zip(&b).chain(c.iter().zip(&d)) {
            worst = worst.max((p - q).abs() / (1.0 + q.abs()));
        }
        // The drag matters when skidding: a different drag moves it differently.
        let stiffer = Sleigh {
            c: s.c * 2.0,
            ..s.clone()
        };
        let e = rhs(SleighSkidding::from_ref(&stiffer), &x);
        assert!(e.iter().zip(&a).any(|(p, q)| (p - q).abs() > 1e-6) || x[2].abs() < 1e-9);
    }
    assert!(worst <= 1e-14, "scene against the model alone: {worst:e}");
}

/// Full coordinates and the gripping sleigh's speeds at a random state.
fn random_motion(rng: &mut Rng) -> ([f64; 3], Vec<f64>) {
    let q = [
        rng.uniform(-1.0, 1.0),
        rng.uniform(-1.0, 1.0),
        rng.uniform(-3.0, 3.0),
    ];
    (q, vec![rng.uniform(-2.0, 2.0), rng.uniform(-2.0, 2.0)])
}

#[test]
fn releasing_the_grip_keeps_the_motion() {
    use appell::switch::switch_state;
    let mut rng = Rng(5);
    for _ in 0..20 {
        let s = sleigh(&mut rng);
        let (q, u) = random_motion(&mut rng);
        let (grip, skid) = (SleighGripping::from_ref(&s), SleighSkidding::from_ref(&s));
        let out = switch_state(grip, skid, 0.0, &q, &u, &[], &[]).unwrap();
        // The skidding speeds are the rates the gripping motion had.
        let mut qdot = [0.0; 3];
        grip.coordinate_rates(0.0, &q, &u, &mut qdot).unwrap();
        for (a, b) in out.speeds.iter().zip(&qdot) {
            assert!((a - b).abs() <= 1e-15 * (1.0 + b.abs()), "{a} against {b}");
        }
        assert!(out.impulses.is_empty());
        assert!(
            out.energy_lost().abs() <= 1e-14 * out.kinetic_before,
            "{out:?}"
        );
        // And back: the motion still satisfies the grip, so nothing jumps.
        let back = switch_state(skid, grip, 0.0, &q, &out.speeds, &[], &[]).unwrap();
        assert!(back.impulses.is_empty());
        for (a, b) in back.speeds.iter().zip(&u) {
            assert!((a - b).abs() <= 1e-14 * (1.0 + b.abs()));
        }
    }
}

#[test]
fn gripping_again_takes_the_sideways_impulse_and_its_energy() {
    use appell::switch::switch_state;
    let mut rng = Rng(11);
    let mut worst = 0.0f64;
    for _ in 0..20 {
        let s = sleigh(&mut rng);
        let q = [
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
            rng.uniform(-3.0, 3.0),
        ];
        let u: Vec<f64> = (0..3).map(|_| rng.uniform(-2.0, 2.0)).collect();
        let (grip, skid) = (SleighGripping::from_ref(&s), SleighSkidding::from_ref(&s));
        let out = switch_state(skid, grip, 0.0, &q, &u, &[], &[]).unwrap();
        // Closed form: the sideways velocity of the blade, v = ẏ cos θ −
        // ẋ sin θ, is stopped by an impulse Λ at P along B.y, against the
        // effective mass 1/(1/m + b²/I) the blade feels there.
        let (sin, cos) = q[2].sin_cos();
        let v = u[1] * cos - u[0] * sin;
        let reduced = 1.0 / (1.0 / s.m + s.b * s.b / s.i0);
        let (impulse, lost) = (-reduced * v, 0.5 * reduced * v * v);
        let scale = 1.0 + impulse.abs();
        worst = worst.max((out.impulses[0] - impulse).abs() / scale);
        worst = worst.max((out.energy_lost() - lost).abs() / (1.0 + lost));
        // After the switch the grip holds.
        let after = out.qdot[1] * cos - out.qdot[0] * sin;
        worst = worst.max(after.abs() / (1.0 + v.abs()));
        assert_eq!(out.speeds, [out.qdot[0], out.qdot[2]]);
    }
    println!("impulse, energy lost and grip after the switch against the closed form: {worst:e}");
    assert!(worst <= 1e-12, "against the closed form: {worst:e}");
}

/// A double pendulum of joints whose elbow has a brake: locked where the
/// brake holds (the full model), free in the scene without it.
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(joint(shoulder, revolute(z), parent = N, child = L1))]
#[appell(joint(elbow, revolute(z), parent = L1, child = L2, xyz = [0.5, 0, 0], dependent))]
#[appell(body(upper, frame = L1, mass = m, center = origin(L1) + 0.25 * L1.x, inertia = principal(0.01, 0.02, 0.02)))]
#[appell(body(lower, frame = L2, mass = m, center = origin(L2) + 0.25 * L2.x, inertia = principal(0.01, 0.02, 0.02)))]
#[appell(gravity(-g * N.y))]
#[appell(nonholonomic(dt(elbow) == 0, effect = brake))]
#[appell(scene(free, effects(gravity), speeds(shoulder, elbow)))]
struct BrakedArm {
    m: f64,
    g: f64,
}

#[test]
fn a_brake_locks_a_joint_in_the_scenes_that_name_it() {
    use appell::switch::switch_state;
    let arm = BrakedArm { m: 1.5, g: 9.81 };
    assert_eq!(BrakedArm::info().speeds, ["shoulder"]);
    assert_eq!(BrakedArmFree::info().speeds, ["shoulder", "elbow"]);
    // Braked, the arm swings as one body: the elbow's rate is zero.
    let (q, u) = ([0.4, 0.7], [1.3]);
    let mut qdot = [0.0; 2];
    arm.coordinate_rates(0.0, &q, &u, &mut qdot).unwrap();
    assert_eq!(qdot, [1.3, 0.0]);
    // Releasing the brake keeps the motion; engaging it again stops the
    // elbow's relative rotation with an impulse and a loss.
    let free = BrakedArmFree::from_ref(&arm);
    let released = switch_state(&arm, free, 0.0, &q, &u, &[], &[]).unwrap();
    assert_eq!(released.speeds, [1.3, 0.0]);
    assert!(released.energy_lost().abs() < 1e-14);
    let engaged = switch_state(free, &arm, 0.0, &q, &[1.3, -2.0], &[], &[]).unwrap();
    assert_eq!(engaged.impulses.len(), 1);
    assert!(engaged.energy_lost() > 0.0 && engaged.qdot[1].abs() < 1e-14);
    // The brake's impulse acts on the elbow's coordinate only: the
    // shoulder's generalized momentum (the angular momentum about the
    // pivot) is the same before and after.
    let (mut mf, mut ff) = ([0.0; 4], [0.0; 2]);
    free.mass_matrix_and_forcing(0.0, &q, &[1.3, -2.0], &[], &mut mf, &mut ff)
        .unwrap();
    let before = mf[0] * 1.3 + mf[1] * -2.0;
    let (mut mb, mut fb) = ([0.0; 1], [0.0; 1]);
    arm.mass_matrix_and_forcing(0.0, &q, &engaged.speeds, &[], &mut mb, &mut fb)
        .unwrap();
    let after = mb[0] * engaged.speeds[0];
    assert!(
        (after - before).abs() < 1e-13 * before.abs(),
        "{after} against {before}"
    );
    assert!(engaged.energy_lost() < engaged.kinetic_before);
}

/// The braked arm written with the joint property `lock = brake`, which
/// stands for the elbow marked `dependent` and
/// `nonholonomic(dt(elbow) == 0, effect = brake)`.
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(joint(shoulder, revolute(z), parent = N, child = L1))]
#[appell(joint(elbow, revolute(z), parent = L1, child = L2, xyz = [0.5, 0, 0], lock = brake))]
#[appell(body(upper, frame = L1, mass = m, center = origin(L1) + 0.25 * L1.x, inertia = principal(0.01, 0.02, 0.02)))]
#[appell(body(lower, frame = L2, mass = m, center = origin(L2) + 0.25 * L2.x, inertia = principal(0.01, 0.02, 0.02)))]
#[appell(gravity(-g * N.y))]
#[appell(scene(free, effects(gravity), speeds(shoulder, elbow)))]
struct LockedArm {
    m: f64,
    g: f64,
}

/// The largest difference between the rhs of `a` and of `b` at `x`.
fn rhs_difference<A: Model, B: Model>(a: &A, b: &B, x: &[f64]) -> f64 {
    let (a, b) = (rhs(a, x), rhs(b, x));
    a.iter()
        .zip(&b)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
}

#[test]
fn a_locked_joint_is_the_brake_written_by_hand() {
    let shape = |i: &appell::ModelInfo| {
        let rows = (i.constraints, i.row_sources, i.effects);
        (i.speeds, i.dependent, i.retained, rows)
    };
    assert_eq!(shape(BrakedArm::info()), shape(LockedArm::info()));
    assert_eq!(shape(BrakedArmFree::info()), shape(LockedArmFree::info()));
    let mut rng = Rng(31);
    let mut worst: f64 = 0.0;
    for _ in 0..50 {
        let (m, g) = (rng.uniform(0.5, 3.0), rng.uniform(1.0, 10.0));
        let (by_hand, locked) = (BrakedArm { m, g }, LockedArm { m, g });
        let mut draw = |n: usize| (0..n).map(|_| rng.uniform(-2.0, 2.0)).collect::<Vec<_>>();
        let x = draw(BrakedArm::info().state_len());
        worst = worst.max(rhs_difference(&by_hand, &locked, &x));
        let x = draw(BrakedArmFree::info().state_len());
        let free = (
            BrakedArmFree::from_ref(&by_hand),
            LockedArmFree::from_ref(&locked),
        );
        worst = worst.max(rhs_difference(free.0, free.1, &x));
    }
    println!("locked against written by hand, braked and free: {worst:e}");
    assert!(worst <= 1e-13, "{worst:e}");
}
