//! The structured form of a kinematic tree's equations: Featherstone's
//! recursions (the articulated-body algorithm for ÿ, recursive
//! Newton–Euler for inverse dynamics, the bias and gravity terms, the
//! composite-rigid-body algorithm for M) unrolled over the links in the
//! expression graph, with every constant folded: a joint axis along z,
//! a placement along one axis and a diagonal inertia leave only the
//! products that do not vanish. Every link's quantities are nodes shared
//! by its children, so the form grows linearly with the links where the
//! closed form of Appell's equations grows like n³.
//!
//! Input: the model's [`TreeSpec`]; output: [`Structured`].

mod links;
mod recursions;
pub mod spatial;

use appell_symbolic::{Id, SymbolicError};

use crate::model::tree::TreeSpec;
use crate::model::Model;

pub use links::Link;

/// The structured equations of a tree: expressions in the coordinates,
/// the privileged speeds, the inputs and the acceleration symbols.
pub struct Structured {
    /// ÿ from the articulated-body algorithm, the ignorable coordinates
    /// fixed at zero (the reduced rhs's accelerations).
    pub accelerations: Vec<Id>,
    /// The generalized forces for accelerations ÿ (the speeds'
    /// acceleration symbols), by recursive Newton–Euler: M ÿ + h.
    pub inverse: Vec<Id>,
    /// M, l×l row-major, by the composite-rigid-body algorithm.
    pub mass: Vec<Id>,
    /// The bias h = −f at zero inputs: velocity products and gravity.
    pub bias: Vec<Id>,
    /// The gravity term: h at zero speeds.
    pub gravity: Vec<Id>,
}

/// The structured equations of `model`'s tree; `fixed` lists the
/// coordinates (indices) the accelerations take at zero.
pub fn structured(
    model: &mut Model,
    spec: &TreeSpec,
    fixed: &[usize],
) -> Result<Structured, SymbolicError> {
    let parts = links::Parts::new(model)?;
    let free = links::links(&mut model.g, spec, &parts, &[])?;
    let gravity = links::gravity(&mut model.g, spec)?;
    let mut r = recursions::Recursions::new(&mut model.g, &free, gravity)?;
    let inverse = r.newton_euler(&parts.speeds, Some(&parts.accels), true)?;
    let bias = r.newton_euler(&parts.speeds, None, true)?;
    let gravity_term = r.newton_euler(&parts.speeds, None, false)?;
    let mass = r.composite_rigid_body()?;
    let reduced = links::links(&mut model.g, spec, &parts, fixed)?;
    let mut r = recursions::Recursions::new(&mut model.g, &reduced, gravity)?;
    let accelerations = r.articulated_body(&parts.speeds)?;
    Ok(Structured {
        accelerations,
        inverse,
        mass,
        bias,
        gravity: gravity_term,
    })
}

#[cfg(test)]
mod tests;
