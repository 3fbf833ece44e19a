//! Driven coordinates: a constraint that an input drives
//! (`nonholonomic(dt(psi1) == w_cmd)`, `holonomic(theta == q_cmd)`), the
//! caller supplying the command's derivatives as the companion inputs
//! `w_cmd_rate` (and `q_cmd_accel`). The driving row's multiplier is the
//! generalized force the drive applies: fed to the undriven model as its
//! motor torque it reproduces the driven motion, and it is the undriven
//! model's inverse dynamics.

#[path = "../examples/models/wheel_axle.rs"]
mod wheel_axle;

mod common;
use appell::constraint_forces::contact_forces;
use appell::{Appell, Model, RowSource};
use common::{close, Rng};
use wheel_axle::WheelAxle;

/// The wheel-axle with wheel 1's spin rate commanded instead of its motor
/// torque: psi1's rate is no longer a privileged speed.
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(coordinates(x1, y1, psi1, x2, y2, psi2, phi))]
#[appell(speeds(phi))]
#[appell(positive(a))]
#[appell(frame(A = N.rotate_z(phi)))]
#[appell(frame(W1 = A.rotate_y(psi1)), frame(W2 = A.rotate_y(psi2)))]
#[appell(point(C1 = O + x1 * N.x + y1 * N.y), point(C2 = O + x2 * N.x + y2 * N.y))]
#[appell(body(wheel1, center = C1, frame = W1, mass = mass,
              inertia = principal(rim * a * a / 2, rim * a * a, rim * a * a / 2)))]
#[appell(body(wheel2, center = C2, frame = W2, mass = mass,
              inertia = principal(rim * a * a / 2, rim * a * a, rim * a * a / 2)))]
#[appell(nonholonomic(dt(x1) == a * dt(psi1) * cos(phi)),
         nonholonomic(dt(y1) == a * dt(psi1) * sin(phi)),
         nonholonomic(dt(x2) == a * dt(psi2) * cos(phi)),
         nonholonomic(dt(y2) == a * dt(psi2) * sin(phi)),
         nonholonomic(a * dt(psi2) == a * dt(psi1) - l * dt(phi)),
         nonholonomic(dt(psi1) == w_cmd))]
#[appell(force(C1, mass * g * sin(alpha) * N.x, effect = gravity),
         force(C2, mass * g * sin(alpha) * N.x, effect = gravity))]
#[appell(inputs(w_cmd))]
struct DrivenWheelAxle {
    a: f64,
    l: f64,
    mass: f64,
    rim: f64,
    g: f64,
    alpha: f64,
}

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
