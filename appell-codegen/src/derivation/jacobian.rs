//! Stage 14: the derivatives of the reduced rhs with respect to the reduced
//! state x = (retained q, ẏ) and the inputs w, for the generated
//! `rhs_jacobian`.
//!
//! Two candidates, each a set of expressions in the model's graph; the
//! emitter lowers both and keeps the one with fewer operations per call:
//!
//! - **closed**: ∂f/∂x, ∂f/∂w, ∂M/∂x (lower triangle) and ∂q̇_r/∂x. At run
//!   time ÿ = M⁻¹ f, then ∂ÿ/∂x_j = M⁻¹ (∂f/∂x_j − (∂M/∂x_j) ÿ), with M
//!   factored once for the values and every column. Only with the symbolic
//!   elimination: a numeric one leaves the dependent rates X and their
//!   remainder w to run time, where no expression differentiates them.
//! - **structured**: ∂ÿ/∂x and ∂ÿ/∂w of the unrolled articulated-body
//!   algorithm's accelerations (a plain tree of joints), whose
//!   constants are folded where they are built.
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

/// The most nodes a candidate's derivatives may add, as a multiple of the
/// graph's nodes before them.
pub const GROWTH_LIMIT: usize = 2;

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
}

impl Jacobians {
    /// No candidate, for `reason` (a model whose derivatives are off).
    pub fn none(columns: Columns, reason: &str) -> Jacobians {
        Jacobians {
            columns,
            closed: Err(reason.to_string()),
            structured: Err(reason.to_string()),
        }
    }
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
    let g = &mut model.g;
    let closed = if matches!(d.elimination, super::Elimination::Symbolic) {
        closed(g, d, &columns)
    } else {
        Err("the elimination is numeric".to_string())
    };
    let structured = match &d.structured {
        Ok(s) => {
            let mut roots: Vec<Id> = d
                .reduction
                .retained
                .iter()
                .map(|&r| d.map.qdot[r])
                .collect();
            roots.extend(&s.accelerations);
            within_budget(g, |g| derivatives(g, &roots, &columns))
        }
        Err(_) => Err("no structured form".to_string()),
    };
    Jacobians {
        columns,
        closed,
        structured,
    }
}

/// The closed form's derivatives.
fn closed(g: &mut Graph, d: &Derivation, columns: &Columns) -> Result<ClosedJacobian, String> {
    let l = d.l;
    let lower: Vec<Id> = (0..l)
        .flat_map(|i| (0..=i).map(move |j| (i, j)))
        .map(|(i, j)| d.equations.mass[i * l + j])
        .collect();
    let rates: Vec<Id> = d
        .reduction
        .retained
        .iter()
        .map(|&r| d.map.qdot[r])
        .collect();
    within_budget(g, |g| {
        let forcing = derivatives(g, &d.equations.forcing, columns)?;
        let rates = derivatives(g, &rates, columns)?;
        let per_column = derivatives(g, &lower, columns)?;
        let n = columns.len();
        let mass = (0..n)
            .map(|c| (0..lower.len()).map(|e| per_column[e * n + c]).collect())
            .collect();
        Ok(ClosedJacobian {
            forcing,
            mass,
            rates,
        })
    })
}

/// ∂root/∂c for every root and column, row-major (one row per root).
fn derivatives(g: &mut Graph, roots: &[Id], columns: &Columns) -> Result<Vec<Id>, SymbolicError> {
    let mut out = Vec::with_capacity(roots.len() * columns.len());
    for &root in roots {
        for s in columns.all() {
            out.push(g.diff(root, s)?);
        }
    }
    Ok(out)
}

/// `build`'s result, or why it is left out: an error, or more new nodes
/// than [`GROWTH_LIMIT`] allows (checked after it ran: the graph keeps
/// what it built, which nothing then reaches).
fn within_budget<T>(
    g: &mut Graph,
    build: impl FnOnce(&mut Graph) -> Result<T, SymbolicError>,
) -> Result<T, String> {
    let before = g.len();
    let limit = GROWTH_LIMIT * before.max(10_000);
    let built = build(g).map_err(|e| format!("differentiating failed: {e}"))?;
    let added = g.len() - before;
    if added > limit {
        return Err(format!(
            "its derivatives added {added} expressions, more than {GROWTH_LIMIT} times the model's {before}"
        ));
    }
    Ok(built)
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
    }

    #[test]
    fn a_candidate_that_grows_the_graph_past_its_budget_is_left_out() {
        let mut g = Graph::new();
        let before = g.len();
        let kept = within_budget(&mut g, |g| g.parse("x + 1"));
        assert!(kept.is_ok());
        let grown = within_budget(&mut g, |g| {
            let mut last = g.int(0)?;
            for k in 0..(GROWTH_LIMIT * before.max(10_000) + 10) {
                last = g.parse(&format!("x^{}", k + 2))?;
            }
            Ok(last)
        });
        let reason = grown.expect_err("past the budget");
        assert!(reason.contains("more than"), "{reason}");
    }
}
