//! Joints, written as the frames, points, coordinates, speeds, inputs and
//! loads they stand for, so a mechanism written with joints and the same
//! mechanism written with frames and points expand identically.
//!
//! `joint(name, kind, parent = A, child = B, xyz = [x, y, z], rpy = [r, p, y])`
//! places the joint frame as URDF does: its origin at A's origin (or at
//! `at = P`) plus x A.x + y A.y + z A.z, its axes A's turned by the
//! fixed-axis roll, pitch, yaw (R = Rz(yaw) Ry(pitch) Rx(roll)); the kind
//! moves the child frame `B` and its origin point `B_origin` from there.

use proc_macro2::Span;
use syn::parse::ParseStream;
use syn::spanned::Spanned;
use syn::{Ident, Token};

use super::expr::convert;
use crate::ast::*;
use crate::parse::keywords as kw;

const KINDS: &str =
    "revolute(axis), prismatic(axis), cylindrical(axis), planar(normal), spherical, free, weld";

pub(super) fn parse_joint(s: ParseStream, span: Span) -> syn::Result<JointDef> {
    let name: Ident = s.parse()?;
    s.parse::<Token![,]>()?;
    let kind = parse_kind(&s.parse::<syn::Expr>()?)?;
    let mut joint = JointDef {
        parent: Ident::new("N", name.span()),
        child: name.clone(),
        name,
        kind,
        at: None,
        xyz: None,
        rpy: None,
        actuated: false,
        dependent: false,
        lock: None,
        elements: Default::default(),
        span,
    };
    let (mut parent, mut child) = (None, None);
    while !s.is_empty() {
        s.parse::<Token![,]>()?;
        if s.is_empty() {
            break;
        }
        let key: Ident = s.parse()?;
        if !s.peek(Token![=]) {
            match key.to_string().as_str() {
                kw::ACTUATED => joint.actuated = true,
                kw::DEPENDENT => joint.dependent = true,
                kw::LOCK => return Err(lock_needs_effect(&key)),
                other => return Err(unknown_property(&key, other)),
            }
            continue;
        }
        s.parse::<Token![=]>()?;
        let value: syn::Expr = s.parse()?;
        if joint.elements.set(&key, &value)? {
            continue;
        }
        match key.to_string().as_str() {
            kw::PARENT => parent = Some(super::items::expr_ident(&value)?),
            kw::CHILD => child = Some(super::items::expr_ident(&value)?),
            kw::AT => joint.at = Some(super::items::expr_ident(&value)?),
            kw::XYZ => joint.xyz = Some(triple(&value, "xyz = [x, y, z]")?),
            kw::RPY => joint.rpy = Some(triple(&value, "rpy = [roll, pitch, yaw]")?),
            kw::LOCK => set_lock(&mut joint, &key, &value)?,
            other => return Err(unknown_property(&key, other)),
        }
    }
    joint.parent = parent.ok_or_else(|| {
        syn::Error::new(
            span,
            format!("joint `{}` needs `parent = A` (a frame, or N)", joint.name),
        )
    })?;
    joint.child = child.ok_or_else(|| {
        syn::Error::new(
            span,
            format!(
                "joint `{}` needs `child = B`, the frame it declares",
                joint.name
            ),
        )
    })?;
    let one_axis = matches!(joint.kind, JointKind::Revolute(_) | JointKind::Prismatic(_));
    if joint.elements.any() && !one_axis {
        return Err(syn::Error::new(
            span,
            "`stiffness`, `damping`, `friction` and `saturation` are for revolute and prismatic joints; load other joints with `torque(...)` and `force(...)`",
        ));
    }
    if joint.elements.saturation.is_some() && !joint.actuated {
        return Err(syn::Error::new(
            span,
            "`saturation` limits the joint's actuation: add the flag `actuated`",
        ));
    }
    if joint.actuated && !one_axis {
        return Err(syn::Error::new(
            span,
            "`actuated` is for revolute and prismatic joints; drive other joints with `torque(...)` and `force(...)`",
        ));
    }
    Ok(joint)
}

/// What to write instead of `lock` on a joint of more (or no) axes; None
/// for a one-axis joint.
fn cannot_lock(joint: &JointDef) -> Option<String> {
    let rates = |names: &[&str]| {
        let q = |s: &&str| format!("`nonholonomic(dt({}{s}) == 0, effect = brake)`", joint.name);
        names.iter().map(q).collect::<Vec<_>>().join(", ")
    };
    let written =
        |rows: String| format!("hold this joint still with {rows}, and mark it `dependent`");
    match joint.kind {
        JointKind::Revolute(_) | JointKind::Prismatic(_) => None,
        JointKind::Cylindrical(_) => Some(written(rates(&["_angle", "_slide"]))),
        JointKind::Planar(_) => Some(written(rates(&["_x", "_y", "_angle"]))),
        JointKind::Weld => Some("a weld joint does not move: there is nothing to lock".into()),
        JointKind::Spherical | JointKind::Free => Some(
            "a spherical or free joint's angular velocity components are always privileged speeds of the model, so no constraint holds it still; write the locked mechanism as a model of its own, with a `weld` joint".into(),
        ),
    }
}

fn lock_needs_effect(at: impl quote::ToTokens) -> syn::Error {
    syn::Error::new_spanned(
        at,
        "`lock` names the effect that holds the joint still: `lock = brake`, kept by the scenes that name `brake`",
    )
}

fn unknown_property(key: &Ident, other: &str) -> syn::Error {
    syn::Error::new(
        key.span(),
        format!("unknown joint property `{other}`; a joint has `parent`, `child`, `xyz`, `rpy`, `at`, `lock`, the elements `stiffness`, `rest`, `damping`, `friction`, `friction_smoothing`, `saturation` and the flags `actuated`, `dependent`"),
    )
}

/// `lock = effect`: one effect, a plain name, on a one-axis joint; the
/// locked joint's rate is not a privileged speed.
fn set_lock(joint: &mut JointDef, key: &Ident, value: &syn::Expr) -> syn::Result<()> {
    if let Some(hint) = cannot_lock(joint) {
        return Err(syn::Error::new(
            key.span(),
            format!("`lock` is for revolute and prismatic joints; {hint}"),
        ));
    }
    if joint.lock.is_some() {
        return Err(syn::Error::new(
            key.span(),
            "a joint takes one `lock`: name its effect in every scene that holds the joint still",
        ));
    }
    let effect = super::items::expr_ident(value).map_err(|_| lock_needs_effect(value))?;
    joint.lock = Some(JointLock {
        at: quote::quote!(#key = #effect),
        effect,
    });
    joint.dependent = true;
    Ok(())
}

fn parse_kind(e: &syn::Expr) -> syn::Result<JointKind> {
    let unknown = |at: Span, what: String| {
        syn::Error::new(
            at,
            format!("unknown joint kind `{what}`; the kinds are {KINDS}"),
        )
    };
    match e {
        syn::Expr::Path(p) => {
            let id = super::items::expr_ident(e)?;
            match id.to_string().as_str() {
                kw::WELD | kw::FIXED => Ok(JointKind::Weld),
                kw::SPHERICAL | kw::BALL => Ok(JointKind::Spherical),
                kw::FREE | kw::FLOATING => Ok(JointKind::Free),
                k @ (kw::REVOLUTE | kw::PRISMATIC | kw::CYLINDRICAL | kw::PLANAR) => {
                    Err(syn::Error::new(
                        p.span(),
                        format!(
                        "`{k}` needs its axis: `{k}(z)` or `{k}([ax, ay, az])`, in the joint frame"
                    ),
                    ))
                }
                other => Err(unknown(p.span(), other.to_string())),
            }
        }
        syn::Expr::Call(c) => {
            let name = super::items::expr_ident(&c.func)?.to_string();
            let [arg] = c.args.iter().collect::<Vec<_>>()[..] else {
                return Err(syn::Error::new(
                    c.span(),
                    format!("`{name}` takes one axis"),
                ));
            };
            let axis = parse_axis(arg)?;
            match name.as_str() {
                kw::REVOLUTE => Ok(JointKind::Revolute(axis)),
                kw::PRISMATIC => Ok(JointKind::Prismatic(axis)),
                kw::CYLINDRICAL => Ok(JointKind::Cylindrical(axis)),
                kw::PLANAR => match axis {
                    JointAxis::Unit(k, _) => Ok(JointKind::Planar(k)),
                    JointAxis::Components(_) => Err(syn::Error::new(
                        arg.span(),
                        "a planar joint's normal is an axis of the joint frame: `planar(z)`; turn the joint frame with `rpy` for another plane",
                    )),
                },
                other => Err(unknown(c.func.span(), other.to_string())),
            }
        }
        other => Err(syn::Error::new(
            other.span(),
            format!("expected the joint's kind: {KINDS}"),
        )),
    }
}

fn parse_axis(e: &syn::Expr) -> syn::Result<JointAxis> {
    let unit = |e: &syn::Expr| match e {
        syn::Expr::Path(p) => match p.path.get_ident().map(|i| i.to_string()).as_deref() {
            Some("x") => Some(0),
            Some("y") => Some(1),
            Some("z") => Some(2),
            _ => None,
        },
        _ => None,
    };
    match e {
        syn::Expr::Unary(u) if matches!(u.op, syn::UnOp::Neg(_)) && unit(&u.expr).is_some() => {
            Ok(JointAxis::Unit(unit(&u.expr).expect("checked"), true))
        }
        syn::Expr::Array(_) => Ok(JointAxis::Components(triple(e, "[ax, ay, az]")?)),
        _ => unit(e).map(|k| JointAxis::Unit(k, false)).ok_or_else(|| {
            syn::Error::new(
                e.span(),
                "a joint axis is `x`, `y`, `z` (or `-z`, ...) of the joint frame, or its components `[ax, ay, az]`",
            )
        }),
    }
}

fn triple(e: &syn::Expr, form: &str) -> syn::Result<[Expr; 3]> {
    match e {
        syn::Expr::Array(a) if a.elems.len() == 3 => {
            let v: Vec<Expr> = a.elems.iter().map(convert).collect::<syn::Result<_>>()?;
            Ok(v.try_into().expect("three"))
        }
        _ => Err(syn::Error::new(e.span(), format!("expected `{form}`"))),
    }
}

/// What one joint adds to the model, in declaration order.
#[derive(Default)]
pub(super) struct Lowered {
    pub frames: Vec<FrameDef>,
    pub points: Vec<PointDef>,
    pub coordinates: Vec<Ident>,
    pub speeds: Vec<Ident>,
    pub inputs: Vec<Ident>,
    pub forces: Vec<LoadDef>,
    pub torques: Vec<LoadDef>,
    /// Quasi-velocities (spherical and free joints).
    pub speed_definitions: Vec<SpeedDef>,
    /// Holonomic constraints (a quaternion's unit norm).
    pub holonomic: Vec<ConstraintDef>,
    /// Velocity constraints (a lock's `dt(q) == 0`).
    pub nonholonomic: Vec<ConstraintDef>,
}

/// The joint's frames, points, coordinates, privileged speeds, inputs and
/// loads; `parent_origin` is the origin of the parent frame (None for a
/// frame not made by a joint, which then needs `at`).
pub(super) fn lower(j: &JointDef, parent_origin: Option<Ident>) -> syn::Result<Lowered> {
    let name = |suffix: &str| Ident::new(&format!("{}{suffix}", j.name), j.name.span());
    let origin_name = Ident::new(&format!("{}_origin", j.child), j.child.span());
    let at = match (&j.at, parent_origin) {
        (Some(p), _) => p.clone(),
        (None, Some(p)) => p,
        (None, None) => {
            return Err(syn::Error::new(
                j.parent.span(),
                format!(
                    "frame `{}` was not made by a joint, so it has no origin: give the joint `at = P`, a point fixed in it",
                    j.parent
                ),
            ))
        }
    };
    let mut out = Lowered::default();
    // The joint frame: the parent's axes turned by rpy, when it turns them.
    let rpy = j.rpy.as_ref().map(rpy_rotations).unwrap_or_default();
    let joint_frame = if rpy.is_empty() {
        j.parent.clone()
    } else {
        let f = name("_frame");
        out.frames.push(FrameDef {
            name: f.clone(),
            parent: j.parent.clone(),
            rotations: rpy,
            quaternion: None,
        });
        f
    };
    let offset = j
        .xyz
        .as_ref()
        .filter(|v| !v.iter().all(is_zero))
        .map(|v| in_frame(&j.parent, v));
    let joint_origin = plus(Expr::Name(at), offset);
    let coordinate = |suffix: &str, out: &mut Lowered| {
        let q = name(suffix);
        out.coordinates.push(q.clone());
        if !j.dependent {
            out.speeds.push(q.clone());
        }
        Expr::Name(q)
    };
    let (rotations, slide) = match &j.kind {
        JointKind::Revolute(axis) => (
            vec![turn(axis, &joint_frame, coordinate("", &mut out))],
            None,
        ),
        JointKind::Prismatic(axis) => {
            let q = coordinate("", &mut out);
            (
                Vec::new(),
                Some(Expr::product(q, unit_vector(axis, &j.child))),
            )
        }
        JointKind::Cylindrical(axis) => {
            let angle = coordinate("_angle", &mut out);
            let s = coordinate("_slide", &mut out);
            (
                vec![turn(axis, &joint_frame, angle)],
                Some(Expr::product(s, unit_vector(axis, &j.child))),
            )
        }
        JointKind::Planar(k) => {
            let (x, y) = (coordinate("_x", &mut out), coordinate("_y", &mut out));
            let angle = coordinate("_angle", &mut out);
            let span = j.name.span();
            let along = |i: usize| Expr::Axis(joint_frame.clone(), (k + i) % 3, span);
            let slide = Expr::sum(Expr::product(x, along(1)), Expr::product(y, along(2)));
            (vec![(RotationAxis::Parent(*k), angle)], Some(slide))
        }
        JointKind::Weld => (Vec::new(), None),
        JointKind::Spherical | JointKind::Free => (Vec::new(), None),
    };
    let (quaternion, slide) = match j.kind {
        JointKind::Spherical => (Some(ball(j, &mut out)), slide),
        JointKind::Free => {
            let e = ball(j, &mut out);
            let span = j.name.span();
            let mut slide = None;
            for (k, axis) in ["_x", "_y", "_z"].into_iter().enumerate() {
                let x = coordinate(axis, &mut out);
                let term = Expr::product(x, Expr::Axis(joint_frame.clone(), k, span));
                slide = Some(match slide {
                    Some(s) => Expr::sum(s, term),
                    None => term,
                });
            }
            (Some(e), slide)
        }
        _ => (None, slide),
    };
    out.frames.push(FrameDef {
        name: j.child.clone(),
        parent: joint_frame,
        rotations,
        quaternion,
    });
    out.points.push(PointDef {
        name: origin_name.clone(),
        location: plus(joint_origin.clone(), slide),
    });
    drives_and_lock(j, &mut out, &origin_name, &joint_origin);
    Ok(out)
}

/// The joint's actuation (input `tau_<joint>`, saturated if asked), its
/// springs, dampers and friction along its axis, and its lock.
fn drives_and_lock(j: &JointDef, out: &mut Lowered, origin_name: &Ident, joint_origin: &Expr) {
    let name = |suffix: &str| Ident::new(&format!("{}{suffix}", j.name), j.name.span());
    if j.actuated {
        let tau = Ident::new(&format!("tau_{}", j.name), j.name.span());
        out.inputs.push(tau.clone());
        let mut magnitude = Expr::Name(tau);
        if let Some(limit) = &j.elements.saturation {
            // max(−limit, min(limit, τ))
            let span = j.name.span();
            let call =
                |f: &str, a: Expr, b: Expr| Expr::Call(Ident::new(f, span), vec![a, b], span);
            let upper = call("min", limit.clone(), magnitude);
            magnitude = call("max", Expr::Neg(Box::new(limit.clone()), span), upper);
        }
        let effect = Ident::new("actuation", j.name.span());
        let at = name("_at");
        along_axis(
            j,
            out,
            magnitude,
            effect,
            origin_name,
            joint_origin.clone(),
            at,
        );
    }
    for (magnitude, effect) in j.elements.torques(&j.name) {
        let at = name(&format!("_{effect}_at"));
        along_axis(
            j,
            out,
            magnitude,
            effect,
            origin_name,
            joint_origin.clone(),
            at,
        );
    }
    if let Some(lock) = &j.lock {
        out.nonholonomic.push(locked(&j.name, lock));
    }
}

/// `dt(q) == 0` on a locked joint's coordinate `q`, of the lock's effect.
fn locked(q: &Ident, lock: &JointLock) -> ConstraintDef {
    let span = lock.effect.span();
    let rate = Expr::Call(Ident::new("dt", span), vec![Expr::Name(q.clone())], span);
    ConstraintDef {
        lhs: rate,
        rhs: Expr::Int(0, span),
        along: None,
        effect: Some(lock.effect.clone()),
        at: lock.at.clone(),
    }
}

/// A ball's quaternion coordinates, its unit-norm constraint and its
/// angular-velocity speeds ω = 2 (e0 ė − ė0 e⃗ − e⃗ × ė), the child's
/// angular velocity relative to the joint frame in the child's axes (on
/// the unit sphere; Method III).
fn ball(j: &JointDef, out: &mut Lowered) -> Box<[Expr; 4]> {
    let span = j.name.span();
    let named = |suffix: &str| Ident::new(&format!("{}{suffix}", j.name), span);
    let e: [Ident; 4] = ["_qw", "_qx", "_qy", "_qz"].map(named);
    out.coordinates.extend(e.iter().cloned());
    let name = |i: &Ident| Expr::Name(i.clone());
    let rate = |i: &Ident| Expr::Call(Ident::new("dt", span), vec![name(i)], span);
    let sub = |a: Expr, b: Expr| Expr::Binary(BinOp::Sub, Box::new(a), Box::new(b), span);
    for (k, w) in ["_wx", "_wy", "_wz"].into_iter().enumerate() {
        let (i, a, b) = (k + 1, (k + 1) % 3 + 1, (k + 2) % 3 + 1);
        let linear = sub(
            Expr::product(name(&e[0]), rate(&e[i])),
            Expr::product(rate(&e[0]), name(&e[i])),
        );
        let cross = sub(
            Expr::product(name(&e[a]), rate(&e[b])),
            Expr::product(name(&e[b]), rate(&e[a])),
        );
        let definition = Expr::product(Expr::Int(2, span), sub(linear, cross));
        out.speed_definitions.push(SpeedDef {
            name: named(w),
            definition: Some(definition),
        });
    }
    let norm = e
        .iter()
        .map(|x| Expr::product(name(x), name(x)))
        .reduce(Expr::sum)
        .expect("four");
    out.holonomic.push(ConstraintDef {
        lhs: norm,
        rhs: Expr::Int(1, span),
        along: None,
        effect: None,
        at: quote::quote_spanned!(span=> #(#e)*),
    });
    Box::new(e.map(Expr::Name))
}

/// A generalized torque (force) `magnitude` on the joint as loads: a torque
/// about the axis on the child and its reaction on the parent (revolute),
/// or a force along it at the child's origin and its reaction at the
/// parent's point there, named `at` (prismatic). The parent N takes no
/// reaction: it does not move.
fn along_axis(
    j: &JointDef,
    out: &mut Lowered,
    magnitude: Expr,
    effect: Ident,
    child_origin: &Ident,
    joint_origin: Expr,
    at: Ident,
) {
    let span = j.name.span();
    let on_parent = j.parent != "N";
    let load = |target: Ident, vector: Expr| LoadDef {
        target,
        vector,
        effect: effect.clone(),
    };
    match &j.kind {
        JointKind::Revolute(axis) => {
            let v = Expr::product(magnitude, unit_vector(axis, &j.child));
            out.torques.push(load(j.child.clone(), v.clone()));
            if on_parent {
                out.torques
                    .push(load(j.parent.clone(), Expr::Neg(Box::new(v), span)));
            }
        }
        JointKind::Prismatic(axis) => {
            let v = Expr::product(magnitude, unit_vector(axis, &j.child));
            out.forces.push(load(child_origin.clone(), v.clone()));
            if on_parent {
                out.points.push(PointDef {
                    name: at.clone(),
                    location: joint_origin,
                });
                out.forces.push(load(at, Expr::Neg(Box::new(v), span)));
            }
        }
        _ => unreachable!("checked when parsed"),
    }
}

/// The rotations of fixed-axis roll, pitch, yaw (R = Rz(yaw) Ry(pitch)
/// Rx(roll)) as a frame chain: yaw, then pitch and roll about the new
/// axes; literal zero angles are left out.
pub(super) fn rpy_rotations([r, p, y]: &[Expr; 3]) -> Vec<(RotationAxis, Expr)> {
    [(2, y), (1, p), (0, r)]
        .into_iter()
        .filter(|(_, a)| !is_zero(a))
        .map(|(k, a)| (RotationAxis::Parent(k), a.clone()))
        .collect()
}

/// The rotation of a joint about its axis by `angle`.
fn turn(axis: &JointAxis, joint_frame: &Ident, angle: Expr) -> (RotationAxis, Expr) {
    match axis {
        JointAxis::Unit(k, false) => (RotationAxis::Parent(*k), angle),
        JointAxis::Unit(k, true) => {
            let span = angle.span();
            (RotationAxis::Parent(*k), Expr::Neg(Box::new(angle), span))
        }
        JointAxis::Components(c) => (RotationAxis::Vector(in_frame(joint_frame, c)), angle),
    }
}

/// The axis as a unit vector written with `frame`'s unit vectors.
fn unit_vector(axis: &JointAxis, frame: &Ident) -> Expr {
    let span = frame.span();
    match axis {
        JointAxis::Unit(k, negative) => {
            let e = Expr::Axis(frame.clone(), *k, span);
            if *negative {
                Expr::Neg(Box::new(e), span)
            } else {
                e
            }
        }
        JointAxis::Components(c) => {
            Expr::Call(Ident::new("unit", span), vec![in_frame(frame, c)], span)
        }
    }
}

/// c0 F.x + c1 F.y + c2 F.z, leaving out literal zero components.
pub(super) fn in_frame(frame: &Ident, c: &[Expr; 3]) -> Expr {
    let span = frame.span();
    let terms: Vec<Expr> = c
        .iter()
        .enumerate()
        .filter(|(_, e)| !is_zero(e))
        .map(|(k, e)| Expr::product(e.clone(), Expr::Axis(frame.clone(), k, span)))
        .collect();
    terms
        .into_iter()
        .reduce(Expr::sum)
        .unwrap_or_else(|| Expr::product(Expr::Int(0, span), Expr::Axis(frame.clone(), 0, span)))
}

pub(super) fn is_zero(e: &Expr) -> bool {
    match e {
        Expr::Int(0, _) => true,
        Expr::Float(x, _) => *x == 0.0,
        Expr::Neg(inner, _) => is_zero(inner),
        _ => false,
    }
}

fn plus(point: Expr, offset: Option<Expr>) -> Expr {
    match offset {
        Some(v) => Expr::sum(point, v),
        None => point,
    }
}
