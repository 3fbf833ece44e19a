//! From the tree as written to the links the recursions walk: each moving
//! joint's transform from its parent link (welded links merged into the
//! link they are fixed to), its motion subspace, its inertia, its input.

use appell_symbolic::{Func, Graph, Id, SymbolicError};

use super::spatial::{Algebra, Transform, M3, M6, V3, V6};
use crate::ast::{BinOp, Expr, Inertia};
use crate::model::tree::{Motion, Term, TreeSpec, Turns};
use crate::model::Model;
use crate::parse::joints::JointAxis;

type R<T> = Result<T, SymbolicError>;

/// One moving link, as the recursions see it.
#[derive(Clone)]
pub struct Link {
    /// The parent's index among the moving links; None for the ground.
    pub parent: Option<usize>,
    /// From the parent link to this one.
    pub transform: Transform,
    /// The joint's motion subspace in this link's axes.
    pub subspace: V6,
    /// The spatial inertia about the origin, in this link's axes (its
    /// welded descendants' included).
    pub inertia: M6,
    /// The joint's input, or 0.
    pub input: Id,
}

/// The symbols the links are written in, in speed order.
pub struct Parts {
    /// q.
    pub coordinates: Vec<Id>,
    /// The privileged speeds (the joint rates).
    pub speeds: Vec<Id>,
    /// Their acceleration symbols.
    pub accels: Vec<Id>,
    /// The inputs by name.
    inputs: Vec<(String, Id)>,
}

impl Parts {
    /// The model's symbols.
    pub fn new(model: &mut Model) -> R<Parts> {
        let g = &mut model.g;
        let coordinates = model
            .coords
            .iter()
            .map(|(_, c)| g.sym(c.q))
            .collect::<R<_>>()?;
        let speeds = model
            .speed_specs
            .iter()
            .map(|s| g.sym(s.symbol))
            .collect::<R<_>>()?;
        let accels = model
            .speed_specs
            .iter()
            .map(|s| g.sym(s.accel))
            .collect::<R<_>>()?;
        let inputs = model
            .inputs
            .iter()
            .map(|(name, s)| Ok((name.to_string(), g.sym(*s)?)))
            .collect::<R<_>>()?;
        Ok(Parts {
            coordinates,
            speeds,
            accels,
            inputs,
        })
    }
}

/// Where a written link ended up: the moving link it is fixed to (None:
/// the ground) and its transform from there.
#[derive(Clone, Copy)]
struct Place {
    moving: Option<usize>,
    from: Transform,
}

/// The moving links of `spec`, the coordinates in `fixed` taken at zero.
pub fn links(g: &mut Graph, spec: &TreeSpec, parts: &Parts, fixed: &[usize]) -> R<Vec<Link>> {
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
        let k = out.len();
        let q = if fixed.contains(&k) {
            a.zero()
        } else {
            parts.coordinates[k]
        };
        let (transform, subspace) = joint(&mut a, &joint_frame, motion, q)?;
        let input = match parts
            .inputs
            .iter()
            .find(|(n, _)| *n == format!("tau_{}", link.joint))
        {
            Some((_, id)) if link.actuated => *id,
            _ => a.zero(),
        };
        out.push(Link {
            parent: moving,
            transform,
            subspace,
            inertia,
            input,
        });
        places.push(Place {
            moving: Some(k),
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

/// The joint's transform from the parent link and its motion subspace.
fn joint(a: &mut Algebra, frame: &Transform, motion: &Motion, q: Id) -> R<(Transform, V6)> {
    let zero = a.zero();
    match motion {
        Motion::Revolute(axis) => {
            let u = unit_axis(a, axis)?;
            let turn = rotation_about(a, axis, u, q)?;
            let rot = a.mat_mul(&frame.rot, &turn)?;
            let s = [u[0], u[1], u[2], zero, zero, zero];
            Ok((
                Transform {
                    rot,
                    pos: frame.pos,
                },
                s,
            ))
        }
        Motion::Prismatic(axis) => {
            let u = unit_axis(a, axis)?;
            let along = a.mat_vec(&frame.rot, u)?;
            let slide = a.scale(along, q)?;
            let pos = a.add(frame.pos, slide)?;
            let s = [zero, zero, zero, u[0], u[1], u[2]];
            Ok((
                Transform {
                    rot: frame.rot,
                    pos,
                },
                s,
            ))
        }
    }
}

/// The axis as a unit vector in the joint frame.
fn unit_axis(a: &mut Algebra, axis: &JointAxis) -> R<V3> {
    let zero = a.zero();
    match axis {
        JointAxis::Unit(k, negative) => {
            let mut u = [zero; 3];
            u[*k] = a.g.int(if *negative { -1 } else { 1 })?;
            Ok(u)
        }
        JointAxis::Components(c) => {
            let mut v = [zero; 3];
            for (i, e) in c.iter().enumerate() {
                v[i] = constant(a.g, e)?;
            }
            let len2 = a.dot((0..3).map(|i| (v[i], v[i])))?;
            let len = a.g.sqrt(len2)?;
            let inv = a.g.recip(len)?;
            a.scale(v, inv)
        }
    }
}

/// The rotation by `q` about the unit axis `u` (Rodrigues' formula; a
/// simple rotation for a coordinate axis).
fn rotation_about(a: &mut Algebra, axis: &JointAxis, u: V3, q: Id) -> R<M3> {
    if let JointAxis::Unit(k, negative) = axis {
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
    for (k, angle) in turns {
        let angle = constant(a.g, angle)?;
        let t = simple(a, *k, angle)?;
        r = a.mat_mul(&r, &t)?;
    }
    Ok(r)
}

/// The joint frame in the parent link: `xyz`, then fixed-axis roll,
/// pitch, yaw (R = Rz(yaw) Ry(pitch) Rx(roll)).
fn placement(a: &mut Algebra, xyz: Option<&[Expr; 3]>, rpy: Option<&[Expr; 3]>) -> R<Transform> {
    let mut x = identity(a)?;
    if let Some(v) = xyz {
        for (i, e) in v.iter().enumerate() {
            x.pos[i] = constant(a.g, e)?;
        }
    }
    if let Some([r, p, y]) = rpy {
        let turns = vec![(2, y.clone()), (1, p.clone()), (0, r.clone())];
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
fn compose(a: &mut Algebra, first: &Transform, second: &Transform) -> R<Transform> {
    let rot = a.mat_mul(&first.rot, &second.rot)?;
    let moved = a.mat_vec(&first.rot, second.pos)?;
    let pos = a.add(first.pos, moved)?;
    Ok(Transform { rot, pos })
}

/// Σ of `terms` as a vector in the link's axes.
fn terms_vector(a: &mut Algebra, terms: &[Term]) -> R<V3> {
    let mut v = [a.zero(); 3];
    for t in terms {
        let k = constant(a.g, &t.coefficient)?;
        let r = turned(a, &t.turns)?;
        let column = [r[0][t.axis], r[1][t.axis], r[2][t.axis]];
        let scaled = a.scale(column, k)?;
        v = a.add(v, scaled)?;
    }
    Ok(v)
}

/// The bodies' spatial inertia about the link's origin, in its axes.
fn link_inertia(a: &mut Algebra, bodies: &[crate::model::tree::MassSpec]) -> R<M6> {
    let mut total = [[a.zero(); 6]; 6];
    for b in bodies {
        let m = constant(a.g, &b.mass)?;
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

/// The central inertia as written, in the body's axes.
fn inertia_matrix(a: &mut Algebra, inertia: &Inertia) -> R<M3> {
    let mut m = [[a.zero(); 3]; 3];
    match inertia {
        Inertia::Principal(d) => {
            for (i, e) in d.iter().enumerate() {
                m[i][i] = constant(a.g, e)?;
            }
        }
        Inertia::Matrix(e) => {
            let v: Vec<Id> = e.iter().map(|x| constant(a.g, x)).collect::<R<_>>()?;
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

/// A constant of the model language (numbers and parameters) in the
/// graph; the tree's checks admitted only those.
pub fn constant(g: &mut Graph, e: &Expr) -> R<Id> {
    match e {
        Expr::Int(i, _) => g.int(*i),
        Expr::Float(x, _) => g.float(*x),
        Expr::Name(n) => match g.symbol_named(&n.to_string()) {
            Some(s) => g.sym(s),
            None => Err(SymbolicError::UnknownSymbol {
                name: n.to_string(),
            }),
        },
        Expr::Neg(x, _) => {
            let x = constant(g, x)?;
            g.neg(x)
        }
        Expr::Binary(op, x, y, _) => {
            let (x, y) = (constant(g, x)?, constant(g, y)?);
            match op {
                BinOp::Add => g.add(x, y),
                BinOp::Sub => g.sub(x, y),
                BinOp::Mul => g.mul(x, y),
                BinOp::Div => g.div(x, y),
            }
        }
        Expr::Call(f, args, _) if args.len() == 1 => {
            let x = constant(g, &args[0])?;
            match Func::from_name(&f.to_string()) {
                Some(func) => g.func(func, x),
                None => Err(SymbolicError::UnknownSymbol {
                    name: f.to_string(),
                }),
            }
        }
        _ => Err(SymbolicError::UnknownSymbol {
            name: "a vector in a scalar".into(),
        }),
    }
}
