//! Stage 14's candidates on small models.

use super::*;
use crate::ctxt::Ctxt;
use crate::derivation::{derive, testing, Derived};

fn derive_source(src: &str) -> Derived {
    let cx = Ctxt::new();
    let derived = derive(&cx, testing::kinematics(src)).expect("a derivation");
    cx.check().expect("no errors");
    derived
}

/// A pendulum on a cart pushed by `push`: state (x, theta, x', theta'),
/// one input.
const CART_POLE: &str = r#"
    #[appell(coordinates(x, theta), speeds(x, theta), inputs(push))]
    #[appell(point(C = O + x * N.x), particle(C, mass = mc))]
    #[appell(point(P = C + l * sin(theta) * N.x - l * cos(theta) * N.y), particle(P, mass = mp))]
    #[appell(gravity(-g * N.y), force(C, push * N.x))]
    struct CartPole { mc: f64, mp: f64, l: f64, g: f64 }
"#;

#[test]
fn the_closed_form_differentiates_m_and_f_by_every_column() {
    let mut derived = derive_source(CART_POLE);
    let j = differentiate(&mut derived.model, &derived.full);
    // x is cyclic: the state is (theta, x', theta'), one input.
    assert_eq!(j.columns.state.len(), 3);
    assert_eq!(j.columns.inputs.len(), 1);
    let closed = j.closed.expect("a symbolic elimination");
    let g = &derived.model.g;
    // M depends on theta only: ∂M/∂speeds and ∂M/∂push vanish.
    for (c, dm) in closed.mass.iter().enumerate() {
        let zero = dm.iter().all(|&e| g.is_zero(e));
        assert_eq!(zero, c != 0, "column {c}");
    }
    // ∂f_x/∂push = 1: the push acts on the cart's coordinate.
    let at = [
        ("mc", 1.0),
        ("mp", 0.3),
        ("l", 0.7),
        ("g", 9.81),
        ("theta", 0.4),
    ];
    let value = |e| g.eval_named(e, &at).unwrap();
    assert!((value(closed.forcing[3]) - 1.0).abs() < 1e-15);
    // ∂θ̇/∂θ' = 1, ∂θ̇/∂x' = 0.
    assert!((value(closed.rates[2]) - 1.0).abs() < 1e-15);
    assert!(g.is_zero(closed.rates[1]));
    assert!(closed.numeric.is_none());
}

/// Two links on revolute joints, each driven.
const ARM: &str = r#"
    #[appell(joint(j_1, revolute(z), parent = N, child = l_1, actuated))]
    #[appell(joint(j_2, revolute(y), parent = l_1, child = l_2, xyz = [0, 0, 0.5], actuated))]
    #[appell(body(b_1, frame = l_1, mass = 1.2, center = origin(l_1) + 0.2 * l_1.z,
                  inertia = principal(0.02, 0.03, 0.01)))]
    #[appell(body(b_2, frame = l_2, mass = 0.8, center = origin(l_2) + 0.1 * l_2.x + 0.2 * l_2.z,
                  inertia = principal(0.01, 0.01, 0.02)))]
    #[appell(gravity(-9.81 * N.z))]
    struct Arm;
"#;

#[test]
fn a_tree_gets_the_inverse_dynamics_candidate() {
    let mut derived = derive_source(ARM);
    let j = differentiate(&mut derived.model, &derived.full);
    let r = j.recursive.expect("a plain tree's candidate");
    // j_1 is ignorable: the state is (j_2, j_1', j_2'), two inputs.
    let n = j.columns.len();
    assert_eq!((j.columns.state.len(), n), (3, 5));
    assert_eq!((r.mass.len(), r.accelerations.len()), (3, 2));
    let g = &derived.model.g;
    let at = [("j_2", 0.4), ("j_1_dot", 0.3), ("j_2_dot", -0.7)];
    let value = |e| g.eval_named(e, &at).unwrap();
    // −∂R/∂τ_k = ∂τ/∂τ_k: one on row k.
    for (k, col) in [(0, 3), (1, 4)] {
        for row in 0..2 {
            let expected = if row == k { 1.0 } else { 0.0 };
            assert_eq!(value(r.forcing[row * n + col]), expected, "row {row}");
        }
    }
    // ∂q̇_2/∂j_2' = 1: the retained coordinate's rate is its speed.
    assert_eq!(value(r.rates[2]), 1.0);
    // The derivatives read ÿ as the articulated-body algorithm's, not
    // as symbols.
    let accels: Vec<Symbol> = derived
        .model
        .constraints
        .speed_specs
        .iter()
        .map(|s| s.accel)
        .collect();
    for &e in &r.forcing {
        let deps = g.dependencies(e);
        assert!(accels.iter().all(|&s| !deps.contains(s)));
    }
}

/// A free base (its joint frame placed and turned) carrying a limb of
/// two links and a third link, under gravity off the vertical.
const FREE_BASE: &str = r#"
    #[appell(joint(base, free, parent = N, child = b, xyz = [0.1, 0, 0.2], rpy = [0.1, 0.2, -0.3]))]
    #[appell(joint(j_1, revolute(y), parent = b, child = l_1, xyz = [0.1, 0.05, 0.2], actuated))]
    #[appell(joint(j_2, revolute(x), parent = l_1, child = l_2, xyz = [0, 0, 0.3], actuated))]
    #[appell(joint(s_3, prismatic(z), parent = b, child = l_3, xyz = [-0.1, 0, 0.1]))]
    #[appell(body(base_body, frame = b, mass = m, center = origin(b) + 0.03 * b.x - 0.02 * b.z,
                  inertia = matrix(0.2, 0.25, 0.3, 0.01, -0.02, 0.015)))]
    #[appell(body(b_1, frame = l_1, mass = 1.3, center = origin(l_1) + 0.15 * l_1.z,
                  inertia = principal(0.04, 0.05, 0.02)))]
    #[appell(body(b_2, frame = l_2, mass = 0.7, center = origin(l_2) + 0.1 * l_2.x + 0.2 * l_2.z,
                  inertia = principal(0.01, 0.02, 0.015)))]
    #[appell(body(b_3, frame = l_3, mass = 0.4, center = origin(l_3) + 0.05 * l_3.y,
                  inertia = principal(0.002, 0.003, 0.004)))]
    #[appell(gravity(-9.81 * N.z + 0.5 * N.x))]
    struct FreeBase { m: f64 }
"#;

/// The world frame's candidate on a free root equals the rhs's
/// derivatives, the quaternion on the unit sphere and off it: the
/// turns, the slides' speeds and the quaternion's scale mapped back.
#[test]
fn a_free_root_gets_the_world_frame_candidate() {
    // The same robot, and on a free joint below a link welded to the ground.
    let welded = FREE_BASE.replace(
        "joint(base, free, parent = N, child = b, ",
        "joint(mount, weld, parent = N, child = m_0, xyz = [0, 0, 1]))]\n#[appell(joint(base, free, parent = m_0, child = b, ",
    );
    assert_ne!(welded, FREE_BASE);
    for src in [FREE_BASE, welded.as_str()] {
        free_root_agrees(src);
    }
}

fn free_root_agrees(src: &str) {
    let mut derived = derive_source(src);
    let j = differentiate(&mut derived.model, &derived.full);
    let world = j.world.expect("the world frame's candidate");
    let d = &derived.full;
    let s = d.structured.as_ref().expect("a structured form");
    let mut roots = retained_rates(d);
    roots.extend(&s.accelerations);
    let expected = derivatives(&mut derived.model.g, &roots, &j.columns).expect("diff");
    assert_eq!(
        expected.len(),
        world
            .derivatives
            .as_ref()
            .expect("solved in the graph within the budget")
            .len()
    );
    let g = &derived.model.g;
    let mut names: Vec<String> = vec!["m".to_string()];
    names.extend(j.columns.all().map(|c| g.symbol_name(c).to_string()));
    let mut x = 0x2545_f491_u64;
    for round in 0..6 {
        let mut values: Vec<f64> = names
            .iter()
            .map(|_| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                (x % 20000) as f64 / 10000.0 - 1.0
            })
            .collect();
        values[0] = 2.5;
        let quaternion: Vec<usize> = (0..names.len())
            .filter(|&k| names[k].starts_with("base_q"))
            .collect();
        assert_eq!(quaternion.len(), 4);
        let norm = quaternion
            .iter()
            .map(|&k| values[k] * values[k])
            .sum::<f64>()
            .sqrt();
        // On the sphere, then off it.
        let radius = if round % 2 == 0 { 1.0 } else { 1.3 };
        quaternion.iter().for_each(|&k| values[k] *= radius / norm);
        let at: Vec<(&str, f64)> = names.iter().map(|n| n.as_str()).zip(values).collect();
        let value = |e| g.eval_named(e, &at).expect("evaluates");
        for (k, (&ours, &theirs)) in world.accelerations.iter().zip(&s.accelerations).enumerate() {
            let (a, b) = (value(ours), value(theirs));
            assert!(
                (a - b).abs() < 1e-10 * (1.0 + b.abs()),
                "ÿ[{k}]: {a} vs {b}"
            );
        }
        let n = j.columns.len();
        for (k, (&ours, &theirs)) in world
            .derivatives
            .as_ref()
            .unwrap()
            .iter()
            .zip(&expected)
            .enumerate()
        {
            let (a, b) = (value(ours), value(theirs));
            assert!(
                (a - b).abs() < 1e-9 * (1.0 + b.abs()),
                "row {}, column {} ({}), round {round}: {a} vs {b}",
                k / n,
                k % n,
                names[1 + k % n]
            );
        }
    }
}

#[test]
fn a_numeric_elimination_gets_the_partials_of_s_r_and_its_right_side() {
    let mut derived = derive_source(testing::SLEIGH);
    let crate::derivation::Elimination::Numeric(ne) = derived.full.elimination.clone() else {
        panic!("the sleigh's elimination is numeric");
    };
    let j = differentiate(&mut derived.model, &derived.full);
    let closed = j.closed.expect("a closed candidate");
    let numeric = closed.numeric.expect("the elimination's partials");
    let n = j.columns.len();
    let nx = ne.k * ne.columns.len();
    assert_eq!(numeric.s.len(), n);
    assert_eq!(numeric.s[0].len(), ne.k * ne.k);
    assert_eq!(numeric.rate_x.len(), ne.k * nx);
    let l = derived.full.l;
    let values = l * (l + 3) / 2 + derived.full.reduction.retained.len();
    assert_eq!(numeric.values_x.len(), values * nx);
    assert_eq!(numeric.values_w.len(), values * ne.k);
    // f depends on w (the dependent accelerations' remainder).
    let g = &derived.model.g;
    assert!(numeric.values_w.iter().any(|&e| !g.is_zero(e)));
}

#[test]
fn a_candidate_that_grows_the_graph_past_its_budget_is_left_out() {
    let mut g = Graph::new();
    let before = g.len();
    let allowed = 1000;
    let kept = within_budget(&mut g, allowed, |g| g.parse("x + 1"));
    assert!(kept.is_ok());
    let grown = within_budget(&mut g, allowed, |g| {
        let mut last = g.int(0)?;
        for k in 0..(allowed + before + 10) {
            last = g.parse(&format!("x^{}", k + 2))?;
        }
        Ok(last)
    });
    let reason = grown.expect_err("past the budget");
    assert!(reason.contains("would add more than"), "{reason}");
    // The graph's own limit is back.
    assert_eq!(
        g.limits().max_nodes,
        appell_symbolic::Limits::default().max_nodes
    );
}
