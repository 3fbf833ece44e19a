//! A ball bouncing on the ground with Newton's coefficient of restitution:
//! an impact against the ground scene's constraint that leaves the ball in
//! flight, checked against the closed form bounce by bounce, and its
//! Zeno ending (infinitely many bounces before a finite time), which the
//! hybrid driver reports as too many switches.

use appell::hybrid::{Guard, Hybrid, HybridError, Phase};
use appell::integrate::Dop853;
use appell::Appell;

/// A ball on the ground (z = 0, the constraint of effect `ground`),
/// rolling along x; in flight without the constraint.
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(coordinates(x, z), speeds(x), positive(m))]
#[appell(point(P = O + x * N.x + z * N.z), particle(P, mass = m))]
#[appell(gravity(-g * N.z))]
#[appell(holonomic(z == 0, effect = ground))]
#[appell(scene(flight, effects(gravity), speeds(x, z)))]
struct Ball {
    m: f64,
    g: f64,
}

const BALL: Ball = Ball { m: 0.5, g: 9.81 };

#[test]
fn each_bounce_keeps_e_of_the_speed_and_the_bounces_end_zeno() {
    let (h, e, vx) = (1.0, 0.8, 0.3);
    let phases = vec![Phase::new("flight", BallFlight::from_ref(&BALL))
        .guard(Guard::new("bounce", 0, |_, q: &[f64], _: &[f64]| Ok(q[1])).impact(&BALL, e))];
    // Closed form: the first impact at √(2h/g) with speed g t, each
    // rebound at e times the impact speed, 2 v/g in the air; the bounces
    // accumulate at t∞ = t1 + 2 e v1 / (g (1 − e)).
    let g = BALL.g;
    let (t1, v1) = ((2.0 * h / g).sqrt(), (2.0 * g * h).sqrt());
    let zeno = t1 + 2.0 * e * v1 / (g * (1.0 - e));
    let bounces = 20;
    let run = Hybrid::new(phases)
        .solver(Dop853::new().rtol(1e-12).atol(1e-14).event_tol(1e-13))
        .max_switches(bounces)
        .run::<4>(0, 0.0, &[0.0, h], &[vx, 0.0], zeno + 1.0);
    let Err(HybridError::TooManySwitches(run)) = run else {
        panic!("the bounces accumulate before {zeno} s: {run:?}");
    };
    assert_eq!(run.switches.len(), bounces);
    let (mut t, mut v, mut worst) = (t1, v1, 0.0f64);
    for s in &run.switches {
        let lost = 0.5 * BALL.m * v * v * (1.0 - e * e);
        let impulse = BALL.m * (1.0 + e) * v;
        worst = worst.max((s.t - t).abs() / t);
        worst = worst.max((s.energy_lost - lost).abs() / lost);
        worst = worst.max((s.impulses[0].abs() - impulse).abs() / impulse);
        let after = run
            .samples
            .iter()
            .find(|x| x.t == s.t && x.u[1] > 0.0)
            .unwrap();
        worst = worst.max((after.u[1] - e * v).abs() / (e * v));
        // The impact is normal: the rolling speed is untouched.
        assert!((after.u[0] - vx).abs() < 1e-12);
        t += 2.0 * e * v / g;
        v *= e;
    }
    println!("{bounces} bounces against the closed form: {worst:.1e} (relative); t∞ = {zeno:.6} s, run stopped at {:.6} s", run.end.t);
    assert!(worst < 1e-9, "{worst:e}");
    assert!(run.end.t < zeno);
}

#[test]
fn bad_settings_are_typed_errors() {
    use appell::switch::{impact_state, SwitchError};
    let flight = BallFlight::from_ref(&BALL);
    let phases = || {
        vec![Phase {
            name: "flight",
            model: flight,
            inputs: Vec::new(),
            state_inputs: None,
            guards: vec![
                Guard::new("bounce", 0, |_, q: &[f64], _: &[f64]| Ok(q[1])).impact(&BALL, 0.5)
            ],
        }]
    };
    for dt in [0.0, -0.1, f64::NAN] {
        let run =
            Hybrid::new(phases())
                .sample_every(dt)
                .run::<4>(0, 0.0, &[0.0, 1.0], &[0.0, 0.0], 1.0);
        assert!(
            matches!(run, Err(HybridError::BadPhase(_))),
            "dt = {dt}: {run:?}"
        );
    }
    let run = Hybrid::new(phases()).run::<3>(0, 0.0, &[0.0, 1.0], &[0.0, 0.0], 1.0);
    assert!(matches!(run, Err(HybridError::BadPhase(_))), "S too small");
    let hit = impact_state(flight, &BALL, 0.0, &[0.0, 0.0], &[0.0, -1.0], &[], &[], 1.5);
    assert_eq!(hit, Err(SwitchError::InvalidRestitution(1.5)));
}
