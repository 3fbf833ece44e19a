//! The derivatives of recursive Newton–Euler by the coordinates and the
//! speeds, in the world frame (Carpentier and Mansard, "Analytical
//! derivatives of rigid body dynamics algorithms", RSS 2018), unrolled
//! over a tree of one-axis joints with constants folded; a free joint at
//! the root is two nodes of three columns each (the `nodes` module).
//!
//! In the world frame a coordinate qⱼ moves its whole subtree rigidly:
//! every world quantity of a descendant changes by the cross product with
//! the joint's axis Jⱼ, and those changes cancel in τᵢ = Jᵢᵀ fᵢᶜ (fᵢᶜ the
//! subtree's force) for every i in j's subtree. What is left is the change
//! of the velocity and acceleration relative to the parent,
//! ∂v/∂qⱼ = v_λ × Jⱼ and ∂a/∂qⱼ = a_λ × Jⱼ + v_λ × ∂v/∂qⱼ, the same for all
//! of them, and a term −vᵢ × ∂v/∂qⱼ in each link's acceleration, which the
//! inertia's variation by the velocity (v ×* Y − Y v×) carries, summed
//! over the subtree like the inertias.
//! So each (joint, descendant) pair costs a few 6-dot products against
//! quantities computed once per link, where differentiating the recursion
//! column by column repeats a recursion over the subtree per column.
//!
//! The accelerations ÿ the forces are taken at are given (on a fixed
//! root), or solved from M ÿ = τ − h with M and h from the same passes (M
//! by the subtrees' inertias, factored leaves first), which costs less
//! than the articulated-body algorithm beside them.
//!
//! Input: the model's tree and [`Accelerations`]; output:
//! [`WorldDerivatives`].

mod factor;
mod inertia;
mod nodes;

use appell_symbolic::{Id, SymbolicError};

use super::links::{self, Parts};
use super::spatial::{Algebra, V6};
use crate::model::tree::{Motion, TreeSpec};
use crate::model::Model;
pub use factor::MassFactor;
use inertia::Shaped;
pub use nodes::FreeRoot;
use nodes::Node;

type R<T> = Result<T, SymbolicError>;

/// ∂Q/∂q, ∂Q/∂ẏ and M of a tree's inverse dynamics Q(q, ẏ, ÿ), each l×l
/// row-major, rows and columns in speed order: column j is the speed j,
/// or the change of the coordinates that moves along speed j's axis (its
/// joint's coordinate, a slide, or a free joint's turn in the body's axes).
/// With free roots, Q is that of the bodies the nodes describe: speeds
/// s ṗ, gravity s g (see [`FreeRoot`]).
pub struct WorldDerivatives {
    /// ∂Qᵢ/∂q along speed j's axis.
    pub by_coordinates: Vec<Id>,
    /// ∂Qᵢ/∂ẏⱼ (by s ṗ for a free root's slides: zero).
    pub by_speeds: Vec<Id>,
    /// M = ∂Q/∂ÿ.
    pub mass: Vec<Id>,
    /// The joints' inputs as generalized forces τ (0 where a joint is not
    /// actuated), in speed order.
    pub inputs: Vec<Id>,
    /// The coordinate moving along each speed's axis, by index among the
    /// model's (None for a free joint's turn), in speed order.
    pub coordinates: Vec<Option<usize>>,
    /// The accelerations the derivatives are taken at (the nodes' ÿ': a
    /// free root's p̈ / s).
    pub accelerations: Vec<Id>,
    /// With [`Accelerations::Solved`], M's factors.
    pub factor: Option<MassFactor>,
    /// The free joints at the root.
    pub roots: Vec<FreeRoot>,
}

/// Where the accelerations come from.
pub enum Accelerations<'a> {
    /// These, in speed order: symbols, or values held.
    At(&'a [Id]),
    /// The forward dynamics' ÿ = M⁻¹ (τ − h), solved by M's factors.
    Solved,
}

/// Why `spec` has no world-frame derivatives, if it has not: every moving
/// joint must turn or slide about one axis, but a free joint at the root
/// (no moving link above it; welded ones may be).
pub fn single_axis(spec: &TreeSpec) -> Result<(), String> {
    let moves_above = |mut parent: Option<usize>| {
        while let Some(p) = parent {
            if spec.links[p].motion.is_some() {
                return true;
            }
            parent = spec.links[p].parent;
        }
        false
    };
    let several = |k: &&crate::model::tree::LinkSpec| match k.motion {
        Some(Motion::Spherical) => true,
        Some(Motion::Free) => moves_above(k.parent),
        _ => false,
    };
    match spec.links.iter().find(several) {
        Some(k) => Err(format!(
            "joint `{}` has more than one axis below the root, so no world-frame derivatives",
            k.joint
        )),
        None => Ok(()),
    }
}

/// The [`WorldDerivatives`] of `model`'s tree at `accelerations`, the
/// coordinates in `fixed` at zero; a tree that does not pass
/// [`single_axis`], or has a free root and given accelerations, is a
/// [`SymbolicError::DimensionMismatch`].
pub fn world_derivatives(
    model: &mut Model,
    spec: &TreeSpec,
    fixed: &[usize],
    accelerations: Accelerations,
) -> R<WorldDerivatives> {
    let parts = Parts::new(model)?;
    let tree = links::links(&mut model.g, spec, &parts, fixed, links::Index::Speeds)?;
    let gravity = links::gravity(&mut model.g, spec)?;
    let size = parts.speeds.len();
    if let Err(why) = single_axis(spec) {
        return Err(SymbolicError::DimensionMismatch {
            expected: "a tree of one-axis joints, or a free joint at its root".to_string(),
            found: why,
        });
    }
    let free = spec
        .links
        .iter()
        .any(|k| matches!(k.motion, Some(Motion::Free)));
    if matches!(accelerations, Accelerations::At(_)) && free {
        return Err(SymbolicError::DimensionMismatch {
            expected: "accelerations to solve for".to_string(),
            found: "a free root and given accelerations".to_string(),
        });
    }
    let mut a = Algebra::new(&mut model.g)?;
    let mut world = nodes::world_tree(&mut a, &tree, spec, &parts, fixed)?;
    let tree = &world.nodes;
    let ground = a.ground(gravity)?;
    let grounds = grounds(&mut a, tree, &world.roots, ground)?;
    let mut inputs = vec![a.zero(); size];
    for node in tree {
        for (c, &s) in node.speeds.iter().enumerate() {
            inputs[s] = node.inputs[c];
        }
    }
    let kin = kinematics(&mut a, tree, &world.speeds)?;
    let composite = composites(&mut a, tree, &kin)?;
    let mass = mass(&mut a, tree, &kin, &composite, size)?;
    let (accelerations, factor) = match accelerations {
        Accelerations::At(given) => (given.to_vec(), None),
        Accelerations::Solved => {
            let resting = vec![a.zero(); size];
            let acc = accelerate(&mut a, tree, &kin, &grounds, &resting)?;
            let forces = subtree_forces(&mut a, tree, &acc)?;
            let mut free = vec![a.zero(); size];
            for (i, node) in tree.iter().enumerate() {
                for (c, &s) in node.speeds.iter().enumerate() {
                    let h = a.dot((0..6).map(|k| (kin[i].axes[c][k], forces[i][k])))?;
                    free[s] = a.g.sub(inputs[s], h)?;
                }
            }
            let order = tree
                .iter()
                .rev()
                .flat_map(|n| n.speeds.iter().rev().copied());
            let factor = MassFactor::new(&mut a, order.collect(), &mass)?;
            (factor.solve(&mut a, &free)?, Some(factor))
        }
    };
    for (r, root) in world.roots.iter_mut().enumerate() {
        root.gravity = gravity_term(&mut a, tree, &kin, &composite, &grounds, r, size)?;
    }
    let acc = accelerate(&mut a, tree, &kin, &grounds, &accelerations)?;
    let forces = subtree_forces(&mut a, tree, &acc)?;
    let sub = subtree(&mut a, &kin, &composite, &acc, &forces)?;
    let mut out = WorldDerivatives {
        by_coordinates: vec![a.zero(); size * size],
        by_speeds: vec![a.zero(); size * size],
        mass,
        inputs,
        coordinates: world.coordinates,
        accelerations,
        factor,
        roots: world.roots,
    };
    pairs(&mut a, tree, &kin, &composite, &acc, &sub, &mut out)?;
    Ok(out)
}

/// The ground's acceleration under each node without a parent: (0, −g),
/// or (0, −s g) under a free root.
fn grounds(a: &mut Algebra, tree: &[Node], roots: &[FreeRoot], ground: V6) -> R<Vec<V6>> {
    let mut out = Vec::with_capacity(tree.len());
    for node in tree {
        out.push(match (node.parent, node.root) {
            (None, Some(r)) => a.scale(ground, roots[r].scale)?,
            _ => ground,
        });
    }
    Ok(out)
}

/// The gravity term of the free root `r`'s subtree, Jᵢ · Yᶜᵢ a₀ with a₀
/// its ground's acceleration, in speed order (zero elsewhere).
fn gravity_term(
    a: &mut Algebra,
    tree: &[Node],
    kin: &[Kinematics],
    composite: &[Composite],
    grounds: &[V6],
    r: usize,
    size: usize,
) -> R<Vec<Id>> {
    let top = tree
        .iter()
        .position(|n| n.parent.is_none() && n.root == Some(r));
    let Some(top) = top else {
        return Err(SymbolicError::DimensionMismatch {
            expected: "a free root's node".to_string(),
            found: "none".to_string(),
        });
    };
    let ground = grounds[top];
    let mut out = vec![a.zero(); size];
    for (i, node) in tree.iter().enumerate() {
        if node.root != Some(r) {
            continue;
        }
        let force = composite[i].inertia.apply(a, ground)?;
        for (c, &s) in node.speeds.iter().enumerate() {
            out[s] = a.dot((0..6).map(|k| (kin[i].axes[c][k], force[k])))?;
        }
    }
    Ok(out)
}

/// One node's world quantities that do not depend on the accelerations.
struct Kinematics {
    /// The columns' axes Jᵢ.
    axes: Vec<V6>,
    /// The parent's velocity v_λ (zero for the ground).
    parent_velocity: V6,
    /// The joint's velocity Σ Jᵢ ẏᵢ.
    joint: V6,
    /// ∂v/∂q along each column, relative to the parent: v_λ × Jᵢ.
    dv_dq: Vec<V6>,
    /// ∂a/∂ẏ of each column relative to the parent: v_λ × Jᵢ + v × Jᵢ
    /// (2 v_λ × Jᵢ for one column).
    da_dv: Vec<V6>,
    /// The world inertia Yᵢ.
    inertia: Shaped,
    /// Its variation by the velocity: v ×* Y − Y v× (symmetric).
    variation: Shaped,
    /// The momentum h = Y v.
    momentum: V6,
    /// v ×* h.
    gyroscopic: V6,
}

/// The forward pass over the velocities, at `speeds` (speed order).
fn kinematics(a: &mut Algebra, tree: &[Node], speeds: &[Id]) -> R<Vec<Kinematics>> {
    let zero6 = [a.zero(); 6];
    let mut velocities: Vec<V6> = Vec::with_capacity(tree.len());
    let mut out = Vec::with_capacity(tree.len());
    for node in tree {
        let v_parent = node.parent.map_or(zero6, |p| velocities[p]);
        let mut joint = a.scale(node.axes[0], speeds[node.speeds[0]])?;
        for (axis, &s) in node.axes.iter().zip(&node.speeds).skip(1) {
            let along = a.scale(*axis, speeds[s])?;
            joint = a.add(joint, along)?;
        }
        let v = a.add(v_parent, joint)?;
        let v = a.hold(v)?;
        let mut dv_dq = Vec::with_capacity(node.axes.len());
        let mut da_dv = Vec::with_capacity(node.axes.len());
        for &axis in &node.axes {
            let turned = a.cross_motion(v_parent, axis)?;
            let turned = a.hold(turned)?;
            dv_dq.push(turned);
            da_dv.push(match node.axes.len() {
                1 => a.add(turned, turned)?,
                _ => {
                    let own = a.cross_motion(v, axis)?;
                    a.add(turned, own)?
                }
            });
        }
        let inertia = match &node.inertia {
            Some(y) => Shaped::placed(a, y, &node.world)?.hold(a)?,
            None => Shaped::zero(a),
        };
        let momentum = inertia.apply(a, v)?;
        let momentum = a.hold(momentum)?;
        let gyroscopic = a.cross_force(v, momentum)?;
        let variation = inertia.variation(a, v)?;
        velocities.push(v);
        out.push(Kinematics {
            axes: node.axes.clone(),
            parent_velocity: v_parent,
            joint,
            dv_dq,
            da_dv,
            inertia,
            variation,
            momentum,
            gyroscopic,
        });
    }
    Ok(out)
}

/// One node's acceleration-dependent quantities.
struct Accelerated {
    /// ∂a/∂q along each column, relative to the parent:
    /// a_λ × Jᵢ + v_λ × ∂v/∂qᵢ.
    da_dq: Vec<V6>,
    /// The force Y a + v ×* h, gravity in a.
    force: V6,
}

/// The forward pass over the accelerations, at `accels` (speed order),
/// gravity as the ground's acceleration under each root (`grounds`).
fn accelerate(
    a: &mut Algebra,
    tree: &[Node],
    kin: &[Kinematics],
    grounds: &[V6],
    accels: &[Id],
) -> R<Vec<Accelerated>> {
    let mut acc: Vec<V6> = Vec::with_capacity(tree.len());
    let mut out = Vec::with_capacity(tree.len());
    for (i, node) in tree.iter().enumerate() {
        let a_parent = node.parent.map_or(grounds[i], |p| acc[p]);
        let k = &kin[i];
        let bias = a.cross_motion(k.parent_velocity, k.joint)?;
        let mut sum = a_parent;
        for (axis, &s) in k.axes.iter().zip(&node.speeds) {
            let along = a.scale(*axis, accels[s])?;
            sum = a.add(sum, along)?;
        }
        let sum = a.add(sum, bias)?;
        let here = a.hold(sum)?;
        let mut da_dq = Vec::with_capacity(k.axes.len());
        for (axis, dv) in k.axes.iter().zip(&k.dv_dq) {
            let turned = a.cross_motion(a_parent, *axis)?;
            let carried = a.cross_motion(k.parent_velocity, *dv)?;
            let sum = a.add(turned, carried)?;
            da_dq.push(a.hold(sum)?);
        }
        let ya = k.inertia.apply(a, here)?;
        let force = a.add(ya, k.gyroscopic)?;
        acc.push(here);
        out.push(Accelerated { da_dq, force });
    }
    Ok(out)
}

/// Each subtree's force fᶜ, summed leaves first and held.
fn subtree_forces(a: &mut Algebra, tree: &[Node], acc: &[Accelerated]) -> R<Vec<V6>> {
    let mut force: Vec<V6> = acc.iter().map(|x| x.force).collect();
    for i in (0..tree.len()).rev() {
        force[i] = a.hold(force[i])?;
        if let Some(p) = tree[i].parent {
            force[p] = a.add(force[p], force[i])?;
        }
    }
    Ok(force)
}

/// One node's subtree sums that do not depend on the accelerations.
struct Composite {
    /// Yᶜ.
    inertia: Shaped,
    /// Bᶜ: the variations' sum.
    variation: Shaped,
    /// hᶜ.
    momentum: V6,
    /// Yᶜ Jᵢ, per column.
    inertia_axis: Vec<V6>,
    /// (∂(v ×* Y v)/∂v − Y v×)ᶜᵀ Jᵢ = Bᶜ Jᵢ − Jᵢ ×* hᶜ, per column.
    variation_axis: Vec<V6>,
    /// ∂fᶜ/∂ẏᵢ: Yᶜ ∂a/∂ẏᵢ + Bᶜ Jᵢ + Jᵢ ×* hᶜ, per column.
    by_speed: Vec<V6>,
}

/// The backward pass over the inertias: the subtrees' inertia, variation
/// and momentum summed leaves first, and each column's vectors.
fn composites(a: &mut Algebra, tree: &[Node], kin: &[Kinematics]) -> R<Vec<Composite>> {
    let n = tree.len();
    let mut inertia: Vec<Shaped> = kin.iter().map(|k| k.inertia).collect();
    let mut variation: Vec<Shaped> = kin.iter().map(|k| k.variation).collect();
    let mut momentum: Vec<V6> = kin.iter().map(|k| k.momentum).collect();
    let mut out: Vec<Option<Composite>> = (0..n).map(|_| None).collect();
    for i in (0..n).rev() {
        let (y, b) = (inertia[i].hold(a)?, variation[i].hold(a)?);
        let h = a.hold(momentum[i])?;
        if let Some(p) = tree[i].parent {
            inertia[p] = inertia[p].add(a, &y)?;
            variation[p] = variation[p].add(a, &b)?;
            momentum[p] = a.add(momentum[p], h)?;
        }
        let mut c = Composite {
            inertia: y,
            variation: b,
            momentum: h,
            inertia_axis: Vec::new(),
            variation_axis: Vec::new(),
            by_speed: Vec::new(),
        };
        for (&j, &da_dv) in kin[i].axes.iter().zip(&kin[i].da_dv) {
            let inertia_axis = y.apply(a, j)?;
            let bj = b.apply(a, j)?;
            let jh = a.cross_force(j, h)?;
            let variation_axis = a.sub(bj, jh)?;
            let by_speed = {
                let ya = y.apply(a, da_dv)?;
                let sum = a.add(ya, bj)?;
                a.add(sum, jh)?
            };
            c.inertia_axis.push(a.hold(inertia_axis)?);
            c.variation_axis.push(a.hold(variation_axis)?);
            c.by_speed.push(a.hold(by_speed)?);
        }
        out[i] = Some(c);
    }
    Ok(out.into_iter().map(|s| s.expect("every node")).collect())
}

/// The (row, column) pairs of speeds whose entries couple: each column of
/// node i with each column of i's ancestors-or-self, as (i, c, k, d):
/// column c of node i, column d of node k. Within a node each pair once
/// for d ≤ c when `triangle`, else every pair.
fn couplings(tree: &[Node], triangle: bool) -> Vec<(usize, usize, usize, usize)> {
    let mut out = Vec::new();
    for i in 0..tree.len() {
        for c in 0..tree[i].speeds.len() {
            let mut j = Some(i);
            while let Some(k) = j {
                let columns = match (k == i, triangle) {
                    (true, true) => c + 1,
                    _ => tree[k].speeds.len(),
                };
                out.extend((0..columns).map(|d| (i, c, k, d)));
                j = tree[k].parent;
            }
        }
    }
    out
}

/// M, l×l row-major: Mᵢⱼ = Jⱼ · Yᶜᵢ Jᵢ for j an ancestor-or-self of i.
fn mass(
    a: &mut Algebra,
    tree: &[Node],
    kin: &[Kinematics],
    composite: &[Composite],
    size: usize,
) -> R<Vec<Id>> {
    let mut m = vec![a.zero(); size * size];
    for (i, c, k, d) in couplings(tree, true) {
        let (row, col) = (tree[i].speeds[c], tree[k].speeds[d]);
        let x = kin[k].axes[d];
        let y = composite[i].inertia_axis[c];
        let entry = a.dot((0..6).map(|r| (x[r], y[r])))?;
        m[row * size + col] = entry;
        m[col * size + row] = entry;
    }
    Ok(m)
}

/// ∂fᶜ/∂q along each column of each subtree:
/// Jᵢ ×* fᶜ + Yᶜ ∂a/∂qᵢ + Bᶜ ∂v/∂qᵢ + ∂v/∂qᵢ ×* hᶜ.
fn subtree(
    a: &mut Algebra,
    kin: &[Kinematics],
    composite: &[Composite],
    acc: &[Accelerated],
    forces: &[V6],
) -> R<Vec<Vec<V6>>> {
    let mut out = Vec::with_capacity(kin.len());
    for (i, c) in composite.iter().enumerate() {
        let mut columns = Vec::with_capacity(kin[i].axes.len());
        for (col, &axis) in kin[i].axes.iter().enumerate() {
            let jf = a.cross_force(axis, forces[i])?;
            let ya = c.inertia.apply(a, acc[i].da_dq[col])?;
            let bv = c.variation.apply(a, kin[i].dv_dq[col])?;
            let vh = a.cross_force(kin[i].dv_dq[col], c.momentum)?;
            let sum = a.add(jf, ya)?;
            let sum = a.add(sum, bv)?;
            let sum = a.add(sum, vh)?;
            columns.push(a.hold(sum)?);
        }
        out.push(columns);
    }
    Ok(out)
}

/// The entries: for column c of node i and each column d of an
/// ancestor-or-self k, ∂Q_c/∂q_d = Yᶜᵢ J_c · ∂a/∂q_d + (B J_c)ᶜ · ∂v/∂q_d
/// and the like by ẏ_d (zero by a free root's slides' speeds); for k a
/// strict ancestor also ∂Q_d/∂q_c = J_d · ∂fᶜᵢ/∂q_c and the like by ẏ_c.
fn pairs(
    a: &mut Algebra,
    tree: &[Node],
    kin: &[Kinematics],
    composite: &[Composite],
    acc: &[Accelerated],
    by_coordinate: &[Vec<V6>],
    out: &mut WorldDerivatives,
) -> R<()> {
    let size = out.coordinates.len();
    let dot = |a: &mut Algebra, x: V6, y: V6| a.dot((0..6).map(|k| (x[k], y[k])));
    for (i, c, k, d) in couplings(tree, false) {
        let (row, col) = (tree[i].speeds[c], tree[k].speeds[d]);
        let (inertia_axis, variation_axis) =
            (composite[i].inertia_axis[c], composite[i].variation_axis[c]);
        let ya = dot(a, inertia_axis, acc[k].da_dq[d])?;
        let bv = dot(a, variation_axis, kin[k].dv_dq[d])?;
        out.by_coordinates[row * size + col] = a.g.add(ya, bv)?;
        if !tree[k].slides {
            let ya = dot(a, inertia_axis, kin[k].da_dv[d])?;
            let bj = dot(a, variation_axis, kin[k].axes[d])?;
            out.by_speeds[row * size + col] = a.g.add(ya, bj)?;
        }
        if k != i {
            let axis = kin[k].axes[d];
            let dq = dot(a, axis, by_coordinate[i][c])?;
            out.by_coordinates[col * size + row] = dq;
            let dv = dot(a, axis, composite[i].by_speed[c])?;
            out.by_speeds[col * size + row] = dv;
        }
    }
    Ok(())
}
