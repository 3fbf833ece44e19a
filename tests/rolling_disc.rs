//! The rolling disc: ignorable coordinates, steady turning, energy, and the
//! independent solver.

mod common;
#[path = "../examples/models/rolling_disc.rs"]
mod rolling_disc;

use appell::animate::simulate;
use appell::contact_watch::ContactWatch;
use appell::integrate::{rk4, Dop853, Dopri5, IntegrateError, Radau5, TrBdf2};
use appell::{ContactEvent, ContactViolation, Model, ModelError};
use common::{close, Rng};
use rolling_disc::RollingDisc;
use std::f64::consts::FRAC_PI_2;

#[test]
fn only_the_lean_is_integrated() {
    let info = RollingDisc::info();
    println!("{}", info.equations);
    assert_eq!(
        info.constraints, 2,
        "the vertical rolling row is identically zero and dropped"
    );
    assert_eq!(info.retained, &["lean"]);
    assert_eq!(info.cyclic, &["x", "y"]);
    assert_eq!(info.ignorable, &["yaw", "spin", "x", "y"]);
}

#[test]
fn steady_turning_is_an_equilibrium() {
    // Euler's equation about the centre for steady turning at lean θ, yaw
    // rate Ω, with W = Ω sin θ + ω the total axial rate (thin disc):
    //   −(3/2) r Ω W cos θ + (1/4) r Ω² cos θ sin θ − g sin θ = 0.
    let p = RollingDisc::default();
    let prepared = p.prepare::<f64>();
    let mut rng = Rng(17);
    for _ in 0..200 {
        let theta = rng.uniform(-1.2, 1.2);
        let omega_yaw = rng.uniform(0.5, 6.0)
            * if rng.uniform(0.0, 1.0) < 0.5 {
                -1.0
            } else {
                1.0
            };
        let (s, c) = theta.sin_cos();
        let w =
            (0.25 * p.r * omega_yaw * omega_yaw * c * s - p.g * s) / (1.5 * p.r * omega_yaw * c);
        let spin = w - omega_yaw * s;
        let mut d = [0.0; 4];
        p.rhs(&prepared, 0.0, &[theta, omega_yaw, 0.0, spin], &[], &mut d)
            .unwrap();
        for (k, v) in d.iter().enumerate() {
            let scale = 1.0 + omega_yaw.abs() * spin.abs() + p.g / p.r;
            assert!(
                v.abs() < 1e-12 * scale,
                "d[{k}] = {v} at theta {theta}, yaw rate {omega_yaw}"
            );
        }
    }
}

#[test]
fn energy_is_conserved() {
    let p = RollingDisc::default();
    let prepared = p.prepare::<f64>();
    let energy = |s: &[f64; 4]| {
        let q = [0.0, s[0], 0.0, 0.0, 0.0];
        p.kinetic_energy(0.0, &q, &s[1..]).unwrap() + p.m * p.g * p.r * s[0].cos()
    };
    let s0 = [0.3, 1.5, 0.2, 12.0];
    let e0 = energy(&s0);
    let s = rk4(&p, &prepared, 0.0, &s0, 1e-4, 20_000, &[]).unwrap();
    let drift = ((energy(&s) - e0) / e0).abs();
    println!("energy drift over 2 s with h = 1e-4: {drift:.2e}");
    assert!(drift < 1e-10, "relative energy drift {drift:e}");
}

#[test]
fn agrees_with_the_oracle() {
    let p = RollingDisc::default();
    let prepared = p.prepare::<f64>();
    let mut rng = Rng(18);
    let mut worst: f64 = 0.0;
    for _ in 0..1000 {
        let q: Vec<f64> = (0..5).map(|_| rng.uniform(-1.3, 1.3)).collect();
        let u: Vec<f64> = (0..3).map(|_| rng.uniform(-5.0, 5.0)).collect();
        let mut d = [0.0; 4];
        p.rhs(&prepared, 0.0, &[q[1], u[0], u[1], u[2]], &[], &mut d)
            .unwrap();
        let o = appell::oracle::reduced_rhs(&p, 0.0, &q, &u, &[]).unwrap();
        for (a, b) in d.iter().zip(&o) {
            worst = worst.max((a - b).abs() / (1.0 + a.abs().max(b.abs())));
            assert!(close(*a, *b, 1e-9), "{a} vs {b}");
        }
    }
    println!("rolling disc vs oracle: largest relative difference {worst:.2e}");
}

#[test]
fn potential_energy_is_the_gravity_potential() {
    let p = RollingDisc::default();
    let q = [0.3, 0.7, -1.1, 0.2, 0.4];
    let v = p.potential_energy(0.0, &q).unwrap();
    // V = m g z of the centre, z = r cos(lean) (N.z up, gravity −g N.z).
    assert!(close(v, p.m * p.g * p.r * q[1].cos(), 1e-15), "{v}");
}

#[test]
fn controller_functions_agree_with_the_equations() {
    let mut rng = Rng(43);
    let worst = common::controller_agrees(&RollingDisc::default(), &mut rng, 50, 1.2);
    assert!(worst < 1e-12, "{worst:.2e}");
}

/// The disc released at rest at lean 1.5 rad falls flat: at lean π/2 its
/// centre reaches the floor, and past it the equations (whose `rolls`
/// contact is a two-sided equality) would carry it on through.
const FALLING: [f64; 4] = [1.5, 0.0, 0.0, 0.0];

/// When the disc released at [`FALLING`] reaches lean π/2, located on the
/// dense output of a run without the watch.
fn time_flat() -> f64 {
    let p = RollingDisc::default();
    let sol = Dop853::new()
        .rtol(1e-10)
        .atol(1e-12)
        .contact_watch(false)
        .solve_model_until(
            &p,
            &[],
            |_t, x: &[f64; 4]| FRAC_PI_2 - x[0],
            0.0,
            &FALLING,
            2.0,
        )
        .unwrap();
    assert!(sol.event, "the disc never reached lean π/2");
    sol.t
}

#[test]
fn falling_flat_stops_at_the_floor_naming_the_contact() {
    let p = RollingDisc::default();
    let t_flat = time_flat();
    // With the watch off the integration goes on through the floor.
    let through = Dop853::new()
        .h_max(Some(1e-3))
        .contact_watch(false)
        .solve_model(&p, &[], 0.0, &FALLING, t_flat + 0.01);
    if let Ok(sol) = through {
        println!("unwatched: lean {} at t = {}", sol.x[0], sol.t);
        assert!(sol.x[0] > FRAC_PI_2, "lean {}", sol.x[0]);
    }
    // Every solve_model* watches a model with contacts: with no event of
    // its own, the watch's margin is the event function, so the disc stops
    // where it leaves the region where the model holds, located on the
    // dense output just before lean π/2, the contact named: a few µrad
    // before it the multiplier system is already singular to working
    // precision (or else the centre reaches the floor).
    let err = Dop853::new()
        .solve_model(&p, &[], 0.0, &FALLING, 2.0)
        .unwrap_err();
    println!("{err}; lean π/2 at t = {t_flat}");
    let IntegrateError::Contact(event) = err else {
        panic!("expected a contact error, got {err:?}");
    };
    assert_eq!((event.contact, event.body, event.point), (0, "disc", "P"));
    assert!(
        event.t < t_flat && event.t > t_flat - 1e-5,
        "stopped at {} against lean π/2 at {t_flat}",
        event.t
    );
    assert!(
        matches!(
            event.kind,
            ContactViolation::Singular | ContactViolation::LeftRegion { side: 0.0..=2e-9 }
        ),
        "{:?}",
        event.kind
    );
    let lean = Dop853::new()
        .rtol(1e-10)
        .atol(1e-12)
        .contact_watch(false)
        .solve_model(&p, &[], 0.0, &FALLING, event.t)
        .unwrap()
        .x[0];
    println!("stopped at lean π/2 − {:.1e} rad", FRAC_PI_2 - lean);
    assert!(lean < FRAC_PI_2 && lean > FRAC_PI_2 - 1e-4, "lean {lean}");
    // With an event of its own (here one that never fires) the run checks
    // the end of each step instead: the stop comes within a step (h_max)
    // past lean π/2.
    let h = 1e-3;
    let err = Dop853::new()
        .h_max(Some(h))
        .solve_model_until(&p, &[], |_, _| 1.0, 0.0, &FALLING, 2.0)
        .unwrap_err();
    let IntegrateError::Contact(event) = err else {
        panic!("expected a contact error, got {err:?}");
    };
    assert_eq!((event.body, event.point), ("disc", "P"));
    assert!(
        event.t > t_flat && event.t <= t_flat + h,
        "{} vs {t_flat}",
        event.t
    );
    assert!(matches!(
        event.kind,
        ContactViolation::LeftRegion { .. } | ContactViolation::Singular
    ));
}

#[test]
fn every_integrator_and_the_animation_stop_the_falling_disc() {
    let p = RollingDisc::default();
    let t_flat = time_flat();
    let named = |e: &ContactEvent, within: f64| {
        assert_eq!((e.body, e.point), ("disc", "P"));
        assert!((e.t - t_flat).abs() < within, "{} vs {t_flat}", e.t);
    };
    let errors = [
        Dopri5::new()
            .solve_model(&p, &[], 0.0, &FALLING, 2.0)
            .unwrap_err(),
        TrBdf2::new()
            .h_max(Some(1e-2))
            .solve_model(&p, &[], 0.0, &FALLING, 2.0)
            .unwrap_err(),
        Radau5::new()
            .h_max(Some(1e-2))
            .solve_model(&p, &[], 0.0, &FALLING, 2.0)
            .unwrap_err(),
    ];
    for err in errors {
        match err {
            IntegrateError::Contact(e) => named(&e, 1e-3),
            other => panic!("expected a contact error, got {other:?}"),
        }
    }
    let q0 = [0.0, FALLING[0], 0.0, 0.0, 0.0];
    match simulate(&p, 0.0, &q0, &[0.0; 3], &[], 2.0, 200) {
        // Checked at every frame (10 ms): the frame after lean π/2.
        Err(ModelError::ContactLost(e)) => named(&e, 0.01),
        other => panic!("expected a contact lost, got {other:?}"),
    }
}

#[test]
fn a_warning_watch_records_the_fall_and_goes_on() {
    let p = RollingDisc::default();
    let t_flat = time_flat();
    let mut watch = ContactWatch::new(&p).warn();
    let sol = Dop853::new()
        .h_max(Some(1e-3))
        .contact_watch(false)
        .solve_model_projected(
            &p,
            &[],
            &mut |t, x: &mut [f64; 4]| watch.check(t, x),
            0.0,
            &FALLING,
            t_flat + 0.01,
        );
    println!("{sol:?}\n{:?}", watch.events);
    let sol = sol.expect("a warning watch lets the integration go on");
    assert_eq!(watch.checks, sol.stats.accepted);
    assert!(sol.x[0] > FRAC_PI_2, "through the floor: lean {}", sol.x[0]);
    // Each once, though every step after is past the floor: the centre
    // crosses the plane, then the normal, turned over, would pull.
    let kinds: Vec<_> = watch.events.iter().map(|e| e.kind).collect();
    assert!(
        matches!(
            kinds[..],
            [
                ContactViolation::LeftRegion { .. },
                ContactViolation::LiftOff { .. }
            ]
        ),
        "{kinds:?}"
    );
    let first = watch.events.first().expect("the fall recorded");
    assert_eq!((first.body, first.point), ("disc", "P"));
    assert!(first.t >= t_flat - 1e-9 && first.t <= t_flat + 1e-3);
    assert!(watch.stopped().is_none());
}

#[test]
fn rolling_motions_are_untouched_by_the_watch() {
    // A wobbling turn: lean 0.3, yaw rate 1.5, lean rate 0.2, spin 12.
    let p = RollingDisc::default();
    let s0 = [0.3, 1.5, 0.2, 12.0];
    let solver = Dop853::new().rtol(1e-9).atol(1e-12);
    let watched = solver.solve_model(&p, &[], 0.0, &s0, 3.0).unwrap();
    let free = solver
        .contact_watch(false)
        .solve_model(&p, &[], 0.0, &s0, 3.0)
        .unwrap();
    assert_eq!(watched.x, free.x);
    assert_eq!(watched.stats, free.stats);
    // The watch saw every step, and nothing to flag.
    let mut watch = ContactWatch::new(&p);
    for k in 0..=30 {
        let t = 0.1 * k as f64;
        let x = solver
            .contact_watch(false)
            .solve_model(&p, &[], 0.0, &s0, t)
            .unwrap()
            .x;
        watch.check(t, &x).unwrap();
    }
    assert!(watch.events.is_empty());
}

#[test]
#[ignore = "a measurement, not a check: `--ignored --nocapture` prints the ratio"]
fn the_watch_costs_about_a_contact_force_per_step() {
    // One Dop853 solve with and without the watch: a ratio, printed.
    let p = RollingDisc::default();
    let s0 = [0.3, 1.5, 0.2, 12.0];
    let solver = Dop853::new().rtol(1e-9).atol(1e-12);
    let time = |on: bool| {
        let start = std::time::Instant::now();
        let mut steps = 0;
        for _ in 0..20 {
            let sol = solver
                .contact_watch(on)
                .solve_model(&p, &[], 0.0, &s0, 3.0)
                .unwrap();
            steps += sol.stats.accepted;
        }
        (start.elapsed().as_secs_f64(), steps)
    };
    let (off, steps) = time(false);
    let (on, _) = time(true);
    println!(
        "Dop853 on the disc, {} steps per solve: {:.3} ms without the watch, {:.3} ms with it ({:.1}x, {:.1} µs per check)",
        steps / 20,
        off / 20.0 * 1e3,
        on / 20.0 * 1e3,
        on / off,
        (on - off) / steps as f64 * 1e6
    );
}

#[test]
fn the_command_lines_animate_says_where_the_disc_hits_the_floor() {
    let args = ["rolling_disc".to_string(), "animate".to_string()];
    let problem = r#"{"q": {"yaw": 0, "lean": 1.5, "spin": 0, "x": 0, "y": 0},
                      "u": {"yaw": 0, "lean": 0, "spin": 0}, "t_end": 0.2, "frames": 20}"#;
    let mut out = Vec::new();
    let result = appell::cli::run_with(
        RollingDisc::default(),
        &args,
        &mut problem.as_bytes(),
        &mut out,
        |_| Ok(()),
    );
    match result {
        Err(appell::cli::CliError::Animate(why)) => {
            println!("{why}");
            assert!(why.contains("the contact of `disc` at `P`"), "{why}");
        }
        other => panic!("expected the contact named, got {other:?}"),
    }
}
