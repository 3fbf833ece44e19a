//! The structured form of a kinematic tree's equations: Featherstone's
//! recursions (the articulated-body algorithm for ÿ, recursive
//! Newton–Euler for inverse dynamics, the bias and gravity terms, the
//! composite-rigid-body algorithm for M) unrolled over the links in the
//! expression graph, with every constant folded: a joint axis along z,
//! a placement along one axis and a diagonal inertia leave only the
//! products that do not vanish. Every link's quantities are nodes shared
//! by its children, held as single factors (`Graph::hold`) so that a child
//! multiplies a parent's velocity, acceleration, force or articulated
//! inertia once instead of multiplying out its terms, and the form grows
//! linearly with the links where the closed form of Appell's equations
//! grows like n³.
//!
//! A tree under constraints gets M and f projected onto its privileged
//! speeds instead ([`projected`]).
//!
//! Input: the model's [`TreeSpec`]; output: [`Structured`].

pub mod equations;
mod free;
mod links;
pub mod projected;
mod recursions;
pub mod spatial;
pub mod world;

use appell_symbolic::{Id, SymbolicError};

type R<T> = Result<T, SymbolicError>;

use crate::model::tree::TreeSpec;
use crate::model::Model;
use spatial::Algebra;

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
    /// The joints' inputs as generalized forces τ (0 where a joint is not
    /// actuated), in speed order: f = τ − h.
    pub inputs: Vec<Id>,
    /// The kinetic energy ½ Σ vᵢ · Iᵢ vᵢ, from the links' velocities.
    pub kinetic: Id,
}

/// The structured equations of `model`'s tree; `fixed` lists the
/// coordinates (indices) the accelerations take at zero.
///
/// ```
/// use appell_codegen::{ctxt::Ctxt, derivation::{self, tree}, model, parse};
///
/// // A pendulum as a one-joint tree: a point mass m at distance l.
/// let input: syn::DeriveInput = syn::parse_str(r#"
///     #[appell(joint(j, revolute(y), parent = N, child = A, actuated))]
///     #[appell(point(P = origin(A) + l * A.x), particle(P, mass = m))]
///     #[appell(gravity(-g * N.z))]
///     struct Pendulum { m: f64, l: f64, g: f64 }
/// "#).unwrap();
/// let cx = Ctxt::new();
/// let ast = parse::parse(&cx, &input);
/// let kinematics = model::build(&cx, &ast).unwrap();
/// let mut derived = derivation::derive(&cx, kinematics).unwrap();
/// cx.check().unwrap();
/// let spec = derived.model.tree.clone().unwrap();
/// let s = tree::structured(&mut derived.model, &spec, &[]).unwrap();
/// // M = m l² by the composite-rigid-body algorithm.
/// let at = [("m", 2.0), ("l", 0.5), ("g", 9.81), ("j", 0.3)];
/// let m = derived.model.g.eval_named(s.mass[0], &at).unwrap();
/// assert!((m - 2.0 * 0.25).abs() < 1e-12);
/// ```
pub fn structured(
    model: &mut Model,
    spec: &TreeSpec,
    fixed: &[usize],
) -> Result<Structured, SymbolicError> {
    let mut s = controller(model, spec)?;
    let parts = links::Parts::new(model)?;
    let gravity = links::gravity(&mut model.g, spec)?;
    let reduced = links::links(&mut model.g, spec, &parts, fixed, links::Index::Speeds)?;
    let body = free::speeds_in(&mut Algebra::new(&mut model.g)?, &reduced, &parts.speeds)?;
    let size = parts.speeds.len();
    let mut r = recursions::Recursions::new(&mut model.g, &reduced, gravity, size)?;
    let body_accels = r.articulated_body(&body)?;
    let mut a = Algebra::new(&mut model.g)?;
    s.accelerations = free::accelerations_out(&mut a, &reduced, &body, &body_accels)?;
    Ok(s)
}

/// The structured form without the accelerations (left empty): what M, f
/// and the controller functions need, at the coordinates as they are.
pub fn controller(model: &mut Model, spec: &TreeSpec) -> Result<Structured, SymbolicError> {
    let parts = links::Parts::new(model)?;
    let tree = links::links(&mut model.g, spec, &parts, &[], links::Index::Speeds)?;
    let gravity = links::gravity(&mut model.g, spec)?;
    let size = parts.speeds.len();
    // The recursions' speeds and accelerations (a free joint's in its
    // child's axes), at the model's and at zero model accelerations.
    let (body, body_accels, resting) = {
        let mut a = Algebra::new(&mut model.g)?;
        let body = free::speeds_in(&mut a, &tree, &parts.speeds)?;
        let accels = free::accelerations_in(&mut a, &tree, &body, &parts.accels)?;
        let zero = vec![a.zero(); size];
        let resting = free::accelerations_in(&mut a, &tree, &body, &zero)?;
        (body, accels, resting)
    };
    let mut r = recursions::Recursions::new(&mut model.g, &tree, gravity, size)?;
    let inverse = r.newton_euler(&body, Some(&body_accels), true)?;
    let bias = r.newton_euler(&body, Some(&resting), true)?;
    let gravity_term = r.newton_euler(&body, None, false)?;
    let mass = r.composite_rigid_body()?;
    let kinetic = r.kinetic_energy(&body)?;
    let inputs = r.inputs();
    let mut a = Algebra::new(&mut model.g)?;
    Ok(Structured {
        accelerations: Vec::new(),
        inverse: free::forces_out(&mut a, &tree, &inverse)?,
        mass: free::mass_out(&mut a, &tree, &mass, size)?,
        bias: free::forces_out(&mut a, &tree, &bias)?,
        gravity: free::forces_out(&mut a, &tree, &gravity_term)?,
        inputs,
        kinetic,
    })
}

/// A tree's equations as a residual, for the derivatives of ÿ by inverse
/// dynamics (Carpentier and Mansard's shape): with R(q, ẏ, ÿ) = M ÿ + h,
/// M ÿ = τ gives ∂ÿ/∂x = M⁻¹ (∂τ/∂x − ∂R/∂x) at the accelerations of the
/// articulated-body algorithm.
pub struct Residual {
    /// M, l×l row-major, by the composite-rigid-body algorithm.
    pub mass: Vec<Id>,
    /// M ÿ + h by recursive Newton–Euler, in the acceleration symbols.
    pub inverse: Vec<Id>,
    /// The joints' inputs as generalized forces τ, in speed order.
    pub inputs: Vec<Id>,
}

/// The [`Residual`] of `model`'s tree, the coordinates `fixed` (indices)
/// at zero as in [`structured`]'s accelerations. A free joint's
/// accelerations come in by the exact inverse of the way [`structured`]'s
/// go out (the `free` module's `exact_inverses`), so that the residual
/// vanishes at the articulated-body ÿ at every state, a quaternion off the
/// unit sphere included, and its derivatives are the rhs's.
pub fn residual(model: &mut Model, spec: &TreeSpec, fixed: &[usize]) -> R<Residual> {
    let parts = links::Parts::new(model)?;
    let tree = links::links(&mut model.g, spec, &parts, fixed, links::Index::Speeds)?;
    let gravity = links::gravity(&mut model.g, spec)?;
    let size = parts.speeds.len();
    let (body, body_accels, exact) = {
        let mut a = Algebra::new(&mut model.g)?;
        let body = free::speeds_in(&mut a, &tree, &parts.speeds)?;
        let exact = free::exact_inverses(&mut a, &tree)?;
        let accels = free::accelerations_in(&mut a, &exact, &body, &parts.accels)?;
        (body, accels, exact)
    };
    let mut r = recursions::Recursions::new(&mut model.g, &tree, gravity, size)?;
    let inverse = r.newton_euler(&body, Some(&body_accels), true)?;
    let mass = r.composite_rigid_body()?;
    let inputs = r.inputs();
    let mut a = Algebra::new(&mut model.g)?;
    Ok(Residual {
        mass: free::mass_out(&mut a, &exact, &mass, size)?,
        inverse: free::forces_out(&mut a, &exact, &inverse)?,
        inputs,
    })
}

/// Moving links from which the closed form is not derived at all: its
/// cost grows like n³ (measured on the spatial chains: 4,505 operations
/// per rhs call at 8 links, 23,795 at 16, against the structured form's
/// 2,772 and 6,637), and so do its expansion time and emitted size.
pub const STRUCTURED_ONLY_LINKS: usize = 12;

/// The number of moving links of `spec`.
pub fn moving_links(spec: &TreeSpec) -> usize {
    spec.links.iter().filter(|k| k.motion.is_some()).count()
}

#[cfg(test)]
mod tests;
