//! The Whipple bicycle benchmark.

mod common;
#[path = "../examples/models/whipple_bicycle.rs"]
mod whipple_bicycle;

use appell::Model;
use whipple_bicycle::WhippleBicycle;

#[test]
fn derives() {
    let info = WhippleBicycle::info();
    println!("{}", &info.equations[..info.equations.len().min(3000)]);
    println!("ops {:?}", info.rhs_ops);
}

/// The largest relative difference between the generated rhs and the
/// oracle over `count` random states (pitch near the steer-axis tilt).
fn oracle_difference(
    p: &WhippleBicycle,
    next: &mut impl FnMut(f64, f64) -> f64,
    count: usize,
) -> f64 {
    let prepared = p.prepare::<f64>();
    let mut worst: f64 = 0.0;
    for _ in 0..count {
        let mut q: Vec<f64> = (0..8).map(|_| next(-1.0, 1.0)).collect();
        q[4] = std::f64::consts::PI / 10.0 + next(-0.2, 0.2); // pitch near the steer-axis tilt
        q[3] = next(-0.6, 0.6); // roll
        q[6] = next(-0.8, 0.8); // steer
        let u = [next(-2.0, 2.0), next(-20.0, 0.0), next(-2.0, 2.0)];
        let state = [q[3], q[4], q[6], u[0], u[1], u[2]];
        let mut d = [0.0; 6];
        let steer = [next(-5.0, 5.0)];
        p.rhs(&prepared, 0.0, &state, &steer, &mut d).unwrap();
        let o = appell::oracle::reduced_rhs(p, 0.0, &q, &u, &steer).unwrap();
        for (a, b) in d.iter().zip(&o) {
            worst = worst.max((a - b).abs() / (1.0 + a.abs().max(b.abs())));
        }
    }
    worst
}

/// Uniform numbers in [lo, hi) from the shared xorshift generator.
fn uniform(seed: u64) -> impl FnMut(f64, f64) -> f64 {
    let mut rng = common::XorShift(seed);
    move |lo, hi| rng.uniform(lo, hi)
}

#[test]
fn agrees_with_the_oracle() {
    let worst = oracle_difference(&WhippleBicycle::default(), &mut uniform(0x5eed), 1000);
    println!("bicycle vs oracle: largest relative difference {worst:.2e}");
    assert!(worst < 1e-9, "{worst:e}");
}

#[test]
fn critical_speeds_match_the_benchmark() {
    let p = WhippleBicycle::default();
    let (weave, capsize) = whipple_bicycle::critical_speeds(&p).unwrap();
    println!("weave {weave:.14} m/s, capsize {capsize:.14} m/s");
    assert!(
        (weave - 4.29238253634111).abs() < 1e-8,
        "weave speed {weave}"
    );
    assert!(
        (capsize - 6.02426201538837).abs() < 1e-8,
        "capsize speed {capsize}"
    );
}

#[test]
fn upright_pitch_is_the_steer_axis_tilt() {
    let q = whipple_bicycle::operating_point(&WhippleBicycle::default()).unwrap();
    assert!(
        (q[4] - std::f64::consts::PI / 10.0).abs() < 1e-12,
        "pitch {}",
        q[4]
    );
}

#[test]
fn mass_matrix_is_symmetric_positive_definite_at_the_operating_point() {
    let p = WhippleBicycle::default();
    let q = whipple_bicycle::operating_point(&p).unwrap();
    let mut m = [0.0; 9];
    let mut f = [0.0; 3];
    p.mass_matrix_and_forcing(0.0, &q, &[0.0, -5.0 / p.rr, 0.0], &[0.0], &mut m, &mut f)
        .unwrap();
    for i in 0..3 {
        for j in 0..3 {
            assert!((m[i * 3 + j] - m[j * 3 + i]).abs() < 1e-12 * (1.0 + m[i * 3 + j].abs()));
        }
    }
    // Leading minors positive (Sylvester's criterion).
    let d1 = m[0];
    let d2 = m[0] * m[4] - m[1] * m[3];
    let d3 = m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6])
        + m[2] * (m[3] * m[7] - m[4] * m[6]);
    assert!(d1 > 0.0 && d2 > 0.0 && d3 > 0.0, "minors {d1} {d2} {d3}");
    // Straight-ahead running at constant speed is an equilibrium.
    assert!(f.iter().all(|x| x.abs() < 1e-10), "{f:?}");
}

#[test]
fn lean_steer_eigenvalues_at_5_m_per_s() {
    // Meijaard et al. (2007), Table 2 (v = 5 m/s): weave −0.775341882195845 ± 4.46486771378823i,
    // capsize −0.322866429004087, castor −14.0783896927982.
    let ev = whipple_bicycle::eigenvalues(&WhippleBicycle::default(), 5.0).unwrap();
    let expected = [
        (-14.0783896927982, 0.0),
        (-0.775341882195845, -4.46486771378823),
        (-0.775341882195845, 4.46486771378823),
        (-0.322866429004087, 0.0),
    ];
    for ((re, im), (er, ei)) in ev.iter().zip(expected) {
        assert!(
            (re - er).abs() < 1e-10 && (im - ei).abs() < 1e-10,
            "({re}, {im}) vs ({er}, {ei})"
        );
    }
}

#[test]
fn coasting_scene_is_the_bicycle_without_its_rider() {
    use whipple_bicycle::{WhippleBicycleCoasting, WhippleBicycleRidden};
    let p = WhippleBicycle::default();
    let full = p.prepare::<f64>();
    let coasting = WhippleBicycleCoasting(p.clone());
    let cp = coasting.prepare::<f64>();
    let ridden = WhippleBicycleRidden(p.clone());
    let rp = ridden.prepare::<f64>();
    let state = [0.1, std::f64::consts::PI / 10.0, -0.2, 0.3, -15.0, 0.4];
    let (mut a, mut b, mut c) = ([0.0; 6], [0.0; 6], [0.0; 6]);
    p.rhs(&full, 0.0, &state, &[0.0], &mut a).unwrap();
    // Gravity alone reads no input: the coasting scene takes none.
    coasting.rhs(&cp, 0.0, &state, &[], &mut b).unwrap();
    ridden.rhs(&rp, 0.0, &state, &[0.0], &mut c).unwrap();
    for k in 0..6 {
        assert!(
            (a[k] - b[k]).abs() <= 1e-12 * (1.0 + a[k].abs()),
            "{k}: {} vs {}",
            a[k],
            b[k]
        );
        assert!((a[k] - c[k]).abs() <= 1e-12 * (1.0 + a[k].abs()));
    }
    println!(
        "bicycle ops: full {}, coasting {}, ridden {}",
        WhippleBicycle::info().rhs_ops.total,
        WhippleBicycleCoasting::info().rhs_ops.total,
        WhippleBicycleRidden::info().rhs_ops.total
    );
    assert!(
        WhippleBicycleCoasting::info().rhs_ops.total < WhippleBicycleRidden::info().rhs_ops.total
    );
}

#[test]
fn energy_rate_is_the_riders_power() {
    // No friction, rolling without slip, gravity in V: d(T + V)/dt is the
    // power of the steer torque, at any state.
    let p = WhippleBicycle::default();
    let mut next = uniform(0xb1c);
    let mut worst: f64 = 0.0;
    for _ in 0..200 {
        let mut q: Vec<f64> = (0..8).map(|_| next(-1.0, 1.0)).collect();
        q[4] = std::f64::consts::PI / 10.0 + next(-0.2, 0.2);
        let u = [next(-2.0, 2.0), next(-20.0, 0.0), next(-2.0, 2.0)];
        let steer = [next(-5.0, 5.0)];
        let e = appell::energy::energies(&p, 0.0, &q, &u, &steer).unwrap();
        worst = worst.max((e.rate - e.input_power).abs() / (1.0 + e.kinetic + e.potential.abs()));
    }
    println!("bicycle: |d(T+V)/dt − rider's power| / (1 + T + |V|) at most {worst:.2e}");
    assert!(worst < 1e-12, "{worst:e}");
}

/// The wheels' terms are folded into the frames' (composite mass centres,
/// rotors), and the folded equations still agree with the oracle, which
/// works body by body, for bicycles other than the benchmark's.
#[test]
fn folded_wheels_agree_with_the_oracle_for_other_bicycles() {
    let text = WhippleBicycle::info().equations;
    for line in [
        "composite: `rear_frame` with `rear_wheel`",
        "composite: `front_frame` with `front_wheel`",
        "rotor: `rear_wheel` spins about axis y of `rear_frame`",
        "rotor: `front_wheel` spins about axis y of `front_frame`",
    ] {
        assert!(text.contains(line), "{line}\n{text}");
    }
    let mut next = uniform(0xf01d);
    let mut worst: f64 = 0.0;
    for _ in 0..20 {
        let b = WhippleBicycle::default();
        let mut scale = || next(0.8, 1.25);
        let p = WhippleBicycle {
            md: b.md * scale(),
            mf: b.mf * scale(),
            mc: b.mc * scale(),
            me: b.me * scale(),
            id11: b.id11 * scale(),
            id22: b.id22 * scale(),
            if11: b.if11 * scale(),
            if22: b.if22 * scale(),
            l1: b.l1 * scale(),
            l3: b.l3 * scale(),
            ..b
        };
        worst = worst.max(oracle_difference(&p, &mut next, 50));
    }
    println!("other bicycles vs oracle: largest relative difference {worst:.2e}");
    assert!(worst < 1e-9, "{worst:e}");
}

#[test]
fn eval_warns_of_a_state_off_the_holonomic_constraint() {
    // On the constraint (the pitch solved from it) the answer has no
    // warning; with the pitch 0.01 rad off, it names the constraint and its
    // residual, and still gives the rates.
    let p = WhippleBicycle::default();
    let q = whipple_bicycle::operating_point(&p).unwrap();
    let eval = |pitch: f64| -> serde_json::Value {
        let line = format!(
            r#"{{"q": {{"q2": {}, "q3": {}, "q4": 0.0, "q5": {pitch}, "q7": 0.0}}, "u": {{"q4": 0.1, "q6": -10.0, "q7": 0.2}}}}"#,
            q[1], q[2]
        );
        let mut out = Vec::new();
        appell::cli::run_with(
            p.clone(),
            &["whipple".to_string(), "eval".to_string()],
            &mut line.as_bytes(),
            &mut out,
            |_| Ok(()),
        )
        .unwrap();
        serde_json::from_slice(&out).unwrap()
    };
    let on = eval(q[4]);
    assert!(on["udot"]["q4"].is_f64(), "{on}");
    assert!(on.get("warning").is_none(), "{on}");
    let off = eval(q[4] + 0.01);
    assert!(off["udot"]["q4"].is_f64(), "{off}");
    let residual = off["warning"]["holonomic_residuals"][0].as_f64().unwrap();
    assert!(residual.abs() > 1e-4, "{off}");
    let message = off["warning"]["message"].as_str().unwrap();
    assert!(message.contains("holonomic constraint 0"), "{message}");
}

#[test]
fn eval_and_contacts_solve_the_pitch_when_it_is_left_out() {
    // q5 (the pitch) is retained but fixed by the holonomic constraint:
    // left out, it is solved (and reported), and the answer is the one for
    // the pitch given on the constraint.
    let p = WhippleBicycle::default();
    let q = whipple_bicycle::operating_point(&p).unwrap();
    let run = |command: &str, pitch: Option<f64>| -> serde_json::Value {
        let pitch = pitch.map_or(String::new(), |x| format!(", \"q5\": {x}"));
        let line = format!(
            r#"{{"q": {{"q2": 0.1, "q3": 0.2, "q4": 0.0, "q7": 0.0{pitch}}}, "u": {{"q4": 0.1, "q6": -10.0, "q7": 0.2}}}}"#
        );
        let mut out = Vec::new();
        appell::cli::run_with(
            p.clone(),
            &["whipple".to_string(), command.to_string()],
            &mut line.as_bytes(),
            &mut out,
            |_| Ok(()),
        )
        .unwrap();
        serde_json::from_slice(&out).unwrap()
    };
    for command in ["eval", "contacts"] {
        let solved = run(command, None);
        let pitch = solved["solved"]["q5"].as_f64().expect("the pitch solved");
        assert!((pitch - q[4]).abs() < 1e-12, "{command}: {solved}");
        assert!(
            solved["residual"].as_f64().unwrap().abs() < 1e-12,
            "{solved}"
        );
        assert!(solved.get("warning").is_none(), "{solved}");
        let mut given = run(command, Some(pitch));
        assert!(given.get("solved").is_none(), "{given}");
        let mut solved = solved;
        for key in ["solved", "residual"] {
            solved.as_object_mut().unwrap().remove(key);
            given.as_object_mut().unwrap().remove(key);
        }
        assert_eq!(solved, given, "{command}");
    }
}

#[test]
fn a_retained_coordinate_the_constraints_do_not_fix_is_still_required() {
    let line = r#"{"q": {"q5": 0.3, "q7": 0.0}, "u": {"q4": 0.1, "q6": -10.0, "q7": 0.2}}"#;
    let mut out = Vec::new();
    appell::cli::run_with(
        WhippleBicycle::default(),
        &["whipple".to_string(), "eval".to_string()],
        &mut line.as_bytes(),
        &mut out,
        |_| Ok(()),
    )
    .unwrap();
    let answer: serde_json::Value = serde_json::from_slice(&out).unwrap();
    let error = answer["error"].as_str().unwrap();
    assert_eq!(
        error,
        "missing coordinate `q4` in `q` (the holonomic constraints do not fix it)"
    );
}

#[test]
fn a_nudged_ride_is_untouched_by_the_contact_watch() {
    // Both wheels are `rolls` contacts, so every solve_model watches them:
    // a ride at 5 m/s nudged by a roll rate of 0.5 rad/s (stable, the
    // weave decays) is the same with the watch as without, and not stopped.
    use appell::integrate::{Dop853, IntegrateError};
    use appell::ContactViolation;
    let p = WhippleBicycle::default();
    let q = whipple_bicycle::operating_point(&p).unwrap();
    let solver = Dop853::new().rtol(1e-9).atol(1e-12);
    let x0 = [q[3], q[4], q[6], 0.5, -5.0 / p.rr, 0.0];
    let watched = solver.solve_model(&p, &[0.0], 0.0, &x0, 3.0).unwrap();
    let free = solver
        .contact_watch(false)
        .solve_model(&p, &[0.0], 0.0, &x0, 3.0)
        .unwrap();
    assert_eq!(watched.x, free.x);
    assert_eq!(watched.stats, free.stats);
    assert!(watched.x[0].abs() < 0.05, "roll {}", watched.x[0]);

    // At 2 m/s it falls, and the steer whips round into the fall (from
    // 0.75 rad at 1.5 rad/s to 1.1 rad at 11 rad/s between 0.81 s and
    // 0.9 s): the front contact's normal force jumps past 1600 N and the
    // rear one would have to pull the wheel down. The watch stops there.
    let x0 = [q[3], q[4], q[6], 0.5, -2.0 / p.rr, 0.0];
    let err = solver.solve_model(&p, &[0.0], 0.0, &x0, 2.0).unwrap_err();
    println!("{err}");
    let IntegrateError::Contact(e) = err else {
        panic!("expected a contact error, got {err:?}");
    };
    assert_eq!((e.contact, e.body, e.point), (0, "rear_wheel", "P"));
    assert!(matches!(e.kind, ContactViolation::LiftOff { normal } if normal < 0.0));
    assert!(e.t > 0.81 && e.t < 0.9, "{}", e.t);
    let steer = solver
        .contact_watch(false)
        .solve_model(&p, &[0.0], 0.0, &x0, e.t)
        .unwrap()
        .x[2];
    assert!(steer > 0.75, "steer {steer}");
}
