//! Scenes: specialised rhs with only the chosen effects, and quadrature
//! outputs, compared with the full model.

mod common;
#[path = "../examples/models/wheel_axle.rs"]
mod wheel_axle;

use appell::Model;
use common::{close, Rng};
use wheel_axle::{
    WheelAxle, WheelAxleCoasting, WheelAxleContactCheck, WheelAxleDriven, WheelAxleTrack,
};

#[test]
fn scenes_are_listed_with_their_states_and_costs() {
    let scenes = WheelAxle::scene_infos();
    let names: Vec<&str> = scenes.iter().map(|s| s.name).collect();
    assert_eq!(
        names,
        [
            "WheelAxle::coasting",
            "WheelAxle::driven",
            "WheelAxle::track",
            "WheelAxle::contact_check"
        ]
    );
    for s in scenes {
        println!(
            "{}: effects {:?}, state {:?} + speeds, {} ops",
            s.name, s.effects, s.retained, s.rhs_ops.total
        );
    }
    assert_eq!(WheelAxleCoasting::info().effects, &["gravity"]);
    // Without gravity nothing depends on the heading: it drops out.
    assert_eq!(WheelAxleDriven::info().retained, &[] as &[&str]);
    assert_eq!(WheelAxleDriven::info().state_len(), 2);
    // The track scene integrates wheel 1's position (and the heading its
    // rates need) beside the speeds.
    assert_eq!(WheelAxleTrack::info().retained, &["x1", "y1", "phi"]);
    assert!(WheelAxleCoasting::info().rhs_ops.total < WheelAxle::info().rhs_ops.total);
}

#[test]
fn each_scene_equals_the_full_model_with_the_other_effects_switched_off() {
    let mut rng = Rng(61);
    for _ in 0..1000 {
        let p = common::random_wheel_axle!(rng);
        let (phi, w, s) = (
            rng.uniform(-3.0, 3.0),
            rng.uniform(-3.0, 3.0),
            rng.uniform(-3.0, 3.0),
        );
        let tau = rng.uniform(-2.0, 2.0);
        // Coasting = full model with no drive torque.
        let mut full = [0.0; 3];
        p.rhs(&p.prepare::<f64>(), 0.0, &[phi, w, s], &[0.0], &mut full)
            .unwrap();
        let coasting = WheelAxleCoasting(p.clone());
        let mut d = [0.0; 3];
        // Gravity alone reads no input: the scene takes none.
        coasting
            .rhs(&coasting.prepare::<f64>(), 0.0, &[phi, w, s], &[], &mut d)
            .unwrap();
        for k in 0..3 {
            assert!(
                close(d[k], full[k], 1e-12),
                "coasting {k}: {} vs {}",
                d[k],
                full[k]
            );
        }
        // Driven = full model with gravity off (g = 0); its state has no heading.
        let level = WheelAxle {
            g: 0.0,
            ..p.clone()
        };
        level
            .rhs(
                &level.prepare::<f64>(),
                0.0,
                &[phi, w, s],
                &[tau],
                &mut full,
            )
            .unwrap();
        let driven = WheelAxleDriven(p.clone());
        let mut d2 = [0.0; 2];
        driven
            .rhs(&driven.prepare::<f64>(), 0.0, &[w, s], &[tau], &mut d2)
            .unwrap();
        assert!(close(d2[0], full[1], 1e-12) && close(d2[1], full[2], 1e-12));
    }
}

#[test]
fn quadrature_output_follows_the_full_system() {
    // Integrate the track scene (x1, y1, phi, speeds) and, separately, the
    // full reduced state with x1, y1 by quadrature of coordinate_rates.
    let p = WheelAxle::default();
    let track = WheelAxleTrack(p.clone());
    let tp = track.prepare::<f64>();
    let fp = p.prepare::<f64>();
    let h = 1e-3;
    let tau = [0.3];
    let mut s = [0.0, 0.0, 0.4, 0.2, 1.0];
    let mut full = [0.4, 0.2, 1.0];
    let mut xy = [0.0, 0.0];
    for step in 0..2000 {
        let t = step as f64 * h;
        s = appell::integrate::rk4_step(&track, &tp, t, h, &s, &tau).unwrap();
        // The same RK4 on (x1, y1, phi, speeds) assembled from the full model.
        let rate = |x: &[f64; 5]| -> [f64; 5] {
            let mut d = [0.0; 3];
            p.rhs(&fp, 0.0, &[x[2], x[3], x[4]], &tau, &mut d).unwrap();
            let mut q = [0.0; 7];
            q[6] = x[2];
            let mut qd = [0.0; 7];
            p.coordinate_rates(0.0, &q, &[x[3], x[4]], &mut qd).unwrap();
            [qd[0], qd[1], d[0], d[1], d[2]]
        };
        let x = [xy[0], xy[1], full[0], full[1], full[2]];
        let k1 = rate(&x);
        let add = |a: &[f64; 5], b: &[f64; 5], c: f64| -> [f64; 5] {
            std::array::from_fn(|i| a[i] + c * b[i])
        };
        let k2 = rate(&add(&x, &k1, h / 2.0));
        let k3 = rate(&add(&x, &k2, h / 2.0));
        let k4 = rate(&add(&x, &k3, h));
        let next: [f64; 5] =
            std::array::from_fn(|i| x[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
        xy = [next[0], next[1]];
        full = [next[2], next[3], next[4]];
    }
    println!("track after 2 s: x1 = {:.9}, y1 = {:.9}", s[0], s[1]);
    assert!(
        close(s[0], xy[0], 1e-12) && close(s[1], xy[1], 1e-12),
        "{:?} vs {:?}",
        &s[..2],
        xy
    );
    assert!(close(s[2], full[0], 1e-12));
}

#[test]
fn command_line_lists_scenes_and_evaluates_one() {
    let args = |v: &[&str]| -> Vec<String> { v.iter().map(|s| s.to_string()).collect() };
    let mut out = Vec::new();
    appell::cli::run_with(
        WheelAxle::default(),
        &args(&["wheel_axle", "info"]),
        &mut &b""[..],
        &mut out,
        |_| Ok(()),
    )
    .unwrap();
    let info: serde_json::Value = serde_json::from_slice(&out).unwrap();
    assert_eq!(info["scenes"][1]["name"], "WheelAxle::driven");
    assert_eq!(info["scenes"][1]["state_len"], 2);
    let line = br#"{"q": {"phi": 0.2}, "u": {"phi": 0.1, "psi1": 2.0}, "inputs": {"tau": 0.5}}"#;
    let mut out = Vec::new();
    appell::cli::run_with(
        WheelAxle::default(),
        &args(&["wheel_axle", "eval", "--scene", "driven"]),
        &mut &line[..],
        &mut out,
        |_| Ok(()),
    )
    .unwrap();
    let v: serde_json::Value = serde_json::from_slice(&out).unwrap();
    // Level ground: the heading does not enter, the torque turns the axle.
    let p = WheelAxle::default();
    let driven = WheelAxleDriven(p.clone());
    let mut d = [0.0; 2];
    driven
        .rhs(&driven.prepare::<f64>(), 0.0, &[0.1, 2.0], &[0.5], &mut d)
        .unwrap();
    assert_eq!(v["udot"]["phi"].as_f64().unwrap(), d[0]);
    assert_eq!(v["udot"]["psi1"].as_f64().unwrap(), d[1]);
    let mut out = Vec::new();
    let err = appell::cli::run_with(
        WheelAxle::default(),
        &args(&["wheel_axle", "eval", "--scene", "flying"]),
        &mut &line[..],
        &mut out,
        |_| Ok(()),
    );
    assert!(matches!(err, Err(appell::cli::CliError::Usage(_))));
    // `--scene` with no name says what it needs and which scenes exist.
    for command in ["eval", "contacts"] {
        let err = appell::cli::run_with(
            WheelAxle::default(),
            &args(&["wheel_axle", command, "--scene"]),
            &mut &line[..],
            &mut Vec::new(),
            |_| Ok(()),
        );
        let Err(appell::cli::CliError::Usage(message)) = err else {
            panic!("a usage error, got {err:?}");
        };
        assert!(
            message.starts_with(&format!(
                "`{command} --scene` needs the name of a scene after it"
            )),
            "{message}"
        );
        assert!(message.contains("WheelAxle::driven"), "{message}");
    }
}

#[test]
fn contact_check_scene_reports_its_outputs_on_the_command_line() {
    let args = |v: &[&str]| -> Vec<String> { v.iter().map(|s| s.to_string()).collect() };
    let run = |argv: &[&str], input: &[u8]| -> serde_json::Value {
        let mut out = Vec::new();
        appell::cli::run_with(
            WheelAxle::default(),
            &args(argv),
            &mut &input[..],
            &mut out,
            |_| Ok(()),
        )
        .unwrap();
        serde_json::from_slice(&out).unwrap()
    };
    let info = run(&["wheel_axle", "info"], b"");
    assert_eq!(info["scenes"][3]["name"], "WheelAxle::contact_check");
    assert_eq!(
        info["scenes"][3]["outputs"],
        serde_json::json!(["contact_forces", "energies"])
    );
    assert_eq!(
        info["scenes"][2]["outputs"],
        serde_json::json!(["quadrature"])
    );
    assert_eq!(info["contacts"], serde_json::json!([]));
    // Same effects as `coasting`: the same reduced equations.
    assert_eq!(info["scenes"][3]["rhs_ops"], info["scenes"][0]["rhs_ops"]);
    assert_eq!(
        info["scenes"][3]["state_len"],
        info["scenes"][0]["state_len"]
    );

    let line = br#"{"q": {"phi": 0.2}, "u": {"phi": 0.1, "psi1": 2.0}}"#;
    let p = WheelAxle::default();
    let scene = WheelAxleContactCheck(p.clone());
    let q = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.2];
    let u = [0.1, 2.0];
    let expected = appell::constraint_forces::contact_forces(&scene, 0.0, &q, &u, &[]).unwrap();
    let energies = appell::energy::energies(&scene, 0.0, &q, &u, &[]).unwrap();
    // `eval --scene contact_check`: rates plus the two outputs.
    let v = run(&["wheel_axle", "eval", "--scene", "contact_check"], line);
    assert!(v["udot"]["phi"].is_f64());
    let lambda: Vec<f64> = v["contact_forces"]["multipliers"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(lambda, expected.multipliers);
    assert_eq!(v["contact_forces"]["rows"][4]["source"], "nonholonomic 4");
    assert_eq!(v["energies"]["kinetic"].as_f64().unwrap(), energies.kinetic);
    // Other scenes and the full model answer with the rates only.
    let v = run(&["wheel_axle", "eval", "--scene", "coasting"], line);
    assert!(v.get("contact_forces").is_none() && v.get("energies").is_none());
    // `contacts` works on any model or scene; the coasting scene's
    // multipliers are those of contact_check (same effects).
    let v = run(&["wheel_axle", "contacts", "--scene", "coasting"], line);
    let lambda: Vec<f64> = v["multipliers"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(lambda, expected.multipliers);
    let v = run(&["wheel_axle", "contacts"], line);
    assert_eq!(v["multipliers"].as_array().unwrap().len(), 5);
}

#[test]
fn energy_of_the_coasting_scene_is_conserved_on_the_slope() {
    // Gravity only: T + V is constant along the motion (V = −M g sin α (x1 + x2)).
    let p = WheelAxle::default();
    let scene = WheelAxleTrack(p.clone());
    let prepared = scene.prepare::<f64>();
    // State (x1, y1, phi, phi_dot, psi1_dot) with no drive torque; x2, y2 follow
    // from the geometry of the axle (wheel 2 at +l along it).
    let energy = |s: &[f64; 5]| {
        let phi = s[2];
        let x2 = s[0] - p.l * phi.sin();
        let q = [s[0], s[1], 0.0, x2, s[1] + p.l * phi.cos(), 0.0, phi];
        p.kinetic_energy(0.0, &q, &s[3..]).unwrap() + p.potential_energy(0.0, &q).unwrap()
    };
    let s0 = [0.0, 0.0, 0.5, 0.3, 1.0];
    let e0 = energy(&s0);
    let s = appell::integrate::rk4(&scene, &prepared, 0.0, &s0, 1e-4, 20_000, &[0.0]).unwrap();
    let drift = ((energy(&s) - e0) / e0.abs().max(1.0)).abs();
    println!("wheel-axle on the slope: energy drift over 2 s {drift:.2e}");
    assert!(drift < 1e-9, "{drift:e}");
}

#[test]
fn input_power_is_torque_times_wheel_rate() {
    // The drive torque τ on wheel 1 about the axle: P = τ ψ̇1.
    let p = WheelAxle::default();
    let q = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7];
    let power = p.input_power(0.0, &q, &[0.8, -1.3], &[0.25]).unwrap();
    assert!(close(power, 0.25 * -1.3, 1e-15), "{power}");
    // The coasting scene has no input loads, and so no inputs; given the
    // full model's, it names the argument as the trait does.
    let coasting = WheelAxleCoasting(p);
    assert_eq!(WheelAxleCoasting::info().inputs, &[] as &[&str]);
    assert_eq!(
        coasting.input_power(0.0, &q, &[0.8, -1.3], &[]).unwrap(),
        0.0
    );
    assert_eq!(
        coasting.input_power(0.0, &q, &[0.8, -1.3], &[0.25]),
        Err(appell::ModelError::Length {
            argument: "inputs",
            expected: 0,
            found: 1
        })
    );
    assert_eq!(WheelAxleDriven::info().inputs, &["tau"]);
}

#[test]
fn energy_rate_is_the_input_power_in_every_scene() {
    // Gravity lives in V and rolling without slip does no work, so
    // d(T + V)/dt is the drive torque's power τ ψ̇1 in the full model, zero
    // in the coasting scene, and again τ ψ̇1 in the driven scene (V = 0).
    use appell::energy::energies;
    let p = WheelAxle::default();
    let mut rng = Rng(0xe4e7);
    let mut worst: f64 = 0.0;
    for _ in 0..1000 {
        let q: Vec<f64> = (0..7).map(|_| rng.uniform(-2.0, 2.0)).collect();
        let u = [rng.uniform(-3.0, 3.0), rng.uniform(-10.0, 10.0)];
        let tau = [rng.uniform(-2.0, 2.0)];
        let full = energies(&p, 0.0, &q, &u, &tau).unwrap();
        let coasting = energies(&WheelAxleCoasting(p.clone()), 0.0, &q, &u, &[]).unwrap();
        let driven = energies(&WheelAxleDriven(p.clone()), 0.0, &q, &u, &tau).unwrap();
        let scale = 1.0 + full.kinetic.abs() + full.potential.abs();
        assert!(close(full.input_power, tau[0] * u[1], 1e-15));
        assert_eq!(driven.potential, 0.0);
        for (rate, power) in [
            (full.rate, full.input_power),
            (coasting.rate, 0.0),
            (driven.rate, driven.input_power),
        ] {
            worst = worst.max((rate - power).abs() / scale);
        }
    }
    println!("wheel-axle: |d(T+V)/dt − input power| / (1 + |T| + |V|) at most {worst:.2e}");
    assert!(worst < 1e-12, "{worst:e}");
    // Bad arguments are typed errors.
    assert!(energies(&p, 0.0, &[0.0; 6], &[0.0; 2], &[0.0]).is_err());
    assert!(energies(&p, f64::NAN, &[0.0; 7], &[0.0; 2], &[0.0]).is_err());
}
