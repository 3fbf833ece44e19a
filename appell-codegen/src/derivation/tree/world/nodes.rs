//! The world-frame tree: each moving link of a one-axis joint as one node,
//! and a free joint at the root as two, its slides (a massless node of
//! three columns fixed in the joint frame) and its turn (the body, three
//! columns fixed in it). A coordinate's change then moves its node's
//! subtree rigidly in every node, the free joint's rotation taken as a
//! turn of the body in its own axes.
//!
//! A free joint's quaternion e writes the quadratic form R(e) = s R̂,
//! s = |e|², and the recursions read R(e) as it is, off the unit sphere
//! too (the tree's `free` module): there the body's velocity is R(e)ᵀ ṗ
//! and gravity R(e)ᵀ g in its axes, and ṗ's rows come out as R(e) times
//! the body's acceleration. That is a body of rotation R̂ whose slides move
//! at s ṗ under gravity s g, with p̈ = s p̈' for its acceleration p̈'.
//! The nodes are placed by R̂ and carry those speeds; [`FreeRoot`] keeps
//! what maps their derivatives back to e and ṗ.

use appell_symbolic::{Id, SymbolicError};

use super::super::links::{self, Link, Parts};
use super::super::spatial::{join, split, Algebra, Transform, M6, V3, V6};
use crate::model::tree::{Motion, TreeSpec};

type R<T> = Result<T, SymbolicError>;

/// One node of the world-frame tree.
pub(super) struct Node {
    /// The parent node; None for the ground.
    pub parent: Option<usize>,
    /// The columns' axes Jᵢ: the motion subspace in world axes about the
    /// world origin.
    pub axes: Vec<V6>,
    /// Each column's speed, in speed order.
    pub speeds: Vec<usize>,
    /// The node's placement in the world.
    pub world: Transform,
    /// The spatial inertia about the node's origin in its axes (None: a
    /// free joint's massless slides).
    pub inertia: Option<M6>,
    /// The joint's input along each column, or 0.
    pub inputs: Vec<Id>,
    /// The free root whose subtree the node is in, by index into
    /// [`World::roots`].
    pub root: Option<usize>,
    /// Whether the node is a free root's slides: their speeds boost the
    /// whole subtree, which changes no force (Galilean invariance), so
    /// inverse dynamics does not depend on them.
    pub slides: bool,
}

/// A free joint at the root: what the reduced rhs's columns by e and ṗ
/// are made of.
pub struct FreeRoot {
    /// The quaternion's coordinates (scalar first), by index among the
    /// model's.
    pub quaternion: [usize; 4],
    /// Their symbols.
    pub e: [Id; 4],
    /// s = |e|².
    pub scale: Id,
    /// The speeds of the body's turn ω, in its axes.
    pub angular: [usize; 3],
    /// The slides' speeds ṗ, in the joint frame's axes.
    pub linear: [usize; 3],
    /// The gravity term of inverse dynamics under gravity s g (zero outside
    /// this root's subtree), in speed order.
    pub gravity: Vec<Id>,
}

/// The world-frame tree of a model's links.
pub(super) struct World {
    /// Parents before children; a free root's slides before its turn.
    pub nodes: Vec<Node>,
    /// The free roots.
    pub roots: Vec<FreeRoot>,
    /// The speeds the nodes move at, in speed order: the model's, but s ṗ
    /// for a free root's slides.
    pub speeds: Vec<Id>,
    /// The coordinate whose change is each speed's column, by index among
    /// the model's: a one-axis joint's, a slide's; None for a free root's
    /// turn.
    pub coordinates: Vec<Option<usize>>,
}

fn unsupported(found: String) -> SymbolicError {
    SymbolicError::DimensionMismatch {
        expected: "a tree of one-axis joints, or a free joint at its root".to_string(),
        found,
    }
}

/// The nodes of `tree` (the links of `spec`), the coordinates in `fixed`
/// at zero.
pub(super) fn world_tree(
    a: &mut Algebra,
    tree: &[Link],
    spec: &TreeSpec,
    parts: &Parts,
    fixed: &[usize],
) -> R<World> {
    let size = parts.speeds.len();
    let mut world = World {
        nodes: Vec::with_capacity(tree.len() + 1),
        roots: Vec::new(),
        speeds: parts.speeds.clone(),
        coordinates: vec![None; size],
    };
    let moving = spec.links.iter().filter(|k| k.motion.is_some());
    // The node each link's children hang from.
    let mut last: Vec<usize> = Vec::with_capacity(tree.len());
    for (link, written) in tree.iter().zip(moving) {
        let parent = link.parent.map(|p| last[p]);
        let root = parent.and_then(|p| world.nodes[p].root);
        match written.motion {
            Some(Motion::Free) if parent.is_none() => {
                free_root(a, &mut world, link, written, parts, fixed)?
            }
            Some(Motion::Free) | Some(Motion::Spherical) => {
                return Err(unsupported(format!(
                    "joint `{}` turns about more than one axis below the root",
                    written.joint
                )))
            }
            _ if link.subspace.len() == 1 && link.free.is_none() => {
                let r = parts.coordinate(&written.coordinates[0])?;
                let q = match fixed.contains(&r) {
                    true => a.zero(),
                    false => parts.coordinates[r],
                };
                let above = parent.map(|p| &world.nodes[p].world);
                let (placed, axis) = placement(a, link, above, q)?;
                let s = link.speeds[0];
                world.coordinates[s] = Some(r);
                world.nodes.push(Node {
                    parent,
                    axes: vec![axis],
                    speeds: vec![s],
                    world: placed,
                    inertia: Some(link.inertia),
                    inputs: vec![link.inputs[0]],
                    root,
                    slides: false,
                });
            }
            _ => return Err(unsupported(format!("joint `{}`", written.joint))),
        }
        last.push(world.nodes.len() - 1);
    }
    if world.nodes.iter().map(|n| n.speeds.len()).sum::<usize>() != size {
        return Err(unsupported("a speed per column".to_string()));
    }
    Ok(world)
}

/// A free joint at the root as its slides' node and its turn's.
fn free_root(
    a: &mut Algebra,
    world: &mut World,
    link: &Link,
    written: &crate::model::tree::LinkSpec,
    parts: &Parts,
    fixed: &[usize],
) -> R<()> {
    let names = &written.coordinates;
    let index = |k: usize| parts.coordinate(&names[k]);
    let quaternion = [index(0)?, index(1)?, index(2)?, index(3)?];
    if quaternion.iter().any(|r| fixed.contains(r)) {
        return Err(unsupported(format!(
            "the orientation of `{}` ignorable",
            written.joint
        )));
    }
    if link.inputs.iter().any(|&i| !a.g.is_zero(i)) {
        return Err(unsupported(format!(
            "free joint `{}` driven",
            written.joint
        )));
    }
    let turn = link
        .free
        .ok_or_else(|| unsupported("a free joint's rotation".to_string()))?;
    let e = quaternion.map(|r| parts.coordinates[r]);
    let scale = a.dot(e.iter().map(|&x| (x, x)))?;
    let scale = a.g.hold(scale)?;
    let over = a.g.recip(scale)?;
    let over = a.g.hold(over)?;
    let mut slide = [a.zero(); 3];
    for k in 0..3 {
        let r = index(4 + k)?;
        world.coordinates[link.speeds[3 + k]] = Some(r);
        if !fixed.contains(&r) {
            slide[k] = parts.coordinates[r];
        }
    }
    let frame = hold_transform(a, &link.frame)?;
    let moved = a.mat_vec(&frame.rot, slide)?;
    let pos = a.add(frame.pos, moved)?;
    let pos = a.hold(pos)?;
    // R̂ = R(e) / s in world axes.
    let mut unit = turn;
    for row in &mut unit {
        for x in row.iter_mut() {
            *x = a.g.mul(*x, over)?;
        }
    }
    let rot = a.mat_mul(&frame.rot, &unit)?;
    let zero = [a.zero(); 3];
    let column = |m: &super::super::spatial::M3, k: usize| [m[0][k], m[1][k], m[2][k]];
    let mut slides = Vec::with_capacity(3);
    let mut turns = Vec::with_capacity(3);
    for k in 0..3 {
        slides.push(a.hold(join(zero, column(&frame.rot, k)))?);
        let along = column(&rot, k);
        let moment = a.cross(pos, along)?;
        turns.push(a.hold(join(along, moment))?);
        let s = link.speeds[3 + k];
        world.speeds[s] = a.g.mul(scale, parts.speeds[s])?;
    }
    let root = Some(world.roots.len());
    let linear = [link.speeds[3], link.speeds[4], link.speeds[5]];
    let angular = [link.speeds[0], link.speeds[1], link.speeds[2]];
    world.nodes.push(Node {
        parent: None,
        axes: slides,
        speeds: linear.to_vec(),
        world: Transform {
            rot: frame.rot,
            pos,
        },
        inertia: None,
        inputs: vec![a.zero(); 3],
        root,
        slides: true,
    });
    let body = Transform { rot, pos };
    world.nodes.push(Node {
        parent: Some(world.nodes.len() - 1),
        axes: turns,
        speeds: angular.to_vec(),
        world: hold_transform(a, &body)?,
        inertia: Some(link.inertia),
        inputs: vec![a.zero(); 3],
        root,
        slides: false,
    });
    world.roots.push(FreeRoot {
        quaternion,
        e,
        scale,
        angular,
        linear,
        gravity: Vec::new(),
    });
    Ok(())
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
    let zero: V3 = [a.zero(); 3];
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
