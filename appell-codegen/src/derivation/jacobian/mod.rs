//! Stage 14: the derivatives of the reduced rhs with respect to the reduced
//! state x = (retained q, ẏ) and the inputs w, for the generated
//! `rhs_jacobian`.
//!
//! Four candidates, each a set of expressions in the model's graph (the
//! world frame's in two forms); the emitter lowers those within its size
//! limits and keeps the one of the lowest estimated cost per call:
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
//! - **world frame** (a plain tree of one-axis joints, on a fixed or a
//!   free base): the same
//!   derivatives of inverse dynamics built directly in the world frame
//!   (Carpentier and Mansard's algorithm unrolled, [`super::tree::world`]),
//!   ÿ solved from M = Jᵀ Yᶜ J by its factors in the graph, and each
//!   column ∂ÿ/∂c = M⁻¹ (∂τ/∂c − ∂Q/∂c) there too (one program), or each
//!   column's right side ∂τ/∂c − ∂Q/∂c left with M's factors for the
//!   emitted code to solve in loops over the columns.
//!
//! Each derivative is [`Graph::diff`](appell_symbolic::Graph::diff), which
//! visits only the subexpressions that depend on the symbol: a joint's
//! coordinate reaches only the links after it. A candidate whose
//! derivatives would add more than [`GROWTH_LIMIT`] times the graph's
//! nodes at the start, or that fails (a function without a derivative),
//! is left out with the reason.

use appell_symbolic::{Graph, Id, Symbol, SymbolicError};

use super::Derivation;
use crate::model::Model;
use world::{world, world_inverse_dynamics};

mod world;

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

/// The world-frame candidate (a tree of one-axis joints, on a fixed or a
/// free root; Carpentier and Mansard's derivatives of recursive
/// Newton–Euler unrolled): ÿ solved by M's factors, and the reduced rhs's
/// derivatives.
#[derive(Clone, Debug)]
pub struct WorldJacobian {
    /// ÿ = M⁻¹ (τ − h), M by the subtrees' inertias (a free root's ṗ rows
    /// scaled as the rhs reads its quaternion, see
    /// [`FreeRoot`](super::tree::world::FreeRoot)).
    pub accelerations: Vec<Id>,
    /// Rows: the retained coordinates' rates, then ÿ; row-major over the
    /// columns; `None` where the columns' solves in the graph could not be
    /// built within what their right sides left of the candidate's budget
    /// (the loops over [`unsolved`](Self::unsolved) stand alone then).
    pub derivatives: Option<Vec<Id>>,
    /// The same columns before their solves, for the emitter to solve in
    /// loops over the columns.
    pub unsolved: UnsolvedColumns,
}

/// The world frame's columns left for the emitted code to solve: for each
/// column c, M ∂ÿ/∂c = ∂τ/∂c − ∂Q/∂c, and M's factors.
#[derive(Clone, Debug)]
pub struct UnsolvedColumns {
    /// The retained coordinates' rates' derivatives, row-major over the
    /// columns.
    pub rates: Vec<Id>,
    /// Per column, its l right-hand sides in speed order.
    pub forcing: Vec<Vec<Id>>,
    /// The speed at each position of M's elimination order.
    pub order: Vec<usize>,
    /// L below its diagonal, `lower[i][k]` for positions k < i (literal
    /// zeros where a row's speed does not move the column's).
    pub lower: Vec<Vec<Id>>,
    /// 1 / dᵢ at each position.
    pub reciprocals: Vec<Id>,
    /// After the solve, a free root's ṗ rows scaled (see
    /// [`FreeRoot`](super::tree::world::FreeRoot)).
    pub rows: Vec<ScaledRow>,
}

/// A row of ÿ scaled after the solve, with terms added to some columns: a
/// free root's ṗ row, by s = |e|², and 2 eₖ ÿ'ᵢ on the quaternion's
/// columns.
#[derive(Clone, Debug)]
pub struct ScaledRow {
    /// The row's speed.
    pub speed: usize,
    /// What the whole row is multiplied by.
    pub scale: Id,
    /// Then added: (the column among the Jacobian's, the term).
    pub adds: Vec<(usize, Id)>,
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
    /// The world frame's candidate (a tree of one-axis joints, on a fixed
    /// or a free root), or why there is none.
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

/// The columns of `d`'s Jacobian: the retained coordinates, then the
/// privileged speeds it was derived in (a scene's own, where it has them).
pub fn columns(model: &Model, d: &Derivation) -> Columns {
    let state = d
        .reduction
        .retained
        .iter()
        .map(|&r| model.coords[r].1.q)
        .chain(d.map.speed_rates.iter().copied())
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
    let accels = d.map.accels.clone();
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
            .chain(d.map.speed_rates.iter().copied())
            .collect(),
        inputs: Vec::new(),
    };
    let forced = model.jacobian == Some(true);
    let g = &mut model.g;
    let allowed = budget(g, &s.inverse, forced);
    let differentiated = within_budget(g, allowed, |g| derivatives(g, &s.inverse, &columns));
    let Ok(world) = world_inverse_dynamics(model, d, allowed) else {
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
mod tests;
