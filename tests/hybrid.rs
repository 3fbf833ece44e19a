//! A hybrid run: a hopping leg (a body on a spring leg with a foot) that
//! alternates stance (the foot held on the ground, a constraint of effect
//! `stance`) and flight (the constraint left out, the foot free), switching
//! at lift-off (the ground's normal force, from the constraint-force
//! output, falls to zero) and at touchdown (the foot's height reaches
//! zero, a plastic impact of the foot). Checked against closed forms.

use appell::hybrid::{Hybrid, Phase};
use appell::integrate::Dop853;

#[path = "../examples/models/hopper.rs"]
mod hopper;
use hopper::HOPPER;

/// The hop from `z0` at rest in stance for 3 s, at `rtol` (seven switches).
fn hop(z0: f64, rtol: f64) -> appell::hybrid::HybridRun {
    let solver = Dop853::new().rtol(rtol).atol(rtol * 1e-2).event_tol(1e-13);
    let run = Hybrid::new(phases())
        .solver(solver)
        .max_switches(7)
        .run::<4>(0, 0.0, &[z0, 0.0], &[0.0], 3.0);
    match run {
        Ok(run) => run,
        Err(appell::hybrid::HybridError::TooManySwitches(run)) => *run,
        Err(e) => panic!("{e}"),
    }
}

fn phases() -> Vec<Phase<'static>> {
    hopper::phases(&HOPPER)
}

fn normal_force(t: f64, q: &[f64], u: &[f64]) -> Result<f64, appell::ModelError> {
    hopper::normal_force(&HOPPER, t, q, u)
}

/// Total energy: both masses' kinetic and gravity energy and the spring's.
fn energy(q: &[f64], qdot: &[f64]) -> f64 {
    let h = &HOPPER;
    let stretch = q[0] - q[1] - h.l0;
    0.5 * h.big_m * qdot[0] * qdot[0]
        + 0.5 * h.m * qdot[1] * qdot[1]
        + (h.big_m * q[0] + h.m * q[1]) * h.g
        + 0.5 * h.k * stretch * stretch
}

#[test]
fn the_normal_force_is_the_foots_equilibrium() {
    // In stance the foot does not move: N = k (l0 − z) + m g.
    let h = &HOPPER;
    for z in [0.3, 0.45, 0.5, 0.52] {
        let n = normal_force(0.0, &[z, 0.0], &[0.7]).unwrap();
        let expected = h.k * (h.l0 - z) + h.m * h.g;
        assert!(
            (n - expected).abs() <= 1e-10 * (1.0 + expected.abs()),
            "{n} against {expected}"
        );
    }
}

#[test]
fn the_leg_lifts_off_where_the_normal_force_vanishes_and_lands_plastically() {
    let h = &HOPPER;
    // Compressed and at rest: the body oscillates about z_eq at ω until
    // the spring pulls the foot up with its weight, at z = l0 + m g / k.
    let (z0, omega) = (0.3, (h.k / h.big_m).sqrt());
    let z_eq = h.l0 - h.big_m * h.g / h.k;
    let z_lift = h.l0 + h.m * h.g / h.k;
    let t_lift = ((z_lift - z_eq) / (z0 - z_eq)).acos() / omega;
    let run = hop(z0, 1e-12);
    for s in &run.switches {
        println!(
            "t = {:.9} s: {} -> {} ({}), impulses {:?}, energy lost {:.3e} J",
            s.t, s.from, s.to, s.reason, s.impulses, s.energy_lost
        );
    }
    let first = &run.switches[0];
    assert_eq!((first.from, first.to, first.reason), (0, 1, "lift-off"));
    println!(
        "lift-off {:.1e} s from the closed form",
        (first.t - t_lift).abs()
    );
    assert!(
        (first.t - t_lift).abs() < 1e-9,
        "lift-off at {} against {t_lift}",
        first.t
    );
    // Releasing the foot keeps the motion: the body's speed and a foot at rest.
    assert!(first.impulses.is_empty() && first.energy_lost.abs() < 1e-12);
    let z_dot = -(z0 - z_eq) * omega * (omega * t_lift).sin();
    let after = run
        .samples
        .iter()
        .find(|s| s.t == first.t && s.phase == 1)
        .unwrap();
    assert!(
        (after.u[0] - z_dot).abs() < 1e-8 && after.u[1] == 0.0,
        "{after:?}"
    );
    // Stance and flight alternate; at each touchdown the foot stops, its
    // momentum the impulse and its kinetic energy the loss.
    for (k, s) in run.switches.iter().enumerate() {
        assert_eq!((s.from, s.to), if k % 2 == 0 { (0, 1) } else { (1, 0) });
    }
    for landing in run.switches.iter().filter(|s| s.reason == "touchdown") {
        let before = run
            .samples
            .iter()
            .rev()
            .find(|s| s.t == landing.t && s.phase == 1)
            .unwrap();
        let foot = before.u[1];
        assert!(foot < 0.0);
        let momentum = h.m * foot.abs();
        assert!((landing.impulses[0].abs() - momentum).abs() < 1e-12 * momentum.max(1.0));
        let lost = 0.5 * h.m * foot * foot;
        let gap = (landing.energy_lost - lost).abs();
        assert!(
            gap < 1e-12 * lost.max(1.0),
            "{} against {lost}",
            landing.energy_lost
        );
    }
    // Energy: what is left at the end is the start's less the impacts'.
    let e0 = energy(&[z0, 0.0], &[0.0, 0.0]);
    let end = &run.end;
    let qdot = if end.phase == 0 {
        vec![end.u[0], 0.0]
    } else {
        end.u.clone()
    };
    let spent: f64 = run.switches.iter().map(|s| s.energy_lost).sum();
    let gap = (energy(&end.q, &qdot) - (e0 - spent)).abs() / e0.abs();
    println!(
        "{} switches, energy balance {gap:.1e} of the total",
        run.switches.len()
    );
    assert!(gap < 1e-9, "energy balance {gap:e}");
    assert!(run.switches.len() >= 3, "it hops at least twice");
}

#[test]
fn the_switch_times_converge_with_the_tolerance() {
    // Work and precision of the hybrid run: each switch time against the
    // run at rtol 1e-12.
    let reference = hop(0.3, 1e-12);
    let mut errors = Vec::new();
    for rtol in [1e-5, 1e-7, 1e-9] {
        let run = hop(0.3, rtol);
        assert_eq!(
            run.switches.len(),
            reference.switches.len(),
            "rtol {rtol:e}"
        );
        let worst = run
            .switches
            .iter()
            .zip(&reference.switches)
            .map(|(a, b)| (a.t - b.t).abs())
            .fold(0.0f64, f64::max);
        println!("rtol {rtol:e}: switch times within {worst:.1e} s of the reference");
        errors.push(worst);
    }
    assert!(errors[0] < 1e-3 && errors[2] < 1e-7, "{errors:?}");
    assert!(errors[2] < errors[0], "{errors:?}");
}

#[test]
fn radau5_switches_where_dop853_does() {
    // The same hop with the stiff integrator: each phase's Jacobian by the
    // phase model's generated rhs_jacobian, and by dual numbers over every
    // coordinate and speed.
    use appell::integrate::Radau5;
    let reference = hop(0.3, 1e-12);
    let stiff = Radau5::new().rtol(1e-10).atol(1e-12).event_tol(1e-13);
    for radau in [stiff, stiff.jacobian_by_duals(true)] {
        let run = Hybrid::new(phases())
            .stiff_solver(radau)
            .max_switches(7)
            .run::<4>(0, 0.0, &[0.3, 0.0], &[0.0], 3.0);
        let run = match run {
            Ok(run) => run,
            Err(appell::hybrid::HybridError::TooManySwitches(run)) => *run,
            Err(e) => panic!("{e}"),
        };
        assert_eq!(run.switches.len(), reference.switches.len());
        let worst = run
            .switches
            .iter()
            .zip(&reference.switches)
            .map(|(a, b)| {
                assert_eq!((a.from, a.to), (b.from, b.to));
                (a.t - b.t).abs()
            })
            .fold(0.0f64, f64::max);
        println!("Radau5 at rtol 1e-10: switch times within {worst:.1e} s of DOP853 at 1e-12");
        assert!(worst < 1e-7, "{worst:e}");
    }
}

#[test]
fn the_command_line_evaluates_a_scene_in_its_own_speeds() {
    // The flight scene has the foot's speed besides the body's, and no
    // ground constraint: the foot off the ground is no warning there.
    use appell::cli::Evaluator;
    let h = &HOPPER;
    let mut ev = Evaluator::with_scene(HOPPER, "flight").unwrap();
    let v = ev.eval_line(r#"{"t": 0.0, "q": {"z": 0.55, "f": 0.1}, "u": {"z": 0.4, "f": -0.7}}"#);
    assert!(
        v.get("error").is_none() && v.get("warning").is_none(),
        "{v}"
    );
    assert_eq!(v["qdot"]["f"].as_f64(), Some(-0.7));
    // The foot: m f̈ = k (z − f − l0) − m g.
    let foot = (h.k * (0.55 - 0.1 - h.l0) - h.m * h.g) / h.m;
    let got = v["udot"]["f"].as_f64().unwrap();
    assert!(
        (got - foot).abs() < 1e-12 * foot.abs().max(1.0),
        "{got} against {foot}"
    );
    // The stance scene holds the foot on the ground: off it, a warning.
    let mut ev = Evaluator::with_scene(HOPPER, "stance").unwrap();
    let v = ev.eval_line(r#"{"t": 0.0, "q": {"z": 0.55, "f": 0.1}, "u": {"z": 0.4}}"#);
    assert!(v.get("warning").is_some(), "{v}");
}

/// An upright disc (no lean: yaw, then spin about the axle) held on the
/// ground by `holonomic(z == r)` and rolling there (`rolls` along the
/// heading and sideways), both of effect `ground`, pulled up by a force
/// that grows with time, `lift * t`. On the ground the normal force is
/// m g − lift t: it comes down through zero at t = m g / lift, where the
/// disc lifts off (the flight scene, without the ground).
#[allow(clippy::duplicated_attributes)] // the scenes name effects alike
#[derive(appell::Appell, Clone, Debug, PartialEq)]
#[appell(coordinates(yaw, spin, x, y, z), speeds(yaw, spin), positive(r, m))]
#[appell(frame(A = N.rotate_z(yaw)), frame(C = A.rotate_y(spin)))]
#[appell(point(D = O + x * N.x + y * N.y + z * N.z), point(P = D - r * N.z))]
#[appell(body(disc, center = D, frame = C, mass = m, inertia = principal(m * r * r / 4, m * r * r / 2, m * r * r / 4)))]
#[appell(holonomic(z == r, effect = ground))]
#[appell(rolls(disc, contact = P, along = [A.x, A.y], effect = ground))]
#[appell(gravity(-g * N.z))]
#[appell(force(D, lift * t * N.z, effect = lift))]
#[appell(scene(grounded, effects(gravity, lift, ground)))]
#[appell(scene(airborne, effects(gravity, lift), speeds(yaw, spin, x, y, z)))]
struct LiftedDisc {
    r: f64,
    m: f64,
    g: f64,
    lift: f64,
}

const LIFTED: LiftedDisc = LiftedDisc {
    r: 0.15,
    m: 1.0,
    g: 9.81,
    lift: 20.0,
};

/// Rolling on the ground at yaw rate 0.5 and spin 10: q and u.
const ROLLING_Q: [f64; 5] = [0.0, 0.0, 0.0, 0.0, 0.15];
const ROLLING_U: [f64; 2] = [0.5, 10.0];

#[test]
fn the_lift_off_guard_switches_where_the_normal_force_vanishes() {
    use appell::hybrid::Guard;
    let t_lift = LIFTED.m * LIFTED.g / LIFTED.lift;
    let ground = LiftedDiscGrounded::from_ref(&LIFTED);
    let air = LiftedDiscAirborne::from_ref(&LIFTED);
    let phases = vec![
        Phase::new("grounded", ground).guard(Guard::lift_off(1, ground, 0, &[])),
        Phase::new("airborne", air),
    ];
    let run = Hybrid::new(phases)
        .run::<10>(0, 0.0, &ROLLING_Q, &ROLLING_U, 1.0)
        .unwrap();
    assert_eq!(run.switches.len(), 1);
    let s = &run.switches[0];
    assert_eq!((s.from, s.to, s.reason), (0, 1, "lift-off"));
    println!("lift-off at {} against m g / lift = {t_lift}", s.t);
    assert!((s.t - t_lift).abs() < 1e-9, "{} vs {t_lift}", s.t);
    // Nothing jumps where the ground lets go; then the disc rises.
    assert!(s.energy_lost.abs() < 1e-12, "{}", s.energy_lost);
    assert!(run.end.q[4] > LIFTED.r + 0.1, "height {}", run.end.q[4]);
}

#[test]
fn the_contact_watch_stops_the_grounded_disc_where_it_would_lift_off() {
    use appell::integrate::IntegrateError;
    use appell::ContactViolation;
    let t_lift = LIFTED.m * LIFTED.g / LIFTED.lift;
    let ground = LiftedDiscGrounded::from_ref(&LIFTED);
    // Reduced state of the grounded scene: the speeds (every coordinate is
    // ignorable).
    assert_eq!(
        <LiftedDiscGrounded as appell::Model>::info().retained.len(),
        0
    );
    let err = Dop853::new()
        .h_max(Some(1e-3))
        .solve_model(ground, &[], 0.0, &ROLLING_U, 1.0)
        .unwrap_err();
    println!("{err}");
    let IntegrateError::Contact(e) = err else {
        panic!("expected a contact error, got {err:?}");
    };
    assert_eq!((e.body, e.point), ("disc", "P"));
    assert!(matches!(e.kind, ContactViolation::LiftOff { normal } if normal < 0.0));
    // Located on the dense output (the watch is the event function).
    assert!((e.t - t_lift).abs() < 1e-9, "{} vs {t_lift}", e.t);
    // Before the lift-off the same integration is untouched.
    Dop853::new()
        .solve_model(ground, &[], 0.0, &ROLLING_U, 0.9 * t_lift)
        .unwrap();
}
