//! Driven coordinates: a constraint that an input drives
//! (`nonholonomic(dt(psi1) == w_cmd)`, `holonomic(theta == q_cmd)`), the
//! caller supplying the command's derivatives as the companion inputs
//! `w_cmd_rate` (and `q_cmd_accel`). The driving row's multiplier is the
//! generalized force the drive applies: fed to the undriven model as its
//! motor torque it reproduces the driven motion, and it is the undriven
//! model's inverse dynamics.

#[path = "../examples/models/driven_wheel_axle.rs"]
mod driven_wheel_axle;
#[path = "../examples/models/wheel_axle.rs"]
mod wheel_axle;

mod common;
use appell::constraint_forces::contact_forces;
use appell::{Appell, Model, RowSource};
use common::{close, Rng};
use driven_wheel_axle::DrivenWheelAxle;
use wheel_axle::WheelAxle;

/// A pendulum whose angle is position-controlled, beside a free particle
/// (its one privileged speed).
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(coordinates(theta, z), speeds(z))]
#[appell(point(P = O + l * sin(theta) * N.x - l * cos(theta) * N.y), particle(P, mass = m))]
#[appell(point(Z = O + z * N.z), particle(Z, mass = m2))]
#[appell(gravity(-g * N.y))]
#[appell(holonomic(theta == q_cmd), inputs(q_cmd))]
struct ServoPendulum {
    m: f64,
    m2: f64,
    l: f64,
    g: f64,
}

fn full_state<M: Model>(q: &[f64], u: &[f64]) -> Vec<f64> {
    let info = M::info();
    let mut s: Vec<f64> = info
        .retained
        .iter()
        .map(|r| q[info.coordinate_index(r).unwrap()])
        .collect();
    s.extend(u);
    s
}

fn rhs<M: Model>(model: &M, q: &[f64], u: &[f64], inputs: &[f64]) -> Vec<f64> {
    let state = full_state::<M>(q, u);
    let mut ds = vec![0.0; state.len()];
    model
        .rhs(&model.prepare(), 0.3, &state, inputs, &mut ds)
        .unwrap();
    ds[ds.len() - u.len()..].to_vec()
}

#[test]
fn the_companion_inputs_follow_the_declared_ones() {
    assert_eq!(DrivenWheelAxle::info().inputs, ["w_cmd", "w_cmd_rate"]);
    assert_eq!(
        ServoPendulum::info().inputs,
        ["q_cmd", "q_cmd_rate", "q_cmd_accel"]
    );
    let last = *DrivenWheelAxle::info().row_sources.last().unwrap();
    assert_eq!(
        last,
        RowSource::Driven {
            holonomic: false,
            index: 5,
            constraint: "nonholonomic: dt(psi1) == w_cmd"
        }
    );
    assert!(matches!(
        ServoPendulum::info().row_sources[0],
        RowSource::Driven {
            holonomic: true,
            index: 0,
            constraint: "holonomic: theta == q_cmd"
        }
    ));
}

#[test]
fn the_drive_torque_reproduces_the_driven_motion_and_is_the_inverse_dynamics() {
    let mut rng = Rng(0x5eed_d21e);
    let mut worst = 0.0_f64;
    for _ in 0..20 {
        let p: WheelAxle = common::random_wheel_axle!(rng);
        let d = DrivenWheelAxle {
            a: p.a,
            l: p.l,
            mass: p.mass,
            rim: p.rim,
            g: p.g,
            alpha: p.alpha,
        };
        let q: Vec<f64> = (0..7).map(|_| rng.uniform(-2.0, 2.0)).collect();
        let (phi_dot, w, w_rate) = (
            rng.uniform(-2.0, 2.0),
            rng.uniform(-3.0, 3.0),
            rng.uniform(-2.0, 2.0),
        );
        let inputs = [w, w_rate];
        // The driven model: its one speed's acceleration, and the torque the
        // drive applies (the driving row's multiplier; D's row is e_psi1).
        let phi_ddot = rhs(&d, &q, &[phi_dot], &inputs)[0];
        let cf = contact_forces(&d, 0.3, &q, &[phi_dot], &inputs).unwrap();
        let row = cf.rows.last().unwrap();
        assert!(matches!(row.source, RowSource::Driven { .. }));
        let psi1 = DrivenWheelAxle::info().coordinate_index("psi1").unwrap();
        let tau = row.generalized[psi1];
        assert!(close(tau, row.multiplier, 1e-14));
        assert!(
            close(cf.qddot[psi1], w_rate, 1e-10),
            "{} {w_rate}",
            cf.qddot[psi1]
        );
        // (a) The undriven model with that torque: the same φ̈, and ψ̈1 the
        // commanded rate's rate.
        let undriven = rhs(&p, &q, &[phi_dot, w], &[tau]);
        worst = worst.max((undriven[0] - phi_ddot).abs() / (1.0 + phi_ddot.abs()));
        worst = worst.max((undriven[1] - w_rate).abs() / (1.0 + w_rate.abs()));
        assert!(
            close(undriven[0], phi_ddot, 1e-10),
            "{undriven:?} {phi_ddot}"
        );
        assert!(close(undriven[1], w_rate, 1e-10), "{undriven:?} {w_rate}");
        // ... and a different torque does not.
        let off = rhs(&p, &q, &[phi_dot, w], &[tau + 0.1]);
        assert!(!close(off[1], w_rate, 1e-6));
        // (b) The undriven model's inverse dynamics at the driven motion.
        let mut forces = [0.0; 2];
        p.inverse_dynamics(0.3, &q, &[phi_dot, w], &[phi_ddot, w_rate], &mut forces)
            .unwrap();
        assert!(close(forces[1], tau, 1e-10), "{forces:?} {tau}");
        assert!(forces[0].abs() < 1e-10 * (1.0 + tau.abs()), "{forces:?}");
    }
    eprintln!("worst relative disagreement {worst:e}");
}

#[test]
fn a_position_controlled_joint_needs_the_torque_of_the_closed_form() {
    let mut rng = Rng(0xfeed_5e70);
    for _ in 0..20 {
        let p = ServoPendulum {
            m: rng.uniform(0.5, 3.0),
            m2: rng.uniform(0.5, 3.0),
            l: rng.uniform(0.2, 2.0),
            g: 9.81,
        };
        // A time-varying command q(t) = A sin(ω t) at a random time.
        let (amp, om, t) = (
            rng.uniform(0.1, 1.5),
            rng.uniform(0.5, 4.0),
            rng.uniform(0.0, 5.0),
        );
        let (qc, qd, qdd) = (
            amp * (om * t).sin(),
            amp * om * (om * t).cos(),
            -amp * om * om * (om * t).sin(),
        );
        let q = [qc, rng.uniform(-1.0, 1.0)];
        let u = [rng.uniform(-1.0, 1.0)];
        let cf = contact_forces(&p, t, &q, &u, &[qc, qd, qdd]).unwrap();
        let torque = cf.rows[0].generalized[0];
        let expected = p.m * p.l * p.l * qdd + p.m * p.g * p.l * qc.sin();
        assert!(close(torque, expected, 1e-10), "{torque} {expected}");
        assert!(close(cf.qddot[0], qdd, 1e-10));
        // The free particle is not affected.
        assert!(close(rhs(&p, &q, &u, &[qc, qd, qdd])[0], 0.0, 1e-12));
    }
}

/// A cart on a rail carrying a pendulum whose angle is position-controlled:
/// the angle appears in the cart's equation, so the reduced state carries
/// it, (theta, x_dot).
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(coordinates(x, theta), speeds(x))]
#[appell(point(C = O + x * N.x), particle(C, mass = big))]
#[appell(point(P = C + l * sin(theta) * N.x - l * cos(theta) * N.y), particle(P, mass = m))]
#[appell(gravity(-g * N.y))]
#[appell(holonomic(theta == q_cmd), inputs(q_cmd))]
struct ServoCart {
    big: f64,
    m: f64,
    l: f64,
    g: f64,
}

/// The command q(t) = A sin(ω t) and its two derivatives, as the inputs
/// (q_cmd, q_cmd_rate, q_cmd_accel).
fn sine_command(amp: f64, om: f64, t: f64) -> [f64; 3] {
    let (s, c) = (om * t).sin_cos();
    [amp * s, amp * om * c, -amp * om * om * s]
}

#[test]
fn the_driven_functions_need_the_inputs_and_the_undriven_ones_say_so() {
    let p = ServoPendulum {
        m: 1.0,
        m2: 2.0,
        l: 0.5,
        g: 9.81,
    };
    let (q, u) = ([0.3, 0.1], [0.2]);
    let needs = |f: &'static str| appell::ModelError::NeedsInputs { function: f };
    assert_eq!(p.kinetic_energy(0.0, &q, &u), Err(needs("kinetic_energy")));
    let (mut c, mut c0) = ([0.0; 2], [0.0; 2]);
    assert_eq!(
        p.speed_transform(0.0, &q, &mut c, &mut c0),
        Err(needs("speed_transform"))
    );
    let (mut h, mut v) = ([0.0], [0.0]);
    assert_eq!(
        p.constraint_residuals(0.0, &q, &[0.0; 2], &mut h, &mut v),
        Err(needs("constraint_residuals"))
    );
    // With them: c carries the commanded rate, the residuals the distance
    // from the command, T the pendulum's motion at the commanded rate.
    let inputs = [0.25, 0.7, -0.4];
    p.driven_speed_transform(0.0, &q, &inputs, &mut c, &mut c0)
        .unwrap();
    assert_eq!((c, c0), ([0.0, 1.0], [0.7, 0.0]));
    p.driven_constraint_residuals(0.0, &q, &[0.7, 0.2], &inputs, &mut h, &mut v)
        .unwrap();
    assert!(close(h[0], 0.05, 1e-12) && v[0] == 0.0, "{h:?} {v:?}");
    let t = p.driven_kinetic_energy(0.0, &q, &u, &inputs).unwrap();
    let expected = 0.5 * p.m * p.l * p.l * 0.49 + 0.5 * p.m2 * 0.04;
    assert!(close(t, expected, 1e-14), "{t} {expected}");
    let still = p
        .driven_kinetic_energy(0.0, &q, &u, &[0.25, 0.0, 0.0])
        .unwrap();
    assert!(!close(still, expected, 1e-3));
    // The wrong number of inputs is a typed error.
    assert!(matches!(
        p.driven_kinetic_energy(0.0, &q, &u, &[0.25]),
        Err(appell::ModelError::Length { .. })
    ));
}

#[test]
fn the_driven_wheel_axle_has_the_undriven_kinetic_energy() {
    let mut rng = Rng(0x0e1e_26e7);
    for _ in 0..20 {
        let p: WheelAxle = common::random_wheel_axle!(rng);
        let d = DrivenWheelAxle {
            a: p.a,
            l: p.l,
            mass: p.mass,
            rim: p.rim,
            g: p.g,
            alpha: p.alpha,
        };
        let q: Vec<f64> = (0..7).map(|_| rng.uniform(-2.0, 2.0)).collect();
        let (phi_dot, w, w_rate) = (
            rng.uniform(-2.0, 2.0),
            rng.uniform(0.5, 3.0),
            rng.uniform(-2.0, 2.0),
        );
        // The undriven model's speeds are (phi, psi1); wheel 1 spinning at
        // the commanded w is the same motion.
        let undriven = p.kinetic_energy(0.3, &q, &[phi_dot, w]).unwrap();
        let driven = d
            .driven_kinetic_energy(0.3, &q, &[phi_dot], &[w, w_rate])
            .unwrap();
        assert!(close(driven, undriven, 1e-12), "{driven} {undriven}");
        // ... and with the command at zero it is another motion.
        let stopped = d
            .driven_kinetic_energy(0.3, &q, &[phi_dot], &[0.0, 0.0])
            .unwrap();
        assert!(!close(stopped, undriven, 1e-6));
        // The energies module reads the driven form, and the motion rates
        // move psi1 at the command.
        let e = appell::energy::energies(&d, 0.3, &q, &[phi_dot], &[w, w_rate]).unwrap();
        assert!(close(e.kinetic, driven, 1e-14), "{} {driven}", e.kinetic);
        let r = appell::motion::rates(&d, 0.3, &q, &[phi_dot], &[w, w_rate]).unwrap();
        let psi1 = DrivenWheelAxle::info().coordinate_index("psi1").unwrap();
        assert_eq!(r.qdot[psi1], w);
        assert!(close(r.qddot[psi1], w_rate, 1e-12), "{:?}", r.qddot);
        // The velocity residuals vanish at the driven rates, not at others.
        let (mut h, mut v) = ([0.0; 0], [0.0; 6]);
        d.driven_constraint_residuals(0.3, &q, &r.qdot, &[w, w_rate], &mut h, &mut v)
            .unwrap();
        assert!(v.iter().all(|x| x.abs() < 1e-12), "{v:?}");
        d.driven_constraint_residuals(0.3, &q, &r.qdot, &[w + 0.1, w_rate], &mut h, &mut v)
            .unwrap();
        assert!(close(v[5].abs(), 0.1, 1e-12), "{v:?}");
    }
}

#[test]
fn a_servo_pendulum_follows_a_sine_command_under_dop853() {
    use appell::integrate::Dop853;
    let p = ServoPendulum {
        m: 1.2,
        m2: 0.7,
        l: 0.8,
        g: 9.81,
    };
    let (amp, om) = (0.8, 2.5);
    // theta is cyclic (not in the reduced state): integrate the full state
    // (theta, z, z_dot), q̇ from the driven coordinate rates at the command.
    let full = |cmd: &dyn Fn(f64) -> [f64; 3]| {
        let prepared = p.prepare::<f64>();
        let f = |t: f64, x: &[f64; 3], dx: &mut [f64; 3]| {
            let inputs = cmd(t);
            let mut qdot = [0.0; 2];
            p.driven_coordinate_rates(t, &x[..2], &x[2..], &inputs, &mut qdot)?;
            let mut ds = [0.0; 1];
            p.rhs(&prepared, t, &x[2..], &inputs, &mut ds)?;
            *dx = [qdot[0], qdot[1], ds[0]];
            Ok(())
        };
        Dop853::new()
            .rtol(1e-11)
            .atol(1e-12)
            .solve(f, 0.0, &[0.0, 0.0, 0.3], 4.0)
            .unwrap()
    };
    let sol = full(&|t| sine_command(amp, om, t));
    let expected = sine_command(amp, om, 4.0)[0];
    assert!(
        (sol.x[0] - expected).abs() < 1e-9,
        "{} {expected}",
        sol.x[0]
    );
    assert!(close(sol.x[1], 1.2, 1e-12) && close(sol.x[2], 0.3, 1e-12));
    // A command held at its initial values does not move it.
    let held = full(&|_| sine_command(amp, om, 0.0));
    assert!((held.x[0] - 4.0 * amp * om).abs() < 1e-9 && (held.x[0] - expected).abs() > 0.1);
}

/// Integrates the servo cart under a sine command with Dop853, projecting
/// onto the command after every step when `project` is set.
fn servo_cart_run(p: &ServoCart, amp: f64, om: f64, project: bool, rtol: f64) -> [f64; 2] {
    use appell::integrate::Dop853;
    use appell::linearize::driven_project_holonomic;
    let prepared = p.prepare::<f64>();
    let f = |t: f64, x: &[f64; 2], dx: &mut [f64; 2]| {
        p.rhs(&prepared, t, x, &sine_command(amp, om, t), dx)
    };
    let mut onto = |t: f64, x: &mut [f64; 2]| {
        driven_project_holonomic(p, t, x, &sine_command(amp, om, t), 1e-14, 20)
            .map(|_| ())
            .map_err(Into::into)
    };
    let dop = Dop853::new().rtol(rtol).atol(rtol);
    let sol = if project {
        dop.solve_projected(f, &mut onto, 0.0, &[0.0, 0.1], 5.0)
    } else {
        dop.solve(f, 0.0, &[0.0, 0.1], 5.0)
    };
    sol.unwrap().x
}

#[test]
fn a_servo_cart_tracks_its_command_and_the_projection_keeps_it_there() {
    use appell::linearize::{check_holonomic, driven_check_holonomic};
    let p = ServoCart {
        big: 2.0,
        m: 0.5,
        l: 0.6,
        g: 9.81,
    };
    let (amp, om) = (0.9, 3.0);
    assert_eq!(ServoCart::info().retained, ["theta"]);
    let cmd = sine_command(amp, om, 5.0);
    let residual = |x: &[f64; 2], inputs: &[f64]| {
        driven_check_holonomic(&p, 5.0, x, inputs, f64::INFINITY).unwrap()[0].abs()
    };
    // Loose: the free run drifts off the command at the integrator's error;
    // projected, it is on it to round-off.
    let free = servo_cart_run(&p, amp, om, false, 1e-6);
    let kept = servo_cart_run(&p, amp, om, true, 1e-6);
    let (r_free, r_kept) = (residual(&free, &cmd), residual(&kept, &cmd));
    println!("servo cart, DOP853 rtol 1e-6: residual {r_free:.2e} free, {r_kept:.2e} projected");
    assert!(r_free < 1e-5 && r_kept < 1e-14, "{r_free:e} {r_kept:e}");
    // Tight: the free run follows to the tolerance, and the cart's speed
    // agrees with the projected run's.
    let tight = servo_cart_run(&p, amp, om, false, 1e-12);
    assert!(residual(&tight, &cmd) < 1e-9, "{tight:?} {cmd:?}");
    assert!(close(tight[1], kept[1], 1e-4), "{tight:?} {kept:?}");
    // Against another command, or without the inputs, it is not.
    assert!(residual(&tight, &sine_command(amp, om, 4.9)) > 1e-2);
    assert!(check_holonomic(&p, 5.0, &tight, 1.0).is_err());
}

#[test]
fn the_drive_power_is_the_rate_of_the_energy() {
    use appell::energy::energies;
    let mut rng = Rng(0x90e5_0a1e);
    let mut worst = 0.0_f64;
    for _ in 0..20 {
        let p = ServoCart {
            big: rng.uniform(0.5, 3.0),
            m: rng.uniform(0.2, 2.0),
            l: rng.uniform(0.2, 1.5),
            g: 9.81,
        };
        let (amp, om, t) = (
            rng.uniform(0.1, 1.5),
            rng.uniform(0.5, 4.0),
            rng.uniform(0.0, 5.0),
        );
        let inputs = sine_command(amp, om, t);
        let theta = ServoCart::info().coordinate_index("theta").unwrap();
        let mut q = [rng.uniform(-1.0, 1.0), 0.0];
        q[theta] = inputs[0];
        let u = [rng.uniform(-2.0, 2.0)];
        let e = energies(&p, t, &q, &u, &inputs).unwrap();
        assert_eq!(e.input_power, 0.0);
        let tk = p.driven_kinetic_energy(t, &q, &u, &inputs).unwrap();
        assert!(close(e.kinetic, tk, 1e-14), "{} {tk}", e.kinetic);
        // The closed form: ½(M+m)ẋ² + m l cosθ ẋ θ̇ + ½ m l² θ̇².
        let (xd, th, thd) = (u[0], inputs[0], inputs[1]);
        let closed = 0.5 * (p.big + p.m) * xd * xd
            + p.m * p.l * th.cos() * xd * thd
            + 0.5 * p.m * p.l * p.l * thd * thd;
        assert!(close(tk, closed, 1e-12), "{tk} {closed}");
        // The drive's power: its row's multiplier times theta's rate.
        let cf = contact_forces(&p, t, &q, &u, &inputs).unwrap();
        let tau = cf.rows[0].generalized[theta];
        let power = tau * inputs[1];
        let scale = 1.0 + power.abs() + e.rate.abs();
        worst = worst.max((e.rate - power).abs() / scale);
        assert!((e.rate - power).abs() < 1e-10 * scale, "{} {power}", e.rate);
        // A command whose acceleration is not the one the rate sees gives
        // another energy rate, not the drive's power.
        let mut off = inputs;
        off[2] += 1.0;
        let e_off = energies(&p, t, &q, &u, &off).unwrap();
        assert!((e_off.rate - power).abs() > 1e-6 * scale);
    }
    eprintln!("worst relative power imbalance {worst:e}");
}

#[test]
fn the_command_line_evaluates_a_driven_model() {
    use appell::cli::Evaluator;
    let p = ServoCart {
        big: 2.0,
        m: 0.5,
        l: 0.6,
        g: 9.81,
    };
    let inputs = sine_command(0.7, 2.0, 0.4);
    let line = |cmd: f64| {
        format!(
            r#"{{"t": 0.4, "q": {{"theta": {}}}, "u": {{"x": 0.3}}, "inputs": {{"q_cmd": {cmd}, "q_cmd_rate": {}, "q_cmd_accel": {}}}}}"#,
            inputs[0], inputs[1], inputs[2]
        )
    };
    let mut ev = Evaluator::new(p.clone()).unwrap();
    let v = ev.eval_line(&line(inputs[0]));
    assert!(v.get("error").is_none(), "{v}");
    assert_eq!(v["qdot"]["theta"].as_f64(), Some(inputs[1]));
    assert_eq!(v["qdot"]["x"].as_f64(), Some(0.3));
    assert!(v.get("warning").is_none(), "{v}");
    let r = appell::motion::rates(&p, 0.4, &[0.0, inputs[0]], &[0.3], &inputs).unwrap();
    let udot = v["udot"]["x"].as_f64().unwrap();
    assert!(close(udot, r.udot[0], 1e-15), "{udot} {:?}", r.udot);
    // Off the command: the holonomic warning, from the residual at the
    // inputs.
    let v = ev.eval_line(&line(inputs[0] + 0.1));
    assert!(v["warning"]["message"]
        .as_str()
        .unwrap()
        .contains("holonomic constraint 0"));
    let h = v["warning"]["holonomic_residuals"][0].as_f64().unwrap();
    assert!(close(h, -0.1, 1e-12), "{h}");
}
