//! Driven coordinates: drives that command a motion instead of a torque.
//!
//! (a) The paper's wheel-axle (Wang & Pao 2003, Sec. IV C) with wheel 1's
//! spin rate commanded (a speed-controlled drive, `nonholonomic(dt(psi1) ==
//! w_cmd)`) on a smooth ramp: the axle's heading follows from the dynamics,
//! and the drive torque is the driving row's multiplier.
//!
//! (b) A two-link arm on a passive sliding base with both joints under
//! position control (`holonomic(th1 == q1_cmd)`, `holonomic(th2 ==
//! q2_cmd)`) following sine trajectories: the joints track the commands
//! (projected onto them between output times), the base recoils, and the
//! joint torques are the driving rows' multipliers.
//!
//! Run `cargo run --release --example driven_drives`; `-- eval`, `-- info`
//! and `-- equations` give the arm's command line.

use std::error::Error;
use std::f64::consts::PI;
use std::process::ExitCode;

use appell::constraint_forces::contact_forces;
use appell::integrate::Dop853;
use appell::linearize::driven_project_holonomic;
use appell::{Appell, Model, ModelInfo, RowSource};

#[path = "models/driven_wheel_axle.rs"]
mod driven_wheel_axle;
use driven_wheel_axle::DrivenWheelAxle;

/// A two-link arm (point masses at the elbow and the tip) on a base that
/// slides freely along N.x, both joints position-controlled.
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(coordinates(x, th1, th2), speeds(x))]
#[appell(point(B = O + x * N.x), particle(B, mass = base))]
#[appell(point(E = B + l1 * sin(th1) * N.x - l1 * cos(th1) * N.y), particle(E, mass = m1))]
#[appell(point(P = E + l2 * sin(th1 + th2) * N.x - l2 * cos(th1 + th2) * N.y),
         particle(P, mass = m2))]
#[appell(gravity(-g * N.y))]
#[appell(holonomic(th1 == q1_cmd), holonomic(th2 == q2_cmd), inputs(q1_cmd, q2_cmd))]
struct ArmOnRail {
    base: f64,
    m1: f64,
    m2: f64,
    l1: f64,
    l2: f64,
    g: f64,
}

impl Default for ArmOnRail {
    fn default() -> Self {
        ArmOnRail {
            base: 4.0,
            m1: 1.5,
            m2: 1.0,
            l1: 0.5,
            l2: 0.4,
            g: 9.81,
        }
    }
}

fn main() -> ExitCode {
    appell::cli::run(ArmOnRail::default(), |arm| {
        wheel_axle()?;
        arm_on_rail(arm)
    })
}

/// The inputs in the model's order, from (name, value) pairs.
fn inputs_named(info: &ModelInfo, values: &[(&str, f64)]) -> Result<Vec<f64>, Box<dyn Error>> {
    info.inputs
        .iter()
        .map(|name| {
            values
                .iter()
                .find(|(n, _)| n == name)
                .map(|&(_, v)| v)
                .ok_or_else(|| format!("no value for input `{name}`").into())
        })
        .collect()
}

/// All coordinates from a reduced state (the ignorable ones at 0) and the
/// privileged speeds.
fn full_q(info: &ModelInfo, state: &[f64]) -> Result<(Vec<f64>, Vec<f64>), Box<dyn Error>> {
    let mut q = vec![0.0; info.coordinates.len()];
    for (k, name) in info.retained.iter().enumerate() {
        let i = info
            .coordinate_index(name)
            .ok_or("a retained coordinate is not a coordinate")?;
        q[i] = state[k];
    }
    Ok((q, state[info.retained.len()..].to_vec()))
}

/// The generalized force of each drive: the multiplier of the driving row
/// of each constraint (`holonomic` or not) in declaration order.
fn drive_forces<M: Model>(
    model: &M,
    t: f64,
    state: &[f64],
    inputs: &[f64],
    holonomic: bool,
) -> Result<Vec<f64>, Box<dyn Error>> {
    let (q, u) = full_q(M::info(), state)?;
    let cf = contact_forces(model, t, &q, &u, inputs)?;
    Ok(cf
        .rows
        .iter()
        .filter(|r| matches!(r.source, RowSource::Driven { holonomic: h, .. } if h == holonomic))
        .map(|r| r.multiplier)
        .collect())
}

/// (a) Wheel 1's spin rate ramped smoothly from 0 to `top` over `ramp`
/// seconds, then held: (w_cmd, w_cmd_rate).
fn wheel_command(t: f64, top: f64, ramp: f64) -> (f64, f64) {
    if t < ramp {
        let s = PI * t / ramp;
        (
            top * (1.0 - s.cos()) / 2.0,
            top * PI / (2.0 * ramp) * s.sin(),
        )
    } else {
        (top, 0.0)
    }
}

fn wheel_axle() -> Result<(), Box<dyn Error>> {
    let p = DrivenWheelAxle {
        a: 0.3,
        l: 1.2,
        mass: 2.0,
        rim: 0.5,
        g: 9.81,
        alpha: 0.2,
    };
    let info = DrivenWheelAxle::info();
    let (top, ramp) = (4.0, 2.0);
    let command = |t: f64| {
        let (w, w_rate) = wheel_command(t, top, ramp);
        inputs_named(info, &[("w_cmd", w), ("w_cmd_rate", w_rate)])
    };
    println!(
        "(a) {}: wheel 1 spun up to {top} rad/s over {ramp} s, on a {} rad incline",
        info.name, p.alpha
    );
    println!(
        "    reduced state: {:?} then speeds {:?}",
        info.retained, info.speeds
    );
    println!(
        "{:>6} {:>10} {:>10} {:>12} {:>14}",
        "t [s]", "w_cmd", "phi", "phi_dot", "torque [N m]"
    );
    let prepared = p.prepare::<f64>();
    let dop = Dop853::new().rtol(1e-10).atol(1e-12);
    let mut state = [0.3, 0.0];
    let (dt, steps) = (0.5, 8);
    for k in 0..=steps {
        let t = k as f64 * dt;
        let inputs = command(t)?;
        let torque = drive_forces(&p, t, &state, &inputs, false)?;
        println!(
            "{t:>6.2} {:>10.4} {:>10.5} {:>12.5} {:>14.5}",
            inputs[0], state[0], state[1], torque[0]
        );
        if k < steps {
            let f = |t: f64, x: &[f64; 2], dx: &mut [f64; 2]| {
                let (w, w_rate) = wheel_command(t, top, ramp);
                p.rhs(&prepared, t, x, &[w, w_rate], dx)
            };
            state = dop.solve(f, t, &state, t + dt)?.x;
        }
    }
    println!(
        "    (the torque holds wheel 1 at the command against gravity and the axle's turning)\n"
    );
    Ok(())
}

/// (b) The joints' trajectories: (q1, q1', q1'', q2, q2', q2'').
fn arm_command(t: f64) -> [f64; 6] {
    let (s1, c1) = (1.5 * t).sin_cos();
    let (s2, c2) = (2.3 * t).sin_cos();
    [
        0.6 * s1,
        0.6 * 1.5 * c1,
        -0.6 * 2.25 * s1,
        0.4 + 0.5 * s2,
        0.5 * 2.3 * c2,
        -0.5 * 2.3 * 2.3 * s2,
    ]
}

fn arm_on_rail(p: &ArmOnRail) -> Result<(), Box<dyn Error>> {
    let info = ArmOnRail::info();
    let command = |t: f64| {
        let c = arm_command(t);
        inputs_named(
            info,
            &[
                ("q1_cmd", c[0]),
                ("q1_cmd_rate", c[1]),
                ("q1_cmd_accel", c[2]),
                ("q2_cmd", c[3]),
                ("q2_cmd_rate", c[4]),
                ("q2_cmd_accel", c[5]),
            ],
        )
    };
    println!(
        "(b) {}: both joints follow sine trajectories, the base slides freely",
        info.name
    );
    println!(
        "    reduced state: {:?} then speeds {:?}",
        info.retained, info.speeds
    );
    println!(
        "{:>6} {:>9} {:>11} {:>9} {:>11} {:>11} {:>11} {:>9}",
        "t [s]", "q1_cmd", "th1-q1", "q2_cmd", "th2-q2", "tau1 [N m]", "tau2 [N m]", "x_dot"
    );
    let prepared = p.prepare::<f64>();
    let dop = Dop853::new().rtol(1e-8).atol(1e-10);
    let (th1, th2) = (
        info.retained
            .iter()
            .position(|r| *r == "th1")
            .ok_or("th1 is not retained")?,
        info.retained
            .iter()
            .position(|r| *r == "th2")
            .ok_or("th2 is not retained")?,
    );
    let mut state = [0.0; 3];
    let c0 = arm_command(0.0);
    (state[th1], state[th2]) = (c0[0], c0[3]);
    let (dt, steps) = (0.25, 12);
    let mut worst = 0.0_f64;
    for k in 0..=steps {
        let t = k as f64 * dt;
        let inputs = command(t)?;
        let c = arm_command(t);
        let (e1, e2) = (state[th1] - c[0], state[th2] - c[3]);
        worst = worst.max(e1.abs()).max(e2.abs());
        let tau = drive_forces(p, t, &state, &inputs, true)?;
        println!(
            "{t:>6.2} {:>9.4} {e1:>11.2e} {:>9.4} {e2:>11.2e} {:>11.5} {:>11.5} {:>9.5}",
            c[0], c[3], tau[0], tau[1], state[2]
        );
        if k < steps {
            let f = |t: f64, x: &[f64; 3], dx: &mut [f64; 3]| {
                let inputs =
                    command(t).map_err(|_| appell::ModelError::NonFinite { what: "inputs" })?;
                p.rhs(&prepared, t, x, &inputs, dx)
            };
            state = dop.solve(f, t, &state, t + dt)?.x;
            let before = state;
            driven_project_holonomic(p, t + dt, &mut state, &command(t + dt)?, 1e-14, 20)?;
            worst = worst
                .max((before[th1] - state[th1]).abs())
                .max((before[th2] - state[th2]).abs());
        }
    }
    println!("    worst tracking error before projection: {worst:.2e} rad (DOP853, rtol 1e-8)");
    Ok(())
}
