//! Generated rhs against the independent multiplier solver (full
//! coordinates, Lagrange multipliers, Jacobians by dual numbers; Wang & Pao
//! eqs. 69-70) at 1,000 random states per model.

#[path = "../examples/models/chaplygin_sleigh.rs"]
mod chaplygin;
#[path = "../examples/models/wheel_axle.rs"]
mod wheel_axle;

mod common;
#[path = "../examples/models/double_pendulum.rs"]
mod double_pendulum;
use appell::Appell;
use common::{agree, Rng};
use double_pendulum::DoublePendulum;

/// A knife edge with an offset mass centre, a drive force along the blade
/// and a steering torque, so forces, torques and the nonholonomic
/// constraint all enter.
#[derive(Appell, Clone)]
#[appell(coordinates(x, y, theta), speeds(x, theta), positive(m, b))]
#[appell(frame(B = N.rotate_z(theta)))]
#[appell(point(P = O + x * N.x + y * N.y), point(C = P + b * B.x))]
#[appell(body(sleigh, center = C, frame = B, mass = m, inertia = principal(i0, i0, i0)))]
#[appell(nonholonomic(dt(y) * cos(theta) - dt(x) * sin(theta) == 0))]
#[appell(inputs(drive, steer))]
#[appell(force(P, drive * B.x, effect = motor), torque(B, steer * N.z, effect = motor))]
struct Sleigh {
    m: f64,
    i0: f64,
    b: f64,
}

/// A body swinging about a point on a rotating arm: time-free but with
/// rotations about two axes, for the gyroscopic terms.
#[derive(Appell, Clone)]
#[appell(coordinates(psi, theta), speeds(psi, theta))]
#[appell(frame(A = N.rotate_z(psi)), frame(B = A.rotate_x(theta)))]
#[appell(point(H = O + r * A.x), point(C = H - h * B.z))]
#[appell(body(bob, center = C, frame = B, mass = m, inertia = matrix(i1, i2, i3, i12, i23, i31)))]
#[appell(gravity(-g * N.z))]
struct SwingingArm {
    m: f64,
    r: f64,
    h: f64,
    g: f64,
    i1: f64,
    i2: f64,
    i3: f64,
    i12: f64,
    i23: f64,
    i31: f64,
}

/// A body spinning about a skew axis of a frame that itself turns about
/// N.z: `rotate(axis, angle)` with an axis fixed in the parent.
#[derive(Appell, Clone)]
#[appell(coordinates(psi, theta), speeds(psi, theta))]
#[appell(frame(A = N.rotate_z(psi)), frame(B = A.rotate(A.x + 2 * A.z, theta)))]
#[appell(point(C = O + r * A.x + h * B.y))]
#[appell(body(rotor, center = C, frame = B, mass = m, inertia = principal(i1, i2, i3)))]
#[appell(gravity(-g * N.z))]
#[appell(inputs(drive), torque(B, drive * unit(A.x + 2 * A.z), effect = motor))]
struct SkewRotor {
    m: f64,
    r: f64,
    h: f64,
    g: f64,
    i1: f64,
    i2: f64,
    i3: f64,
}

#[test]
fn skew_axis_rotation_agrees_with_the_oracle() {
    let mut rng = Rng(25);
    let p = SkewRotor {
        m: 1.1,
        r: 0.5,
        h: 0.2,
        g: 9.81,
        i1: 0.02,
        i2: 0.03,
        i3: 0.05,
    };
    let worst = agree(&p, &mut rng, 1000, 3.0);
    assert!(worst < 1e-10, "largest relative difference {worst:e}");
}

/// A heavy top: a body pivoted at O, oriented by a body-fixed z-x-y
/// sequence (three-angle sugar), with its mass centre on its own z axis.
#[derive(Appell, Clone)]
#[appell(coordinates(a1, a2, a3), speeds(a1, a2, a3))]
#[appell(frame(B = N.body_zxy(a1, a2, a3)))]
#[appell(point(C = O + h * B.z))]
#[appell(body(top, center = C, frame = B, mass = m, inertia = matrix(i1, i2, i3, i12, 0, i31)))]
#[appell(gravity(-g * N.z))]
struct HeavyTop {
    m: f64,
    h: f64,
    g: f64,
    i1: f64,
    i2: f64,
    i3: f64,
    i12: f64,
    i31: f64,
}

#[test]
fn body_sequence_top_agrees_with_the_oracle() {
    let mut rng = Rng(26);
    let p = HeavyTop {
        m: 0.8,
        h: 0.15,
        g: 9.81,
        i1: 0.004,
        i2: 0.005,
        i3: 0.007,
        i12: 0.0004,
        i31: -0.0003,
    };
    // Away from the sequence's singular middle angle (a2 = ±π/2).
    let worst = agree(&p, &mut rng, 1000, 1.2);
    assert!(worst < 1e-10, "largest relative difference {worst:e}");
}

#[test]
fn chaplygin_sleigh_example_agrees_with_the_oracle() {
    let mut rng = Rng(27);
    let p = chaplygin::ChaplyginSleigh::default();
    let worst = agree(&p, &mut rng, 1000, 1.2);
    assert!(worst < 1e-10, "largest relative difference {worst:e}");
}

#[test]
fn wheel_axle_agrees_with_the_oracle() {
    let mut rng = Rng(21);
    let p = wheel_axle::WheelAxle::default();
    let worst = agree(&p, &mut rng, 1000, 3.0);
    assert!(worst < 1e-10, "largest relative difference {worst:e}");
}

#[test]
fn double_pendulum_agrees_with_the_oracle() {
    let mut rng = Rng(22);
    let p = DoublePendulum {
        m1: 1.2,
        m2: 0.7,
        l1: 1.1,
        l2: 0.6,
        g: 9.81,
    };
    let worst = agree(&p, &mut rng, 1000, 3.0);
    assert!(worst < 1e-10, "largest relative difference {worst:e}");
}

#[test]
fn sleigh_agrees_with_the_oracle() {
    // Headings within ±1.2 rad keep the dependent-speed pivot cos θ away
    // from zero (the generated code reports the singular heading instead).
    let mut rng = Rng(23);
    let p = Sleigh {
        m: 2.0,
        i0: 0.3,
        b: 0.4,
    };
    let worst = agree(&p, &mut rng, 1000, 1.2);
    assert!(worst < 1e-10, "largest relative difference {worst:e}");
}

#[test]
fn swinging_arm_agrees_with_the_oracle() {
    let mut rng = Rng(24);
    let p = SwingingArm {
        m: 1.5,
        r: 0.7,
        h: 0.4,
        g: 9.81,
        i1: 0.05,
        i2: 0.04,
        i3: 0.03,
        i12: 0.004,
        i23: -0.003,
        i31: 0.002,
    };
    let worst = agree(&p, &mut rng, 1000, 3.0);
    assert!(worst < 1e-10, "largest relative difference {worst:e}");
}
