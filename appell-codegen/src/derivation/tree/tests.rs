//! The structured form against the closed form of the same model: M, the
//! bias, inverse dynamics and ÿ agree at random states.

use super::{projected::projected, structured};
use crate::derivation::testing::kinematics;
use crate::derivation::{derive, derive_with, Derived, Options};

/// Every kind of link the tree takes: revolute joints about coordinate
/// and skew axes, a prismatic joint, a weld carrying a body, rpy
/// placements, a turned inertial frame, a particle, a parameter.
const MIXED: &str = r#"
    #[appell(joint(j_1, revolute(z), parent = N, child = l_1, actuated))]
    #[appell(joint(j_2, revolute(-y), parent = l_1, child = l_2, xyz = [0.1, 0, 0.5], rpy = [0.3, -0.2, 0.1], actuated))]
    #[appell(joint(s_3, prismatic(x), parent = l_2, child = l_3, xyz = [0, 0.2, 0.4], actuated))]
    #[appell(joint(w_4, weld, parent = l_3, child = l_4, xyz = [0.3, 0, 0], rpy = [0, 0.5, 0]))]
    #[appell(joint(j_5, revolute([1, 2, 2]), parent = l_4, child = l_5, xyz = [0, 0, 0.2]))]
    #[appell(body(b_1, frame = l_1, mass = m, center = origin(l_1) + 0.05 * l_1.x + 0.2 * l_1.z,
                  inertia = matrix(0.02, 0.025, 0.01, 0.001, 0.0015, -0.002)))]
    #[appell(frame(i_2 = l_2.rotate_x(0.4).rotate_z(-0.3)))]
    #[appell(body(b_2, frame = i_2, mass = 1.3, center = origin(l_2) + 0.1 * i_2.y - 0.25 * l_2.z,
                  inertia = principal(0.04, 0.05, 0.02)))]
    #[appell(body(b_3, frame = l_3, mass = 0.8, center = origin(l_3) + 0.1 * l_3.y, inertia = principal(0.01, 0.01, 0.02)))]
    #[appell(body(b_4, frame = l_4, mass = 0.6, center = origin(l_4) + 0.05 * l_4.z, inertia = principal(0.003, 0.004, 0.005)))]
    #[appell(point(p_5 = origin(l_5) + 0.3 * l_5.y + 0.1 * l_5.x), particle(p_5, mass = 0.7))]
    #[appell(gravity(-9.81 * N.z))]
    struct Mixed { m: f64 }
"#;

fn derived(src: &str) -> Derived {
    let cx = crate::ctxt::Ctxt::new();
    let d = derive(&cx, kinematics(src)).expect("derived");
    cx.check().expect("no errors");
    d
}

/// Values for every symbol of the model at one state.
fn state(d: &Derived, seed: u64) -> Vec<(String, f64)> {
    let mut x = seed;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x % 20000) as f64 / 10000.0 - 1.0
    };
    let g = &d.model.g;
    let mut out = vec![
        ("m".to_string(), 1.7),
        ("r".to_string(), 0.1),
        ("w".to_string(), 0.25),
    ];
    for (q, c) in &d.model.coords {
        out.push((q.to_string(), 3.0 * next()));
        out.push((g.symbol_name(c.rate).to_string(), next()));
    }
    for s in &d.model.constraints.speed_specs {
        out.push((g.symbol_name(s.symbol).to_string(), next()));
        out.push((g.symbol_name(s.accel).to_string(), next()));
    }
    for (name, _) in &d.model.inputs {
        out.push((name.to_string(), next()));
    }
    // Quaternions on the unit sphere, where the model's rotations are.
    let names: Vec<String> = out.iter().map(|(n, _)| n.clone()).collect();
    for (k, name) in names.iter().enumerate() {
        if let Some(joint) = name.strip_suffix("_qw") {
            let at: Vec<usize> = ["_qw", "_qx", "_qy", "_qz"]
                .iter()
                .map(|s| {
                    names
                        .iter()
                        .position(|n| *n == format!("{joint}{s}"))
                        .unwrap()
                })
                .collect();
            let norm = at.iter().map(|&i| out[i].1 * out[i].1).sum::<f64>().sqrt();
            at.iter().for_each(|&i| out[i].1 /= norm);
            assert_eq!(at[0], k);
        }
    }
    out
}

/// A free base carrying an arm whose second joint is a ball, with the
/// base's mass centre off its origin.
const BALLS: &str = r#"
    #[appell(joint(base, free, parent = N, child = b))]
    #[appell(joint(j_1, revolute(y), parent = b, child = l_1, xyz = [0.1, 0.05, 0.2], actuated))]
    #[appell(joint(ball, spherical, parent = l_1, child = l_2, xyz = [0, 0, 0.3], rpy = [0.2, 0, -0.4]))]
    #[appell(body(base_body, frame = b, mass = m, center = origin(b) + 0.03 * b.x - 0.02 * b.z,
                  inertia = matrix(0.2, 0.25, 0.3, 0.01, -0.02, 0.015)))]
    #[appell(body(b_1, frame = l_1, mass = 1.3, center = origin(l_1) + 0.15 * l_1.z,
                  inertia = principal(0.04, 0.05, 0.02)))]
    #[appell(body(b_2, frame = l_2, mass = 0.7, center = origin(l_2) + 0.1 * l_2.x + 0.2 * l_2.z,
                  inertia = principal(0.01, 0.02, 0.015)))]
    #[appell(gravity(-9.81 * N.z))]
    struct Balls { m: f64 }
"#;

#[test]
fn structured_form_agrees_with_the_closed_form() {
    agrees_with_the_closed_form(MIXED, 5, 4);
}

#[test]
fn free_and_spherical_joints_agree_with_the_closed_form() {
    // The free joint, the revolute, the ball.
    agrees_with_the_closed_form(BALLS, 3, 10);
}

/// M, the bias, inverse dynamics, ÿ, the gravity term and T of the
/// structured form against the closed form's at random states.
fn agrees_with_the_closed_form(src: &str, links: usize, speeds: usize) {
    let mut d = derived(src);
    let spec = d.model.tree.clone().expect("a tree");
    assert_eq!(spec.links.len(), links);
    spec.plain.clone().expect("plain");
    let s = structured(&mut d.model, &spec, &[]).expect("structured");
    let l = d.full.l;
    assert_eq!(l, speeds);
    let (mass, forcing) = (
        d.full.equations.mass.clone(),
        d.full.equations.forcing.clone(),
    );
    for seed in 1..6 {
        let values = state(&d, seed * 7919);
        let at: Vec<(&str, f64)> = values.iter().map(|(n, v)| (n.as_str(), *v)).collect();
        let g = &d.model.g;
        let value = |e| g.eval_named(e, &at).expect("evaluates");
        let zero_inputs: Vec<(&str, f64)> = at
            .iter()
            .map(|&(n, v)| {
                if n.starts_with("tau_") {
                    (n, 0.0)
                } else {
                    (n, v)
                }
            })
            .collect();
        let value0 = |e| g.eval_named(e, &zero_inputs).expect("evaluates");
        let accel: Vec<f64> = (0..l)
            .map(|k| lookup(&at, g.symbol_name(d.model.constraints.speed_specs[k].accel)))
            .collect();
        let ydd: Vec<f64> = s.accelerations.iter().map(|&e| value(e)).collect();
        // T from the links' velocities, the large trees' energy, against
        // the closed form's.
        let (t_links, t_closed) = (value(s.kinetic), value(d.full.energies.kinetic));
        assert!(
            (t_links - t_closed).abs() < 1e-12 * (1.0 + t_closed.abs()),
            "T: {t_links} vs {t_closed}"
        );
        for i in 0..l {
            for j in 0..l {
                let (a, b) = (value(s.mass[i * l + j]), value(mass[i * l + j]));
                assert!((a - b).abs() < 1e-12, "M[{i},{j}]: {a} vs {b}");
            }
            let (h, f0) = (value(s.bias[i]), value0(forcing[i]));
            assert!((h + f0).abs() < 1e-11, "bias {i}: {h} vs {}", -f0);
            let ma: f64 = (0..l).map(|j| value(mass[i * l + j]) * accel[j]).sum();
            let tau = value(s.inverse[i]);
            assert!(
                (tau - (ma - f0)).abs() < 1e-11,
                "inverse {i}: {tau} vs {}",
                ma - f0
            );
            let my: f64 = (0..l).map(|j| value(mass[i * l + j]) * ydd[j]).sum();
            let f = value(forcing[i]);
            assert!(
                (my - f).abs() < 1e-10 * (1.0 + f.abs()),
                "ABA row {i}: {my} vs {f}"
            );
            let grav = value(s.gravity[i]);
            let moving: Vec<(&str, f64)> = zero_inputs
                .iter()
                .map(|&(n, v)| {
                    if d.model
                        .constraints
                        .speed_specs
                        .iter()
                        .any(|sp| g.symbol_name(sp.symbol) == n)
                    {
                        (n, 0.0)
                    } else {
                        (n, v)
                    }
                })
                .collect();
            let f00 = g.eval_named(forcing[i], &moving).expect("evaluates");
            assert!(
                (grav + f00).abs() < 1e-11,
                "gravity {i}: {grav} vs {}",
                -f00
            );
        }
    }
}

fn lookup(at: &[(&str, f64)], name: &str) -> f64 {
    at.iter()
        .find(|(n, _)| *n == name)
        .map(|(_, v)| *v)
        .expect("bound")
}

/// A differential-drive base (a dependent planar joint, two rolling
/// wheels) carrying a two-link arm placed with `at`.
const ON_WHEELS: &str = r#"
    #[appell(positive(r, w), gravity(-9.81 * N.z))]
    #[appell(joint(base, planar(z), parent = N, child = c, xyz = [0, 0, r], dependent),
             joint(left, revolute(y), parent = c, child = lw, xyz = [0, w, 0], actuated),
             joint(right, revolute(y), parent = c, child = rw, xyz = [0, -w, 0], actuated),
             point(mount = c_origin + 0.1 * c.x + 0.3 * c.z),
             joint(j_1, revolute(z), parent = c, child = a_1, at = mount, actuated),
             joint(j_2, revolute(-y), parent = a_1, child = a_2, xyz = [0, 0.05, 0.2], rpy = [0.2, 0, 0.1], actuated),
             point(lp = lw_origin - r * N.z), point(rp = rw_origin - r * N.z))]
    #[appell(body(chassis, center = c_origin - 0.1 * c.x + 0.05 * c.z, frame = c, mass = m,
                  inertia = principal(1.0, 1.5, 2.0)),
             body(left_wheel, center = lw_origin, frame = lw, mass = 2, inertia = principal(0.005, 0.01, 0.005)),
             body(right_wheel, center = rw_origin, frame = rw, mass = 2, inertia = principal(0.005, 0.01, 0.005)),
             body(b_1, frame = a_1, mass = 1.3, center = origin(a_1) + 0.02 * a_1.x + 0.1 * a_1.z,
                  inertia = matrix(0.02, 0.025, 0.01, 0.001, 0.0015, -0.002)),
             body(b_2, frame = a_2, mass = 0.8, center = origin(a_2) + 0.2 * a_2.x + 0.03 * a_2.y,
                  inertia = principal(0.01, 0.02, 0.015)),
             rolls(left_wheel, contact = lp, along = [c.x, c.y]),
             rolls(right_wheel, contact = rp, along = [c.x]))]
    struct OnWheels { m: f64, r: f64, w: f64 }
"#;

#[test]
fn the_projected_tree_agrees_with_the_closed_form() {
    let cx = crate::ctxt::Ctxt::new();
    let options = Options {
        closed_form_only: true,
        ..Options::default()
    };
    let mut d = derive_with(&cx, kinematics(ON_WHEELS), &options).expect("derived");
    cx.check().expect("no errors");
    let spec = d.model.tree.clone().expect("a tree");
    assert_eq!(
        spec.plain.as_ref().unwrap_err(),
        "the model has rolling contacts"
    );
    // The planar joint's three links, two wheels, two arm links.
    assert_eq!(spec.links.len(), 7);
    let l = d.full.l;
    assert_eq!(l, 4);
    let (map, fixed) = (d.full.map.clone(), d.full.reduction.ignorable.clone());
    assert_eq!(fixed.len(), 5, "the base's pose and the wheels' angles");
    let p = projected(&mut d.model, &spec, &map, &fixed).expect("projected");
    let (mass, forcing) = (&d.full.equations.mass, &d.full.equations.forcing);
    for seed in 1..6 {
        let values = state(&d, seed * 104_729);
        let at: Vec<(&str, f64)> = values.iter().map(|(n, v)| (n.as_str(), *v)).collect();
        let value = |e| d.model.g.eval_named(e, &at).expect("evaluates");
        for k in 0..l * l {
            let (a, b) = (value(p.mass[k]), value(mass[k]));
            assert!(
                (a - b).abs() < 1e-12 * (1.0 + b.abs()),
                "M[{k}]: {a} vs {b}"
            );
        }
        for k in 0..l {
            let (a, b) = (value(p.forcing[k]), value(forcing[k]));
            assert!(
                (a - b).abs() < 1e-11 * (1.0 + b.abs()),
                "f[{k}]: {a} vs {b}"
            );
        }
    }
}

/// The residual M ÿ + h − τ vanishes at the articulated-body ÿ, and its
/// change along each acceleration is M's column: at random states, a free
/// joint's quaternion off the unit sphere included.
#[test]
fn the_residual_vanishes_at_the_articulated_body_accelerations() {
    for (src, seed) in [(MIXED, 3), (BALLS, 5)] {
        let mut d = derived(src);
        let spec = d.model.tree.clone().expect("a tree");
        let s = structured(&mut d.model, &spec, &[]).expect("structured");
        let r = super::residual(&mut d.model, &spec, &[]).expect("residual");
        let l = d.full.l;
        let g = &d.model.g;
        let accels: Vec<&str> = d
            .model
            .constraints
            .speed_specs
            .iter()
            .map(|sp| g.symbol_name(sp.accel))
            .collect();
        for k in 1..4 {
            // The quaternions moved off the unit sphere.
            let values: Vec<(String, f64)> = state(&d, seed * 104_729 * k)
                .into_iter()
                .map(|(n, v)| {
                    let quaternion = ["_qw", "_qx", "_qy", "_qz"].iter().any(|e| n.ends_with(e));
                    let v = if quaternion { 1.3 * v } else { v };
                    (n, v)
                })
                .collect();
            let at: Vec<(&str, f64)> = values.iter().map(|(n, v)| (n.as_str(), *v)).collect();
            let ydd: Vec<f64> = s
                .accelerations
                .iter()
                .map(|&e| g.eval_named(e, &at).expect("evaluates"))
                .collect();
            let residual = |ydd: &[f64]| -> Vec<f64> {
                let at: Vec<(&str, f64)> = at
                    .iter()
                    .map(|&(n, v)| match accels.iter().position(|a| *a == n) {
                        Some(j) => (n, ydd[j]),
                        None => (n, v),
                    })
                    .collect();
                let value = |e| g.eval_named(e, &at).expect("evaluates");
                (0..l)
                    .map(|i| value(r.inverse[i]) - value(r.inputs[i]))
                    .collect()
            };
            let at_solution = residual(&ydd);
            for (i, v) in at_solution.iter().enumerate() {
                assert!(v.abs() < 1e-9, "seed {seed}: row {i} is {v}");
            }
            let value = |e| g.eval_named(e, &at).expect("evaluates");
            for j in 0..l {
                let mut moved = ydd.clone();
                moved[j] += 1.0;
                let column = residual(&moved);
                for i in 0..l {
                    let (change, m) = (column[i] - at_solution[i], value(r.mass[i * l + j]));
                    assert!(
                        (change - m).abs() < 1e-9 * (1.0 + m.abs()),
                        "M[{i},{j}]: {change} vs {m}"
                    );
                }
            }
        }
    }
}

/// A branching tree: two limbs on one base link, one ending in a slide.
const BRANCHED: &str = r#"
    #[appell(joint(j_1, revolute(z), parent = N, child = l_1, xyz = [0, 0, 0.3], actuated))]
    #[appell(joint(j_2, revolute(x), parent = l_1, child = l_2, xyz = [0.2, 0.1, 0], actuated))]
    #[appell(joint(j_3, revolute([0, 1, 1]), parent = l_2, child = l_3, xyz = [0, 0, 0.4], rpy = [0.2, 0, -0.4]))]
    #[appell(joint(j_4, revolute(y), parent = l_1, child = l_4, xyz = [-0.2, 0, 0.1], actuated))]
    #[appell(joint(s_5, prismatic(z), parent = l_4, child = l_5, xyz = [0, 0.1, 0.3]))]
    #[appell(body(b_1, frame = l_1, mass = 2.0, center = origin(l_1) + 0.05 * l_1.z, inertia = principal(0.05, 0.06, 0.04)))]
    #[appell(body(b_2, frame = l_2, mass = 1.1, center = origin(l_2) + 0.2 * l_2.z - 0.03 * l_2.y,
                  inertia = matrix(0.02, 0.025, 0.01, 0.001, 0.0015, -0.002)))]
    #[appell(body(b_3, frame = l_3, mass = 0.7, center = origin(l_3) + 0.1 * l_3.x, inertia = principal(0.01, 0.02, 0.02)))]
    #[appell(body(b_4, frame = l_4, mass = m, center = origin(l_4) + 0.15 * l_4.z, inertia = principal(0.03, 0.03, 0.01)))]
    #[appell(body(b_5, frame = l_5, mass = 0.4, center = origin(l_5) + 0.02 * l_5.x, inertia = principal(0.002, 0.003, 0.004)))]
    #[appell(gravity(-9.81 * N.z + 0.5 * N.x))]
    struct Branched { m: f64 }
"#;

/// The world-frame derivatives of inverse dynamics and its M agree with
/// the recursive Newton–Euler residual's by differentiation, at random
/// states and accelerations, on a chain and on a branching tree.
#[test]
fn the_world_frame_derivatives_agree_with_differentiation() {
    for (src, seed) in [(MIXED, 7), (BRANCHED, 11)] {
        let mut d = derived(src);
        let spec = d.model.tree.clone().expect("a tree");
        super::world::single_axis(&spec).expect("one-axis joints");
        let r = super::residual(&mut d.model, &spec, &[]).expect("residual");
        let accels: Vec<appell_symbolic::Id> = d
            .model
            .constraints
            .speed_specs
            .iter()
            .map(|s| d.model.g.sym(s.accel))
            .collect::<Result<_, _>>()
            .expect("symbols");
        let at = super::world::Accelerations::At(&accels);
        let w = super::world::world_derivatives(&mut d.model, &spec, &[], at)
            .expect("world derivatives");
        let solved = super::world::Accelerations::Solved;
        let forward = super::world::world_derivatives(&mut d.model, &spec, &[], solved)
            .expect("world derivatives at the forward dynamics' accelerations");
        let s = structured(&mut d.model, &spec, &[]).expect("structured");
        let factor = forward.factor.as_ref().expect("M's factors");
        // The chain's factor has no zero below its diagonal; the branching
        // tree's has, and M⁻¹ by the factors is M's inverse either way.
        assert_eq!(factor.is_dense(), src == MIXED);
        let inverse = {
            let mut a = super::spatial::Algebra::new(&mut d.model.g).expect("algebra");
            factor.inverse(&mut a).expect("M⁻¹")
        };
        let l = d.full.l;
        let speeds: Vec<_> = d
            .model
            .constraints
            .speed_specs
            .iter()
            .map(|s| s.symbol)
            .collect();
        let coordinates: Vec<_> = w
            .coordinates
            .iter()
            .map(|&r| d.model.coords[r.expect("a joint coordinate")].1.q)
            .collect();
        let mut expected = Vec::new();
        for i in 0..l {
            for j in 0..l {
                let g = &mut d.model.g;
                let dq = g.diff(r.inverse[i], coordinates[j]).expect("dq");
                let dv = g.diff(r.inverse[i], speeds[j]).expect("dv");
                expected.push((i, j, dq, dv));
            }
        }
        let g = &d.model.g;
        for k in 1..4 {
            let values = state(&d, seed * 7919 * k);
            let at: Vec<(&str, f64)> = values.iter().map(|(n, v)| (n.as_str(), *v)).collect();
            let value = |e| g.eval_named(e, &at).expect("evaluates");
            for i in 0..l {
                for j in 0..l {
                    let product: f64 = (0..l)
                        .map(|k| value(forward.mass[i * l + k]) * value(inverse[k * l + j]))
                        .sum();
                    let identity = if i == j { 1.0 } else { 0.0 };
                    assert!(
                        (product - identity).abs() < 1e-9,
                        "(M M⁻¹)[{i},{j}] = {product}"
                    );
                }
            }
            // ÿ by M's factors is the articulated-body algorithm's.
            for (i, (&ours, &theirs)) in forward
                .accelerations
                .iter()
                .zip(&s.accelerations)
                .enumerate()
            {
                let (a, b) = (value(ours), value(theirs));
                assert!(
                    (a - b).abs() < 1e-10 * (1.0 + b.abs()),
                    "ÿ[{i}]: {a} vs {b}"
                );
            }
            for &(i, j, dq, dv) in &expected {
                for (what, ours, theirs) in [
                    ("∂Q/∂q", w.by_coordinates[i * l + j], dq),
                    ("∂Q/∂v", w.by_speeds[i * l + j], dv),
                    ("M", w.mass[i * l + j], r.mass[i * l + j]),
                ] {
                    let (a, b) = (value(ours), value(theirs));
                    assert!(
                        (a - b).abs() < 1e-10 * (1.0 + b.abs()),
                        "{what}[{i},{j}]: {a} vs {b} (seed {seed})"
                    );
                }
            }
        }
    }
}
