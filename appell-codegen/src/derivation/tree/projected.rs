//! A tree of joints under constraints (rolling wheels, closing rows,
//! dependent joints, privileged speeds other than the joint rates): the
//! tree's equations in its joint rates q̇, projected onto the privileged
//! speeds through q̇ = C ẏ + c (stage 4, eqs. 30-31). With M_q from the
//! composite-rigid-body algorithm and the generalized forces of recursive
//! Newton–Euler,
//!
//! M = Cᵀ M_q C,  f = Cᵀ (τ − RNEA(q, C ẏ + c, Ċ ẏ + ċ)),
//!
//! which is Appell's equation (eq. 56) written with the tree's forces: a
//! link's partial velocities are C's columns carried through the joints'
//! motion subspaces, and the constraint forces do no work along them.
//! Coordinates the closed form showed the equations do not depend on
//! (`fixed`) are taken at zero after the rates are differentiated.
//!
//! Input: the model's [`TreeSpec`] and [`SpeedMap`]; output:
//! [`Projected`].

use appell_symbolic::{Graph, Id, RateRules, Substitution, SymbolicError};

use super::free;
use super::links::{self, Parts};
use super::recursions::Recursions;
use super::spatial::Algebra;
use crate::derivation::SpeedMap;
use crate::model::tree::TreeSpec;
use crate::model::{ConstraintSet, Model, SpeedSpec};

type R<T> = Result<T, SymbolicError>;

/// M (l×l, row-major) and f (l) of the projected tree.
pub struct Projected {
    /// M = Cᵀ M_q C.
    pub mass: Vec<Id>,
    /// f = Cᵀ (τ − RNEA).
    pub forcing: Vec<Id>,
}

/// The projected equations of `model`'s tree, the coordinates in `fixed`
/// at zero.
///
/// ```
/// use appell_codegen::{ctxt::Ctxt, derivation::{self, tree}, model, parse};
///
/// // A slider on a rail (prismatic x) carrying a pendulum, the slider's
/// // position tied to the pendulum's angle by x' = l cos(j) j'.
/// let input: syn::DeriveInput = syn::parse_str(r#"
///     #[appell(joint(x, prismatic(x), parent = N, child = S, dependent))]
///     #[appell(joint(j, revolute(y), parent = S, child = A))]
///     #[appell(point(P = origin(A) + l * A.x), particle(P, mass = m),
///              particle(S_origin, mass = m_s))]
///     #[appell(nonholonomic(dt(x) == l * cos(j) * dt(j)))]
///     #[appell(gravity(-g * N.z))]
///     struct Tied { m: f64, m_s: f64, l: f64, g: f64 }
/// "#).unwrap();
/// let cx = Ctxt::new();
/// let ast = parse::parse(&cx, &input);
/// let kinematics = model::build(&cx, &ast).unwrap();
/// let mut derived = derivation::derive_with(&cx, kinematics, &Default::default()).unwrap();
/// cx.check().unwrap();
/// let spec = derived.model.tree.clone().unwrap();
/// assert!(spec.plain.is_err());
/// let map = derived.full.map.clone();
/// let p = tree::projected::projected(&mut derived.model, &spec, &map, &[]).unwrap();
/// // One privileged speed, j': P moves at l j' (cos j − sin j, 0, −cos j)
/// // and the slider at l j' cos j, so M = m l² ((cos j − sin j)² + cos² j)
/// // + m_s l² cos² j.
/// let at = [("m", 2.0), ("m_s", 3.0), ("l", 0.5), ("g", 9.81), ("j", 0.3), ("x", 0.1)];
/// let m = derived.model.g.eval_named(p.mass[0], &at).unwrap();
/// let (c, s) = (0.3_f64.cos(), 0.3_f64.sin());
/// let expected = 2.0 * 0.25 * ((c - s).powi(2) + c * c) + 3.0 * 0.25 * c * c;
/// assert!((m - expected).abs() < 1e-12);
/// ```
pub fn projected(
    model: &mut Model,
    spec: &TreeSpec,
    map: &SpeedMap,
    fixed: &[usize],
) -> R<Projected> {
    let (n, l) = (model.coords.len(), map.speed_rates.len());
    let parts = Parts::new(model)?;
    let g = &mut model.g;
    let driving = model.input_rates.clone();
    let rates = joint_accelerations(
        g,
        model_symbols(&model.coords, &model.inputs),
        map,
        &driving,
    )?;
    let mut at_zero = Substitution::new();
    let zero = g.int(0)?;
    for &r in fixed {
        at_zero.insert(model.coords[r].1.q, zero);
    }
    let c = at_zero.apply_all(g, &map.c)?;
    let qdot = at_zero.apply_all(g, &map.qdot)?;
    let qddot = at_zero.apply_all(g, &rates)?;
    let tree = links::links(g, spec, &parts, fixed, links::Index::Coordinates)?;
    let gravity = links::gravity(g, spec)?;
    let mut r = Recursions::new(g, &tree, gravity, n)?;
    let forces = r.newton_euler(&qdot, Some(&qddot), true)?;
    let mass_q = r.composite_rigid_body()?;
    let torques = r.inputs();
    let mut net = Vec::with_capacity(n);
    for (&tau, &force) in torques.iter().zip(&forces) {
        net.push(g.sub(tau, force)?);
    }
    Ok(Projected {
        mass: congruence(g, &c, &mass_q, n, l)?,
        forcing: transposed_product(g, &c, &net, n, l)?,
    })
}

/// The tree's equations in its own speeds u (the model's declared ones,
/// `tree_speeds`: a ball's angular velocity, the joint rates), projected
/// onto a scene's privileged speeds ẏ through u = C_u ẏ + c_u: a scene
/// speed is one of u, a dependent joint rate is its row of q̇ = C ẏ + c
/// (stage 4; under a numeric elimination its entries are X's symbols).
/// u̇ at ÿ = 0 is u's rate on the reduced system (`reduced`, where X moves
/// as w) with ÿ set to zero. M = C_uᵀ M_u C_u and f = C_uᵀ (τ − RNEA(q,
/// u, u̇)), with the energies T = ½ Σ vᵢ · Iᵢ vᵢ and the input power τ · u.
/// None when a speed of the tree is neither a scene speed nor a
/// coordinate's rate (a ball's angular velocity the scene does not keep).
pub fn in_speeds(
    model: &mut Model,
    set: &ConstraintSet,
    spec: &TreeSpec,
    map: &SpeedMap,
    reduced: &RateRules,
    tree_speeds: &[SpeedSpec],
) -> R<Option<InSpeeds>> {
    let (n, l) = (tree_speeds.len(), set.speed_specs.len());
    let parts = Parts::with_speeds(model, tree_speeds)?;
    let g = &mut model.g;
    let (zero, one) = (g.int(0)?, g.int(1)?);
    let mut c = vec![zero; n * l];
    let mut u = Vec::with_capacity(n);
    for (i, t) in tree_speeds.iter().enumerate() {
        if let Some(k) = set.speed_specs.iter().position(|s| s.name == t.name) {
            c[i * l + k] = one;
            u.push(g.sym(set.speed_specs[k].symbol)?);
        } else if let Some(r) = t.coordinate {
            c[i * l..(i + 1) * l].copy_from_slice(&map.c[r * l..(r + 1) * l]);
            u.push(map.qdot[r]);
        } else {
            return Ok(None);
        }
    }
    let mut at_rest = Substitution::new();
    for s in &set.speed_specs {
        at_rest.insert(s.accel, zero);
    }
    let rates = g.time_derivatives(&u, reduced)?;
    let u_dot = at_rest.apply_all(g, &rates)?;
    let tree = links::links(g, spec, &parts, &[], links::Index::Speeds)?;
    let gravity = links::gravity(g, spec)?;
    let (body, accels) = {
        let mut a = Algebra::new(g)?;
        let body = free::speeds_in(&mut a, &tree, &u)?;
        let accels = free::accelerations_in(&mut a, &tree, &body, &u_dot)?;
        (body, accels)
    };
    let mut r = Recursions::new(g, &tree, gravity, n)?;
    let forces = r.newton_euler(&body, Some(&accels), true)?;
    let mass_u = r.composite_rigid_body()?;
    let kinetic = r.kinetic_energy(&body)?;
    let torques = r.inputs();
    let (forces, mass_u) = {
        let mut a = Algebra::new(g)?;
        (
            free::forces_out(&mut a, &tree, &forces)?,
            free::mass_out(&mut a, &tree, &mass_u, n)?,
        )
    };
    let mut net = Vec::with_capacity(n);
    for (&tau, &force) in torques.iter().zip(&forces) {
        net.push(g.sub(tau, force)?);
    }
    let input_power = dot(g, &torques, &u)?;
    Ok(Some(InSpeeds {
        projected: Projected {
            mass: congruence(g, &c, &mass_u, n, l)?,
            forcing: transposed_product(g, &c, &net, n, l)?,
        },
        kinetic,
        input_power,
    }))
}

/// [`in_speeds`]'s output: M and f, T and the input power.
pub struct InSpeeds {
    /// M and f on the scene's speeds.
    pub projected: Projected,
    /// The kinetic energy.
    pub kinetic: Id,
    /// τ · u.
    pub input_power: Id,
}

/// The coordinates' and inputs' symbols the rates are differentiated in.
struct Symbols {
    coordinates: Vec<appell_symbolic::Symbol>,
    inputs: Vec<appell_symbolic::Symbol>,
}

fn model_symbols(
    coords: &[(syn::Ident, appell_symbolic::Coordinate)],
    inputs: &[(syn::Ident, appell_symbolic::Symbol)],
) -> Symbols {
    Symbols {
        coordinates: coords.iter().map(|(_, c)| c.q).collect(),
        inputs: inputs.iter().map(|(_, s)| *s).collect(),
    }
}

/// q̈ at ÿ = 0: Ċ ẏ + ċ, the time derivative of q̇ = C ẏ + c with the
/// coordinates moving at q̇, the speeds and inputs held, except that the
/// inputs driving constraints move at their companions' rates.
fn joint_accelerations(
    g: &mut Graph,
    symbols: Symbols,
    map: &SpeedMap,
    driving: &[(appell_symbolic::Symbol, appell_symbolic::Symbol)],
) -> R<Vec<Id>> {
    let mut rules = Model::with_input_rates(g, driving, RateRules::coordinates())?;
    for (&q, &rate) in symbols.coordinates.iter().zip(&map.qdot) {
        rules = rules.with(q, rate);
    }
    for &s in map.speed_rates.iter().chain(&symbols.inputs) {
        if !driving.iter().any(|(d, _)| *d == s) {
            rules = rules.constant(s);
        }
    }
    g.time_derivatives(&map.qdot, &rules)
}

/// Cᵀ A C for the n×n symmetric `a` and the n×l `c`, skipping zeros.
fn congruence(g: &mut Graph, c: &[Id], a: &[Id], n: usize, l: usize) -> R<Vec<Id>> {
    let mut ac = Vec::with_capacity(n * l);
    for r in 0..n {
        let row: Vec<Id> = (0..n).map(|s| a[r * n + s]).collect();
        for k in 0..l {
            let column: Vec<Id> = (0..n).map(|s| c[s * l + k]).collect();
            ac.push(dot(g, &row, &column)?);
        }
    }
    let mut out = vec![g.int(0)?; l * l];
    for i in 0..l {
        let column: Vec<Id> = (0..n).map(|r| c[r * l + i]).collect();
        for j in i..l {
            let ac_j: Vec<Id> = (0..n).map(|r| ac[r * l + j]).collect();
            out[i * l + j] = dot(g, &column, &ac_j)?;
            out[j * l + i] = out[i * l + j];
        }
    }
    Ok(out)
}

/// Cᵀ v for the n×l `c`.
fn transposed_product(g: &mut Graph, c: &[Id], v: &[Id], n: usize, l: usize) -> R<Vec<Id>> {
    (0..l)
        .map(|k| {
            let column: Vec<Id> = (0..n).map(|r| c[r * l + k]).collect();
            dot(g, &column, v)
        })
        .collect()
}

/// Σ aᵢ bᵢ over the pairs where neither is zero.
fn dot(g: &mut Graph, a: &[Id], b: &[Id]) -> R<Id> {
    let mut terms = Vec::new();
    for (&x, &y) in a.iter().zip(b) {
        if !g.is_zero(x) && !g.is_zero(y) {
            terms.push(g.mul(x, y)?);
        }
    }
    g.sum(&terms)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_congruence_skips_zeros_and_is_symmetric() {
        let mut g = Graph::new();
        let e = |g: &mut Graph, s: &str| g.parse(s).unwrap();
        // C = [[1, 0], [a, 1], [0, 0]] and A symmetric 3×3.
        let c = ["1", "0", "a", "1", "0", "0"].map(|s| e(&mut g, s));
        let a = ["p", "q", "r", "q", "s", "t", "r", "t", "w"].map(|s| e(&mut g, s));
        let m = congruence(&mut g, &c, &a, 3, 2).unwrap();
        let expected = ["p + 2*a*q + a^2*s", "q + a*s", "q + a*s", "s"];
        for (k, text) in expected.iter().enumerate() {
            let want = e(&mut g, text);
            let at = [("a", 0.3), ("p", 2.0), ("q", -0.7), ("s", 1.5), ("r", 9.0)];
            let (x, y) = (
                g.eval_named(m[k], &at).unwrap(),
                g.eval_named(want, &at).unwrap(),
            );
            assert!((x - y).abs() < 1e-14, "entry {k}: {x} against {y}");
        }
        assert_eq!(m[1], m[2]);
    }
}
