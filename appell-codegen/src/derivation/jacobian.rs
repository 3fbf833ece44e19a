//! Stage 14: the derivatives of the reduced rhs with respect to the reduced
//! state x = (retained q, ẏ) and the inputs w, for the generated
//! `rhs_jacobian`.
//!
//! Four candidates, each a set of expressions in the model's graph; the
//! emitter lowers those within its size limits and keeps the one with the
//! fewest operations per call:
//!
//! - **closed**: ∂f/∂x, ∂f/∂w, ∂M/∂x (lower triangle) and ∂q̇_r/∂x. At run
//!   time ÿ = M⁻¹ f, then ∂ÿ/∂x_j = M⁻¹ (∂f/∂x_j − (∂M/∂x_j) ÿ), with M
//!   factored once for the values and every column. With a numeric
//!   elimination (S X = R and S w = r solved at run time, stage 5) the
//!   partials treat X and w as symbols, and the emitted code adds their
//!   total derivatives: ∂X/∂c = S⁻¹ (∂R/∂c − (∂S/∂c) X) and
//!   ∂w/∂c = S⁻¹ (∂r/∂c + (∂r/∂X) ∂X/∂c − (∂S/∂c) w), by S's factors.
//! - **structured**: ∂ÿ/∂x and ∂ÿ/∂w of the unrolled articulated-body
//!   algorithm's accelerations (a plain tree of joints), whose
//!   constants are folded where they are built.
//! - **inverse dynamics** (a plain tree; the shape of Carpentier and
//!   Mansard's analytical derivatives): the residual R = M ÿ + h − τ of
//!   recursive Newton–Euler differentiated with ÿ held, then evaluated at
//!   the articulated-body algorithm's ÿ; at run time
//!   ∂ÿ/∂x_j = −M⁻¹ ∂R/∂x_j with M by the composite-rigid-body algorithm,
//!   factored once. No ∂M appears: the recursion's held accelerations
//!   carry it.
//! - **world frame** (a plain tree of one-axis joints): the same
//!   derivatives of inverse dynamics built directly in the world frame
//!   (Carpentier and Mansard's algorithm unrolled, [`super::tree::world`]),
//!   ÿ solved from M = Jᵀ Yᶜ J by its factors in the graph, and each
//!   column ∂ÿ/∂c = M⁻¹ (∂τ/∂c − ∂Q/∂c) there too: one program.
//!
//! Each derivative is [`Graph::diff`](appell_symbolic::Graph::diff), which
//! visits only the subexpressions that depend on the symbol: a joint's
//! coordinate reaches only the links after it. A candidate whose
//! derivatives would add more than [`GROWTH_LIMIT`] times the graph's
//! nodes at the start, or that fails (a function without a derivative),
//! is left out with the reason.

use appell_symbolic::{Graph, Id, Symbol, SymbolicError};

use super::tree::world::{Accelerations, WorldDerivatives};
use super::Derivation;
use crate::model::Model;

/// The most nodes a candidate's derivatives may add, as a multiple of the
/// graph's nodes before them, for a model that asks for its Jacobian
/// (`jacobian(on)`).
pub const GROWTH_LIMIT: usize = 2;

/// The most expressions a Jacobian written by default may have, as a
/// multiple of the values it differentiates (q̇ and ÿ, or M, f and q̇, and
/// a numeric elimination's S, R and right side): beyond it the generated
/// code would grow past about twice the model's. The emitter writes none
/// larger, and stage 14 stops a candidate whose derivatives add three
/// times as many nodes.
pub const SIZE_LIMIT: usize = 4;

/// The symbols the Jacobian's columns differentiate by: the reduced state
/// (retained coordinates, then the privileged speeds), then the model's
/// inputs (a scene takes those of its loads; the emitter picks their
/// columns by symbol).
#[derive(Clone, Debug)]
pub struct Columns {
    /// The state's symbols, in state order.
    pub state: Vec<Symbol>,
    /// The model's inputs, in declaration order.
    pub inputs: Vec<Symbol>,
}

impl Columns {
    /// Every column's symbol: the state's, then the inputs'.
    pub fn all(&self) -> impl Iterator<Item = Symbol> + '_ {
        self.state.iter().chain(&self.inputs).copied()
    }

    /// The number of columns.
    pub fn len(&self) -> usize {
        self.state.len() + self.inputs.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The closed form's derivatives, one entry per column of [`Columns`].
#[derive(Clone, Debug)]
pub struct ClosedJacobian {
    /// ∂f_k/∂c, l rows, row-major over the columns.
    pub forcing: Vec<Id>,
    /// ∂M/∂c per column: M's lower triangle (row i, j ≤ i) in row order.
    pub mass: Vec<Vec<Id>>,
    /// ∂q̇_r/∂c for each retained coordinate r, row-major over the columns.
    pub rates: Vec<Id>,
    /// With a numeric elimination, the partials its total derivatives
    /// need.
    pub numeric: Option<NumericPartials>,
}

/// The partial derivatives of a numeric elimination's expressions, X and w
/// held as symbols. X's symbols are those of R's non-zero columns, row by
/// row (x_i,j for j in `columns`), nx of them.
#[derive(Clone, Debug)]
pub struct NumericPartials {
    /// ∂S/∂c per column (k×k).
    pub s: Vec<Vec<Id>>,
    /// ∂R/∂c per column, k × the non-zero columns.
    pub r: Vec<Vec<Id>>,
    /// ∂r/∂c per column (k), r the right side of S w = r.
    pub rate: Vec<Vec<Id>>,
    /// ∂r/∂X, k × nx.
    pub rate_x: Vec<Id>,
    /// ∂e/∂X (nx each) for each of the closed form's values e: M's lower
    /// triangle, f, the retained rates, in that order.
    pub values_x: Vec<Id>,
    /// ∂e/∂w (k each) for the same values.
    pub values_w: Vec<Id>,
}

/// The inverse-dynamics candidate's values and derivatives, one entry per
/// column of [`Columns`] in each row.
#[derive(Clone, Debug)]
pub struct RecursiveJacobian {
    /// M by the composite-rigid-body algorithm: its lower triangle (row i,
    /// j ≤ i) in row order.
    pub mass: Vec<Id>,
    /// ÿ by the articulated-body algorithm.
    pub accelerations: Vec<Id>,
    /// −∂R/∂c = ∂τ/∂c − ∂(M ÿ + h)/∂c at those ÿ, l rows, row-major over
    /// the columns.
    pub forcing: Vec<Id>,
    /// ∂q̇_r/∂c for each retained coordinate r, row-major over the columns.
    pub rates: Vec<Id>,
}

/// The world-frame candidate (a tree of one-axis joints; Carpentier and
/// Mansard's derivatives of recursive Newton–Euler unrolled): ÿ solved by
/// M's factors, and the reduced rhs's derivatives.
#[derive(Clone, Debug)]
pub struct WorldJacobian {
    /// ÿ = M⁻¹ (τ − h), M by the subtrees' inertias.
    pub accelerations: Vec<Id>,
    /// Rows: the retained coordinates' rates, then ÿ; row-major over the
    /// columns.
    pub derivatives: Vec<Id>,
}

/// The derivatives of the reduced rhs (stage 14), and why a candidate is
/// missing.
#[derive(Clone, Debug)]
pub struct Jacobians {
    /// What the columns differentiate by.
    pub columns: Columns,
    /// The closed form's candidate, or why there is none.
    pub closed: Result<ClosedJacobian, String>,
    /// The structured form's candidate (rows: the retained coordinates'
    /// rates, then ÿ; row-major over the columns), or why there is none.
    pub structured: Result<Vec<Id>, String>,
    /// The inverse-dynamics candidate, or why there is none.
    pub recursive: Result<RecursiveJacobian, String>,
    /// The world frame's candidate (a tree of one-axis joints), or why
    /// there is none.
    pub world: Result<WorldJacobian, String>,
    /// For a tree's recursive Newton–Euler inverse dynamics Q(q, u, ÿ):
    /// ∂Q/∂q (l rows, one column per coordinate) then ∂Q/∂u (l × l), each
    /// row-major; or why there is none (set by [`inverse_dynamics`]).
    pub inverse: Result<Vec<Id>, String>,
}

impl Jacobians {
    /// No candidate, for `reason` (a model whose derivatives are off).
    pub fn none(columns: Columns, reason: &str) -> Jacobians {
        Jacobians {
            columns,
            closed: Err(reason.to_string()),
            structured: Err(reason.to_string()),
            recursive: Err(reason.to_string()),
            world: Err(reason.to_string()),
            inverse: Err(reason.to_string()),
        }
    }
}

/// The rates q̇_r of `d`'s retained coordinates, in state order: the rows
/// of the Jacobian before ÿ's.
pub fn retained_rates(d: &Derivation) -> Vec<Id> {
    d.reduction
        .retained
        .iter()
        .map(|&r| d.map.qdot[r])
        .collect()
}

/// The lower triangle (row i, j ≤ i, in row order) of the l×l row-major
/// `m`.
pub fn lower_triangle(m: &[Id], l: usize) -> Vec<Id> {
    (0..l)
        .flat_map(|i| (0..=i).map(move |j| m[i * l + j]))
        .collect()
}

/// The columns of `d`'s Jacobian in `model` as it stands (a scene's speeds
/// in place).
pub fn columns(model: &Model, d: &Derivation) -> Columns {
    let state = d
        .reduction
        .retained
        .iter()
        .map(|&r| model.coords[r].1.q)
        .chain(model.speed_specs.iter().map(|s| s.symbol))
        .collect();
    let inputs = model.inputs.iter().map(|(_, s)| *s).collect();
    Columns { state, inputs }
}

/// Stage 14: both candidates' derivatives of `d` (none where the model
/// says `jacobian(off)`).
pub fn differentiate(model: &mut Model, d: &Derivation) -> Jacobians {
    let columns = columns(model, d);
    if model.jacobian == Some(false) {
        return Jacobians::none(columns, "turned off by `jacobian(off)`");
    }
    let forced = model.jacobian == Some(true);
    let g = &mut model.g;
    let closed = closed(g, d, &columns, forced);
    let structured = match &d.structured {
        Ok(s) => {
            let mut roots = retained_rates(d);
            roots.extend(&s.accelerations);
            let allowed = budget(g, &roots, forced);
            within_budget(g, allowed, |g| derivatives(g, &roots, &columns))
        }
        Err(_) => Err("no structured form".to_string()),
    };
    let recursive = match &d.structured {
        Ok(s) => recursive(model, d, &s.accelerations, &columns, forced),
        Err(_) => Err("no structured form".to_string()),
    };
    let world = world(model, d, &columns, forced);
    Jacobians {
        columns,
        closed,
        structured,
        recursive,
        world,
        inverse: Err("not asked for".to_string()),
    }
}

/// The inverse-dynamics candidate: the residual's derivatives with ÿ held
/// ([`Graph::diff_held`]), then ÿ put in as the articulated-body
/// algorithm's `accelerations` (held, so that no product multiplies them
/// out).
fn recursive(
    model: &mut Model,
    d: &Derivation,
    accelerations: &[Id],
    columns: &Columns,
    forced: bool,
) -> Result<RecursiveJacobian, String> {
    let spec = model.tree.clone()?;
    let residual = super::tree::residual(model, &spec, &d.reduction.ignorable)
        .map_err(|e| format!("the residual failed: {e}"))?;
    let accels: Vec<Symbol> = model.speed_specs.iter().map(|s| s.accel).collect();
    let rates = retained_rates(d);
    let mass = lower_triangle(&residual.mass, d.l);
    let g = &mut model.g;
    let mut values = residual.inverse.clone();
    values.extend(&mass);
    let allowed = budget(g, &values, forced);
    within_budget(g, allowed, |g| {
        let forcing: Vec<Id> = residual
            .inputs
            .iter()
            .zip(&residual.inverse)
            .map(|(&tau, &id)| g.sub(tau, id))
            .collect::<Result<_, _>>()?;
        // Held derivatives: the recursion's velocities, accelerations and
        // forces stay single factors in their derivatives too.
        let partials = derivatives_by(g, &forcing, columns, Graph::diff_held)?;
        let mut at = appell_symbolic::Substitution::new();
        for (&s, &a) in accels.iter().zip(accelerations) {
            at.insert(s, g.hold(a)?);
        }
        Ok(RecursiveJacobian {
            mass,
            accelerations: accelerations.to_vec(),
            forcing: at.apply_all(g, &partials)?,
            rates: derivatives(g, &rates, columns)?,
        })
    })
}

/// The world-frame candidate: the tree's inverse-dynamics derivatives
/// built directly ([`world_derivatives`](super::tree::world::world_derivatives)),
/// with ÿ solved by M's factors in the same graph, and each column
/// ∂ÿ/∂c = M⁻¹ (∂τ/∂c − ∂Q/∂c) by those factors (on a chain, by M⁻¹).
/// Within the budget of a candidate differentiating the rhs's values.
fn world(
    model: &mut Model,
    d: &Derivation,
    columns: &Columns,
    forced: bool,
) -> Result<WorldJacobian, String> {
    let Ok(s) = &d.structured else {
        return Err("no structured form".to_string());
    };
    super::tree::world::single_axis(model.tree.as_ref()?)?;
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
/// `fixed` at zero, or why there are none (a joint of more than one axis).
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
    super::tree::world::world_derivatives(model, &spec, fixed, at)
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
    for c in columns.all() {
        let mut forcing = Vec::with_capacity(l);
        for k in 0..l {
            let entry = if let Some(j) = speeds.iter().position(|&s| s == c) {
                g.neg(w.by_speeds[k * l + j])?
            } else if let Some(r) = model.coords.iter().position(|x| x.1.q == c) {
                match w.coordinates.iter().position(|&x| x == Some(r)) {
                    Some(j) => g.neg(w.by_coordinates[k * l + j])?,
                    None => g.int(0)?,
                }
            } else {
                g.diff(w.inputs[k], c)?
            };
            forcing.push(entry);
        }
        solved.push(forcing);
    }
    // A free root's turns in the body's axes and its gravity's scale.
    for root in &w.roots {
        for &j in &root.angular {
            let column = (0..l).map(|k| g.neg(w.by_coordinates[k * l + j]));
            solved.push(column.collect::<Result<_, _>>()?);
        }
        let column = root.gravity.iter().map(|&x| g.neg(x));
        solved.push(column.collect::<Result<_, _>>()?);
    }
    let mut a = super::tree::spatial::Algebra::new(g)?;
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
    let at = Roots {
        speeds: &speeds,
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
    })
}

/// The symbols a free root's columns are found by.
struct Roots<'a> {
    speeds: &'a [Symbol],
    coordinates: &'a [Symbol],
    columns: &'a [Symbol],
}

/// The reduced rhs's columns and accelerations from the nodes' (`solved`,
/// in the Jacobian's columns; `extra`, per free root, its three turns and
/// its gravity's scale): with s = |e|², the rhs's ÿ is S ÿ' for ÿ' the
/// nodes' (S: s on ṗ's rows), which move at s ṗ under gravity s g. So
/// ∂/∂ṗ is s ∂/∂ṗ', and the quaternion's columns are the turns by
/// δθ = 2 vec(e* ⊗ δe) / s plus 2 e times d/ds, where
/// dÿ'/ds = Σ ∂ÿ'/∂ṗ' ṗ + ∂ÿ'/∂(gravity's scale) / s, and S's own
/// derivative adds ÿ' on ṗ's rows.
fn free_roots(
    a: &mut super::tree::spatial::Algebra,
    at: &Roots,
    w: &WorldDerivatives,
    solved: &mut [Vec<Id>],
    extra: &[Vec<Id>],
    accelerations: &mut [Id],
) -> Result<(), SymbolicError> {
    let column = |s: Symbol| at.columns.iter().position(|&c| c == s);
    let l = accelerations.len();
    for (root, extra) in w.roots.iter().zip(extra.chunks(4)) {
        let linear: Vec<Option<usize>> =
            root.linear.iter().map(|&j| column(at.speeds[j])).collect();
        // dÿ'/ds.
        let mut radial = Vec::with_capacity(l);
        let over = a.g.recip(root.scale)?;
        for i in 0..l {
            let mut terms = vec![(extra[3][i], over)];
            for (k, &c) in linear.iter().enumerate() {
                if let Some(c) = c {
                    terms.push((solved[c][i], a.g.sym(at.speeds[root.linear[k]])?));
                }
            }
            let sum = a.dot(terms)?;
            radial.push(a.g.hold(sum)?);
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
            let scale = a.g.mul(two, root.e[k])?;
            for i in 0..l {
                let mut terms: Vec<(Id, Id)> = (0..3).map(|m| (weights[m], extra[m][i])).collect();
                terms.push((scale, radial[i]));
                solved[c][i] = a.dot(terms)?;
            }
            quaternion.push((c, scale));
        }
        for c in linear.into_iter().flatten() {
            for x in solved[c].iter_mut() {
                *x = a.g.mul(root.scale, *x)?;
            }
        }
        // S on ṗ's rows, and S's derivative on the quaternion's columns.
        for &i in &root.linear {
            for column in solved.iter_mut() {
                column[i] = a.g.mul(root.scale, column[i])?;
            }
            for &(c, scale) in &quaternion {
                let from_s = a.g.mul(scale, accelerations[i])?;
                solved[c][i] = a.g.add(solved[c][i], from_s)?;
            }
            accelerations[i] = a.g.mul(root.scale, accelerations[i])?;
        }
    }
    Ok(())
}

/// The derivatives of a tree's inverse dynamics Q(q, u, ÿ) by every
/// coordinate, then every privileged speed (∂Q/∂ÿ is M), for the generated
/// `inverse_dynamics_derivatives`: recursive Newton–Euler differentiated,
/// or the world frame's derivatives where those have fewer expressions,
/// each within the same budget as the rhs's.
pub fn inverse_dynamics(model: &mut Model, d: &Derivation) -> Result<Vec<Id>, String> {
    if model.jacobian == Some(false) {
        return Err("turned off by `jacobian(off)`".to_string());
    }
    let Ok(s) = &d.structured else {
        return Err("no structured form".to_string());
    };
    let columns = Columns {
        state: model
            .coords
            .iter()
            .map(|c| c.1.q)
            .chain(model.speed_specs.iter().map(|s| s.symbol))
            .collect(),
        inputs: Vec::new(),
    };
    let forced = model.jacobian == Some(true);
    let g = &mut model.g;
    let allowed = budget(g, &s.inverse, forced);
    let differentiated = within_budget(g, allowed, |g| derivatives(g, &s.inverse, &columns));
    let Ok(world) = world_inverse_dynamics(model, allowed) else {
        return differentiated;
    };
    // The one with fewer expressions beside Q's.
    let size = |g: &Graph, partials: &[Id]| {
        let mut roots = s.inverse.clone();
        roots.extend(partials);
        g.dag_size(&roots)
    };
    match differentiated {
        Ok(p) if size(&model.g, &p) <= size(&model.g, &world) => Ok(p),
        _ => Ok(world),
    }
}

/// [`inverse_dynamics`]' partials by the world frame's derivatives, at the
/// acceleration symbols (a tree of one-axis joints), within `allowed` new
/// expressions.
fn world_inverse_dynamics(model: &mut Model, allowed: usize) -> Result<Vec<Id>, String> {
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

/// The closed form's derivatives.
fn closed(
    g: &mut Graph,
    d: &Derivation,
    columns: &Columns,
    forced: bool,
) -> Result<ClosedJacobian, String> {
    let lower = lower_triangle(&d.equations.mass, d.l);
    let rates = retained_rates(d);
    let mut values: Vec<Id> = lower
        .iter()
        .chain(&d.equations.forcing)
        .chain(&rates)
        .copied()
        .collect();
    if let super::Elimination::Numeric(ne) = &d.elimination {
        values.extend(ne.expressions());
    }
    let allowed = budget(g, &values, forced);
    within_budget(g, allowed, |g| {
        let forcing = derivatives(g, &d.equations.forcing, columns)?;
        let rate_partials = derivatives(g, &rates, columns)?;
        let per_column = derivatives(g, &lower, columns)?;
        let n = columns.len();
        let mass = (0..n)
            .map(|c| (0..lower.len()).map(|e| per_column[e * n + c]).collect())
            .collect();
        let numeric = match &d.elimination {
            super::Elimination::Numeric(ne) => {
                let values: Vec<Id> = lower
                    .iter()
                    .chain(&d.equations.forcing)
                    .chain(&rates)
                    .copied()
                    .collect();
                Some(numeric_partials(g, ne, d.l, &values, columns)?)
            }
            super::Elimination::Symbolic => None,
        };
        Ok(ClosedJacobian {
            forcing,
            mass,
            rates: rate_partials,
            numeric,
        })
    })
}

/// The partials of a numeric elimination's S, R and r, and of `values`
/// with respect to X and w.
fn numeric_partials(
    g: &mut Graph,
    ne: &super::NumericElimination,
    l: usize,
    values: &[Id],
    columns: &Columns,
) -> Result<NumericPartials, SymbolicError> {
    let k = ne.k;
    let used: Vec<usize> = (0..k)
        .flat_map(|i| ne.columns.iter().map(move |&j| i * (l + 1) + j))
        .collect();
    let r_used: Vec<Id> = used.iter().map(|&e| ne.r[e]).collect();
    let x: Vec<Symbol> = used.iter().map(|&e| ne.x[e]).collect();
    let per_column = |g: &mut Graph, roots: &[Id]| -> Result<Vec<Vec<Id>>, SymbolicError> {
        let all = derivatives(g, roots, columns)?;
        let n = columns.len();
        Ok((0..n)
            .map(|c| (0..roots.len()).map(|e| all[e * n + c]).collect())
            .collect())
    };
    let by = |g: &mut Graph, roots: &[Id], symbols: &[Symbol]| -> Result<Vec<Id>, SymbolicError> {
        let mut out = Vec::with_capacity(roots.len() * symbols.len());
        for &e in roots {
            for &s in symbols {
                out.push(g.diff(e, s)?);
            }
        }
        Ok(out)
    };
    Ok(NumericPartials {
        s: per_column(g, &ne.s)?,
        r: per_column(g, &r_used)?,
        rate: per_column(g, &ne.rhs_rate)?,
        rate_x: by(g, &ne.rhs_rate, &x)?,
        values_x: by(g, values, &x)?,
        values_w: by(g, values, &ne.w)?,
    })
}

/// ∂root/∂c for every root and column, row-major (one row per root).
fn derivatives(g: &mut Graph, roots: &[Id], columns: &Columns) -> Result<Vec<Id>, SymbolicError> {
    derivatives_by(g, roots, columns, Graph::diff)
}

/// [`derivatives`] taken by `diff` ([`Graph::diff`] or
/// [`Graph::diff_held`]).
fn derivatives_by(
    g: &mut Graph,
    roots: &[Id],
    columns: &Columns,
    diff: fn(&mut Graph, Id, Symbol) -> Result<Id, SymbolicError>,
) -> Result<Vec<Id>, SymbolicError> {
    let mut out = Vec::with_capacity(roots.len() * columns.len());
    for &root in roots {
        for s in columns.all() {
            out.push(diff(g, root, s)?);
        }
    }
    Ok(out)
}

/// `build`'s result, or why it is left out: an error, or more new nodes
/// than [`GROWTH_LIMIT`] allows, which stops it there (the graph's node
/// limit is lowered while it runs; what it built stays, and nothing
/// reaches it).
fn within_budget<T>(
    g: &mut Graph,
    allowed: usize,
    build: impl FnOnce(&mut Graph) -> Result<T, SymbolicError>,
) -> Result<T, String> {
    budgeted(g, |g| g, allowed, build)
}

/// [`within_budget`] for a `build` that needs more than the graph (`cx`,
/// whose graph `graph` reaches).
fn budgeted<C, T>(
    cx: &mut C,
    graph: impl Fn(&mut C) -> &mut Graph,
    allowed: usize,
    build: impl FnOnce(&mut C) -> Result<T, SymbolicError>,
) -> Result<T, String> {
    let g = graph(cx);
    let (before, limits) = (g.len(), g.limits());
    let cap = limits.max_nodes.min(before + allowed);
    g.set_limits(appell_symbolic::Limits {
        max_nodes: cap,
        ..limits
    });
    let built = build(cx);
    graph(cx).set_limits(limits);
    match built {
        Ok(b) => Ok(b),
        Err(SymbolicError::NodeLimit { limit }) if limit == cap && cap < limits.max_nodes => {
            Err(format!(
                "its derivatives would add more than {allowed} expressions (`jacobian(on)` allows {GROWTH_LIMIT} times the model's {before})"
            ))
        }
        Err(e) => Err(format!("differentiating failed: {e}")),
    }
}

/// The new nodes a candidate differentiating `values` may add: three
/// times [`SIZE_LIMIT`] times their expressions, or with `jacobian(on)`
/// [`GROWTH_LIMIT`] times the graph.
fn budget(g: &Graph, values: &[Id], forced: bool) -> usize {
    if forced {
        GROWTH_LIMIT * g.len().max(10_000)
    } else {
        // New nodes include intermediates the canonical forms then drop:
        // the emitter's count of the derivatives decides; this only stops
        // a candidate far past it.
        3 * SIZE_LIMIT * g.dag_size(values).max(100)
    }
}

#[cfg(test)]
mod tests {
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
        let accels: Vec<Symbol> = derived.model.speed_specs.iter().map(|s| s.accel).collect();
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
        let mut derived = derive_source(FREE_BASE);
        let j = differentiate(&mut derived.model, &derived.full);
        let world = j.world.expect("the world frame's candidate");
        let d = &derived.full;
        let s = d.structured.as_ref().expect("a structured form");
        let mut roots = retained_rates(d);
        roots.extend(&s.accelerations);
        let expected = derivatives(&mut derived.model.g, &roots, &j.columns).expect("diff");
        assert_eq!(expected.len(), world.derivatives.len());
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
            for (k, (&ours, &theirs)) in
                world.accelerations.iter().zip(&s.accelerations).enumerate()
            {
                let (a, b) = (value(ours), value(theirs));
                assert!(
                    (a - b).abs() < 1e-10 * (1.0 + b.abs()),
                    "ÿ[{k}]: {a} vs {b}"
                );
            }
            let n = j.columns.len();
            for (k, (&ours, &theirs)) in world.derivatives.iter().zip(&expected).enumerate() {
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
}
