//! The generated `rhs_jacobian` (∂rhs/∂state and ∂rhs/∂inputs in one
//! call) against dual numbers through the generated rhs and against central
//! differences, at random states: trees (the double pendulum and UR5: the
//! closed form's derivatives; Panda, an 8-link chain and a leg on a free
//! base with `jacobian(on)`: inverse dynamics differentiated; two legs on
//! a free base: the world frame's derivatives), rolling contacts (the wheel-axle and two of its scenes)
//! and numeric eliminations of the dependent speeds (the four-bar, the
//! Chaplygin sleigh, the Whipple bicycle); and the rhs in dual numbers
//! where the derive writes no symbolic derivatives (the mobile manipulator,
//! an 8-link chain).

#[path = "../examples/models/chaplygin_sleigh.rs"]
mod chaplygin_sleigh;
mod common;
#[path = "../examples/models/double_pendulum.rs"]
mod double_pendulum;
#[path = "../examples/models/four_bar.rs"]
mod four_bar;
#[path = "../examples/models/mobile_manipulator.rs"]
mod mobile_manipulator;
#[path = "../examples/models/ur5.rs"]
mod ur5;
#[path = "../examples/models/wheel_axle.rs"]
mod wheel_axle;
#[path = "../examples/models/whipple_bicycle.rs"]
#[allow(dead_code)] // the model alone
mod whipple_bicycle;

use appell::num_dual::Dual64;
use appell::{Appell, Model, ModelError};
use common::Rng;

/// Panda as `examples/models/panda.rs` has it, its Jacobian written
/// although it is larger than the derive writes by default.
#[derive(Appell, Clone, Debug, Default)]
#[appell(urdf(
    "examples/robots/panda/panda.urdf",
    weld(panda_finger_joint1, panda_finger_joint2)
))]
#[appell(gravity(-9.81 * N.z), jacobian(on))]
struct Panda;

/// `SpatialChain8` of `examples/models/spatial_chain.rs` (that file's
/// 32- and 64-link chains would take minutes to build here).
#[derive(Appell, Clone, Debug, Default)]
#[appell(joint(j[1], revolute(z), parent = N, child = link[1], actuated))]
#[appell(repeat(k in 2..=8,
    repeat(even in 0..1 - k % 2, joint(j[k], revolute(y), parent = link[k - 1], child = link[k], xyz = [0, 0, 0.5], actuated)),
    repeat(odd in 0..k % 2, joint(j[k], revolute(z), parent = link[k - 1], child = link[k], xyz = [0, 0, 0.5], actuated))))]
#[appell(repeat(k in 1..=8, body(link[k], frame = link[k], mass = 1 + 0.1 * k,
    center = origin(link[k]) + 0.05 * link[k].x + 0.02 * link[k].y + 0.25 * link[k].z,
    inertia = matrix(0.02 + 0.001 * k, 0.03 + 0.001 * k, 0.01 + 0.001 * k, 0.001, 0.0015, -0.002))))]
#[appell(gravity(-9.81 * N.z))]
struct SpatialChain8;

/// The 8-link chain with its Jacobian written.
#[derive(Appell, Clone, Debug, Default)]
#[appell(joint(j[1], revolute(z), parent = N, child = link[1], actuated))]
#[appell(repeat(k in 2..=8,
    repeat(even in 0..1 - k % 2, joint(j[k], revolute(y), parent = link[k - 1], child = link[k], xyz = [0, 0, 0.5], actuated)),
    repeat(odd in 0..k % 2, joint(j[k], revolute(z), parent = link[k - 1], child = link[k], xyz = [0, 0, 0.5], actuated))))]
#[appell(repeat(k in 1..=8, body(link[k], frame = link[k], mass = 1 + 0.1 * k,
    center = origin(link[k]) + 0.05 * link[k].x + 0.02 * link[k].y + 0.25 * link[k].z,
    inertia = matrix(0.02 + 0.001 * k, 0.03 + 0.001 * k, 0.01 + 0.001 * k, 0.001, 0.0015, -0.002))))]
#[appell(gravity(-9.81 * N.z), jacobian(on))]
struct SpatialChain8Derived;

/// A body on one leg of three joints on a free base (a unit quaternion
/// among the coordinates), its Jacobian written.
#[derive(Appell, Clone, Debug, Default)]
#[appell(urdf("tests/data/one_leg.urdf", base = free), gravity(-9.81 * N.z), jacobian(on))]
struct OneLeg;

/// Two legs of two joints on a free base, its Jacobian written: the world
/// frame's candidate with the free root's turns, slides and the
/// quaternion's scale mapped back (the states' quaternions are off the
/// unit sphere).
#[derive(Appell, Clone, Debug, Default)]
#[appell(joint(base, free, parent = N, child = b))]
#[appell(joint(hip_l, revolute(y), parent = b, child = thigh_l, xyz = [0, 0.1, -0.05], actuated))]
#[appell(joint(knee_l, revolute(y), parent = thigh_l, child = shank_l, xyz = [0, 0, -0.2], actuated))]
#[appell(joint(hip_r, revolute(y), parent = b, child = thigh_r, xyz = [0, -0.1, -0.05], actuated))]
#[appell(joint(knee_r, revolute(y), parent = thigh_r, child = shank_r, xyz = [0, 0, -0.2], actuated))]
#[appell(body(trunk, frame = b, mass = 3, center = origin(b) + 0.02 * b.z, inertia = principal(0.03, 0.04, 0.05)))]
#[appell(body(thigh_l_body, frame = thigh_l, mass = 0.5, center = origin(thigh_l) - 0.1 * thigh_l.z,
    inertia = principal(0.002, 0.002, 0.0004)))]
#[appell(body(shank_l_body, frame = shank_l, mass = 0.3, center = origin(shank_l) - 0.1 * shank_l.z,
    inertia = principal(0.001, 0.001, 0.0002)))]
#[appell(body(thigh_r_body, frame = thigh_r, mass = 0.5, center = origin(thigh_r) - 0.1 * thigh_r.z,
    inertia = principal(0.002, 0.002, 0.0004)))]
#[appell(body(shank_r_body, frame = shank_r, mass = 0.3, center = origin(shank_r) - 0.1 * shank_r.z,
    inertia = principal(0.001, 0.001, 0.0002)))]
#[appell(gravity(-9.81 * N.z), jacobian(on))]
struct TwoLegs;

/// A planar base carrying an arm: a tree small enough for the symbolic
/// inverse dynamics derivatives, whose rows mix a three-coordinate joint
/// with a one-coordinate one.
#[derive(Appell, Clone, Debug, Default)]
#[appell(gravity(-9.81 * N.y))]
#[appell(joint(base, planar(z), parent = N, child = Base, xyz = [0.1, 0.0, -0.3]))]
#[appell(body(base_body, center = origin(Base) + 0.27 * Base.x + 0.16 * Base.z, frame = Base, mass = 2.7,
    inertia = principal(0.31, 0.2, 0.44)))]
#[appell(joint(arm, revolute(z), parent = Base, child = Arm, xyz = [0.4, 0.1, 0.0]))]
#[appell(body(arm_body, center = origin(Arm) + 0.3 * Arm.x, frame = Arm, mass = 1.1,
    inertia = principal(0.02, 0.05, 0.04)))]
struct PlanarArm;

/// Two particles on a double pendulum, with a generated Jacobian and
/// without.
macro_rules! particles_pendulum {
    ($name:ident $(, $switch:ident)?) => {
        #[derive(Appell, Clone, Debug, Default)]
        #[appell(coordinates(q1, q2), speeds(q1, q2))]
        #[appell(frame(A = N.rotate_z(q1)), frame(B = N.rotate_z(q2)))]
        #[appell(point(P = O + A.x), point(Q = P + B.x))]
        #[appell(particle(P, mass = 1), particle(Q, mass = 1), gravity(-9.81 * N.y))]
        $(#[appell(jacobian($switch))])?
        struct $name;
    };
}
particles_pendulum!(WithJacobian);
particles_pendulum!(NoJacobian, off);

/// The generated Jacobians at (x, u), with the rhs's values.
struct Generated {
    values: Vec<f64>,
    a: Vec<f64>,
    b: Vec<f64>,
}

fn generated<M: Model>(model: &M, t: f64, x: &[f64], u: &[f64]) -> Result<Generated, ModelError> {
    let (s, ni) = (x.len(), u.len());
    let mut g = Generated {
        values: vec![0.0; s],
        a: vec![f64::NAN; s * s],
        b: vec![f64::NAN; s * ni],
    };
    model.rhs_jacobian(t, x, u, &mut g.values, &mut g.a, &mut g.b)?;
    Ok(g)
}

/// Column `j` of [A | B] by one dual-number evaluation of the rhs.
fn dual_column<M: Model>(model: &M, t: f64, x: &[f64], u: &[f64], j: usize) -> Vec<f64> {
    let prepared = model.prepare::<Dual64>();
    let mut xd: Vec<Dual64> = x.iter().map(|&v| Dual64::from_re(v)).collect();
    let mut ud: Vec<Dual64> = u.iter().map(|&v| Dual64::from_re(v)).collect();
    if j < x.len() {
        xd[j].eps = 1.0;
    } else {
        ud[j - x.len()].eps = 1.0;
    }
    let mut out = vec![Dual64::from_re(0.0); x.len()];
    model
        .rhs(&prepared, Dual64::from_re(t), &xd, &ud, &mut out)
        .unwrap();
    out.iter().map(|d| d.eps).collect()
}

/// Column `j` of [A | B] by central differences of the rhs in f64, four
/// points (error h⁴ f⁽⁵⁾/30 and about 1e-16/h).
fn difference_column<M: Model>(model: &M, t: f64, x: &[f64], u: &[f64], j: usize) -> Vec<f64> {
    let prepared = model.prepare::<f64>();
    let eps = 5e-4;
    let at = |sign: f64| {
        let (mut x, mut u) = (x.to_vec(), u.to_vec());
        if j < x.len() {
            x[j] += sign * eps;
        } else {
            u[j - x.len()] += sign * eps;
        }
        let mut out = vec![0.0; x.len()];
        model.rhs(&prepared, t, &x, &u, &mut out).unwrap();
        out
    };
    let (p1, m1, p2, m2) = (at(1.0), at(-1.0), at(2.0), at(-2.0));
    (0..x.len())
        .map(|i| (8.0 * (p1[i] - m1[i]) - (p2[i] - m2[i])) / (12.0 * eps))
        .collect()
}

/// The worst differences of the generated Jacobian from the dual numbers'
/// and from central differences, each relative to 1 + |entry|, at
/// `samples` random states in [−1, 1] (inputs likewise); the generated
/// values equal the rhs's to rounding.
fn worst<M: Model>(model: &M, seed: u64, samples: usize) -> (f64, f64) {
    let info = M::info();
    assert!(
        info.jacobian.is_some(),
        "{} has a generated Jacobian",
        info.name
    );
    let (s, ni) = (info.state_len(), info.inputs.len());
    let mut rng = Rng(seed);
    let (mut dual, mut fd) = (0.0f64, 0.0f64);
    for _ in 0..samples {
        let x: Vec<f64> = (0..s).map(|_| rng.uniform(-1.0, 1.0)).collect();
        let u: Vec<f64> = (0..ni).map(|_| rng.uniform(-1.0, 1.0)).collect();
        let t = rng.uniform(0.0, 1.0);
        let g = generated(model, t, &x, &u).unwrap();
        let prepared = model.prepare::<f64>();
        let mut values = vec![0.0; s];
        model.rhs(&prepared, t, &x, &u, &mut values).unwrap();
        for (a, b) in g.values.iter().zip(&values) {
            assert!(
                (a - b).abs() <= 1e-12 * (1.0 + b.abs()),
                "{}: {a} against {b}",
                info.name
            );
        }
        for j in 0..s + ni {
            let (d, f) = (
                dual_column(model, t, &x, &u, j),
                difference_column(model, t, &x, &u, j),
            );
            for i in 0..s {
                let exact = if j < s {
                    g.a[i * s + j]
                } else {
                    g.b[i * ni + j - s]
                };
                dual = dual.max((exact - d[i]).abs() / (1.0 + d[i].abs()));
                fd = fd.max((exact - f[i]).abs() / (1.0 + f[i].abs()));
            }
        }
    }
    (dual, fd)
}

fn assert_agrees<M: Model>(model: &M, seed: u64) {
    let (dual, fd) = worst(model, seed, 5);
    let info = M::info();
    let name = info.name;
    let form = info.jacobian.map_or("", |j| j.form);
    println!("{name}: against duals {dual:.1e}, against central differences {fd:.1e}; {form}");
    assert!(dual < 1e-11, "{name}: {dual:e} from the dual numbers");
    assert!(fd < 1e-9, "{name}: {fd:e} from central differences");
}

#[test]
fn trees_agree_with_dual_numbers_and_differences() {
    assert_agrees(&double_pendulum::DoublePendulum::default(), 1);
    assert_agrees(&ur5::Ur5, 2);
    assert_agrees(&Panda, 4);
    assert_agrees(&SpatialChain8Derived, 5);
    assert_agrees(&OneLeg, 9);
    assert_agrees(&TwoLegs, 10);
    for info in [Panda::info(), SpatialChain8Derived::info(), OneLeg::info()] {
        let j = info.jacobian.unwrap();
        assert!(j.form.starts_with("inverse dynamics"), "{}", j.form);
    }
    for info in [ur5::Ur5::info(), TwoLegs::info()] {
        let form = info.jacobian.unwrap().form;
        assert!(
            form.starts_with("inverse dynamics in the world frame"),
            "{form}"
        );
    }
    // The chain's and the two legs' columns are solved in loops (the
    // latter on a free root).
    for info in [SpatialChain8Derived::info(), TwoLegs::info()] {
        let form = info.jacobian.unwrap().form;
        assert!(form.contains("in loops over the columns"), "{form}");
    }
}

#[test]
fn rolling_contacts_and_their_scenes_agree() {
    let axle = wheel_axle::WheelAxle::default();
    assert_agrees(&axle, 6);
    assert_agrees(&wheel_axle::WheelAxleDriven(axle.clone()), 7);
    assert_agrees(&wheel_axle::WheelAxleCoasting(axle.clone()), 8);
}

#[test]
fn numeric_eliminations_agree() {
    let four_bar = four_bar::FourBar2 {
        a: 0.7,
        m: 1.3,
        g: 9.81,
    };
    assert_agrees(&four_bar, 11);
    assert_agrees(&chaplygin_sleigh::ChaplyginSleigh::default(), 12);
    assert_agrees(&whipple_bicycle::WhippleBicycle::default(), 13);
}

/// Models whose symbolic derivatives the derive does not write by default
/// get the rhs in dual numbers, and `info` says so with its cost.
#[test]
fn dual_number_jacobians_agree() {
    let manipulator = mobile_manipulator::MobileManipulator::default();
    assert_agrees(&manipulator, 14);
    let info = mobile_manipulator::MobileManipulator::info();
    let j = info.jacobian.unwrap();
    assert!(j.form.starts_with("dual numbers: "), "{}", j.form);
    // More than one dual pass costs more than the rhs.
    assert!(j.ops.total > 2 * info.rhs_ops.total, "{:?}", j.ops);
    let columns = info.state_len() + info.inputs.len();
    let passes = columns.div_ceil(8);
    let width = columns.div_ceil(passes);
    assert!(
        j.form.contains(&format!(
            "{passes} passes of {width} directions over the {columns} columns"
        )),
        "{}",
        j.form
    );
}

/// The 8-link chain's symbolic Jacobian is written by default: with its
/// columns solved in loops, its expressions are within the size limit
/// (its 15 states, the first joint's angle ignorable, and 8 torques).
#[test]
fn the_chains_jacobian_is_written_by_default() {
    assert_agrees(&SpatialChain8, 15);
    let chain = SpatialChain8::info();
    assert_eq!((chain.state_len(), chain.inputs.len()), (15, 8));
    let form = chain.jacobian.unwrap().form;
    assert!(form.contains("in loops over the columns"), "{form}");
}

#[test]
fn linearize_reads_the_generated_jacobian_and_falls_back_to_dual_numbers() {
    let x = [0.3, -0.7, 0.2, 0.5];
    let lin = appell::linearize::linearize(&WithJacobian, 0.0, &x, &[]).unwrap();
    let g = generated(&WithJacobian, 0.0, &x, &[]).unwrap();
    assert_eq!(lin.a.transpose().as_slice(), &g.a[..]);
    // Without a generated Jacobian: the trait's default, and the duals.
    assert!(NoJacobian::info().jacobian.is_none());
    assert!(NoJacobian::info()
        .equations
        .contains("jacobian: none (turned off by `jacobian(off)`"));
    let err = generated(&NoJacobian, 0.0, &x, &[]).err();
    assert!(matches!(
        err,
        Some(ModelError::NotGenerated {
            function: "rhs_jacobian"
        })
    ));
    let off = appell::linearize::linearize(&NoJacobian, 0.0, &x, &[]).unwrap();
    let worst = off
        .a
        .iter()
        .zip(lin.a.iter())
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-12, "{worst}");
}

#[test]
fn a_steps_jacobian_chained_through_the_generated_one_equals_the_dual_numbers() {
    use appell::linearize::{step_jacobian, FixedStep};
    let x = [0.3, -0.7, 0.2, 0.5];
    for method in [FixedStep::Rk4, FixedStep::SemiImplicitEuler] {
        let chained = step_jacobian(&WithJacobian, method, 0.1, 0.01, &x, &[]).unwrap();
        let dual = step_jacobian(&NoJacobian, method, 0.1, 0.01, &x, &[]).unwrap();
        assert_eq!(chained.next, dual.next);
        let worst = chained
            .a
            .iter()
            .zip(dual.a.iter())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-13, "{method:?}: {worst}");
    }
}

#[test]
fn wrong_buffers_and_non_finite_states_are_typed_errors() {
    let model = ur5::Ur5;
    let (s, ni) = (ur5::Ur5::info().state_len(), ur5::Ur5::info().inputs.len());
    let (mut v, mut a, mut b) = (vec![0.0; s], vec![0.0; s * s], vec![0.0; s * ni]);
    let (x, u) = (vec![0.1; s], vec![0.0; ni]);
    let short = model.rhs_jacobian(0.0, &x, &u, &mut v, &mut a[1..], &mut b);
    assert!(matches!(short, Err(ModelError::Length { .. })), "{short:?}");
    let mut bad = x.clone();
    bad[2] = f64::NAN;
    let nan = model.rhs_jacobian(0.0, &bad, &u, &mut v, &mut a, &mut b);
    assert!(matches!(nan, Err(ModelError::NonFinite { .. })), "{nan:?}");
}

/// `inverse_dynamics_derivatives` (symbolic for a tree, dual numbers
/// otherwise) against num-dual's dual numbers and central differences
/// through `inverse_dynamics`, and `forward_dynamics_derivatives` against
/// `rhs_jacobian`'s rows, at random full coordinates, speeds and
/// accelerations; the worst differences relative to 1 + |entry|.
fn controller_derivatives_worst<M: Model>(model: &M, seed: u64) -> (f64, f64) {
    let info = M::info();
    let (n, l, ni) = (info.coordinates.len(), info.speeds.len(), info.inputs.len());
    let mut rng = Rng(seed);
    let (mut worst_dual, mut worst) = (0.0f64, 0.0f64);
    for _ in 0..5 {
        let q: Vec<f64> = (0..n).map(|_| rng.uniform(-1.0, 1.0)).collect();
        let u: Vec<f64> = (0..l).map(|_| rng.uniform(-1.0, 1.0)).collect();
        let acc: Vec<f64> = (0..l).map(|_| rng.uniform(-1.0, 1.0)).collect();
        let w: Vec<f64> = (0..ni).map(|_| rng.uniform(-1.0, 1.0)).collect();
        let (mut f, mut dq, mut du, mut m) = (
            vec![0.0; l],
            vec![0.0; l * n],
            vec![0.0; l * l],
            vec![0.0; l * l],
        );
        model
            .inverse_dynamics_derivatives(0.0, &q, &u, &acc, &mut f, &mut dq, &mut du, &mut m)
            .unwrap();
        let tau = |q: &[f64], u: &[f64], a: &[f64]| {
            let mut out = vec![0.0; l];
            model.inverse_dynamics(0.0, q, u, a, &mut out).unwrap();
            out
        };
        // The values are the function's (to rounding: the symbolic program
        // computes them beside the partials, in its own order).
        let values = tau(&q, &u, &acc);
        let scale = values.iter().fold(1.0f64, |s, v| s.max(v.abs()));
        assert!(
            f.iter()
                .zip(&values)
                .all(|(a, b)| (a - b).abs() <= 1e-14 * scale),
            "{}: {f:?} against the function's {values:?}",
            info.name
        );
        // Four-point central differences along one argument's entry.
        let eps = 5e-4;
        let column = |which: usize, j: usize| -> Vec<f64> {
            let at = |h: f64| {
                let mut args = [q.clone(), u.clone(), acc.clone()];
                args[which][j] += h;
                tau(&args[0], &args[1], &args[2])
            };
            let (p1, m1, p2, m2) = (at(eps), at(-eps), at(2.0 * eps), at(-2.0 * eps));
            (0..l)
                .map(|i| (8.0 * (p1[i] - m1[i]) - (p2[i] - m2[i])) / (12.0 * eps))
                .collect()
        };
        let dual = |which: usize, j: usize| -> Vec<f64> {
            let mut args =
                [&q, &u, &acc].map(|v| v.iter().map(|&x| Dual64::from_re(x)).collect::<Vec<_>>());
            args[which][j].eps = 1.0;
            let mut out = vec![Dual64::from_re(0.0); l];
            let t = Dual64::from_re(0.0);
            model
                .inverse_dynamics(t, &args[0], &args[1], &args[2], &mut out)
                .unwrap();
            out.iter().map(|d| d.eps).collect()
        };
        for (which, matrix, cols) in [(0, &dq, n), (1, &du, l), (2, &m, l)] {
            for j in 0..cols {
                for (i, d) in column(which, j).iter().enumerate() {
                    worst = worst.max((matrix[i * cols + j] - d).abs() / (1.0 + d.abs()));
                }
                for (i, d) in dual(which, j).iter().enumerate() {
                    let e = (matrix[i * cols + j] - d).abs() / (1.0 + d.abs());
                    worst_dual = worst_dual.max(e);
                }
            }
        }
        // The forward derivatives are rhs_jacobian's rows for ÿ.
        let (mut accel, mut fq, mut fu, mut fw) = (
            vec![0.0; l],
            vec![0.0; l * n],
            vec![0.0; l * l],
            vec![0.0; l * ni],
        );
        model
            .forward_dynamics_derivatives(0.0, &q, &u, &w, &mut accel, &mut fq, &mut fu, &mut fw)
            .unwrap();
        let mut x: Vec<f64> = info
            .retained
            .iter()
            .map(|c| q[info.coordinate_index(c).unwrap()])
            .collect();
        let nr = x.len();
        x.extend(&u);
        let g = generated(model, 0.0, &x, &w).unwrap();
        let s = x.len();
        assert_eq!(accel, g.values[nr..], "{}", info.name);
        for k in 0..l {
            for (r, c) in info.retained.iter().enumerate() {
                let c = info.coordinate_index(c).unwrap();
                assert_eq!(fq[k * n + c], g.a[(nr + k) * s + r]);
            }
            assert_eq!(
                fu[k * l..(k + 1) * l],
                g.a[(nr + k) * s + nr..(nr + k + 1) * s]
            );
            assert_eq!(
                fw[k * ni..(k + 1) * ni],
                g.b[(nr + k) * ni..(nr + k + 1) * ni]
            );
        }
    }
    (worst_dual, worst)
}

#[test]
fn the_controller_functions_derivatives_agree_with_differences() {
    let axle = wheel_axle::WheelAxle::default();
    let four_bar = four_bar::FourBar2 {
        a: 0.7,
        m: 1.3,
        g: 9.81,
    };
    let worst = [
        controller_derivatives_worst(&double_pendulum::DoublePendulum::default(), 21),
        controller_derivatives_worst(&ur5::Ur5, 22),
        controller_derivatives_worst(&SpatialChain8, 23),
        controller_derivatives_worst(&axle, 24),
        controller_derivatives_worst(&four_bar, 25),
        controller_derivatives_worst(&mobile_manipulator::MobileManipulator::default(), 26),
        controller_derivatives_worst(&PlanarArm, 27),
    ];
    println!("inverse dynamics derivatives against (duals, central differences): {worst:?}");
    for (k, (dual, fd)) in worst.into_iter().enumerate() {
        assert!(dual < 1e-11, "{k}: {dual:e} from the dual numbers");
        // The four-bar at random full coordinates (its loop far from
        // closed): differences of 5e-4 miss by 5e-5 (measured), where the
        // dual numbers agree to 3e-13.
        if k != 4 {
            assert!(fd < 1e-8, "{k}: {fd:e} from central differences");
        }
    }
    // With the Jacobian off there are none.
    let (mut f, mut dq, mut du, mut m) = ([0.0; 2], [0.0; 4], [0.0; 4], [0.0; 4]);
    let off = NoJacobian.inverse_dynamics_derivatives(
        0.0,
        &[0.1, 0.2],
        &[0.0; 2],
        &[0.0; 2],
        &mut f,
        &mut dq,
        &mut du,
        &mut m,
    );
    assert!(
        matches!(off, Err(ModelError::NotGenerated { .. })),
        "{off:?}"
    );
}
