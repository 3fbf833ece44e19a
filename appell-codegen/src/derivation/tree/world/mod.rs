//! The derivatives of recursive Newton–Euler by the coordinates and the
//! speeds, in the world frame (Carpentier and Mansard, "Analytical
//! derivatives of rigid body dynamics algorithms", RSS 2018), unrolled
//! over a tree of one-axis joints with constants folded.
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
//! The accelerations ÿ the forces are taken at are given, or solved from
//! M ÿ = τ − h with M and h from the same passes (M by the subtrees'
//! inertias, factored leaves first), which costs less than the
//! articulated-body algorithm beside them.
//!
//! Input: the model's tree and [`Accelerations`]; output:
//! [`WorldDerivatives`].

mod factor;
mod inertia;

use appell_symbolic::{Id, SymbolicError};

use super::links::{self, Link, Parts};
use super::spatial::{join, split, Algebra, Transform, V6};
use crate::model::tree::{Motion, TreeSpec};
use crate::model::Model;
pub use factor::MassFactor;
use inertia::Shaped;

type R<T> = Result<T, SymbolicError>;

/// ∂Q/∂q, ∂Q/∂ẏ and M of a tree's inverse dynamics Q(q, ẏ, ÿ), each l×l
/// row-major, rows and columns in speed order: column j is the speed of
/// the link whose joint has speed j, or that joint's coordinate.
pub struct WorldDerivatives {
    /// ∂Qᵢ/∂q of the coordinate of speed j's joint.
    pub by_coordinates: Vec<Id>,
    /// ∂Qᵢ/∂ẏⱼ.
    pub by_speeds: Vec<Id>,
    /// M = ∂Q/∂ÿ.
    pub mass: Vec<Id>,
    /// The joints' inputs as generalized forces τ (0 where a joint is not
    /// actuated), in speed order.
    pub inputs: Vec<Id>,
    /// The index among the model's coordinates of each speed's joint
    /// coordinate, in speed order.
    pub coordinates: Vec<usize>,
    /// The accelerations the derivatives are taken at.
    pub accelerations: Vec<Id>,
    /// With [`Accelerations::Solved`], M's factors.
    pub factor: Option<MassFactor>,
}

/// Where the accelerations come from.
pub enum Accelerations<'a> {
    /// These, in speed order: symbols, or values held.
    At(&'a [Id]),
    /// The forward dynamics' ÿ = M⁻¹ (τ − h), solved by M's factors.
    Solved,
}

/// Why `spec` has no world-frame derivatives, if it has not: every moving
/// joint must turn or slide about one axis.
pub fn single_axis(spec: &TreeSpec) -> Result<(), String> {
    let several = |k: &&crate::model::tree::LinkSpec| {
        matches!(k.motion, Some(Motion::Spherical) | Some(Motion::Free))
    };
    match spec.links.iter().find(several) {
        Some(k) => Err(format!(
            "joint `{}` has more than one axis, so no world-frame derivatives",
            k.joint
        )),
        None => Ok(()),
    }
}

/// The [`WorldDerivatives`] of `model`'s tree at `accelerations`, the
/// coordinates in `fixed` at zero; a tree that does not pass
/// [`single_axis`] is a [`SymbolicError::DimensionMismatch`].
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
    let one_axis = tree
        .iter()
        .all(|k| k.subspace.len() == 1 && k.free.is_none());
    if let Err(why) = single_axis(spec).and_then(|()| match one_axis && tree.len() == size {
        true => Ok(()),
        false => Err("a speed per link".to_string()),
    }) {
        return Err(SymbolicError::DimensionMismatch {
            expected: "a tree of one-axis joints, one speed each".to_string(),
            found: why,
        });
    }
    let coordinates = joint_coordinates(&parts, spec, &tree)?;
    let mut a = Algebra::new(&mut model.g)?;
    let ground = a.ground(gravity)?;
    let mut q = vec![a.zero(); size];
    for (s, &r) in coordinates.iter().enumerate() {
        if !fixed.contains(&r) {
            q[s] = parts.coordinates[r];
        }
    }
    let mut inputs = vec![a.zero(); size];
    for link in &tree {
        inputs[link.speeds[0]] = link.inputs[0];
    }
    let kin = kinematics(&mut a, &tree, &q, &parts.speeds)?;
    let composite = composites(&mut a, &tree, &kin)?;
    let mass = mass(&mut a, &tree, &kin, &composite, size)?;
    let (accelerations, factor) = match accelerations {
        Accelerations::At(given) => (given.to_vec(), None),
        Accelerations::Solved => {
            let resting = vec![a.zero(); size];
            let acc = accelerate(&mut a, &tree, &kin, ground, &resting)?;
            let forces = subtree_forces(&mut a, &tree, &acc)?;
            let mut free = vec![a.zero(); size];
            for (i, link) in tree.iter().enumerate() {
                let h = a.dot((0..6).map(|k| (kin[i].axis[k], forces[i][k])))?;
                free[link.speeds[0]] = a.g.sub(inputs[link.speeds[0]], h)?;
            }
            let factor = MassFactor::new(&mut a, &tree, &mass)?;
            (factor.solve(&mut a, &free)?, Some(factor))
        }
    };
    let acc = accelerate(&mut a, &tree, &kin, ground, &accelerations)?;
    let forces = subtree_forces(&mut a, &tree, &acc)?;
    let sub = subtree(&mut a, &kin, &composite, &acc, &forces)?;
    let mut out = WorldDerivatives {
        by_coordinates: vec![a.zero(); size * size],
        by_speeds: vec![a.zero(); size * size],
        mass,
        inputs,
        coordinates,
        accelerations,
        factor,
    };
    pairs(&mut a, &tree, &kin, &composite, &acc, &sub, &mut out)?;
    Ok(out)
}

/// Each speed's joint coordinate, by the moving links in order.
fn joint_coordinates(parts: &Parts, spec: &TreeSpec, tree: &[Link]) -> R<Vec<usize>> {
    let mut out = vec![0; parts.speeds.len()];
    let moving = spec.links.iter().filter(|k| k.motion.is_some());
    for (link, written) in tree.iter().zip(moving) {
        out[link.speeds[0]] = parts.coordinate(&written.coordinates[0])?;
    }
    Ok(out)
}

/// One link's world quantities that do not depend on the accelerations.
struct Kinematics {
    /// The joint's axis Jᵢ: its motion subspace in world axes about the
    /// world origin.
    axis: V6,
    /// The parent's velocity v_λ (zero for the ground).
    parent_velocity: V6,
    /// The joint's velocity Jᵢ ẏᵢ.
    joint: V6,
    /// ∂v/∂qᵢ relative to the parent: v_λ × Jᵢ.
    dv_dq: V6,
    /// ∂a/∂ẏᵢ relative to the parent: 2 v_λ × Jᵢ.
    da_dv: V6,
    /// The world inertia Yᵢ.
    inertia: Shaped,
    /// Its variation by the velocity: v ×* Y − Y v× (symmetric).
    variation: Shaped,
    /// The momentum h = Y v.
    momentum: V6,
    /// v ×* h.
    gyroscopic: V6,
}

/// The forward pass over the placements and velocities.
fn kinematics(a: &mut Algebra, tree: &[Link], q: &[Id], speeds: &[Id]) -> R<Vec<Kinematics>> {
    let zero6 = [a.zero(); 6];
    let mut placed: Vec<(Transform, V6)> = Vec::with_capacity(tree.len());
    let mut out = Vec::with_capacity(tree.len());
    for link in tree {
        let v_parent = link.parent.map_or(zero6, |p| placed[p].1);
        let s = link.speeds[0];
        let (world, axis) = placement(a, link, link.parent.map(|p| &placed[p].0), q[s])?;
        let joint = a.scale(axis, speeds[s])?;
        let v = a.add(v_parent, joint)?;
        let v = a.hold(v)?;
        let dv_dq = a.cross_motion(v_parent, axis)?;
        let dv_dq = a.hold(dv_dq)?;
        let da_dv = a.add(dv_dq, dv_dq)?;
        let inertia = Shaped::placed(a, &link.inertia, &world)?.hold(a)?;
        let momentum = inertia.apply(a, v)?;
        let momentum = a.hold(momentum)?;
        let gyroscopic = a.cross_force(v, momentum)?;
        let variation = inertia.variation(a, v)?;
        placed.push((world, v));
        out.push(Kinematics {
            axis,
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

/// One link's acceleration-dependent quantities.
struct Accelerated {
    /// ∂a/∂qᵢ relative to the parent: a_λ × Jᵢ + v_λ × ∂v/∂qᵢ.
    da_dq: V6,
    /// The force Y a + v ×* h, gravity in a.
    force: V6,
}

/// The forward pass over the accelerations, at `accels` (speed order),
/// gravity as the ground's acceleration `ground`.
fn accelerate(
    a: &mut Algebra,
    tree: &[Link],
    kin: &[Kinematics],
    ground: V6,
    accels: &[Id],
) -> R<Vec<Accelerated>> {
    let mut acc: Vec<V6> = Vec::with_capacity(tree.len());
    let mut out = Vec::with_capacity(tree.len());
    for (i, link) in tree.iter().enumerate() {
        let a_parent = link.parent.map_or(ground, |p| acc[p]);
        let k = &kin[i];
        let s = link.speeds[0];
        let bias = a.cross_motion(k.parent_velocity, k.joint)?;
        let along = a.scale(k.axis, accels[s])?;
        let sum = a.add(a_parent, along)?;
        let sum = a.add(sum, bias)?;
        let here = a.hold(sum)?;
        let turned = a.cross_motion(a_parent, k.axis)?;
        let carried = a.cross_motion(k.parent_velocity, k.dv_dq)?;
        let da_dq = a.add(turned, carried)?;
        let ya = k.inertia.apply(a, here)?;
        let force = a.add(ya, k.gyroscopic)?;
        acc.push(here);
        out.push(Accelerated {
            da_dq: a.hold(da_dq)?,
            force,
        });
    }
    Ok(out)
}

/// Each subtree's force fᶜ, summed leaves first and held.
fn subtree_forces(a: &mut Algebra, tree: &[Link], acc: &[Accelerated]) -> R<Vec<V6>> {
    let mut force: Vec<V6> = acc.iter().map(|x| x.force).collect();
    for i in (0..tree.len()).rev() {
        force[i] = a.hold(force[i])?;
        if let Some(p) = tree[i].parent {
            force[p] = a.add(force[p], force[i])?;
        }
    }
    Ok(force)
}

/// A link's world placement and its joint's axis Jᵢ there, from its
/// parent's (None: the ground) and its joint coordinate `q`: the joint
/// frame placed first (a constant transform), then the joint's turn or
/// slide, so that a coordinate axis leaves a column of the placed frame.
fn placement(
    a: &mut Algebra,
    link: &Link,
    parent: Option<&Transform>,
    q: Id,
) -> R<(Transform, V6)> {
    let frame = match parent {
        Some(p) => links::compose(a, p, &link.frame)?,
        None => link.frame,
    };
    let frame = hold_transform(a, &frame)?;
    let (w, v) = split(link.subspace[0]);
    let zero = [a.zero(); 3];
    let (world, axis) = match link.turn {
        Some(turn) => {
            let rot = a.mat_mul(&frame.rot, &turn)?;
            let along = a.mat_vec(&frame.rot, w)?;
            let moment = a.cross(frame.pos, along)?;
            let world = Transform {
                rot,
                pos: frame.pos,
            };
            (world, join(along, moment))
        }
        None => {
            let along = a.mat_vec(&frame.rot, v)?;
            let slide = a.scale(along, q)?;
            let pos = a.add(frame.pos, slide)?;
            let world = Transform {
                rot: frame.rot,
                pos,
            };
            (world, join(zero, along))
        }
    };
    Ok((hold_transform(a, &world)?, a.hold(axis)?))
}

/// Every entry held.
fn hold_transform(a: &mut Algebra, x: &Transform) -> R<Transform> {
    Ok(Transform {
        rot: [a.hold(x.rot[0])?, a.hold(x.rot[1])?, a.hold(x.rot[2])?],
        pos: a.hold(x.pos)?,
    })
}

/// One link's subtree sums that do not depend on the accelerations.
struct Composite {
    /// Yᶜ.
    inertia: Shaped,
    /// Bᶜ: the variations' sum.
    variation: Shaped,
    /// hᶜ.
    momentum: V6,
    /// Yᶜ Jᵢ.
    inertia_axis: V6,
    /// (∂(v ×* Y v)/∂v − Y v×)ᶜᵀ Jᵢ = Bᶜ Jᵢ − Jᵢ ×* hᶜ.
    variation_axis: V6,
    /// ∂fᶜ/∂ẏᵢ: Yᶜ ∂a/∂ẏᵢ + Bᶜ Jᵢ + Jᵢ ×* hᶜ.
    by_speed: V6,
}

/// The backward pass over the inertias: the subtrees' inertia, variation
/// and momentum summed leaves first, and each link's vectors.
fn composites(a: &mut Algebra, tree: &[Link], kin: &[Kinematics]) -> R<Vec<Composite>> {
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
        let j = kin[i].axis;
        let inertia_axis = y.apply(a, j)?;
        let bj = b.apply(a, j)?;
        let jh = a.cross_force(j, h)?;
        let variation_axis = a.sub(bj, jh)?;
        let by_speed = {
            let ya = y.apply(a, kin[i].da_dv)?;
            let sum = a.add(ya, bj)?;
            a.add(sum, jh)?
        };
        out[i] = Some(Composite {
            inertia: y,
            variation: b,
            momentum: h,
            inertia_axis: a.hold(inertia_axis)?,
            variation_axis: a.hold(variation_axis)?,
            by_speed: a.hold(by_speed)?,
        });
    }
    Ok(out.into_iter().map(|s| s.expect("every link")).collect())
}

/// M, l×l row-major: Mᵢⱼ = Jⱼ · Yᶜᵢ Jᵢ for j an ancestor-or-self of i.
fn mass(
    a: &mut Algebra,
    tree: &[Link],
    kin: &[Kinematics],
    composite: &[Composite],
    size: usize,
) -> R<Vec<Id>> {
    let mut m = vec![a.zero(); size * size];
    for i in 0..tree.len() {
        let row = tree[i].speeds[0];
        let mut j = Some(i);
        while let Some(k) = j {
            let col = tree[k].speeds[0];
            let x = kin[k].axis;
            let y = composite[i].inertia_axis;
            let entry = a.dot((0..6).map(|r| (x[r], y[r])))?;
            m[row * size + col] = entry;
            m[col * size + row] = entry;
            j = tree[k].parent;
        }
    }
    Ok(m)
}

/// ∂fᶜ/∂qᵢ of each subtree: Jᵢ ×* fᶜ + Yᶜ ∂a/∂qᵢ + Bᶜ ∂v/∂qᵢ + ∂v/∂qᵢ ×* hᶜ.
fn subtree(
    a: &mut Algebra,
    kin: &[Kinematics],
    composite: &[Composite],
    acc: &[Accelerated],
    forces: &[V6],
) -> R<Vec<V6>> {
    let mut out = Vec::with_capacity(kin.len());
    for (i, c) in composite.iter().enumerate() {
        let jf = a.cross_force(kin[i].axis, forces[i])?;
        let ya = c.inertia.apply(a, acc[i].da_dq)?;
        let bv = c.variation.apply(a, kin[i].dv_dq)?;
        let vh = a.cross_force(kin[i].dv_dq, c.momentum)?;
        let sum = a.add(jf, ya)?;
        let sum = a.add(sum, bv)?;
        let sum = a.add(sum, vh)?;
        out.push(a.hold(sum)?);
    }
    Ok(out)
}

/// The entries: for link i and each ancestor-or-self j,
/// ∂Qᵢ/∂qⱼ = Yᶜᵢ Jᵢ · ∂a/∂qⱼ + (B Jᵢ)ᶜ · ∂v/∂qⱼ and the like by ẏⱼ; for j a
/// strict ancestor also ∂Qⱼ/∂qᵢ = Jⱼ · ∂fᶜᵢ/∂qᵢ and the like by ẏᵢ.
fn pairs(
    a: &mut Algebra,
    tree: &[Link],
    kin: &[Kinematics],
    composite: &[Composite],
    acc: &[Accelerated],
    by_coordinate: &[V6],
    out: &mut WorldDerivatives,
) -> R<()> {
    let size = out.coordinates.len();
    let dot = |a: &mut Algebra, x: V6, y: V6| a.dot((0..6).map(|k| (x[k], y[k])));
    for i in 0..tree.len() {
        let row = tree[i].speeds[0];
        let c = &composite[i];
        let mut j = Some(i);
        while let Some(k) = j {
            let col = tree[k].speeds[0];
            let ya = dot(a, c.inertia_axis, acc[k].da_dq)?;
            let bv = dot(a, c.variation_axis, kin[k].dv_dq)?;
            out.by_coordinates[row * size + col] = a.g.add(ya, bv)?;
            let ya = dot(a, c.inertia_axis, kin[k].da_dv)?;
            let bj = dot(a, c.variation_axis, kin[k].axis)?;
            out.by_speeds[row * size + col] = a.g.add(ya, bj)?;
            if k != i {
                let dq = dot(a, kin[k].axis, by_coordinate[i])?;
                out.by_coordinates[col * size + row] = dq;
                let dv = dot(a, kin[k].axis, c.by_speed)?;
                out.by_speeds[col * size + row] = dv;
            }
            j = tree[k].parent;
        }
    }
    Ok(())
}
