//! Constraint forces (eqs. 69-70) against Newton's and Euler's laws, with
//! the accelerations taken from the *generated* reduced equations (not the
//! oracle that produced the multipliers), and friction coefficients against
//! closed forms.

mod common;
#[path = "../examples/models/rolling_disc.rs"]
mod rolling_disc;
#[path = "../examples/models/wheel_axle.rs"]
mod wheel_axle;
// Only the model is used here, not the example's analysis helpers.
#[allow(dead_code)]
#[path = "../examples/models/whipple_bicycle.rs"]
mod whipple_bicycle;

use appell::constraint_forces::{
    contact_forces, Friction, Normal, NormalSource, NormalUnavailable,
};
use appell::{Model, RowSource};
use common::{close, Rng};
use num_dual::{Dual2_64, Dual64};
use rolling_disc::RollingDisc;
use wheel_axle::{WheelAxle, WheelAxleContactCheck};
use whipple_bicycle::WhippleBicycle;

/// The motion of every body from the generated equations: q̇ from
/// `coordinate_rates`, u̇ from `rhs`, q̈ by a dual number along (q̇, u̇),
/// then mass-centre accelerations, ω and α by second-order duals.
struct Motion {
    qdot: Vec<f64>,
    position: Vec<[f64; 3]>,
    rotation: Vec<[f64; 9]>,
    acceleration: Vec<[f64; 3]>,
    omega: Vec<[f64; 3]>,
    alpha: Vec<[f64; 3]>,
}

fn generated_motion<M: Model>(model: &M, t: f64, q: &[f64], u: &[f64], inputs: &[f64]) -> Motion {
    let info = M::info();
    let (n, l, nb) = (q.len(), u.len(), info.bodies.len());
    let mut state: Vec<f64> = info
        .retained
        .iter()
        .map(|c| q[info.coordinate_index(c).unwrap()])
        .collect();
    state.extend(u);
    let mut d = vec![0.0; state.len()];
    model
        .rhs(&model.prepare::<f64>(), t, &state, inputs, &mut d)
        .unwrap();
    let udot = &d[info.retained.len()..];
    let mut qdot = vec![0.0; n];
    model.coordinate_rates(t, q, u, &mut qdot).unwrap();
    let qd: Vec<Dual64> = (0..n).map(|i| Dual64::new(q[i], qdot[i])).collect();
    let ud: Vec<Dual64> = (0..l).map(|k| Dual64::new(u[k], udot[k])).collect();
    let mut rates = vec![Dual64::from(0.0); n];
    model
        .coordinate_rates(Dual64::new(t, 1.0), &qd, &ud, &mut rates)
        .unwrap();
    let path: Vec<Dual2_64> = (0..n)
        .map(|i| Dual2_64::new(q[i], qdot[i], rates[i].eps))
        .collect();
    let mut pos = vec![[Dual2_64::from(0.0); 3]; nb];
    let mut rot = vec![[Dual2_64::from(0.0); 9]; nb];
    model
        .body_poses(Dual2_64::new(t, 1.0, 0.0), &path, &mut pos, &mut rot)
        .unwrap();
    let mut m = Motion {
        qdot,
        position: vec![],
        rotation: vec![],
        acceleration: vec![],
        omega: vec![],
        alpha: vec![],
    };
    for j in 0..nb {
        let r: [f64; 9] = std::array::from_fn(|i| rot[j][i].re);
        let rd: [f64; 9] = std::array::from_fn(|i| rot[j][i].v1);
        let rdd: [f64; 9] = std::array::from_fn(|i| rot[j][i].v2);
        m.position.push(std::array::from_fn(|i| pos[j][i].re));
        m.acceleration.push(std::array::from_fn(|i| pos[j][i].v2));
        m.omega.push(vee(&mul_bt(&rd, &r)));
        m.alpha.push(vee(&mul_bt(&rdd, &r)));
        m.rotation.push(r);
    }
    m
}

fn mul_bt(a: &[f64; 9], b: &[f64; 9]) -> [f64; 9] {
    std::array::from_fn(|k| {
        (0..3)
            .map(|i| a[3 * (k / 3) + i] * b[3 * (k % 3) + i])
            .sum()
    })
}
fn mul(a: &[f64; 9], b: &[f64; 9]) -> [f64; 9] {
    std::array::from_fn(|k| (0..3).map(|i| a[3 * (k / 3) + i] * b[3 * i + k % 3]).sum())
}
fn vee(s: &[f64; 9]) -> [f64; 3] {
    [
        0.5 * (s[7] - s[5]),
        0.5 * (s[2] - s[6]),
        0.5 * (s[3] - s[1]),
    ]
}
fn mat_vec(a: &[f64; 9], v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| (0..3).map(|k| a[3 * i + k] * v[k]).sum())
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| a[i] - b[i])
}
fn norm(a: [f64; 3]) -> f64 {
    a.iter().map(|x| x * x).sum::<f64>().sqrt()
}
/// Largest component difference of two vectors relative to `scale`.
fn rel(a: [f64; 3], b: [f64; 3], scale: f64) -> f64 {
    norm(sub(a, b)) / scale
}

/// Σ over bodies of (m a, r × m a + I α + ω × I ω) about `o`, and the
/// applied loads' (Σ F, Σ r × F + L).
fn balances<M: Model>(
    model: &M,
    q: &[f64],
    inputs: &[f64],
    mo: &Motion,
    o: [f64; 3],
) -> ([f64; 3], [f64; 3], [f64; 3], [f64; 3], f64) {
    let info = M::info();
    let nb = info.bodies.len();
    let mut masses = vec![0.0; nb];
    let mut inertias = vec![[0.0; 9]; nb];
    model.mass_properties(&mut masses, &mut inertias).unwrap();
    let (mut lin, mut ang) = ([0.0; 3], [0.0; 3]);
    let mut scale: f64 = 0.0;
    for j in 0..nb {
        let ma: [f64; 3] = std::array::from_fn(|i| masses[j] * mo.acceleration[j][i]);
        let mut h = cross(sub(mo.position[j], o), ma);
        if info.bodies[j].rigid {
            let r = &mo.rotation[j];
            let i_n = mul_bt(&mul(r, &inertias[j]), r);
            let w = mo.omega[j];
            let e = mat_vec(&i_n, mo.alpha[j]);
            let gyro = cross(w, mat_vec(&i_n, w));
            h = std::array::from_fn(|i| h[i] + e[i] + gyro[i]);
            scale = scale.max(norm(e)).max(norm(gyro));
        }
        scale = scale.max(norm(ma));
        lin = std::array::from_fn(|i| lin[i] + ma[i]);
        ang = std::array::from_fn(|i| ang[i] + h[i]);
    }
    let mut points = vec![[0.0; 3]; info.force_points];
    let mut frames = vec![[0.0; 9]; info.torques];
    model
        .load_geometry(0.0, q, &mut points, &mut frames)
        .unwrap();
    let mut forces = vec![[0.0; 3]; info.force_points];
    let mut torques = vec![[0.0; 3]; info.torques];
    model
        .load_values(0.0, q, &mo.qdot, inputs, &mut forces, &mut torques)
        .unwrap();
    let (mut f, mut l) = ([0.0; 3], [0.0; 3]);
    for (p, fp) in points.iter().zip(&forces) {
        let m = cross(sub(*p, o), *fp);
        f = std::array::from_fn(|i| f[i] + fp[i]);
        l = std::array::from_fn(|i| l[i] + m[i]);
        scale = scale.max(norm(*fp));
    }
    for tq in &torques {
        l = std::array::from_fn(|i| l[i] + tq[i]);
        scale = scale.max(norm(*tq));
    }
    (lin, ang, f, l, scale)
}

fn random_disc(rng: &mut Rng) -> (RollingDisc, Vec<f64>, Vec<f64>) {
    let p = RollingDisc {
        r: rng.uniform(0.05, 1.0),
        m: rng.uniform(0.2, 5.0),
        g: 9.81,
    };
    let q: Vec<f64> = vec![
        rng.uniform(-3.0, 3.0),
        rng.uniform(-1.2, 1.2),
        rng.uniform(-3.0, 3.0),
        rng.uniform(-2.0, 2.0),
        rng.uniform(-2.0, 2.0),
    ];
    let u: Vec<f64> = (0..3).map(|_| rng.uniform(-5.0, 5.0)).collect();
    (p, q, u)
}

#[test]
fn rolling_disc_obeys_newton_and_euler_with_its_contact_force() {
    let info = RollingDisc::info();
    assert_eq!(info.contacts.len(), 1);
    assert_eq!(info.contacts[0].point, "P");
    // The coordinates keep the disc on the ground: the N.z row is dropped.
    assert_eq!(
        info.row_sources,
        &[
            RowSource::Rolling {
                contact: 0,
                direction: 0
            },
            RowSource::Rolling {
                contact: 0,
                direction: 1
            }
        ]
    );
    let mut rng = Rng(0xd15c);
    let (mut worst_lin, mut worst_ang) = (0.0_f64, 0.0_f64);
    for _ in 0..1000 {
        let (p, q, u) = random_disc(&mut rng);
        let cf = contact_forces(&p, 0.0, &q, &u, &[]).unwrap();
        let c = &cf.contacts[0];
        match c.normal {
            Normal::Available {
                direction, source, ..
            } => {
                assert_eq!(source, NormalSource::MomentumBalance);
                assert!(rel(direction, [0.0, 0.0, 1.0], 1.0) < 1e-15);
            }
            other => panic!("{other:?}"),
        }
        // The tangential part is the multipliers along N.x and N.y.
        assert_eq!(c.rolling, [cf.multipliers[0], cf.multipliers[1], 0.0]);
        let mo = generated_motion(&p, 0.0, &q, &u, &[]);
        // m a = m g + F.
        let ma: [f64; 3] = std::array::from_fn(|i| p.m * mo.acceleration[0][i]);
        let weight = [0.0, 0.0, -p.m * p.g];
        let rhs: [f64; 3] = std::array::from_fn(|i| weight[i] + c.force[i]);
        let scale = norm(ma).max(p.m * p.g).max(norm(c.force));
        worst_lin = worst_lin.max(rel(ma, rhs, scale));
        // I α + ω × I ω = (P − D) × F about the mass centre.
        let r = &mo.rotation[0];
        let i_b = [
            p.m * p.r * p.r / 4.0,
            0.0,
            0.0,
            0.0,
            p.m * p.r * p.r / 2.0,
            0.0,
            0.0,
            0.0,
            p.m * p.r * p.r / 4.0,
        ];
        let i_n = mul_bt(&mul(r, &i_b), r);
        let w = mo.omega[0];
        let e = mat_vec(&i_n, mo.alpha[0]);
        let gyro = cross(w, mat_vec(&i_n, w));
        let lhs: [f64; 3] = std::array::from_fn(|i| e[i] + gyro[i]);
        let moment = cross(sub(c.position, mo.position[0]), c.force);
        let scale = norm(e)
            .max(norm(gyro))
            .max(norm(moment))
            .max(p.m * p.g * p.r);
        worst_ang = worst_ang.max(rel(lhs, moment, scale));
    }
    println!("rolling disc, 1000 states: |m a − m g − F| / scale ≤ {worst_lin:.2e}, |I α + ω × I ω − r × F| / scale ≤ {worst_ang:.2e}");
    assert!(worst_lin < 1e-10, "{worst_lin:e}");
    assert!(worst_ang < 1e-10, "{worst_ang:e}");
}

#[test]
fn wheel_axle_system_obeys_newton_with_its_constraint_reactions() {
    // The wheel-axle's constraints are written as nonholonomic rows (eq. 65),
    // so the reactions are generalized: their net force and moment are
    // their virtual power under a rigid translation / rotation of the whole
    // assemblage in the plane.
    let info = WheelAxleContactCheck::info();
    assert!(info.has_output("contact_forces"));
    assert_eq!(info.effects, &["gravity"]);
    assert!(info.contacts.is_empty());
    assert_eq!(info.row_sources[4], RowSource::Nonholonomic { index: 4 });
    let mut rng = Rng(0xa71e);
    let (mut worst_lin, mut worst_ang) = (0.0_f64, 0.0_f64);
    for _ in 0..1000 {
        let p = common::random_wheel_axle!(rng);
        let mut q: Vec<f64> = (0..7).map(|_| rng.uniform(-3.0, 3.0)).collect();
        // Wheel 2 at +l along the axle (the rows keep it there).
        q[3] = q[0] - p.l * q[6].sin();
        q[4] = q[1] + p.l * q[6].cos();
        let u = [rng.uniform(-3.0, 3.0), rng.uniform(-3.0, 3.0)];
        let tau = [rng.uniform(-2.0, 2.0)];
        let s = WheelAxleContactCheck::from_ref(&p);
        // The scene keeps gravity only, which reads no input: it takes none.
        for check_scene in [true, false] {
            let inputs = if check_scene { &[][..] } else { &tau[..] };
            let (lin, ang, f, l, scale, cf) = if check_scene {
                let mo = generated_motion(s, 0.0, &q, &u, inputs);
                let (lin, ang, f, l, scale) = balances(s, &q, inputs, &mo, [0.0; 3]);
                (
                    lin,
                    ang,
                    f,
                    l,
                    scale,
                    contact_forces(s, 0.0, &q, &u, inputs).unwrap(),
                )
            } else {
                let mo = generated_motion(&p, 0.0, &q, &u, inputs);
                let (lin, ang, f, l, scale) = balances(&p, &q, inputs, &mo, [0.0; 3]);
                (
                    lin,
                    ang,
                    f,
                    l,
                    scale,
                    contact_forces(&p, 0.0, &q, &u, inputs).unwrap(),
                )
            };
            // Rigid motions in the plane: x, y translations and a rotation
            // about N.z through O.
            let tx = [1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
            let ty = [0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0];
            let tz = [-q[1], q[0], 0.0, -q[4], q[3], 0.0, 1.0];
            let power = |tau: &[f64; 7]| -> f64 {
                cf.rows
                    .iter()
                    .map(|r| {
                        r.generalized
                            .iter()
                            .zip(tau)
                            .map(|(a, b)| a * b)
                            .sum::<f64>()
                    })
                    .sum()
            };
            let fc = [power(&tx), power(&ty), 0.0];
            let scale = scale.max(norm(fc)).max(1.0);
            let expect: [f64; 3] = std::array::from_fn(|i| f[i] + fc[i]);
            worst_lin = worst_lin.max(rel(
                [lin[0], lin[1], 0.0],
                [expect[0], expect[1], 0.0],
                scale,
            ));
            worst_ang = worst_ang.max(
                (ang[2] - l[2] - power(&tz)).abs()
                    / (scale * (1.0 + norm([q[0], q[1], q[3]]) + norm([q[3], q[4], 0.0]))),
            );
        }
    }
    println!("wheel-axle, 1000 states × (contact_check, full): |Σ m a − Σ F − Σ F_c| / scale ≤ {worst_lin:.2e}, moment about N.z ≤ {worst_ang:.2e}");
    assert!(worst_lin < 1e-10, "{worst_lin:e}");
    assert!(worst_ang < 1e-10, "{worst_ang:e}");
}

fn bicycle_state(rng: &mut Rng, p: &WhippleBicycle) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut q: Vec<f64> = (0..8).map(|_| rng.uniform(-1.0, 1.0)).collect();
    q[3] = rng.uniform(-0.5, 0.5);
    q[6] = rng.uniform(-0.6, 0.6);
    q[4] = std::f64::consts::PI / 10.0;
    // Pitch from the holonomic constraint (front wheel on the ground).
    appell::linearize::solve_holonomic(p, 0.0, &mut q, &[4], 1e-14, 50).unwrap();
    let u = vec![
        rng.uniform(-1.0, 1.0),
        rng.uniform(-12.0, -2.0),
        rng.uniform(-1.0, 1.0),
    ];
    let steer = vec![rng.uniform(-2.0, 2.0)];
    (q, u, steer)
}

#[test]
fn whipple_bicycle_normals_from_the_holonomic_row_and_the_balance() {
    let p = WhippleBicycle::default();
    let mut rng = Rng(0xb1c7);
    let mut worst: f64 = 0.0;
    for _ in 0..200 {
        let (q, u, steer) = bicycle_state(&mut rng, &p);
        let cf = contact_forces(&p, 0.0, &q, &u, &steer).unwrap();
        let sources: Vec<NormalSource> = cf
            .contacts
            .iter()
            .map(|c| match c.normal {
                Normal::Available { source, .. } => source,
                other => panic!("{other:?}"),
            })
            .collect();
        assert_eq!(
            sources,
            [
                NormalSource::MomentumBalance,
                NormalSource::HolonomicRow { index: 0 }
            ]
        );
        let mo = generated_motion(&p, 0.0, &q, &u, &steer);
        let o = cf.contacts[0].position;
        let (lin, ang, f, l, scale) = balances(&p, &q, &steer, &mo, o);
        let (mut fc, mut lc) = ([0.0; 3], [0.0; 3]);
        for c in &cf.contacts {
            let m = cross(sub(c.position, o), c.force);
            fc = std::array::from_fn(|i| fc[i] + c.force[i]);
            lc = std::array::from_fn(|i| lc[i] + m[i]);
        }
        let scale = scale.max(norm(fc));
        worst = worst
            .max(rel(lin, std::array::from_fn(|i| f[i] + fc[i]), scale))
            .max(rel(ang, std::array::from_fn(|i| l[i] + lc[i]), scale));
    }
    println!("bicycle, 200 states on the constraint: momentum balances close to {worst:.2e}");
    assert!(worst < 1e-10, "{worst:e}");
}

#[test]
fn upright_straight_rolling_needs_no_friction() {
    // Disc: the weight on the ground, no tangential force.
    let p = RollingDisc::default();
    let cf = contact_forces(&p, 0.0, &[0.4, 0.0, 1.0, 0.2, -0.3], &[0.0, 0.0, 7.0], &[]).unwrap();
    match cf.contacts[0].friction() {
        Friction::Required { mu, normal, .. } => {
            assert!(mu < 1e-14, "{mu:e}");
            assert!(close(normal, p.m * p.g, 1e-14), "{normal}");
        }
        other => panic!("{other:?}"),
    }
    // Bicycle at the benchmark's upright straight run: the two normals
    // carry the weight, no friction.
    let b = WhippleBicycle::default();
    let mut q = [
        0.0,
        0.0,
        0.0,
        0.0,
        std::f64::consts::PI / 10.0,
        0.0,
        0.0,
        0.0,
    ];
    appell::linearize::solve_holonomic(&b, 0.0, &mut q, &[4], 1e-15, 50).unwrap();
    let cf = contact_forces(&b, 0.0, &q, &[0.0, -5.0 / b.rr, 0.0], &[0.0]).unwrap();
    let mut masses = [0.0; 4];
    let mut inertias = [[0.0; 9]; 4];
    b.mass_properties(&mut masses, &mut inertias).unwrap();
    let weight: f64 = masses.iter().sum::<f64>() * b.g;
    let mut total = 0.0;
    for c in &cf.contacts {
        match c.friction() {
            Friction::Required { mu, normal, .. } => {
                assert!(mu < 1e-12, "{mu:e}");
                total += normal;
            }
            other => panic!("{other:?}"),
        }
    }
    assert!(close(total, weight, 1e-12), "{total} vs {weight}");
}

#[test]
fn steady_turn_friction_is_the_centripetal_ratio() {
    // In a steady turn the disc's centre moves uniformly on a horizontal
    // circle at the yaw rate Ω: the ground pushes m Ω v_c inward and m g up,
    // so μ = Ω v_c / g. The spin rate that makes the turn steady solves
    // lean'' = 0 (linear in the spin rate).
    let p = RollingDisc::default();
    let prepared = p.prepare::<f64>();
    let lean_acc = |lean: f64, yaw_rate: f64, spin_rate: f64| {
        let mut d = [0.0; 4];
        p.rhs(
            &prepared,
            0.0,
            &[lean, yaw_rate, 0.0, spin_rate],
            &[],
            &mut d,
        )
        .unwrap();
        d
    };
    let mut checked = 0;
    for (lean, yaw_rate) in [(0.2, 1.5), (-0.3, 2.0), (0.5, -0.8), (0.1, 4.0)] {
        let (a0, a1) = (
            lean_acc(lean, yaw_rate, 0.0)[2],
            lean_acc(lean, yaw_rate, 1.0)[2],
        );
        let spin = -a0 / (a1 - a0);
        let d = lean_acc(lean, yaw_rate, spin);
        assert!(d.iter().skip(1).all(|x| x.abs() < 1e-12), "{d:?}");
        let q = [0.3, lean, 0.0, 0.0, 0.0];
        let u = [yaw_rate, 0.0, spin];
        let mut qdot = [0.0; 5];
        p.coordinate_rates(0.0, &q, &u, &mut qdot).unwrap();
        let vc = qdot[3].hypot(qdot[4]);
        let expected = yaw_rate.abs() * vc / p.g;
        let cf = contact_forces(&p, 0.0, &q, &u, &[]).unwrap();
        match cf.contacts[0].friction() {
            Friction::Required { mu, normal, .. } => {
                assert!(close(normal, p.m * p.g, 1e-12), "{normal}");
                assert!(close(mu, expected, 1e-12), "{mu} vs {expected}");
                println!("steady turn: lean {lean}, yaw rate {yaw_rate}, spin rate {spin:.6}: μ = {mu:.15} (Ω v_c / g = {expected:.15})");
                checked += 1;
            }
            other => panic!("{other:?}"),
        }
    }
    assert_eq!(checked, 4);
}

#[test]
fn a_disc_flipping_up_fast_lifts_off() {
    // Upright with lean rate w: the centre's height r cos(lean) accelerates
    // at −r w², so N = m (g − r w²); negative past w² = g / r.
    let p = RollingDisc::default();
    for w in [2.0, 5.0, 8.0, 12.0] {
        let cf = contact_forces(&p, 0.0, &[0.0; 5], &[0.0, w, 0.0], &[]).unwrap();
        let exact = p.m * (p.g - p.r * w * w);
        match (cf.contacts[0].normal, cf.contacts[0].friction()) {
            (Normal::Available { force, .. }, Friction::Required { normal, .. }) => {
                assert!(exact > 0.0);
                assert!(
                    close(force, exact, 1e-12) && normal == force,
                    "{force} vs {exact}"
                );
            }
            (Normal::Available { force, .. }, Friction::LiftOff { normal }) => {
                assert!(exact < 0.0 && normal == force);
                assert!(close(force, exact, 1e-12), "{force} vs {exact}");
            }
            other => panic!("{other:?}"),
        }
    }
}

#[test]
fn bad_states_are_typed_errors() {
    let p = RollingDisc::default();
    assert!(contact_forces(&p, 0.0, &[0.0; 4], &[0.0; 3], &[]).is_err());
    assert!(contact_forces(&p, 0.0, &[f64::NAN, 0.0, 0.0, 0.0, 0.0], &[0.0; 3], &[]).is_err());
    assert!(contact_forces(&p, 0.0, &[0.0; 5], &[0.0, f64::INFINITY, 0.0], &[]).is_err());
    // Lying flat (lean = π/2) the disc's contact is singular.
    let flat = contact_forces(
        &p,
        0.0,
        &[0.0, std::f64::consts::FRAC_PI_2, 0.0, 0.0, 0.0],
        &[1.0, 0.0, 1.0],
        &[],
    );
    match flat {
        Err(e) => println!("flat disc: {e}"),
        Ok(cf) => {
            // If the solve goes through, nothing is NaN.
            assert!(cf.contacts[0].force.iter().all(|x| x.is_finite()));
            if let Normal::Unavailable(why) = cf.contacts[0].normal {
                assert_ne!(why, NormalUnavailable::NoDirection);
            }
        }
    }
}
