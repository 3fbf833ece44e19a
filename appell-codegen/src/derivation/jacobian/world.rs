//! The world frame's candidate ([`super::super::tree::world`]): ÿ and the
//! reduced rhs's columns solved by M's factors in the graph, a free root's
//! columns mapped back to its quaternion and slides; and the world frame's
//! derivatives of inverse dynamics.

use appell_symbolic::{Id, Symbol, SymbolicError};

use super::super::tree::world::{Accelerations, WorldDerivatives};
use super::super::Derivation;
use super::{
    budget, budgeted, derivatives, retained_rates, Columns, UnsolvedColumns, WorldJacobian,
};
use crate::model::Model;

/// The world-frame candidate: the tree's inverse-dynamics derivatives
/// built directly ([`world_derivatives`](super::super::tree::world::world_derivatives)),
/// with ÿ solved by M's factors in the same graph, and each column
/// ∂ÿ/∂c = M⁻¹ (∂τ/∂c − ∂Q/∂c) by those factors (on a chain, by M⁻¹).
/// Within the budget of a candidate differentiating the rhs's values.
pub(super) fn world(
    model: &mut Model,
    d: &Derivation,
    columns: &Columns,
    forced: bool,
) -> Result<WorldJacobian, String> {
    let Ok(s) = &d.structured else {
        return Err("no structured form".to_string());
    };
    super::super::tree::world::single_axis(model.tree.as_ref()?)?;
    let mut values = retained_rates(d);
    values.extend(&s.accelerations);
    let allowed = budget(&model.g, &values, forced);
    let fixed = &d.reduction.ignorable;
    budgeted(
        model,
        |m| &mut m.g,
        allowed,
        |model| {
            let w = world_frame(model, fixed, Accelerations::Solved)?;
            world_columns(model, d, columns, &w)
        },
    )
}

/// The world frame's derivatives of `model`'s tree, the coordinates
/// `fixed` at zero, or why there are none (a joint of more than one axis
/// below the root; a free root with the accelerations given).
fn world_frame(
    model: &mut Model,
    fixed: &[usize],
    at: Accelerations,
) -> Result<WorldDerivatives, SymbolicError> {
    let spec = model
        .tree
        .clone()
        .map_err(|why| SymbolicError::DimensionMismatch {
            expected: "a tree of joints".to_string(),
            found: why,
        })?;
    super::super::tree::world::world_derivatives(model, &spec, fixed, at)
}

/// The reduced rhs's rows and columns from the world frame's `w`: each
/// column's ∂τ/∂c − ∂Q/∂c solved by M's factors, after the retained
/// coordinates' rates' derivatives; a free root's columns and rows mapped
/// back to e and ṗ ([`free_roots`]).
fn world_columns(
    model: &mut Model,
    d: &Derivation,
    columns: &Columns,
    w: &WorldDerivatives,
) -> Result<WorldJacobian, SymbolicError> {
    let factor = w
        .factor
        .as_ref()
        .ok_or_else(|| SymbolicError::DimensionMismatch {
            expected: "M's factors".to_string(),
            found: "accelerations given".to_string(),
        })?;
    let (l, n) = (d.l, columns.len());
    let speeds: Vec<Symbol> = model.speed_specs.iter().map(|s| s.symbol).collect();
    let rates = retained_rates(d);
    let g = &mut model.g;
    let mut derivatives = self::derivatives(g, &rates, columns)?;
    let mut solved = Vec::with_capacity(n + 4 * w.roots.len());
    // −∂Q/∂c as the l entries of column j of the l×l matrix `m`.
    let negated =
        |g: &mut appell_symbolic::Graph, m: &[Id], j: usize| -> Result<Vec<Id>, SymbolicError> {
            (0..l).map(|k| g.neg(m[k * l + j])).collect()
        };
    for c in columns.all() {
        let forcing = if let Some(j) = speeds.iter().position(|&s| s == c) {
            negated(g, &w.by_speeds, j)?
        } else if let Some(r) = model.coords.iter().position(|x| x.1.q == c) {
            match w.coordinates.iter().position(|&x| x == Some(r)) {
                Some(j) => negated(g, &w.by_coordinates, j)?,
                None => vec![g.int(0)?; l],
            }
        } else {
            let inputs = w.inputs.iter().map(|&tau| g.diff(tau, c));
            inputs.collect::<Result<_, _>>()?
        };
        solved.push(forcing);
    }
    // A free root's turns in the body's axes and its gravity's scale.
    for root in &w.roots {
        for &j in &root.angular {
            solved.push(negated(g, &w.by_coordinates, j)?);
        }
        let column = root.gravity.iter().map(|&x| g.neg(x));
        solved.push(column.collect::<Result<_, _>>()?);
    }
    let unsolved = w.roots.is_empty().then(|| {
        let l = factor.order().len();
        UnsolvedColumns {
            rates: derivatives.clone(),
            forcing: solved.clone(),
            order: factor.order().to_vec(),
            lower: (0..l)
                .map(|i| (0..i).map(|k| factor.lower(i, k)).collect())
                .collect(),
            reciprocals: factor.reciprocals().to_vec(),
        }
    });
    let mut a = super::super::tree::spatial::Algebra::new(g)?;
    if factor.is_dense() {
        // A chain: each column M⁻¹ b by M⁻¹ formed once (its columns are
        // ∂ÿ/∂τ where the joints are driven) costs what a solve does, and
        // the driven joints' columns come for free.
        let inverse = factor.inverse(&mut a)?;
        for column in solved.iter_mut() {
            let mut out = Vec::with_capacity(l);
            for k in 0..l {
                out.push(a.dot((0..l).map(|j| (inverse[k * l + j], column[j])))?);
            }
            *column = out;
        }
    } else {
        // A branching tree: solves by the factors, whose zeros they skip.
        for column in solved.iter_mut() {
            *column = factor.solve(&mut a, column)?;
        }
    }
    let extra = solved.split_off(n);
    let symbols: Vec<Symbol> = columns.all().collect();
    let mut accelerations = w.accelerations.clone();
    let coords: Vec<Symbol> = model.coords.iter().map(|c| c.1.q).collect();
    let at = Symbols {
        coordinates: &coords,
        columns: &symbols,
    };
    free_roots(&mut a, &at, w, &mut solved, &extra, &mut accelerations)?;
    for k in 0..l {
        derivatives.extend(solved.iter().map(|column| column[k]));
    }
    Ok(WorldJacobian {
        accelerations,
        derivatives,
        unsolved,
    })
}

/// The symbols a free root's columns are found by.
struct Symbols<'a> {
    coordinates: &'a [Symbol],
    columns: &'a [Symbol],
}

/// The reduced rhs's columns and accelerations from the nodes' (`solved`,
/// in the Jacobian's columns; `extra`, per free root, its three turns and
/// its gravity's scale): with s = |e|², the rhs's ÿ is S ÿ' for ÿ' the
/// nodes' (S: s on ṗ's rows), which move at s ṗ under gravity s g. The
/// quaternion's columns are the turns by δθ = 2 vec(e* ⊗ δe) / s plus
/// 2 e times d/ds: dÿ'/ds = ∂ÿ'/∂(gravity's scale) / s (the speeds s ṗ
/// add nothing: ∂ÿ'/∂ṗ' is zero, a boost changing no force), and S's own
/// derivative adds ÿ' on ṗ's rows. The columns by ṗ are zero.
fn free_roots(
    a: &mut super::super::tree::spatial::Algebra,
    at: &Symbols,
    w: &WorldDerivatives,
    solved: &mut [Vec<Id>],
    extra: &[Vec<Id>],
    accelerations: &mut [Id],
) -> Result<(), SymbolicError> {
    let column = |s: Symbol| at.columns.iter().position(|&c| c == s);
    let l = accelerations.len();
    for (root, extra) in w.roots.iter().zip(extra.chunks(4)) {
        // dÿ'/ds.
        let over = a.g.recip(root.scale)?;
        let mut radial = Vec::with_capacity(l);
        for &x in &extra[3] {
            let scaled = a.g.mul(x, over)?;
            radial.push(a.g.hold(scaled)?);
        }
        let two = a.g.int(2)?;
        let twice = a.g.mul(two, over)?;
        let twice = a.g.hold(twice)?;
        let (e0, v) = (root.e[0], [root.e[1], root.e[2], root.e[3]]);
        let mut quaternion = Vec::new();
        for (k, &r) in root.quaternion.iter().enumerate() {
            let Some(c) = column(at.coordinates[r]) else {
                continue;
            };
            // δθ for δe along e_k: vec(e* ⊗ δe) = e₀ δv − δe₀ v − v × δv.
            let turn = if k == 0 {
                [a.g.neg(v[0])?, a.g.neg(v[1])?, a.g.neg(v[2])?]
            } else {
                let mut u = [a.zero(); 3];
                u[k - 1] = a.g.int(1)?;
                let along = a.scale(u, e0)?;
                let across = a.cross(v, u)?;
                a.sub(along, across)?
            };
            let weights: Vec<Id> = turn
                .iter()
                .map(|&x| a.g.mul(twice, x))
                .collect::<Result<_, _>>()?;
            let doubled = a.g.mul(two, root.e[k])?;
            for i in 0..l {
                let mut terms: Vec<(Id, Id)> = (0..3).map(|m| (weights[m], extra[m][i])).collect();
                terms.push((doubled, radial[i]));
                solved[c][i] = a.dot(terms)?;
            }
            quaternion.push((c, doubled));
        }
        // S on ṗ's rows, and S's derivative on the quaternion's columns.
        for &i in &root.linear {
            for column in solved.iter_mut() {
                column[i] = a.g.mul(root.scale, column[i])?;
            }
            for &(c, doubled) in &quaternion {
                let from_s = a.g.mul(doubled, accelerations[i])?;
                solved[c][i] = a.g.add(solved[c][i], from_s)?;
            }
            accelerations[i] = a.g.mul(root.scale, accelerations[i])?;
        }
    }
    Ok(())
}

/// [`inverse_dynamics`]' partials by the world frame's derivatives, at the
/// acceleration symbols (a tree of one-axis joints on a fixed root), within `allowed` new
/// expressions.
pub(super) fn world_inverse_dynamics(model: &mut Model, allowed: usize) -> Result<Vec<Id>, String> {
    budgeted(
        model,
        |m| &mut m.g,
        allowed,
        |model| {
            let accels: Vec<Id> = model
                .speed_specs
                .iter()
                .map(|s| model.g.sym(s.accel))
                .collect::<Result<_, _>>()?;
            let w = world_frame(model, &[], Accelerations::At(&accels))?;
            let (n, l) = (model.coords.len(), w.coordinates.len());
            let zero = model.g.int(0)?;
            let mut out = Vec::with_capacity(l * (n + l));
            for i in 0..l {
                for r in 0..n {
                    out.push(match w.coordinates.iter().position(|&x| x == Some(r)) {
                        Some(j) => w.by_coordinates[i * l + j],
                        None => zero,
                    });
                }
                out.extend(&w.by_speeds[i * l..(i + 1) * l]);
            }
            Ok(out)
        },
    )
}
