//! Quasi-velocities (Method III, eq. 56): speeds defined as combinations of
//! the coordinate rates.

mod common;

use appell::{Appell, Model};
use common::{close, Rng};

/// The Chaplygin sleigh in its natural speeds: the forward speed of the
/// knife edge along the blade and the turning rate. Heading and position
/// drop out, and no heading is singular.
#[derive(Appell, Clone)]
#[appell(coordinates(x, y, theta), positive(m, b))]
#[appell(speeds(v = dot(velocity(P), B.x), w = dot(omega(B), N.z)))]
#[appell(frame(B = N.rotate_z(theta)))]
#[appell(point(P = O + x * N.x + y * N.y), point(C = P + b * B.x))]
#[appell(body(sleigh, center = C, frame = B, mass = m, inertia = principal(i0, i0, i0)))]
#[appell(nonholonomic(dt(y) * cos(theta) - dt(x) * sin(theta) == 0))]
struct Sleigh {
    m: f64,
    i0: f64,
    b: f64,
}

/// A body spinning about its fixed mass centre, with its body-frame angular
/// velocity components as speeds: the derived equations are Euler's.
#[derive(Appell, Clone)]
#[appell(coordinates(a1, a2, a3))]
#[appell(speeds(w1 = dot(omega(B), B.x), w2 = dot(omega(B), B.y), w3 = dot(omega(B), B.z)))]
#[appell(frame(B = N.body_zxz(a1, a2, a3)))]
#[appell(body(rotor, center = O, frame = B, mass = m, inertia = principal(i1, i2, i3)))]
struct FreeRotor {
    m: f64,
    i1: f64,
    i2: f64,
    i3: f64,
}

#[test]
fn sleigh_state_is_just_the_two_speeds() {
    let info = Sleigh::info();
    println!("{}", info.equations);
    assert_eq!(info.speeds, &["v", "w"]);
    assert_eq!(info.retained, &[] as &[&str]);
    assert_eq!(info.ignorable, &["x", "y", "theta"]);
    assert_eq!(info.state_len(), 2);
}

#[test]
fn sleigh_matches_the_closed_form_at_every_heading() {
    // v̇ = b ω², (I + m b²) ω̇ = −m b v ω, whatever the heading.
    let p = Sleigh {
        m: 1.7,
        i0: 0.08,
        b: 0.25,
    };
    let prepared = p.prepare::<f64>();
    let mut rng = Rng(51);
    for _ in 0..1000 {
        let (v, w) = (rng.uniform(-2.0, 2.0), rng.uniform(-3.0, 3.0));
        let mut d = [0.0; 2];
        p.rhs(&prepared, 0.0, &[v, w], &[], &mut d).unwrap();
        assert!(
            close(d[0], p.b * w * w, 1e-12),
            "{} vs {}",
            d[0],
            p.b * w * w
        );
        let wdot = -p.m * p.b * v * w / (p.i0 + p.m * p.b * p.b);
        assert!(close(d[1], wdot, 1e-12), "{} vs {wdot}", d[1]);
    }
    // The coordinates follow by quadrature: ẋ = v cos θ, ẏ = v sin θ, θ̇ = ω.
    let mut qdot = [0.0; 3];
    let theta = std::f64::consts::FRAC_PI_2;
    p.coordinate_rates(0.0, &[0.0, 0.0, theta], &[1.5, 0.3], &mut qdot)
        .unwrap();
    assert!(
        close(qdot[0], 1.5 * theta.cos(), 1e-15)
            && close(qdot[1], 1.5, 1e-15)
            && close(qdot[2], 0.3, 1e-15)
    );
}

#[test]
fn sleigh_agrees_with_the_oracle() {
    let p = Sleigh {
        m: 1.7,
        i0: 0.08,
        b: 0.25,
    };
    let prepared = p.prepare::<f64>();
    let mut rng = Rng(52);
    for _ in 0..1000 {
        let q = [
            rng.uniform(-3.0, 3.0),
            rng.uniform(-3.0, 3.0),
            rng.uniform(-3.0, 3.0),
        ];
        let u = [rng.uniform(-2.0, 2.0), rng.uniform(-2.0, 2.0)];
        let mut d = [0.0; 2];
        p.rhs(&prepared, 0.0, &u, &[], &mut d).unwrap();
        let o = appell::oracle::reduced_rhs(&p, 0.0, &q, &u, &[]).unwrap();
        for (a, b) in d.iter().zip(&o) {
            assert!(close(*a, *b, 1e-10), "{a} vs {b}");
        }
    }
}

#[test]
fn body_frame_speeds_give_eulers_equations() {
    // (I1) ω̇1 = (I2 − I3) ω2 ω3 and cyclic.
    // The Euler-angle kinematics W(a2, a3) are singular at a2 = 0 (gimbal
    // lock), so the rates are solved numerically and S reads a2 and a3;
    // M and f do not depend on them through the solve, so the reduced
    // state is ω alone, and no orientation is singular for it.
    let p = FreeRotor {
        m: 1.0,
        i1: 0.2,
        i2: 0.3,
        i3: 0.45,
    };
    let info = FreeRotor::info();
    assert!(info.retained.is_empty());
    assert_eq!(info.ignorable, &["a1", "a2", "a3"]);
    let prepared = p.prepare::<f64>();
    let mut rng = Rng(53);
    for _ in 0..500 {
        let w = [
            rng.uniform(-3.0, 3.0),
            rng.uniform(-3.0, 3.0),
            rng.uniform(-3.0, 3.0),
        ];
        let mut d = [0.0; 3];
        p.rhs(&prepared, 0.0, &w, &[], &mut d).unwrap();
        let e = [
            (p.i2 - p.i3) * w[1] * w[2] / p.i1,
            (p.i3 - p.i1) * w[2] * w[0] / p.i2,
            (p.i1 - p.i2) * w[0] * w[1] / p.i3,
        ];
        for k in 0..3 {
            assert!(close(d[k], e[k], 1e-12), "{k}: {} vs {}", d[k], e[k]);
        }
    }
}

/// The snakeboard: a board with a rotor at its centre P and two steered
/// wheel axles a distance `r` ahead and behind, neither of which may slide
/// sideways; the rider turns the rotor against the board and steers both
/// axles. The constraints are written in the ground frame, so the heading
/// enters the numeric elimination; nothing the board does depends on it.
#[derive(Appell, Clone)]
#[appell(coordinates(x, y, theta, psi, phi_b, phi_f))]
#[appell(speeds(v = dot(velocity(P), B.x), psi, phi_b, phi_f))]
#[appell(frame(B = N.rotate_z(theta)), frame(R = B.rotate_z(psi)))]
#[appell(frame(Wb = B.rotate_z(phi_b)), frame(Wf = B.rotate_z(phi_f)))]
#[appell(point(P = O + x * N.x + y * N.y))]
#[appell(point(Pb = P - r * B.x), point(Pf = P + r * B.x))]
#[appell(body(board, center = P, frame = B, mass = m, inertia = principal(j, j, j)))]
#[appell(body(rotor, center = P, frame = R, mass = mr, inertia = principal(jr, jr, jr)))]
#[appell(body(back, center = Pb, frame = Wb, mass = mw, inertia = principal(jw, jw, jw)))]
#[appell(body(front, center = Pf, frame = Wf, mass = mw, inertia = principal(jw, jw, jw)))]
#[appell(nonholonomic(dot(velocity(Pb), Wb.y) == 0))]
#[appell(nonholonomic(dot(velocity(Pf), Wf.y) == 0))]
#[appell(inputs(spin, steer))]
#[appell(torque(R, spin * B.z), torque(B, -spin * B.z))]
#[appell(torque(Wb, -steer * B.z), torque(Wf, steer * B.z))]
struct Snakeboard {
    m: f64,
    j: f64,
    mr: f64,
    jr: f64,
    mw: f64,
    jw: f64,
    r: f64,
}

fn snakeboard() -> Snakeboard {
    Snakeboard {
        m: 3.0,
        j: 0.2,
        mr: 1.0,
        jr: 0.05,
        mw: 0.3,
        jw: 0.01,
        r: 0.4,
    }
}

#[test]
fn snakeboard_state_leaves_out_position_heading_and_rotor_angle() {
    // Six where seven were kept before: the heading enters S and R of the
    // numeric elimination but not M, f through it.
    let info = Snakeboard::info();
    assert_eq!(info.retained, ["phi_b", "phi_f"]);
    assert_eq!(info.ignorable, ["x", "y", "theta", "psi"]);
    assert_eq!(info.state_len(), 6);
}

#[test]
fn snakeboard_agrees_with_the_oracle_at_every_heading() {
    // The oracle integrates all six coordinates at random headings.
    let mut rng = Rng(0x5a4e);
    let worst = common::agree_with_inputs(&snakeboard(), &mut rng, 300, 1.2, 1.0);
    assert!(worst < 1e-9, "largest relative difference {worst:.2e}");
}

#[test]
fn snakeboard_coordinate_rates_turn_with_the_heading() {
    // q̇ still comes from the model's own elimination: at any heading the
    // wheels do not slide sideways, and (ẋ, ẏ) is the board-frame velocity
    // turned by θ.
    let model = snakeboard();
    let u = [0.8, 1.5, -0.4, 0.6];
    let rates_at = |theta: f64| {
        let q = [0.3, -0.2, theta, 0.5, 0.35, -0.25];
        let mut qdot = [0.0; 6];
        model.coordinate_rates(0.0, &q, &u, &mut qdot).unwrap();
        let (mut holonomic, mut velocity) = ([0.0; 0], [0.0; 2]);
        model
            .constraint_residuals(0.0, &q, &qdot, &mut holonomic, &mut velocity)
            .unwrap();
        assert!(velocity.iter().all(|v| v.abs() < 1e-12), "{velocity:?}");
        qdot
    };
    let level = rates_at(0.0);
    for theta in [0.7, -2.1, 3.0] {
        let turned = rates_at(theta);
        let (c, s) = (theta.cos(), theta.sin());
        assert!(close(turned[0], c * level[0] - s * level[1], 1e-12));
        assert!(close(turned[1], s * level[0] + c * level[1], 1e-12));
        for k in 2..6 {
            assert!(close(turned[k], level[k], 1e-12));
        }
    }
}
