//! From the lowered tree (its numbers graph nodes, see
//! [`TreeSpec::lower`](crate::model::tree::TreeSpec::lower)) to the links
//! the recursions walk: each moving
//! joint's transform from its parent link (welded links merged into the
//! link they are fixed to), its motion subspace, its inertia, its input.

use appell_symbolic::{Graph, Id, SymbolicError};

use super::spatial::{Algebra, Transform, M3, M6, V3, V6};
use crate::model::tree::{Axis, CentralInertia, MassSpec, Motion, Term, TreeSpec, Turns};
use crate::model::Model;

type R<T> = Result<T, SymbolicError>;

/// One moving link, as the recursions see it.
#[derive(Clone)]
pub struct Link {
    /// The parent's index among the moving links; None for the ground.
    pub parent: Option<usize>,
    /// From the parent link to this one.
    pub transform: Transform,
    /// From the parent link to the joint frame: `transform` before the
    /// joint moves.
    pub frame: Transform,
    /// A revolute joint's rotation of the child in the joint frame.
    pub turn: Option<M3>,
    /// The joint's motion subspace in this link's axes: one column per
    /// speed (one for a revolute or prismatic joint, three for a ball).
    pub subspace: Vec<V6>,
    /// The index of each column's speed among the speeds the recursions
    /// are given.
    pub speeds: Vec<usize>,
    /// The spatial inertia about the origin, in this link's axes (its
    /// welded descendants' included).
    pub inertia: M6,
    /// The joint's input along each column, or 0.
    pub inputs: Vec<Id>,
    /// A free joint's rotation of the child from the joint frame: its
    /// columns turn the child's velocity, in which the recursions run, into
    /// the rates of the joint's slides (see the `free` module beside this one).
    pub free: Option<M3>,
}

/// The symbols the links are written in, in speed order.
pub struct Parts {
    /// q.
    pub coordinates: Vec<Id>,
    /// The coordinates' names, in order.
    coordinate_names: Vec<String>,
    /// The privileged speeds' names, in order.
    speed_names: Vec<String>,
    /// The privileged speeds (the joint rates).
    pub speeds: Vec<Id>,
    /// Their acceleration symbols.
    pub accels: Vec<Id>,
    /// The inputs by name.
    inputs: Vec<(String, Id)>,
}

impl Parts {
    /// The model's symbols, in its own privileged speeds (a plain tree's:
    /// [`Model::constraints`]).
    pub fn new(model: &mut Model) -> R<Parts> {
        let speeds = model.constraints.speed_specs.clone();
        Parts::with_speeds(model, &speeds)
    }

    /// The model's symbols with `speed_specs` as the privileged speeds (a
    /// scene's tree keeps the model's own).
    pub fn with_speeds(model: &mut Model, speed_specs: &[crate::model::SpeedSpec]) -> R<Parts> {
        let g = &mut model.g;
        let coordinates = model
            .coords
            .iter()
            .map(|(_, c)| g.sym(c.q))
            .collect::<R<_>>()?;
        let speeds = speed_specs
            .iter()
            .map(|s| g.sym(s.symbol))
            .collect::<R<_>>()?;
        let accels = speed_specs
            .iter()
            .map(|s| g.sym(s.accel))
            .collect::<R<_>>()?;
        let inputs = model
            .inputs
            .iter()
            .map(|(name, s)| Ok((name.to_string(), g.sym(*s)?)))
            .collect::<R<_>>()?;
        let coordinate_names = model.coords.iter().map(|(c, _)| c.to_string()).collect();
        let speed_names = speed_specs.iter().map(|s| s.name.clone()).collect();
        Ok(Parts {
            coordinates,
            coordinate_names,
            speed_names,
            speeds,
            accels,
            inputs,
        })
    }

    /// The index of the coordinate named `name`.
    pub(super) fn coordinate(&self, name: &str) -> R<usize> {
        let found = self.coordinate_names.iter().position(|c| c == name);
        found.ok_or_else(|| SymbolicError::UnknownSymbol { name: name.into() })
    }

    /// The index of the link's speed named `name`: among the privileged
    /// speeds, or (`Index::Coordinates`) among the coordinates.
    fn speed(&self, name: &str, index: Index) -> R<usize> {
        match index {
            Index::Speeds => {
                let found = self.speed_names.iter().position(|c| c == name);
                found.ok_or_else(|| SymbolicError::UnknownSymbol { name: name.into() })
            }
            Index::Coordinates => self.coordinate(name),
        }
    }
}

/// What the links' speeds are: the privileged speeds (a plain tree), or
/// the coordinates' rates (a tree whose equations are projected, where a
/// ball has no place).
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Index {
    /// The model's privileged speeds.
    Speeds,
    /// The coordinates' rates q̇.
    Coordinates,
}

/// Where a written link ended up: the moving link it is fixed to (None:
/// the ground) and its transform from there.
#[derive(Clone, Copy)]
struct Place {
    moving: Option<usize>,
    from: Transform,
}

/// The moving links of `spec`, the coordinates in `fixed` taken at zero,
/// their speeds indexed as `index` says.
pub fn links(
    g: &mut Graph,
    spec: &TreeSpec,
    parts: &Parts,
    fixed: &[usize],
    index: Index,
) -> R<Vec<Link>> {
    let mut a = Algebra::new(g)?;
    let mut places: Vec<Place> = Vec::with_capacity(spec.links.len());
    let mut out: Vec<Link> = Vec::new();
    for link in &spec.links {
        let parent_frame = Transform {
            rot: turned(&mut a, &link.parent_turns)?,
            pos: terms_vector(&mut a, &link.parent_origin)?,
        };
        let local = placement(&mut a, link.xyz.as_ref(), link.rpy.as_ref())?;
        let placement = compose(&mut a, &parent_frame, &local)?;
        let (moving, before) = match link.parent {
            Some(p) => (places[p].moving, places[p].from),
            None => (None, identity(&mut a)?),
        };
        let joint_frame = compose(&mut a, &before, &placement)?;
        let inertia = link_inertia(&mut a, &link.bodies)?;
        let Some(motion) = &link.motion else {
            // A weld: the link is part of `moving`.
            if let Some(m) = moving {
                let moved = a.congruence(&joint_frame, &inertia)?;
                out[m].inertia = a.add6(&out[m].inertia, &moved)?;
            }
            places.push(Place {
                moving,
                from: joint_frame,
            });
            continue;
        };
        let mut q = Vec::with_capacity(link.coordinates.len());
        for name in &link.coordinates {
            let r = parts.coordinate(name)?;
            q.push(if fixed.contains(&r) {
                a.zero()
            } else {
                parts.coordinates[r]
            });
        }
        let speeds = link
            .speeds
            .iter()
            .map(|s| parts.speed(s, index))
            .collect::<R<Vec<_>>>()?;
        let (transform, subspace, free, turn) = joint(&mut a, &joint_frame, motion, &q)?;
        let input = match parts
            .inputs
            .iter()
            .find(|(n, _)| *n == format!("tau_{}", link.joint))
        {
            Some((_, id)) if link.actuated => *id,
            _ => a.zero(),
        };
        let mut inputs = vec![a.zero(); subspace.len()];
        inputs[0] = input;
        out.push(Link {
            parent: moving,
            transform,
            frame: joint_frame,
            turn,
            subspace,
            speeds,
            inertia,
            inputs,
            free,
        });
        places.push(Place {
            moving: Some(out.len() - 1),
            from: identity(&mut a)?,
        });
    }
    Ok(out)
}

/// The gravity acceleration in N's axes.
pub fn gravity(g: &mut Graph, spec: &TreeSpec) -> R<V3> {
    let mut a = Algebra::new(g)?;
    terms_vector(&mut a, &spec.gravity)
}

/// What a joint contributes: its transform from the parent link, its
/// motion subspace's columns and, for a free joint, its rotation, for a
/// revolute joint, its turn.
type Joint = (Transform, Vec<V6>, Option<M3>, Option<M3>);

/// The joint's transform, subspace and rotation at the coordinates `q`
/// its motion reads.
fn joint(a: &mut Algebra, frame: &Transform, motion: &Motion, q: &[Id]) -> R<Joint> {
    let zero = a.zero();
    match motion {
        Motion::Revolute(axis) => {
            let u = unit_axis(a, axis)?;
            let turn = rotation_about(a, axis, u, q[0])?;
            let rot = a.mat_mul(&frame.rot, &turn)?;
            let s = [u[0], u[1], u[2], zero, zero, zero];
            let pos = frame.pos;
            Ok((Transform { rot, pos }, vec![s], None, Some(turn)))
        }
        Motion::Prismatic(axis) => {
            let u = unit_axis(a, axis)?;
            let along = a.mat_vec(&frame.rot, u)?;
            let slide = a.scale(along, q[0])?;
            let pos = a.add(frame.pos, slide)?;
            let s = [zero, zero, zero, u[0], u[1], u[2]];
            let rot = frame.rot;
            Ok((Transform { rot, pos }, vec![s], None, None))
        }
        Motion::Spherical => {
            let turn = quaternion_rotation(a, [q[0], q[1], q[2], q[3]])?;
            let rot = a.mat_mul(&frame.rot, &turn)?;
            let pos = frame.pos;
            Ok((Transform { rot, pos }, unit_columns(a, 3)?, None, None))
        }
        Motion::Free => {
            let turn = quaternion_rotation(a, [q[0], q[1], q[2], q[3]])?;
            let rot = a.mat_mul(&frame.rot, &turn)?;
            let slide = a.mat_vec(&frame.rot, [q[4], q[5], q[6]])?;
            let pos = a.add(frame.pos, slide)?;
            Ok((
                Transform { rot, pos },
                unit_columns(a, 6)?,
                Some(turn),
                None,
            ))
        }
    }
}

/// The first `k` unit vectors of the spatial axes.
fn unit_columns(a: &mut Algebra, k: usize) -> R<Vec<V6>> {
    let (one, zero) = (a.g.int(1)?, a.zero());
    Ok((0..k)
        .map(|c| {
            let mut s = [zero; 6];
            s[c] = one;
            s
        })
        .collect())
}

/// The rotation by the quaternion e = (e0, e1, e2, e3), scalar first: the
/// child's axes in the joint frame, the quadratic forms the closed form
/// writes (a rotation on the unit sphere the model keeps).
fn quaternion_rotation(a: &mut Algebra, e: [Id; 4]) -> R<M3> {
    let g = &mut *a.g;
    let two = g.int(2)?;
    let mut p = [[e[0]; 4]; 4];
    for i in 0..4 {
        for j in i..4 {
            p[i][j] = g.mul(e[i], e[j])?;
            p[j][i] = p[i][j];
        }
    }
    let mut r = [[e[0]; 3]; 3];
    for i in 0..3 {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        let plus = g.add(p[0][0], p[i + 1][i + 1])?;
        let minus = g.add(p[j + 1][j + 1], p[k + 1][k + 1])?;
        r[i][i] = g.sub(plus, minus)?;
        // (j, i) and (i, j): 2 (e_i e_j ± e0 e_k).
        let lower = g.add(p[i + 1][j + 1], p[0][k + 1])?;
        let upper = g.sub(p[i + 1][j + 1], p[0][k + 1])?;
        r[j][i] = g.mul(two, lower)?;
        r[i][j] = g.mul(two, upper)?;
    }
    Ok(r)
}

/// The axis as a unit vector in the joint frame.
fn unit_axis(a: &mut Algebra, axis: &Axis) -> R<V3> {
    let zero = a.zero();
    match axis {
        Axis::Unit(k, negative) => {
            let mut u = [zero; 3];
            u[*k] = a.g.int(if *negative { -1 } else { 1 })?;
            Ok(u)
        }
        Axis::Components(c) => {
            let v = *c;
            let len2 = a.dot((0..3).map(|i| (v[i], v[i])))?;
            let len = a.g.sqrt(len2)?;
            let inv = a.g.recip(len)?;
            a.scale(v, inv)
        }
    }
}

/// The rotation by `q` about the unit axis `u` (Rodrigues' formula; a
/// simple rotation for a coordinate axis).
fn rotation_about(a: &mut Algebra, axis: &Axis, u: V3, q: Id) -> R<M3> {
    if let Axis::Unit(k, negative) = axis {
        let angle = if *negative { a.g.neg(q)? } else { q };
        return simple(a, *k, angle);
    }
    let (c, s) = (a.g.cos(q)?, a.g.sin(q)?);
    let one = a.g.int(1)?;
    let versine = a.g.sub(one, c)?;
    let mut r = [[a.zero(); 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            let uu = a.g.mul(u[i], u[j])?;
            let mut v = a.g.mul(versine, uu)?;
            if i == j {
                v = a.g.add(v, c)?;
            } else {
                // s ũ: ũ[i][j] = −ε_ijk u_k.
                let k = 3 - i - j;
                let sign = if (i + 1) % 3 == j { -1 } else { 1 };
                let su = a.g.mul(s, u[k])?;
                let term = if sign < 0 { a.g.neg(su)? } else { su };
                v = a.g.add(v, term)?;
            }
            r[i][j] = v;
        }
    }
    Ok(r)
}

/// The rotation about axis `k` by `angle`: the new axes in the old.
fn simple(a: &mut Algebra, k: usize, angle: Id) -> R<M3> {
    let (c, s) = (a.g.cos(angle)?, a.g.sin(angle)?);
    let (one, zero) = (a.g.int(1)?, a.zero());
    let ms = a.g.neg(s)?;
    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
    let mut r = [[zero; 3]; 3];
    r[k][k] = one;
    r[i][i] = c;
    r[j][j] = c;
    r[i][j] = ms;
    r[j][i] = s;
    Ok(r)
}

/// The product of `turns` from a link's axes.
fn turned(a: &mut Algebra, turns: &Turns) -> R<M3> {
    let mut r = identity(a)?.rot;
    for &(k, angle) in turns {
        let t = simple(a, k, angle)?;
        r = a.mat_mul(&r, &t)?;
    }
    Ok(r)
}

/// The joint frame in the parent link: `xyz`, then fixed-axis roll,
/// pitch, yaw (R = Rz(yaw) Ry(pitch) Rx(roll)).
fn placement(a: &mut Algebra, xyz: Option<&[Id; 3]>, rpy: Option<&[Id; 3]>) -> R<Transform> {
    let mut x = identity(a)?;
    if let Some(v) = xyz {
        x.pos = *v;
    }
    if let Some(&[r, p, y]) = rpy {
        let turns = vec![(2, y), (1, p), (0, r)];
        x.rot = turned(a, &turns)?;
    }
    Ok(x)
}

/// The identity transform.
fn identity(a: &mut Algebra) -> R<Transform> {
    let (one, zero) = (a.g.int(1)?, a.zero());
    let mut rot = [[zero; 3]; 3];
    for (i, row) in rot.iter_mut().enumerate() {
        row[i] = one;
    }
    Ok(Transform {
        rot,
        pos: [zero; 3],
    })
}

/// `first`, then `second` in `first`'s axes.
pub(super) fn compose(a: &mut Algebra, first: &Transform, second: &Transform) -> R<Transform> {
    let rot = a.mat_mul(&first.rot, &second.rot)?;
    let moved = a.mat_vec(&first.rot, second.pos)?;
    let pos = a.add(first.pos, moved)?;
    Ok(Transform { rot, pos })
}

/// Σ of `terms` as a vector in the link's axes.
fn terms_vector(a: &mut Algebra, terms: &[Term]) -> R<V3> {
    let mut v = [a.zero(); 3];
    for t in terms {
        let k = t.coefficient;
        let r = turned(a, &t.turns)?;
        let column = [r[0][t.axis], r[1][t.axis], r[2][t.axis]];
        let scaled = a.scale(column, k)?;
        v = a.add(v, scaled)?;
    }
    Ok(v)
}

/// The bodies' spatial inertia about the link's origin, in its axes.
fn link_inertia(a: &mut Algebra, bodies: &[MassSpec]) -> R<M6> {
    let mut total = [[a.zero(); 6]; 6];
    for b in bodies {
        let m = b.mass;
        let c = terms_vector(a, &b.center)?;
        let central = match &b.inertia {
            Some((turns, inertia)) => {
                let r = turned(a, turns)?;
                let own = inertia_matrix(a, inertia)?;
                let ri = a.mat_mul(&r, &own)?;
                let rt = transpose(&r);
                a.mat_mul(&ri, &rt)?
            }
            None => [[a.zero(); 3]; 3],
        };
        let body = a.rigid_inertia(m, c, &central)?;
        total = a.add6(&total, &body)?;
    }
    Ok(total)
}

/// The central inertia as a matrix, in the body's axes.
fn inertia_matrix(a: &mut Algebra, inertia: &CentralInertia) -> R<M3> {
    let mut m = [[a.zero(); 3]; 3];
    match *inertia {
        CentralInertia::Principal(d) => {
            for (i, e) in d.into_iter().enumerate() {
                m[i][i] = e;
            }
        }
        CentralInertia::Matrix(v) => {
            m = [[v[0], v[3], v[5]], [v[3], v[1], v[4]], [v[5], v[4], v[2]]];
        }
    }
    Ok(m)
}

fn transpose(m: &M3) -> M3 {
    let mut t = *m;
    for (i, row) in m.iter().enumerate() {
        for (j, x) in row.iter().enumerate() {
            t[j][i] = *x;
        }
    }
    t
}
