//! Force elements (`spring`, `damper`, `friction` and a joint's
//! `stiffness`, `damping`, `friction`, `saturation`) against the laws
//! written by hand and against closed forms: the creep speed of a
//! regularised Coulomb contact under a push below μN, the slide above it,
//! and the stopping distance v0²/(2μg).

use appell::integrate::Dop853;
use appell::{Appell, Model};

/// A block on the ground (x along N.x), Coulomb friction with the normal
/// force m g, pushed by the input `push`.
#[derive(Appell)]
#[appell(coordinates(x), speeds(x), inputs(push), positive(m, g, mu, eps))]
#[appell(point(P = O + x * N.x), particle(P, mass = m))]
#[appell(friction(P, normal = m * g, mu = mu, smoothing = eps))]
#[appell(force(P, push * N.x, effect = pushing))]
#[appell(scene(free, effects(pushing)))]
struct Block {
    m: f64,
    g: f64,
    mu: f64,
    eps: f64,
}

const BLOCK: Block = Block {
    m: 2.0,
    g: 9.81,
    mu: 0.4,
    eps: 1e-4,
};

fn accel(p: &Block, v: f64, push: f64) -> f64 {
    let mut d = [0.0; 1];
    p.rhs(&p.prepare::<f64>(), 0.0, &[v], &[push], &mut d)
        .unwrap();
    d[0]
}

#[test]
fn regularised_coulomb_friction_is_the_law_written_by_hand() {
    let p = BLOCK;
    let n = p.m * p.g;
    for v in [-3.0, -1e-3, -1e-5, 0.0, 2e-5, 0.01, 1.5] {
        for push in [-10.0, 0.0, 5.0] {
            let expected = (push - p.mu * n * v / (v * v + p.eps * p.eps).sqrt()) / p.m;
            let a = accel(&p, v, push);
            assert!(
                (a - expected).abs() < 1e-13 * (1.0 + expected.abs()),
                "{v} {push}: {a} vs {expected}"
            );
        }
    }
    // The scene without friction: the push alone.
    let free = BlockFree::from_ref(&p);
    let mut d = [0.0; 1];
    free.rhs(&free.prepare::<f64>(), 0.0, &[0.7], &[3.0], &mut d)
        .unwrap();
    assert_eq!(d[0], 1.5);
    assert!(BlockFree::info().rhs_ops.total < Block::info().rhs_ops.total);
}

#[test]
fn below_mu_n_the_block_creeps_at_the_regularisation_speed_and_above_it_slides() {
    let p = BLOCK;
    let n = p.m * p.g;
    // From rest, a push of 0.9 μN: the speed settles where μN v/√(v² + ε²)
    // equals the push, v* = ε r/√(1 − r²) with r = push/(μN).
    let r = 0.9;
    let creep = p.eps * r / (1.0 - r * r).sqrt();
    let sol = Dop853::new()
        .rtol(1e-10)
        .atol(1e-14)
        .solve_model(&p, &[r * p.mu * n], 0.0, &[0.0], 0.5)
        .unwrap();
    assert!(
        (sol.x[0] - creep).abs() < 1e-9 * creep,
        "{} vs {creep}",
        sol.x[0]
    );
    // A push of 1.1 μN: once v ≫ ε the block accelerates at (push − μN)/m.
    let push = 1.1 * p.mu * n;
    let sol = Dop853::new()
        .rtol(1e-10)
        .atol(1e-14)
        .solve_model(&p, &[push], 0.0, &[0.0], 1.0)
        .unwrap();
    let slide = (push - p.mu * n) / p.m;
    // v(1) = slide·1 less the time spent below ε (negligible: ~ε/a).
    assert!(
        (sol.x[0] - slide).abs() < 1e-3 * slide,
        "{} vs {slide}",
        sol.x[0]
    );
}

/// The block with its position in the state (to measure the distance).
#[derive(Appell)]
#[appell(coordinates(x), speeds(x), positive(m, g, mu, eps))]
#[appell(point(P = O + x * N.x), particle(P, mass = m))]
#[appell(friction(P, normal = m * g, mu = mu, smoothing = eps))]
#[appell(scene(track, effects(friction), outputs(quadrature(x))))]
struct Sliding {
    m: f64,
    g: f64,
    mu: f64,
    eps: f64,
}

#[test]
fn a_sliding_block_stops_after_v0_squared_over_2_mu_g_and_friction_took_its_energy() {
    let p = Sliding {
        m: 2.0,
        g: 9.81,
        mu: 0.4,
        eps: 1e-7,
    };
    let v0 = 2.0;
    let t_stop = v0 / (p.mu * p.g);
    // Up to just before the stop (at rest the regularised law is stiff, a
    // case for an implicit integrator): v = v0 − μ g t, x = v0 t − μ g t²/2,
    // so the block stops after v0²/(2 μ g).
    let t = 0.999 * t_stop;
    let track = SlidingTrack::from_ref(&p);
    let sol = Dop853::new()
        .rtol(1e-12)
        .atol(1e-14)
        .solve_model(track, &[], 0.0, &[0.0, v0], t)
        .unwrap();
    let (x, v) = (sol.x[0], sol.x[1]);
    assert!((v - (v0 - p.mu * p.g * t)).abs() < 1e-10, "{v}");
    assert!(
        (x - (v0 * t - 0.5 * p.mu * p.g * t * t)).abs() < 1e-10,
        "{x}"
    );
    let distance = v0 * v0 / (2.0 * p.mu * p.g);
    assert!((x + v * v / (2.0 * p.mu * p.g) - distance).abs() < 1e-10);
    // The kinetic energy lost is the work of friction, μ m g x.
    let lost = 0.5 * p.m * (v0 * v0 - v * v);
    assert!((lost - p.mu * p.m * p.g * x).abs() < 1e-9, "{lost}");
    // d(T + V)/dt is the friction's power, −μ m g v²/√(v² + ε²).
    for v in [1.5, 0.3, -0.2] {
        let e = appell::energy::energies(&p, 0.0, &[0.1], &[v], &[]).unwrap();
        let power = -p.mu * p.m * p.g * v * v / (v * v + p.eps * p.eps).sqrt();
        assert!((e.rate - power).abs() < 1e-12, "{} vs {power}", e.rate);
    }
}

/// A point mass in a plane on a spring and a damper from the fixed point A.
#[derive(Appell)]
#[appell(coordinates(x, y), speeds(x, y), positive(m, k, l0, c))]
#[appell(point(A = O + 0.5 * N.x), point(P = O + x * N.x + y * N.y), particle(P, mass = m))]
#[appell(spring(A, P, stiffness = k, length = l0), damper(A, P, damping = c))]
#[appell(scene(undamped, effects(springs)))]
struct Tethered {
    m: f64,
    k: f64,
    l0: f64,
    c: f64,
}

#[test]
fn a_spring_and_a_damper_pull_along_the_line_between_their_points() {
    let p = Tethered {
        m: 1.5,
        k: 40.0,
        l0: 0.8,
        c: 0.7,
    };
    let prepared = p.prepare::<f64>();
    for (x, y, vx, vy) in [
        (1.7f64, 0.4f64, 0.3f64, -1.0f64),
        (-0.2, -1.1, 2.0, 0.5),
        (0.6, 0.1, 0.0, 0.0),
    ] {
        let (dx, dy) = (x - 0.5, y);
        let len = (dx * dx + dy * dy).sqrt();
        let (ux, uy) = (dx / len, dy / len);
        let stretch_rate = vx * ux + vy * uy;
        let tension = p.k * (len - p.l0) + p.c * stretch_rate;
        let expected = [-tension * ux / p.m, -tension * uy / p.m];
        let mut d = [0.0; 4];
        p.rhs(&prepared, 0.0, &[x, y, vx, vy], &[], &mut d).unwrap();
        for k in 0..2 {
            assert!(
                (d[2 + k] - expected[k]).abs() < 1e-12,
                "{:?} vs {expected:?}",
                &d[2..]
            );
        }
        // The scene without the damper keeps the spring only.
        let s = TetheredUndamped::from_ref(&p);
        let mut d = [0.0; 4];
        s.rhs(&s.prepare::<f64>(), 0.0, &[x, y, vx, vy], &[], &mut d)
            .unwrap();
        let spring = p.k * (len - p.l0);
        assert!((d[2] + spring * ux / p.m).abs() < 1e-12);
    }
}

/// A pendulum on a revolute joint with a torsion spring, a damper, Coulomb
/// friction and a saturated motor.
#[derive(Appell)]
#[appell(joint(swing, revolute(z), parent = N, child = L, actuated, saturation = 2.0,
               stiffness = k, rest = 0.3, damping = c, friction = 0.5, friction_smoothing = 0.01))]
#[appell(body(link, center = L_origin + 0.4 * L.x, frame = L, mass = 1.2, inertia = principal(0.01, 0.02, 0.03)))]
#[appell(gravity(-9.81 * N.y))]
#[appell(scene(passive, effects(gravity)))]
struct Arm {
    k: f64,
    c: f64,
}

#[test]
fn joint_elements_are_generalized_torques_on_the_joint() {
    let p = Arm { k: 3.0, c: 0.2 };
    let prepared = p.prepare::<f64>();
    let inertia = 0.03 + 1.2 * 0.4 * 0.4;
    for (q, w, tau) in [
        (0.1f64, 0.5f64, 1.0f64),
        (-1.2, -0.002, 5.0),
        (2.0, 3.0, -7.0),
    ] {
        let gravity = -1.2 * 9.81 * 0.4 * f64::cos(q);
        let spring = -3.0 * (q - 0.3);
        let damper = -0.2 * w;
        let friction = -0.5 * w / (w * w + 1e-4).sqrt();
        let motor = f64::clamp(tau, -2.0, 2.0);
        let expected = (gravity + spring + damper + friction + motor) / inertia;
        let mut d = [0.0; 2];
        p.rhs(&prepared, 0.0, &[q, w], &[tau], &mut d).unwrap();
        assert!((d[1] - expected).abs() < 1e-12, "{} vs {expected}", d[1]);
        let s = ArmPassive::from_ref(&p);
        s.rhs(&s.prepare::<f64>(), 0.0, &[q, w], &[], &mut d)
            .unwrap();
        assert!((d[1] - gravity / inertia).abs() < 1e-12);
    }
    let effects = Arm::info().effects;
    for e in ["actuation", "springs", "dampers", "friction", "gravity"] {
        assert!(effects.contains(&e), "{e} in {effects:?}");
    }
}

/// A ball dropped on a one-sided spring (a contact that only pushes): the
/// force is `if x < 0 { -k x } else { 0 }`.
#[derive(Appell)]
#[appell(coordinates(x), speeds(x), positive(m, k))]
#[appell(point(P = O + x * N.z), particle(P, mass = m))]
#[appell(force(P, (if x < 0 { -k * x } else { 0 }) * N.z, effect = contact))]
#[appell(gravity(-9.81 * N.z))]
struct Bouncer {
    m: f64,
    k: f64,
}

#[test]
fn a_one_sided_contact_keeps_the_closed_form_contact_time_and_rebound() {
    let p = Bouncer { m: 0.5, k: 2e4 };
    let (g, h) = (9.81, 0.2);
    let solver = Dop853::new().rtol(1e-12).atol(1e-14);
    // Free fall to the contact: t = √(2h/g), v = −√(2gh).
    let fall = solver
        .solve_model_until(&p, &[], |_t, x: &[f64; 2]| x[0], 0.0, &[h, 0.0], 1.0)
        .unwrap();
    let v0 = (2.0 * g * h).sqrt();
    assert!(fall.event);
    assert!((fall.t - (2.0 * h / g).sqrt()).abs() < 1e-9, "{}", fall.t);
    assert!((fall.x[1] + v0).abs() < 1e-8, "{}", fall.x[1]);
    // In contact: simple harmonic motion about x = −m g/k at ω = √(k/m),
    // amplitude A = √(δ² + (v0/ω)²), δ = m g/k; it leaves the spring after
    // t_c = 2(π − acos(δ/A))/ω, at the speed it arrived with.
    let omega = (p.k / p.m).sqrt();
    let delta = p.m * g / p.k;
    let amplitude = (delta * delta + (v0 / omega).powi(2)).sqrt();
    let contact = 2.0 * (std::f64::consts::PI - (delta / amplitude).acos()) / omega;
    let rebound = solver
        .solve_model_until(
            &p,
            &[],
            |_t, x: &[f64; 2]| x[0],
            fall.t,
            &fall.x,
            fall.t + 1.0,
        )
        .unwrap();
    assert!(rebound.event);
    assert!(
        (rebound.t - fall.t - contact).abs() < 1e-9,
        "{} vs {contact}",
        rebound.t - fall.t
    );
    assert!((rebound.x[1] - v0).abs() < 1e-7, "{} vs {v0}", rebound.x[1]);
}

/// A particle tied to the origin by a spring of zero rest length, and the
/// same with `length = 0.0` written out.
#[derive(Appell)]
#[appell(coordinates(x, y), speeds(x, y), positive(m, k))]
#[appell(point(P = O + x * N.x + y * N.y), particle(P, mass = m))]
#[appell(spring(O, P, stiffness = k))]
struct Tether {
    m: f64,
    k: f64,
}

#[derive(Appell)]
#[appell(coordinates(x, y), speeds(x, y), positive(m, k))]
#[appell(point(P = O + x * N.x + y * N.y), particle(P, mass = m))]
#[appell(spring(O, P, stiffness = k, length = 0.0))]
struct TetherWritten {
    m: f64,
    k: f64,
}

#[test]
fn a_spring_of_zero_rest_length_pulls_k_d_and_is_regular_where_its_points_meet() {
    let (m, k) = (2.0, 5.0);
    let tether = Tether { m, k };
    let written = TetherWritten { m, k };
    for (x, y) in [(0.3, -0.4), (1e-300, 0.0), (0.0, 0.0)] {
        let state = [x, y, 0.1, -0.2];
        let (mut d, mut e) = ([0.0; 4], [0.0; 4]);
        tether
            .rhs(&tether.prepare::<f64>(), 0.0, &state, &[], &mut d)
            .unwrap();
        written
            .rhs(&written.prepare::<f64>(), 0.0, &state, &[], &mut e)
            .unwrap();
        assert_eq!(d, e);
        let expected = [0.1, -0.2, -k / m * x, -k / m * y];
        for (a, b) in d.iter().zip(expected) {
            assert!((a - b).abs() < 1e-15 * (1.0 + b.abs()), "{x} {y}: {d:?}");
        }
    }
}
