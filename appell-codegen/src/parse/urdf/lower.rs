//! The robot as model items: the root link's frame and origin, a
//! `joint(...)` per URDF joint, a `body(...)` per link with mass, and a
//! holonomic constraint per mimic joint.

use proc_macro2::Span;
use syn::Ident;

use super::numbers::{angles, floats, slot, JointNumbers, LinkNumbers, JOINT_FIELDS, LINK_FIELDS};
use super::options::{Base, Promotion, Spec};
use super::read::Read;
use super::tree::Tree;
use crate::ast::*;
use crate::ctxt::{did_you_mean, suggest, Ctxt};
use crate::parse::joints::{in_frame, is_zero, rpy_rotations};

/// Writes the robot into `ast`. Errors about elements go to `cx` (all of
/// them); the result's error is one that stops the lowering.
pub(super) fn lower(
    cx: &Ctxt,
    ast: &mut ModelAst,
    read: &Read,
    tree: &Tree,
    spec: &Spec,
) -> syn::Result<()> {
    let span = spec.path.span();
    let robot = &read.robot;
    let mut joints: Vec<JointNumbers> = robot
        .joints
        .iter()
        .map(|j| JointNumbers {
            xyz: floats(&j.origin.xyz.0, span),
            rpy: angles(&j.origin.rpy.0, span, spec.right_angles),
        })
        .collect();
    let mut links: Vec<LinkNumbers> = robot
        .links
        .iter()
        .map(|l| {
            let (i, o) = (&l.inertial.inertia, &l.inertial.origin);
            LinkNumbers {
                mass: Expr::Float(l.inertial.mass.value, span),
                xyz: floats(&o.xyz.0, span),
                rpy: angles(&o.rpy.0, span, spec.right_angles),
                inertia: [i.ixx, i.iyy, i.izz, i.ixy, i.iyz, i.ixz].map(|x| Expr::Float(x, span)),
                promoted: Vec::new(),
            }
        })
        .collect();
    for p in &spec.parameters {
        promote(cx, tree, p, &mut joints, &mut links);
    }
    let welded = welds(cx, robot, tree, &spec.welds);
    let kinds = kinds(cx, read, &welded, span);
    let origins: Vec<([Expr; 3], [Expr; 3])> = joints
        .iter()
        .map(|j| (j.xyz.clone(), j.rpy.clone()))
        .collect();
    let bodies = super::bodies::bodies(cx, read, tree, spec, &kinds, &origins, &mut links);
    if cx.has_errors() {
        return Ok(());
    }
    unloaded(cx, read, tree, spec, &kinds, &bodies.body);
    if cx.has_errors() {
        return Ok(());
    }
    for &l in &bodies.unchecked {
        ast.unchecked_inertia.push(tree.links[l].to_string());
    }
    root(ast, tree, spec)?;
    let body_of = |ast: &mut ModelAst, l: usize| {
        if bodies.body[l] {
            body(ast, &tree.links[l], &links[l], span);
        } else {
            ast.massless_links.push(tree.links[l].to_string());
        }
    };
    body_of(ast, tree.root);
    for &j in &tree.order {
        let urdf = &robot.joints[j];
        let (parent, child) = tree.ends[j];
        let kind = kinds[j].clone().expect("checked");
        let mimic = spec.mimic && urdf.mimic.is_some() && !matches!(kind, JointKind::Weld);
        let joint = JointDef {
            name: tree.joints[j].clone(),
            actuated: matches!(kind, JointKind::Revolute(_) | JointKind::Prismatic(_)) && !mimic,
            kind,
            parent: tree.links[parent].clone(),
            child: tree.links[child].clone(),
            at: None,
            xyz: Some(joints[j].xyz.clone()),
            rpy: Some(joints[j].rpy.clone()),
            dependent: mimic,
            lock: None,
            elements: Default::default(),
            span,
        };
        if matches!(joint.kind, JointKind::Revolute(_) | JointKind::Prismatic(_)) {
            ast.joint_limits
                .push((joint.name.to_string(), limits(urdf)));
        }
        crate::parse::add_joint(ast, &joint)?;
        body_of(ast, child);
    }
    mimics(cx, ast, read, tree, spec, &welded);
    record_names(ast, robot, tree);
    Ok(())
}

/// A joint's lower, upper, velocity and effort limits as written; a
/// continuous joint's positions are unbounded.
fn limits(j: &urdf_rs::Joint) -> [f64; 4] {
    let l = &j.limit;
    match j.joint_type {
        urdf_rs::JointType::Continuous => [f64::NEG_INFINITY, f64::INFINITY, l.velocity, l.effort],
        _ => [l.lower, l.upper, l.velocity, l.effort],
    }
}

/// An error for each joint that moves no body: its speed has no inertia,
/// a zero row in the mass matrix, and the accelerations are undefined
/// (Pinocchio loads such a robot, and its ABA gives NaN: Romeo's hands,
/// whose fingers are links without inertial). A joint moves a body when a
/// link below it is one, or when a mimic joint that does is tied to it.
fn unloaded(
    cx: &Ctxt,
    read: &Read,
    tree: &Tree,
    spec: &Spec,
    kinds: &[Option<JointKind>],
    body: &[bool],
) {
    let robot = &read.robot;
    // Whether the subtree below each link has a body, leaves first.
    let mut loaded = body.to_vec();
    for &j in tree.order.iter().rev() {
        let (p, c) = tree.ends[j];
        loaded[p] |= loaded[c];
    }
    let moving = |j: usize| !matches!(kinds[j], Some(JointKind::Weld) | None);
    let mimicked = |j: usize| spec.mimic && moving(j) && robot.joints[j].mimic.is_some();
    // Joints loaded through the mimic joints tied to them (chains too).
    let mut carries: Vec<bool> = (0..robot.joints.len())
        .map(|j| loaded[tree.ends[j].1])
        .collect();
    loop {
        let mut changed = false;
        for j in 0..robot.joints.len() {
            if !(mimicked(j) && carries[j]) {
                continue;
            }
            let name = &robot.joints[j].mimic.as_ref().expect("mimic").joint;
            if let Some(o) = robot.joints.iter().position(|x| x.name == *name) {
                if !carries[o] {
                    carries[o] = true;
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
    let span = spec.path.span();
    for &j in &tree.order {
        if !moving(j) || mimicked(j) || carries[j] {
            continue;
        }
        let name = &tree.joints[j];
        cx.error_at(
            span,
            format!(
                "URDF {}: it moves no link with mass, so nothing resists its acceleration (a zero row of the mass matrix; Pinocchio's ABA gives NaN for it): `weld({name})` among the `urdf(...)` options fixes it at 0, or give a link it moves an `<inertial>`",
                read.lines.describe("joint", &robot.joints[j].name)
            ),
        );
    }
}

/// Replaces a number by the expression `parameters(...)` gives for it.
fn promote(
    cx: &Ctxt,
    tree: &Tree,
    p: &Promotion,
    joints: &mut [JointNumbers],
    links: &mut [LinkNumbers],
) {
    let field = p.field_text();
    let joint = tree.joints.iter().position(|j| *j == p.element);
    let link = tree.links.iter().position(|l| *l == p.element);
    let (target, fields) = match (joint, link) {
        (Some(j), None) => {
            let n = &mut joints[j];
            (slot(&mut n.xyz, &mut n.rpy, &field), JOINT_FIELDS)
        }
        (None, Some(l)) => {
            links[l].promoted.push(field.clone());
            (links[l].slot(&field), LINK_FIELDS)
        }
        (Some(_), Some(_)) => {
            cx.error_spanned_by(
                &p.element,
                format!("`{}` is both a link and a joint of the URDF", p.element),
            );
            return;
        }
        (None, None) => {
            let all = tree.joints.iter().chain(&tree.links).map(|i| i.to_string());
            let hint = hint(&p.element.to_string(), all);
            cx.error_spanned_by(
                &p.element,
                format!("`{}` is not a link or joint of the URDF{hint}", p.element),
            );
            return;
        }
    };
    match target {
        Some(slot) => *slot = p.value.clone(),
        None => {
            let hint = did_you_mean(&field, fields.iter().copied())
                .map(|s| format!(" (did you mean `{s}`?)"))
                .unwrap_or_default();
            let kind = if joint.is_some() { "joint" } else { "link" };
            cx.error_spanned_by(
                &p.field[0],
                format!(
                    "a {kind} has no number `{field}`{hint}; a {kind}'s numbers are {}",
                    fields.join(", ")
                ),
            );
        }
    }
}

/// Which joints `weld(...)` names; an error for a name that is no joint or
/// a joint that is already fixed.
fn welds(cx: &Ctxt, robot: &urdf_rs::Robot, tree: &Tree, names: &[Ident]) -> Vec<bool> {
    let mut welded = vec![false; tree.joints.len()];
    for name in names {
        match tree.joints.iter().position(|j| j == name) {
            Some(j) if robot.joints[j].joint_type == urdf_rs::JointType::Fixed => {
                cx.error_spanned_by(
                    name,
                    format!("joint `{name}` is fixed already; `weld` is for movable joints"),
                );
            }
            Some(j) => welded[j] = true,
            None => {
                let hint = hint(&name.to_string(), tree.joints.iter().map(|j| j.to_string()));
                cx.error_spanned_by(name, format!("`{name}` is not a joint of the URDF{hint}"));
            }
        }
    }
    welded
}

/// Each joint's kind in the model (`None` where it has none, reported).
fn kinds(cx: &Ctxt, read: &Read, welded: &[bool], span: Span) -> Vec<Option<JointKind>> {
    let mut out = Vec::new();
    for (j, weld) in read.robot.joints.iter().zip(welded) {
        let kind = if *weld {
            Ok(JointKind::Weld)
        } else {
            kind(j, span)
        };
        out.push(match kind {
            Ok(k) => Some(k),
            Err(e) => {
                cx.error_at(
                    span,
                    format!("URDF {}: {e}", read.lines.describe("joint", &j.name)),
                );
                None
            }
        })
    }
    out
}

fn kind(j: &urdf_rs::Joint, span: Span) -> Result<JointKind, String> {
    use urdf_rs::JointType as T;
    Ok(match j.joint_type {
        T::Revolute | T::Continuous => JointKind::Revolute(axis(j, span)?),
        T::Prismatic => JointKind::Prismatic(axis(j, span)?),
        T::Fixed => JointKind::Weld,
        T::Planar => match axis(j, span)? {
            JointAxis::Unit(k, false) => JointKind::Planar(k),
            _ => return Err(format!(
                "a planar joint's axis (its plane's normal) must be x, y or z of its frame, not {:?}; turn the joint frame with `rpy` instead",
                j.axis.xyz.0
            )),
        },
        T::Floating => JointKind::Free,
        T::Spherical => JointKind::Spherical,
    })
}

/// The joint's axis: `Unit` when it is exactly ±x, ±y or ±z, else its
/// components (normalized by the joint).
fn axis(j: &urdf_rs::Joint, span: Span) -> Result<JointAxis, String> {
    let a = j.axis.xyz.0;
    if a.iter().any(|x| !x.is_finite()) || a.iter().all(|x| *x == 0.0) {
        return Err(format!("its axis {a:?} is not a direction"));
    }
    let nonzero: Vec<usize> = (0..3).filter(|&k| a[k] != 0.0).collect();
    Ok(match nonzero[..] {
        [k] if a[k].abs() == 1.0 => JointAxis::Unit(k, a[k] < 0.0),
        _ => JointAxis::Components(floats(&a, span)),
    })
}

/// The root link: a frame with the parent's axes (N's unless `parent = A`)
/// and its origin point at `at` (the parent's origin unless given).
fn root(ast: &mut ModelAst, tree: &Tree, spec: &Spec) -> syn::Result<()> {
    let span = spec.path.span();
    let name = tree.links[tree.root].clone();
    let parent = spec.parent.clone().unwrap_or_else(|| Ident::new("N", span));
    let at = match &spec.at {
        Some(p) => p.clone(),
        None if parent == "N" => Ident::new("O", span),
        None => match ast.origins.iter().find(|(f, _)| *f == parent) {
            Some((_, p)) => p.clone(),
            None => {
                if let Some(e) = crate::parse::unknown_parent(ast, &parent) {
                    return Err(e);
                }
                return Err(syn::Error::new(
                    parent.span(),
                    format!("frame `{parent}` was not made by a joint, so it has no origin: give `at = P`, a point fixed in it, for the URDF's root link"),
                ));
            }
        },
    };
    if spec.base != Base::Fixed {
        return floating_root(ast, spec, name, parent);
    }
    let origin = Ident::new(&format!("{name}_origin"), span);
    ast.frames.push(FrameDef {
        name: name.clone(),
        parent,
        rotations: Vec::new(),
        quaternion: None,
    });
    ast.points.push(PointDef {
        name: origin.clone(),
        location: Expr::Name(at),
    });
    ast.origins.push((name, origin));
    Ok(())
}

/// The root link on a joint of its own, `root_joint` (Pinocchio's name for
/// the joint `buildModel(urdf, JointModelFreeFlyer())` adds): free (unit
/// quaternion `root_joint_qw, _qx, _qy, _qz` and translation
/// `root_joint_x, _y, _z` along the parent's axes) or planar about the
/// parent's z axis (`root_joint_x, _y, _angle`).
fn floating_root(ast: &mut ModelAst, spec: &Spec, link: Ident, parent: Ident) -> syn::Result<()> {
    let span = spec.path.span();
    let joint = JointDef {
        name: Ident::new("root_joint", span),
        kind: match spec.base {
            Base::Planar => JointKind::Planar(2),
            _ => JointKind::Free,
        },
        parent,
        child: link,
        at: spec.at.clone(),
        xyz: None,
        rpy: None,
        actuated: false,
        dependent: false,
        lock: None,
        elements: Default::default(),
        span,
    };
    crate::parse::add_joint(ast, &joint)
}

/// A link's body: its centre `{link}_center` at the inertial origin
/// (the link's origin when that is zero), its frame `{link}_inertial`
/// turned by the inertial's rpy (the link's frame when zero).
fn body(ast: &mut ModelAst, link: &Ident, n: &LinkNumbers, span: Span) {
    let named = |suffix: &str| Ident::new(&format!("{link}{suffix}"), span);
    let origin = named("_origin");
    let frame = if n.rpy.iter().all(is_zero) {
        link.clone()
    } else {
        let f = named("_inertial");
        ast.frames.push(FrameDef {
            name: f.clone(),
            parent: link.clone(),
            rotations: rpy_rotations(&n.rpy),
            quaternion: None,
        });
        f
    };
    let center = if n.xyz.iter().all(is_zero) {
        origin
    } else {
        let c = named("_center");
        ast.points.push(PointDef {
            name: c.clone(),
            location: Expr::sum(Expr::Name(origin), in_frame(link, &n.xyz)),
        });
        c
    };
    let [ixx, iyy, izz, ixy, iyz, ixz] = n.inertia.clone();
    ast.bodies.push(BodyDef {
        name: link.clone(),
        center,
        frame: Some(frame),
        mass: n.mass.clone(),
        inertia: Some(Inertia::Matrix([ixx, iyy, izz, ixy, iyz, ixz])),
        span,
    });
}

/// `holonomic(joint == multiplier * other + offset)` for each mimic joint
/// that moves (unless `mimic = false`): a fixed or welded joint's mimic
/// tag is ignored, as Pinocchio ignores it, and a joint that mimics a
/// fixed or welded one is held at the offset.
fn mimics(cx: &Ctxt, ast: &mut ModelAst, read: &Read, tree: &Tree, spec: &Spec, welded: &[bool]) {
    use urdf_rs::JointType as T;
    if !spec.mimic {
        return;
    }
    let span = spec.path.span();
    let path = &spec.path;
    let still = |k: usize| welded[k] || read.robot.joints[k].joint_type == T::Fixed;
    for (j, urdf) in read.robot.joints.iter().enumerate() {
        let Some(mimic) = &urdf.mimic else { continue };
        if still(j) {
            continue;
        }
        let at = read.lines.describe("joint", &urdf.name);
        let Some(other) = read.robot.joints.iter().position(|o| o.name == mimic.joint) else {
            let hint = hint(
                &mimic.joint,
                read.robot
                    .joints
                    .iter()
                    .filter(|o| o.name != urdf.name)
                    .map(|o| o.name.clone()),
            );
            cx.error_at(
                span,
                format!(
                    "URDF {at}: it mimics `{}`, which is not a joint of the file{hint}; `mimic = false` among the `urdf(...)` options ignores mimic tags, as Pinocchio's default",
                    mimic.joint
                ),
            );
            continue;
        };
        let single = |k: usize| {
            matches!(
                read.robot.joints[k].joint_type,
                T::Revolute | T::Continuous | T::Prismatic
            )
        };
        if !single(j) || !(single(other) || still(other)) {
            cx.error_at(span, format!("URDF {at}: a mimic joint and the joint it mimics must be revolute, continuous or prismatic; `mimic = false` among the `urdf(...)` options makes every mimic joint an independent joint, as Pinocchio's default"));
            continue;
        }
        let offset = Expr::Float(mimic.offset.unwrap_or(0.0), span);
        let rhs = if still(other) {
            offset
        } else {
            let scaled = Expr::product(
                Expr::Float(mimic.multiplier.unwrap_or(1.0), span),
                Expr::Name(tree.joints[other].clone()),
            );
            if is_zero(&offset) {
                scaled
            } else {
                Expr::sum(scaled, offset)
            }
        };
        ast.holonomic.push(ConstraintDef {
            lhs: Expr::Name(tree.joints[j].clone()),
            rhs,
            along: None,
            effect: None,
            at: quote::quote!(#path),
        });
    }
}

/// The names the robot made, with the element that made each, for errors
/// about clashes with the model's own names.
fn record_names(ast: &mut ModelAst, robot: &urdf_rs::Robot, tree: &Tree) {
    for (l, name) in robot.links.iter().zip(&tree.links) {
        let what = format!("the URDF's link `{}`", l.name);
        for suffix in ["", "_origin", "_center", "_inertial"] {
            ast.urdf_names
                .push((format!("{name}{suffix}"), what.clone()));
        }
    }
    for (j, name) in robot.joints.iter().zip(&tree.joints) {
        let what = format!("the URDF's joint `{}`", j.name);
        for form in [
            "{}", "tau_{}", "{}_frame", "{}_at", "{}_x", "{}_y", "{}_angle",
        ] {
            ast.urdf_names
                .push((form.replace("{}", &name.to_string()), what.clone()));
        }
    }
}

/// "; did you mean `x`?" when `name` is close to a candidate, or a name
/// it is the start of (`elbow` for `elbow_joint`).
fn hint(name: &str, candidates: impl IntoIterator<Item = String>) -> String {
    let all: Vec<String> = candidates.into_iter().collect();
    suggest(name, all.iter().map(|s| s.as_str()))
        .map(|s| format!("; did you mean `{s}`?"))
        .unwrap_or_default()
}
