//! The world frame's candidate ([`super::super::tree::world`]): ÿ solved
//! by M's factors in the graph, the reduced rhs's columns' right sides left
//! for the emitter's loops and solved by the same factors in the graph too,
//! a free root's columns mapped back to its quaternion and slides; and the
//! world frame's derivatives of inverse dynamics.

use appell_symbolic::{Id, Symbol, SymbolicError};

use super::super::tree::world::{Accelerations, WorldDerivatives};
use super::super::Derivation;
use super::{
    budget, budgeted, derivatives, retained_rates, Columns, ScaledRow, UnsolvedColumns,
    WorldJacobian,
};
use crate::model::Model;

/// The world-frame candidate: the tree's inverse-dynamics derivatives
/// built directly ([`world_derivatives`](super::super::tree::world::world_derivatives)),
/// with ÿ solved by M's factors in the same graph, and each column's right
/// side ∂τ/∂c − ∂Q/∂c left for the emitter's loops ([`right_sides`]),
/// within the budget of a candidate differentiating the rhs's values; then,
/// within what is left of it, each column ∂ÿ/∂c = M⁻¹ (∂τ/∂c − ∂Q/∂c)
/// solved by those factors in the graph too (on a chain, by M⁻¹), or
/// `None` past it.
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
    let before = model.g.len();
    let (w, sides) = budgeted(
        model,
        |m| &mut m.g,
        allowed,
        |model| {
            let w = world_frame(model, fixed, Accelerations::Solved)?;
            let sides = right_sides(model, d, columns, &w)?;
            Ok((w, sides))
        },
    )?;
    let left = allowed.saturating_sub(model.g.len() - before);
    let derivatives = budgeted(
        model,
        |m| &mut m.g,
        left,
        |model| solved_in_graph(model, &w, &sides),
    )
    .ok();
    Ok(WorldJacobian {
        accelerations: sides.accelerations,
        derivatives,
        unsolved: sides.unsolved,
    })
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

/// A candidate's columns before their solves ([`right_sides`]).
struct RightSides {
    /// The Jacobian's columns, then each free root's four extra ones
    /// ([`quaternion_columns`]), each its l right sides in speed order.
    columns: Vec<Vec<Id>>,
    /// The reduced rhs's ÿ: the nodes', a free root's ṗ rows by s.
    accelerations: Vec<Id>,
    /// What the emitter's loops solve.
    unsolved: UnsolvedColumns,
    /// The symbols the columns are by.
    at: Symbols,
}

/// The right sides ∂τ/∂c − ∂Q/∂c of every column from the world frame's
/// `w`, the retained coordinates' rates' derivatives, and the reduced
/// rhs's ÿ; the same columns for the emitter's loops, a free root's
/// quaternion columns combined and its ṗ rows to scale after the solve.
fn right_sides(
    model: &mut Model,
    d: &Derivation,
    columns: &Columns,
    w: &WorldDerivatives,
) -> Result<RightSides, SymbolicError> {
    let factor = w
        .factor
        .as_ref()
        .ok_or_else(|| SymbolicError::DimensionMismatch {
            expected: "M's factors".to_string(),
            found: "accelerations given".to_string(),
        })?;
    let l = d.l;
    let speeds = d.map.speed_rates.clone();
    let rates = retained_rates(d);
    let g = &mut model.g;
    let derivatives = self::derivatives(g, &rates, columns)?;
    let mut sides = Vec::with_capacity(columns.len() + 4 * w.roots.len());
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
        sides.push(forcing);
    }
    // A free root's turns in the body's axes and its gravity's scale.
    for root in &w.roots {
        for &j in &root.angular {
            sides.push(negated(g, &w.by_coordinates, j)?);
        }
        let column = root.gravity.iter().map(|&x| g.neg(x));
        sides.push(column.collect::<Result<_, _>>()?);
    }
    let at = Symbols {
        coordinates: model.coords.iter().map(|c| c.1.q).collect(),
        columns: columns.all().collect(),
    };
    let mut a = super::super::tree::spatial::Algebra::new(g)?;
    let unsolved = unsolved(&mut a, &at, w, factor, &sides, derivatives)?;
    let mut accelerations = w.accelerations.clone();
    for root in &w.roots {
        for &i in &root.linear {
            accelerations[i] = a.g.mul(root.scale, accelerations[i])?;
        }
    }
    Ok(RightSides {
        columns: sides,
        accelerations,
        unsolved,
        at,
    })
}

/// The reduced rhs's rows over the columns, each column of `sides` solved
/// by M's factors in the graph after the retained coordinates' rates'
/// derivatives; a free root's columns and rows mapped back to e and ṗ
/// ([`quaternion_columns`], then its rows scaled as
/// [`UnsolvedColumns::rows`] says).
fn solved_in_graph(
    model: &mut Model,
    w: &WorldDerivatives,
    sides: &RightSides,
) -> Result<Vec<Id>, SymbolicError> {
    let factor = w.factor.as_ref().expect("factors with the right sides");
    let (l, n) = (w.accelerations.len(), sides.at.columns.len());
    let mut a = super::super::tree::spatial::Algebra::new(&mut model.g)?;
    let mut solved = sides.columns.clone();
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
    quaternion_columns(&mut a, &sides.at, w, &mut solved, &extra)?;
    for row in &sides.unsolved.rows {
        for column in solved.iter_mut() {
            column[row.speed] = a.g.mul(row.scale, column[row.speed])?;
        }
        for &(c, term) in &row.adds {
            solved[c][row.speed] = a.g.add(solved[c][row.speed], term)?;
        }
    }
    let mut derivatives = sides.unsolved.rates.clone();
    for k in 0..l {
        derivatives.extend(solved.iter().map(|column| column[k]));
    }
    Ok(derivatives)
}

/// The symbols a free root's columns are found by.
struct Symbols {
    /// The model's coordinates.
    coordinates: Vec<Symbol>,
    /// The Jacobian's columns.
    columns: Vec<Symbol>,
}

/// The columns left unsolved for the emitted code (`columns`: the
/// Jacobian's, then each free root's four extra ones, see
/// [`quaternion_columns`]), with M's factors and the rows to scale after
/// the solve.
fn unsolved(
    a: &mut super::super::tree::spatial::Algebra,
    at: &Symbols,
    w: &WorldDerivatives,
    factor: &super::super::tree::world::MassFactor,
    columns: &[Vec<Id>],
    rates: Vec<Id>,
) -> Result<UnsolvedColumns, SymbolicError> {
    let l = factor.order().len();
    let n = at.columns.len();
    let mut forcing = columns[..n].to_vec();
    // The quaternion's columns are linear in the extra ones: combined
    // before the solve, they are solved as any other.
    let quaternions = quaternion_columns(a, at, w, &mut forcing, &columns[n..])?;
    let mut rows = Vec::new();
    for (root, quaternion) in w.roots.iter().zip(&quaternions) {
        for &i in &root.linear {
            let mut adds = Vec::with_capacity(quaternion.len());
            for &(c, doubled) in quaternion {
                adds.push((c, a.g.mul(doubled, w.accelerations[i])?));
            }
            rows.push(ScaledRow {
                speed: i,
                scale: root.scale,
                adds,
            });
        }
    }
    Ok(UnsolvedColumns {
        rates,
        forcing,
        order: factor.order().to_vec(),
        lower: (0..l)
            .map(|i| (0..i).map(|k| factor.lower(i, k)).collect())
            .collect(),
        reciprocals: factor.reciprocals().to_vec(),
        rows,
    })
}

/// The quaternion's columns of `columns` (the Jacobian's) from `extra`
/// (per free root, the columns of its three turns and of its gravity's
/// scale), solved or not, since the map is linear; per root, each such
/// column with its 2 eₖ. With s = |e|², the rhs's ÿ is S ÿ' for ÿ' the
/// nodes' (S: s on ṗ's rows), which move at s ṗ under gravity s g. The
/// quaternion's columns are the turns by δθ = 2 vec(e* ⊗ δe) / s plus
/// 2 e times d/ds: dÿ'/ds = ∂ÿ'/∂(gravity's scale) / s (the speeds s ṗ
/// add nothing: ∂ÿ'/∂ṗ' is zero, a boost changing no force). S's own
/// part, after the solve, is [`ScaledRow`]'s. The columns by ṗ are zero.
fn quaternion_columns(
    a: &mut super::super::tree::spatial::Algebra,
    at: &Symbols,
    w: &WorldDerivatives,
    columns: &mut [Vec<Id>],
    extra: &[Vec<Id>],
) -> Result<Vec<Vec<(usize, Id)>>, SymbolicError> {
    let column = |s: Symbol| at.columns.iter().position(|&c| c == s);
    let l = w.accelerations.len();
    let mut out = Vec::with_capacity(w.roots.len());
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
                columns[c][i] = a.dot(terms)?;
            }
            quaternion.push((c, doubled));
        }
        out.push(quaternion);
    }
    Ok(out)
}

/// [`inverse_dynamics`]' partials by the world frame's derivatives, at the
/// acceleration symbols (a tree of one-axis joints on a fixed root), within `allowed` new
/// expressions.
pub(super) fn world_inverse_dynamics(
    model: &mut Model,
    d: &Derivation,
    allowed: usize,
) -> Result<Vec<Id>, String> {
    budgeted(
        model,
        |m| &mut m.g,
        allowed,
        |model| {
            let accels: Vec<Id> = d
                .map
                .accels
                .iter()
                .map(|&a| model.g.sym(a))
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
