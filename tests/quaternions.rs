//! Quaternion orientation: a free body and the Chaplygin ball through
//! orientations where Euler angles are singular, with the multiplier
//! oracle and the conserved quantities as references.

mod common;
#[path = "../examples/models/free_body.rs"]
mod free_body;

use appell::integrate::Dop853;
use appell::linearize::project_holonomic;
use appell::Model;
use common::Rng;
use free_body::{ChaplyginBall, FreeBody};

/// The rotation matrix of a unit quaternion (scalar first): columns are
/// the body axes in N.
fn rotation(e: &[f64]) -> [[f64; 3]; 3] {
    let (w, x, y, z) = (e[0], e[1], e[2], e[3]);
    [
        [
            w * w + x * x - y * y - z * z,
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            w * w - x * x + y * y - z * z,
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            w * w - x * x - y * y + z * z,
        ],
    ]
}

fn apply(r: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    core::array::from_fn(|i| (0..3).map(|k| r[i][k] * v[k]).sum())
}

fn random_unit_quaternion(rng: &mut Rng) -> [f64; 4] {
    let e: [f64; 4] = core::array::from_fn(|_| rng.uniform(-1.0, 1.0));
    let n = e.iter().map(|x| x * x).sum::<f64>().sqrt();
    e.map(|x| x / n)
}

/// The largest relative difference between the generated rhs and the
/// multiplier oracle at 1,000 random consistent states.
fn oracle_agreement<M: Model>(model: &M, coordinates: impl Fn(&mut Rng) -> Vec<f64>) -> f64 {
    let info = M::info();
    let prepared = model.prepare::<f64>();
    let mut rng = Rng(11);
    let mut worst: f64 = 0.0;
    for _ in 0..1000 {
        let q = coordinates(&mut rng);
        let u: Vec<f64> = info.speeds.iter().map(|_| rng.uniform(-3.0, 3.0)).collect();
        let mut state: Vec<f64> = info
            .retained
            .iter()
            .map(|name| q[info.coordinates.iter().position(|c| c == name).unwrap()])
            .collect();
        state.extend(&u);
        let mut d = vec![0.0; state.len()];
        model.rhs(&prepared, 0.0, &state, &[], &mut d).unwrap();
        let o = appell::oracle::reduced_rhs(model, 0.0, &q, &u, &[]).unwrap();
        for (a, b) in d.iter().zip(&o) {
            worst = worst.max((a - b).abs() / (1.0 + a.abs().max(b.abs())));
        }
    }
    println!(
        "{}: largest relative difference to the oracle {worst:.2e}",
        info.name
    );
    worst
}

#[test]
fn both_agree_with_the_oracle() {
    let free = oracle_agreement(&FreeBody::default(), |rng| {
        let mut q = random_unit_quaternion(rng).to_vec();
        q.extend([
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
        ]);
        q
    });
    let ball = oracle_agreement(&ChaplyginBall::default(), |rng| {
        let mut q = vec![rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)];
        q.extend(random_unit_quaternion(rng));
        q
    });
    assert!(free < 1e-10 && ball < 1e-10, "{free:e} {ball:e}");
}

/// Integrates with DOP853 and projection onto |e| = 1, reporting the state
/// every `dt` through `each`.
fn tumble<M: Model, const S: usize>(
    model: &M,
    x0: [f64; S],
    dt: f64,
    steps: usize,
    mut each: impl FnMut(&[f64; S]),
) {
    let mut onto = |t: f64, x: &mut [f64; S]| {
        project_holonomic(model, t, x, 1e-15, 20)
            .map(|_| ())
            .map_err(Into::into)
    };
    let solver = Dop853::new().rtol(1e-13).atol(1e-13);
    let mut x = x0;
    for k in 0..steps {
        let t = k as f64 * dt;
        x = solver
            .solve_model_projected(model, &[], &mut onto, t, &x, t + dt)
            .unwrap()
            .x;
        each(&x);
    }
}

#[test]
fn a_free_body_spun_about_its_intermediate_axis_flips_and_conserves_energy_and_momentum() {
    let body = FreeBody::default();
    let inertia = [body.i1, body.i2, body.i3];
    // State: quaternion, ω in body axes, centre velocity. Identity start:
    // B = N, where a ZXZ Euler-angle model is singular.
    let x0 = [1.0, 0.0, 0.0, 0.0, 0.01, 4.0, 0.01, 0.1, 0.0, 0.0];
    let energy = |x: &[f64; 10]| {
        0.5 * (0..3)
            .map(|k| inertia[k] * x[4 + k] * x[4 + k])
            .sum::<f64>()
    };
    let momentum = |x: &[f64; 10]| {
        let body_axes = core::array::from_fn(|k| inertia[k] * x[4 + k]);
        apply(&rotation(&x[..4]), body_axes)
    };
    let (e0, h0) = (energy(&x0), momentum(&x0));
    let h_norm = h0.iter().map(|v| v * v).sum::<f64>().sqrt();
    let (mut worst_e, mut worst_h, mut flips, mut sign) = (0.0f64, 0.0f64, 0, 1.0);
    let mut lowest_cos: f64 = 1.0;
    tumble(&body, x0, 0.05, 800, |x| {
        worst_e = worst_e.max(((energy(x) - e0) / e0).abs());
        let h = momentum(x);
        worst_h = worst_h.max((0..3).map(|k| (h[k] - h0[k]).abs()).fold(0.0, f64::max) / h_norm);
        if x[5].signum() != sign {
            flips += 1;
            sign = x[5].signum();
        }
        // B.y against N.y: the body turns all the way over.
        lowest_cos = lowest_cos.min(rotation(&x[..4])[1][1]);
        assert!((x[7] - 0.1).abs() < 1e-12, "the centre keeps its velocity");
    });
    println!(
        "free body, 40 s: {flips} flips, B.y·N.y down to {lowest_cos:.3}, energy {worst_e:.1e}, momentum {worst_h:.1e}"
    );
    assert!(flips >= 4, "{flips}");
    assert!(lowest_cos < -0.99);
    assert!(
        worst_e < 1e-12 && worst_h < 1e-12,
        "{worst_e:e} {worst_h:e}"
    );
}

#[test]
fn the_chaplygin_ball_rolls_through_every_orientation_conserving_its_integrals() {
    let ball = ChaplyginBall::default();
    let inertia = [ball.i1, ball.i2, ball.i3];
    let (m, r) = (ball.m, ball.r);
    // ω in body axes; the identity start is the Euler-angle singularity.
    let x0 = [1.0, 0.0, 0.0, 0.0, 2.5, -0.7, 0.5];
    let omega_n = |x: &[f64; 7]| apply(&rotation(&x[..4]), [x[4], x[5], x[6]]);
    // Kinetic energy (the potential is constant): rotation plus the
    // centre's rolling velocity ω × (r N.z).
    let energy = |x: &[f64; 7]| {
        let w = omega_n(x);
        let v2 = r * r * (w[0] * w[0] + w[1] * w[1]);
        0.5 * (0..3)
            .map(|k| inertia[k] * x[4 + k] * x[4 + k])
            .sum::<f64>()
            + 0.5 * m * v2
    };
    // Angular momentum about the contact point: I ω + m a × (ω × a) with
    // a = r N.z, conserved in N.
    let momentum = |x: &[f64; 7]| {
        let w = omega_n(x);
        let rot = apply(
            &rotation(&x[..4]),
            core::array::from_fn(|k| inertia[k] * x[4 + k]),
        );
        [rot[0] + m * r * r * w[0], rot[1] + m * r * r * w[1], rot[2]]
    };
    let (e0, k0) = (energy(&x0), momentum(&x0));
    let k_norm = k0.iter().map(|v| v * v).sum::<f64>().sqrt();
    let (mut worst_e, mut worst_k): (f64, f64) = (0.0, 0.0);
    let mut z_range = (1.0f64, -1.0f64);
    tumble(&ball, x0, 0.05, 400, |x| {
        worst_e = worst_e.max(((energy(x) - e0) / e0).abs());
        let k = momentum(x);
        worst_k = worst_k.max((0..3).map(|i| (k[i] - k0[i]).abs()).fold(0.0, f64::max) / k_norm);
        let bz = rotation(&x[..4])[2][2];
        z_range = (z_range.0.min(bz), z_range.1.max(bz));
    });
    println!(
        "Chaplygin ball, 20 s: B.z·N.z from {:.3} to {:.3}, energy {worst_e:.1e}, momentum about the contact {worst_k:.1e}",
        z_range.0, z_range.1
    );
    assert!(z_range.0 < -0.5 && z_range.1 > 0.5, "{z_range:?}");
    assert!(
        worst_e < 1e-12 && worst_k < 1e-12,
        "{worst_e:e} {worst_k:e}"
    );
}

#[test]
fn the_quaternion_rates_are_solved_in_closed_form() {
    // ė = Aᵀ ω / 4 on the unit sphere: no run-time solve, and M is I's diagonal.
    for info in [FreeBody::info(), ChaplyginBall::info()] {
        println!("{}: {} operations per rhs", info.name, info.rhs_ops.total);
        assert!(info.symbolic_elimination, "{}", info.name);
        assert!(!info.equations.contains("__x"), "{}", info.equations);
    }
    let eq = FreeBody::info().equations;
    let m = &eq[eq.find("M[pose_wx, pose_wx]").unwrap()..];
    println!("{}", &m[..m.find('\n').unwrap()]);
}

#[test]
fn a_zero_quaternion_is_a_typed_error_not_a_nan() {
    let body = FreeBody::default();
    let mut d = [0.0; 10];
    let x = [0.0, 0.0, 0.0, 0.0, 1.0, 2.0, 3.0, 0.0, 0.0, 0.0];
    let err = body
        .rhs(&body.prepare::<f64>(), 0.0, &x, &[], &mut d)
        .unwrap_err();
    assert!(err.to_string().contains("quaternion of frame `B`"), "{err}");
}

/// The same body from a URDF whose joint is `floating`.
#[derive(appell::Appell, Clone, Debug, Default)]
#[appell(urdf("tests/data/floating_base.urdf"))]
struct FloatingUrdf;

#[test]
fn a_urdf_floating_joint_is_the_free_joint() {
    assert_eq!(
        FloatingUrdf::info().coordinates,
        FreeBody::info().coordinates
    );
    assert_eq!(FloatingUrdf::info().speeds, FreeBody::info().speeds);
    let (a, b) = (FloatingUrdf, FreeBody::default());
    let mut rng = Rng(12);
    for _ in 0..100 {
        let mut x: Vec<f64> = random_unit_quaternion(&mut rng).to_vec();
        x.extend((0..6).map(|_| rng.uniform(-2.0, 2.0)));
        let (mut da, mut db) = ([0.0; 10], [0.0; 10]);
        a.rhs(&a.prepare::<f64>(), 0.0, &x, &[], &mut da).unwrap();
        b.rhs(&b.prepare::<f64>(), 0.0, &x, &[], &mut db).unwrap();
        for (p, q) in da.iter().zip(&db) {
            assert!((p - q).abs() < 1e-14 * (1.0 + q.abs()), "{da:?} {db:?}");
        }
    }
}
