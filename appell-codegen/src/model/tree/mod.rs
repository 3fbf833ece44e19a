//! The kinematic tree of a model made of joints: which link each joint
//! moves, where its frame sits in the parent link, and the bodies each
//! link carries. [`tree_spec`] reads it off the syntax, every number an
//! expression of the model language; [`TreeSpec::lower`] puts those
//! numbers in the model's graph, and the structured form of the equations
//! ([`crate::derivation::tree`]) is built from the lowered tree. A tree under
//! constraints (rolling contacts, closing rows, dependent joints, speeds
//! other than the joint rates) is still a tree: its equations are the
//! tree's projected onto the privileged speeds, and [`TreeSpec::plain`]
//! says why it is not plain. A model that is not a tree of joints (a
//! coordinate no joint makes, a load other than gravity and joint
//! actuation, ...) gets the reason instead, reported in `info()`.

mod lower;

use std::collections::HashMap;

use appell_symbolic::Id;

use crate::ast::{BinOp, Expr, Inertia, ModelAst, RotationAxis};
use crate::ast::{JointAxis, JointDef, JointKind};

/// Constant rotations from a link's axes to a frame fixed in it: each
/// about the current frame's axis 0, 1 or 2 by the angle. `C`, here and
/// in the types below, is a constant: an expression as written while the
/// tree is read, a node of the model's graph once lowered.
pub type Turns<C = Id> = Vec<(usize, C)>;

/// A joint's axis in the joint frame.
#[derive(Clone, Debug)]
pub enum Axis<C = Id> {
    /// Axis 0, 1 or 2 (`x`, `y`, `z`), negated when the flag is set.
    Unit(usize, bool),
    /// Components in the joint frame, of any length.
    Components([C; 3]),
}

/// What a joint lets its child do, in the joint frame.
#[derive(Clone, Debug)]
pub enum Motion<C = Id> {
    /// Turn about the axis.
    Revolute(Axis<C>),
    /// Slide along the axis.
    Prismatic(Axis<C>),
    /// Turn about the joint origin by a unit quaternion (its coordinates
    /// `{joint}_qw, _qx, _qy, _qz`), at the child's angular velocity
    /// relative to the joint frame in the child's axes (its speeds
    /// `{joint}_wx, _wy, _wz`).
    Spherical,
    /// Slide along the joint frame's axes by `{joint}_x, _y, _z` and turn
    /// as a ball: the speeds are the ball's and the slides' rates (in the
    /// joint frame's axes); the recursions run in the child's velocity in
    /// its own axes and convert (see `derivation::tree::free`).
    Free,
}

/// One term of a vector fixed in a link: `coefficient · F.axis`, with `F`
/// reached from the link's axes by `turns`.
#[derive(Clone, Debug)]
pub struct Term<C = Id> {
    /// The scalar coefficient (parameters and numbers only).
    pub coefficient: C,
    /// The frame's rotations from the link.
    pub turns: Turns<C>,
    /// Its axis, 0, 1 or 2.
    pub axis: usize,
    /// The link the frame is fixed in (None: the ground).
    pub link: Option<usize>,
}

/// A central inertia in a body's axes, as written.
#[derive(Clone, Debug)]
pub enum CentralInertia<C = Id> {
    /// `principal(i1, i2, i3)`.
    Principal([C; 3]),
    /// `matrix(ixx, iyy, izz, ixy, iyz, izx)`.
    Matrix([C; 6]),
}

/// A body or particle carried by a link.
#[derive(Clone, Debug)]
pub struct MassSpec<C = Id> {
    /// The body's name.
    pub name: String,
    /// Its mass.
    pub mass: C,
    /// Its mass centre from the link's origin.
    pub center: Vec<Term<C>>,
    /// Its frame's rotations from the link and its central inertia in that
    /// frame (none for a particle).
    pub inertia: Option<(Turns<C>, CentralInertia<C>)>,
}

/// One link: the child of one joint.
#[derive(Clone, Debug)]
pub struct LinkSpec<C = Id> {
    /// The joint's name (its coordinate's, for a moving joint).
    pub joint: String,
    /// The parent link; None for the ground N.
    pub parent: Option<usize>,
    /// The parent frame's rotations from the parent link.
    pub parent_turns: Turns<C>,
    /// The parent frame's origin from the parent link's.
    pub parent_origin: Vec<Term<C>>,
    /// The joint frame's origin in the parent frame's axes (zero when
    /// None).
    pub xyz: Option<[C; 3]>,
    /// The joint frame's fixed-axis roll, pitch, yaw in the parent frame.
    pub rpy: Option<[C; 3]>,
    /// The joint's motion; None for a weld.
    pub motion: Option<Motion<C>>,
    /// The coordinates the link's motion reads, by name: the joint's for
    /// one degree of freedom, a ball's quaternion (none for a weld).
    pub coordinates: Vec<String>,
    /// The privileged speeds of its motion, by name, one per column of its
    /// motion subspace.
    pub speeds: Vec<String>,
    /// Whether the joint carries the input `tau_{joint}`.
    pub actuated: bool,
    /// The bodies fixed in the link.
    pub bodies: Vec<MassSpec<C>>,
}

/// A model's kinematic tree.
#[derive(Clone, Debug)]
pub struct TreeSpec<C = Id> {
    /// Links in declaration order: a parent comes before its children.
    pub links: Vec<LinkSpec<C>>,
    /// The gravity acceleration as terms along N's axes.
    pub gravity: Vec<Term<C>>,
    /// Ok for a plain tree, whose privileged speeds are its joint rates
    /// and which has no constraints; else why not. Moving link k moves
    /// coordinate k either way.
    pub plain: Result<(), String>,
}

/// Where a frame or point sits: its link (None: the ground) and, for a
/// frame, its rotations from the link, for a point, its offset.
type FrameAt = (Option<usize>, Turns<Expr>);
type PointAt = (Option<usize>, Vec<Term<Expr>>);

/// The model's kinematic tree as written, or why it has none.
///
/// ```
/// use appell_codegen::{ctxt::Ctxt, parse, model::tree};
///
/// let input: syn::DeriveInput = syn::parse_str(r#"
///     #[appell(joint(j_1, revolute(z), parent = N, child = link_1, actuated))]
///     #[appell(body(link_1, frame = link_1, mass = m, center = origin(link_1) + 0.5 * link_1.x,
///                   inertia = principal(0.1, 0.2, 0.3)))]
///     #[appell(gravity(-9.81 * N.z))]
///     struct Arm { m: f64 }
/// "#).unwrap();
/// let cx = Ctxt::new();
/// let ast = parse::parse(&cx, &input);
/// cx.check().unwrap();
/// let spec = tree::tree_spec(&ast).unwrap();
/// assert_eq!(spec.links.len(), 1);
/// assert_eq!(spec.links[0].bodies[0].center.len(), 1);
/// ```
pub fn tree_spec(ast: &ModelAst) -> Result<TreeSpec<Expr>, String> {
    if ast.joints.is_empty() {
        // No reason to give: a model without joints is not a tree of them.
        return Err(String::new());
    }
    tree_checks(ast)?;
    let plain = plain_checks(ast);
    let mut frames: HashMap<String, FrameAt> = HashMap::new();
    let mut points: HashMap<String, PointAt> = HashMap::new();
    frames.insert("N".into(), (None, Vec::new()));
    points.insert("O".into(), (None, Vec::new()));
    let mut links = Vec::new();
    let variables = coordinate_names(ast);
    // What joints declare themselves: child frames, joint frames, origins.
    let joint_frames: Vec<String> = ast
        .joints
        .iter()
        .flat_map(|j| [format!("{}_frame", j.name), j.child.to_string()])
        .collect();
    let joint_points: Vec<String> = ast
        .joints
        .iter()
        .flat_map(|j| [format!("{}_at", j.name), format!("{}_origin", j.child)])
        .collect();
    let mut pending = ast.joints.iter().peekable();
    // Frames and points are resolved as their parents are: a joint's
    // parent may be a frame declared before it and fixed in a link.
    loop {
        let mut progress = false;
        for f in &ast.frames {
            let name = f.name.to_string();
            if frames.contains_key(&name) || joint_frames.contains(&name) {
                continue;
            }
            if let Some(at) = frame_at(f, &frames, &variables)? {
                frames.insert(name, at);
                progress = true;
            }
        }
        for p in &ast.points {
            let name = p.name.to_string();
            if points.contains_key(&name) || joint_points.contains(&name) {
                continue;
            }
            if let Some(at) = point_at(&p.location, &frames, &points, &variables) {
                points.insert(name, at);
                progress = true;
            }
        }
        if let Some(j) = pending.peek() {
            if let Some(made) = links_of(j, ast, &frames, &points, links.len())? {
                let index = links.len() + made.len() - 1;
                frames.insert(j.child.to_string(), (Some(index), Vec::new()));
                points.insert(format!("{}_origin", j.child), (Some(index), Vec::new()));
                links.extend(made);
                pending.next();
                progress = true;
            }
        }
        if !progress {
            break;
        }
    }
    if let Some(j) = pending.next() {
        return Err(format!(
            "joint `{}`'s parent `{}` is not fixed in a link or in N",
            j.name, j.parent
        ));
    }
    for b in &ast.bodies {
        let (link, mass) = mass_spec(b, &frames, &points)?;
        if let Some(i) = link {
            links[i].bodies.push(mass);
        }
    }
    let gravity = match &ast.gravity {
        Some(e) => {
            let mut terms = Vec::new();
            if !vector_terms(e, None, &frames, &variables, &mut terms)
                || terms.iter().any(|t| !t.turns.is_empty())
            {
                return Err("gravity is not a constant vector along N's axes".into());
            }
            terms
        }
        None => Vec::new(),
    };
    Ok(TreeSpec {
        links,
        gravity,
        plain,
    })
}

/// What a tree of joints may not have: scenes that leave out loads (a
/// scene may differ only in the contacts it holds), coordinates no joint
/// makes, inputs and loads other than the joints' own.
fn tree_checks(ast: &ModelAst) -> Result<(), String> {
    let actuated = ast.joints.iter().any(|j| j.actuated);
    for sc in &ast.scenes {
        let keeps = |e: &str| sc.effects.iter().any(|x| x == e);
        if (ast.gravity.is_some() && !keeps("gravity")) || (actuated && !keeps("actuation")) {
            return Err(format!("scene `{}` leaves out loads", sc.name));
        }
    }
    let mut expected_loads = 0;
    let mut inputs = Vec::new();
    for j in &ast.joints {
        match j.kind {
            JointKind::Revolute(_) | JointKind::Prismatic(_) | JointKind::Weld => {}
            JointKind::Planar(_) | JointKind::Spherical | JointKind::Free if !j.actuated => {}
            JointKind::Planar(_) => return Err(format!("planar joint `{}` is actuated", j.name)),
            _ => {
                return Err(format!(
                    "joint `{}` is not revolute, prismatic, planar, spherical, free or fixed",
                    j.name
                ))
            }
        }
        if j.actuated {
            inputs.push(format!("tau_{}", j.name));
            expected_loads += if j.parent == "N" { 1 } else { 2 };
        }
    }
    let declared: Vec<String> = ast.coordinates.iter().map(|c| c.to_string()).collect();
    if declared != joint_coordinates(ast) {
        return Err("the model has coordinates no joint makes".into());
    }
    let declared_inputs: Vec<String> = ast.inputs.iter().map(|i| i.to_string()).collect();
    if declared_inputs != inputs {
        return Err("the model has inputs other than the joints' torques".into());
    }
    let loads = ast.forces.iter().chain(&ast.torques);
    if loads.clone().any(|l| l.effect != "actuation") || loads.count() != expected_loads {
        return Err("the model has loads other than gravity and joint actuation".into());
    }
    Ok(())
}

/// What a plain tree may not have besides: constraints other than its
/// balls' unit norms, rolling contacts, dependent joints, speeds other
/// than the joint rates and the balls' angular velocities.
fn plain_checks(ast: &ModelAst) -> Result<(), String> {
    let balls: Vec<&JointDef> = ast
        .joints
        .iter()
        .filter(|j| matches!(j.kind, JointKind::Spherical | JointKind::Free))
        .collect();
    let norms_only = ast.holonomic.len() == balls.len()
        && ast
            .holonomic
            .iter()
            .all(|c| balls.iter().any(|j| is_unit_norm(c, &ball_names(j, "_q"))));
    if !norms_only || !ast.nonholonomic.is_empty() {
        return Err("the model has constraints".into());
    }
    if !ast.rolls.is_empty() {
        return Err("the model has rolling contacts".into());
    }
    if let Some(j) = ast.joints.iter().find(|j| j.dependent) {
        return Err(format!("joint `{}` is dependent", j.name));
    }
    let rates = joint_rates(ast);
    let angular: Vec<String> = balls.iter().flat_map(|j| ball_names(j, "_w")).collect();
    let speeds_match = ast.speeds.as_ref().is_some_and(|(list, _)| {
        list.len() == rates.len() + angular.len()
            && list.iter().all(|s| {
                let name = s.name.to_string();
                match &s.definition {
                    None => rates.contains(&name),
                    Some(_) => angular.contains(&name),
                }
            })
    });
    if !speeds_match && !rates.is_empty() {
        return Err("the privileged speeds are not the joint rates".into());
    }
    Ok(())
}

/// A ball's quaternion (`_q`: `{joint}_qw` ... `_qz`) or angular velocity
/// (`_w`: `{joint}_wx` ... `_wz`) names.
fn ball_names(j: &JointDef, kind: &str) -> Vec<String> {
    let parts: &[&str] = if kind == "_q" {
        &["w", "x", "y", "z"]
    } else {
        &["x", "y", "z"]
    };
    parts
        .iter()
        .map(|p| format!("{}{kind}{p}", j.name))
        .collect()
}

/// Whether `c` is `Σ e² == 1` over the names `e`, as a ball writes it.
fn is_unit_norm(c: &crate::ast::ConstraintDef, e: &[String]) -> bool {
    fn squares(x: &Expr, out: &mut Vec<String>) -> bool {
        match x {
            Expr::Binary(BinOp::Add, a, b, _) => squares(a, out) && squares(b, out),
            Expr::Binary(BinOp::Mul, a, b, _) => match (&**a, &**b) {
                (Expr::Name(p), Expr::Name(q)) if p == q => {
                    out.push(p.to_string());
                    true
                }
                _ => false,
            },
            _ => false,
        }
    }
    let mut names = Vec::new();
    squares(&c.lhs, &mut names)
        && names == e
        && c.along.is_none()
        && matches!(c.rhs, Expr::Int(1, _))
}

/// The coordinates the joints make, in order (a planar joint's three, a
/// ball's quaternion, a free joint's quaternion and then its slides).
fn joint_coordinates(ast: &ModelAst) -> Vec<String> {
    let mut out = Vec::new();
    for j in &ast.joints {
        match j.kind {
            JointKind::Spherical => out.extend(ball_names(j, "_q")),
            JointKind::Free => {
                out.extend(ball_names(j, "_q"));
                out.extend(["_x", "_y", "_z"].map(|s| format!("{}{s}", j.name)));
            }
            _ => out.extend(joint_rates_of(j)),
        }
    }
    out
}

/// The coordinates whose rates are privileged speeds of a plain tree.
fn joint_rates(ast: &ModelAst) -> Vec<String> {
    ast.joints.iter().flat_map(joint_rates_of).collect()
}

/// A joint's coordinates whose rates are speeds: all but a quaternion's.
fn joint_rates_of(j: &JointDef) -> Vec<String> {
    let named = |s: [&str; 3]| s.map(|s| format!("{}{s}", j.name)).to_vec();
    match j.kind {
        JointKind::Planar(_) => named(["_x", "_y", "_angle"]),
        JointKind::Free => named(["_x", "_y", "_z"]),
        JointKind::Weld | JointKind::Spherical => Vec::new(),
        _ => vec![j.name.to_string()],
    }
}

/// The names that vary: coordinates, inputs and time.
fn coordinate_names(ast: &ModelAst) -> Vec<String> {
    let names = ast.coordinates.iter().chain(&ast.inputs);
    names
        .map(|c| c.to_string())
        .chain(["t".to_string()])
        .collect()
}

/// A frame fixed in a link by constant rotations from a resolved parent;
/// None while the parent is not resolved.
fn frame_at(
    f: &crate::ast::FrameDef,
    frames: &HashMap<String, FrameAt>,
    variables: &[String],
) -> Result<Option<FrameAt>, String> {
    let name = &f.name;
    let Some((link, mut turns)) = frames.get(&f.parent.to_string()).cloned() else {
        return Ok(None);
    };
    if f.quaternion.is_some() {
        return Err(format!("frame `{name}` is turned by a quaternion"));
    }
    for (axis, angle) in &f.rotations {
        match axis {
            RotationAxis::Parent(k) if constant(angle, variables) => {
                turns.push((*k, angle.clone()))
            }
            _ => {
                return Err(format!(
                    "frame `{name}` turns with a coordinate but not by a joint"
                ))
            }
        }
    }
    Ok(Some((link, turns)))
}

/// The links a joint makes, placed in its parent frame (a planar joint's
/// three: two massless slides and the turn that carries the child, the
/// first at index `first`); None while the parent frame or its origin is
/// not resolved.
fn links_of(
    j: &JointDef,
    ast: &ModelAst,
    frames: &HashMap<String, FrameAt>,
    points: &HashMap<String, PointAt>,
    first: usize,
) -> Result<Option<Vec<LinkSpec<Expr>>>, String> {
    let Some((parent, parent_turns)) = frames.get(&j.parent.to_string()).cloned() else {
        return Ok(None);
    };
    let origin = match (&j.at, j.parent == "N") {
        (Some(p), _) => p.to_string(),
        (None, true) => "O".to_string(),
        (None, false) => match ast.origins.iter().find(|(f, _)| *f == j.parent) {
            Some((_, p)) => p.to_string(),
            None => return Ok(None),
        },
    };
    let Some((origin_link, parent_origin)) = points.get(&origin).cloned() else {
        return Ok(None);
    };
    if origin_link != parent {
        return Err(format!(
            "joint `{}`'s origin is not fixed in its parent",
            j.name
        ));
    }
    let link = |joint: String, motion: Option<Motion<Expr>>| LinkSpec {
        coordinates: link_coordinates(&joint, motion.as_ref()),
        speeds: link_speeds(&joint, motion.as_ref()),
        joint,
        parent,
        parent_turns: parent_turns.clone(),
        parent_origin: parent_origin.clone(),
        xyz: j.xyz.clone(),
        rpy: j.rpy.clone(),
        motion,
        actuated: j.actuated,
        bodies: Vec::new(),
    };
    // A link moving on the one before it, in its axes.
    let next = |joint: String, parent: usize, motion: Option<Motion<Expr>>| LinkSpec {
        coordinates: link_coordinates(&joint, motion.as_ref()),
        speeds: link_speeds(&joint, motion.as_ref()),
        joint,
        parent: Some(parent),
        parent_turns: Vec::new(),
        parent_origin: Vec::new(),
        xyz: None,
        rpy: None,
        motion,
        actuated: false,
        bodies: Vec::new(),
    };
    let slide = |k: usize| Some(Motion::Prismatic(Axis::Unit(k, false)));
    let name = j.name.to_string();
    Ok(Some(match &j.kind {
        JointKind::Revolute(a) => vec![link(name, Some(Motion::Revolute(axis(a))))],
        JointKind::Prismatic(a) => vec![link(name, Some(Motion::Prismatic(axis(a))))],
        JointKind::Planar(k) => {
            let turn = Some(Motion::Revolute(Axis::Unit(*k, false)));
            vec![
                link(format!("{name}_x"), slide((k + 1) % 3)),
                next(format!("{name}_y"), first, slide((k + 2) % 3)),
                next(format!("{name}_angle"), first + 1, turn),
            ]
        }
        JointKind::Spherical => vec![link(name, Some(Motion::Spherical))],
        JointKind::Free => vec![link(name, Some(Motion::Free))],
        _ => vec![link(name, None)],
    }))
}

/// A joint's axis as written.
fn axis(a: &JointAxis) -> Axis<Expr> {
    match a {
        JointAxis::Unit(k, negative) => Axis::Unit(*k, *negative),
        JointAxis::Components(c) => Axis::Components(c.clone()),
    }
}

/// The coordinates a link named `joint` reads.
fn link_coordinates(joint: &str, motion: Option<&Motion<Expr>>) -> Vec<String> {
    match motion {
        None => Vec::new(),
        Some(Motion::Spherical) => ["w", "x", "y", "z"]
            .map(|c| format!("{joint}_q{c}"))
            .to_vec(),
        Some(Motion::Free) => ["_qw", "_qx", "_qy", "_qz", "_x", "_y", "_z"]
            .map(|c| format!("{joint}{c}"))
            .to_vec(),
        Some(_) => vec![joint.to_string()],
    }
}

/// The speeds of a link named `joint`'s motion.
fn link_speeds(joint: &str, motion: Option<&Motion<Expr>>) -> Vec<String> {
    match motion {
        None => Vec::new(),
        Some(Motion::Spherical) => ["x", "y", "z"].map(|c| format!("{joint}_w{c}")).to_vec(),
        Some(Motion::Free) => ["_wx", "_wy", "_wz", "_x", "_y", "_z"]
            .map(|c| format!("{joint}{c}"))
            .to_vec(),
        Some(_) => vec![joint.to_string()],
    }
}

/// The link a body is fixed in (None: the ground) and its mass spec.
fn mass_spec(
    b: &crate::ast::BodyDef,
    frames: &HashMap<String, FrameAt>,
    points: &HashMap<String, PointAt>,
) -> Result<(Option<usize>, MassSpec<Expr>), String> {
    let not_fixed = || format!("body `{}` is not fixed in a link", b.name);
    let (link, center) = points
        .get(&b.center.to_string())
        .cloned()
        .ok_or_else(not_fixed)?;
    let inertia = match (&b.frame, &b.inertia) {
        (Some(f), Some(i)) => {
            let (frame_link, turns) = frames.get(&f.to_string()).cloned().ok_or_else(not_fixed)?;
            if frame_link != link {
                return Err(not_fixed());
            }
            let central = match i {
                Inertia::Principal(d) => CentralInertia::Principal(d.clone()),
                Inertia::Matrix(e) => CentralInertia::Matrix(e.clone()),
            };
            Some((turns, central))
        }
        (Some(f), None) => {
            let (frame_link, _) = frames.get(&f.to_string()).ok_or_else(not_fixed)?;
            if *frame_link != link {
                return Err(not_fixed());
            }
            None
        }
        (None, _) => None,
    };
    Ok((
        link,
        MassSpec {
            name: b.name.to_string(),
            mass: b.mass.clone(),
            center,
            inertia,
        },
    ))
}

/// A point expression `P + Σ c F.axis` whose base and frames are fixed in
/// one link.
fn point_at(
    e: &Expr,
    frames: &HashMap<String, FrameAt>,
    points: &HashMap<String, PointAt>,
    coordinates: &[String],
) -> Option<PointAt> {
    match e {
        Expr::Name(p) => points.get(&p.to_string()).cloned(),
        Expr::Call(f, args, _) if f == "origin" && args.len() == 1 => match &args[0] {
            Expr::Name(frame) => match frames.get(&frame.to_string()) {
                Some((link, turns)) if turns.is_empty() => Some((*link, Vec::new())),
                _ => None,
            },
            _ => None,
        },
        Expr::Binary(op @ (BinOp::Add | BinOp::Sub), a, b, span) => {
            let (link, mut terms) = point_at(a, frames, points, coordinates)?;
            let sign = (*op == BinOp::Sub).then_some(Expr::Int(-1, *span));
            let mut more = Vec::new();
            if !vector_terms(b, sign, frames, coordinates, &mut more) {
                return None;
            }
            if more.iter().any(|t| t.link != link) {
                return None;
            }
            terms.extend(more);
            Some((link, terms))
        }
        _ => None,
    }
}

/// Appends the terms of the vector expression `e` times `factor`; false
/// when `e` is not a constant combination of frame axes fixed in links.
fn vector_terms(
    e: &Expr,
    factor: Option<Expr>,
    frames: &HashMap<String, FrameAt>,
    coordinates: &[String],
    out: &mut Vec<Term<Expr>>,
) -> bool {
    let scaled = |k: &Expr| match &factor {
        Some(f) => Expr::Binary(
            BinOp::Mul,
            Box::new(f.clone()),
            Box::new(k.clone()),
            k.span(),
        ),
        None => k.clone(),
    };
    match e {
        Expr::Axis(f, k, span) => match frames.get(&f.to_string()) {
            Some((link, turns)) => {
                out.push(Term {
                    coefficient: factor.clone().unwrap_or(Expr::Int(1, *span)),
                    turns: turns.clone(),
                    axis: *k,
                    link: *link,
                });
                true
            }
            None => false,
        },
        Expr::Neg(v, span) => vector_terms(
            v,
            Some(scaled(&Expr::Int(-1, *span))),
            frames,
            coordinates,
            out,
        ),
        Expr::Binary(BinOp::Add, a, b, _) => {
            vector_terms(a, factor.clone(), frames, coordinates, out)
                && vector_terms(b, factor, frames, coordinates, out)
        }
        Expr::Binary(BinOp::Sub, a, b, span) => {
            vector_terms(a, factor.clone(), frames, coordinates, out)
                && vector_terms(
                    b,
                    Some(scaled(&Expr::Int(-1, *span))),
                    frames,
                    coordinates,
                    out,
                )
        }
        Expr::Binary(BinOp::Mul, a, b, _) => {
            let (k, v) = if has_axis(b) { (a, b) } else { (b, a) };
            !has_axis(k)
                && constant(k, coordinates)
                && vector_terms(v, Some(scaled(k)), frames, coordinates, out)
        }
        Expr::Binary(BinOp::Div, v, k, span) => {
            let inverse = Expr::Binary(BinOp::Div, Box::new(Expr::Int(1, *span)), k.clone(), *span);
            !has_axis(k)
                && constant(k, coordinates)
                && vector_terms(v, Some(scaled(&inverse)), frames, coordinates, out)
        }
        _ => false,
    }
}

/// Whether `e` holds a frame axis.
fn has_axis(e: &Expr) -> bool {
    match e {
        Expr::Axis(..) => true,
        Expr::Int(..) | Expr::Float(..) | Expr::Name(_) => false,
        Expr::Call(_, args, _) => args.iter().any(has_axis),
        Expr::Binary(_, a, b, _) => has_axis(a) || has_axis(b),
        Expr::Neg(a, _) => has_axis(a),
    }
}

/// Whether `e` is a scalar of parameters and numbers: no coordinate, no
/// input, no time, no `dt`.
fn constant(e: &Expr, coordinates: &[String]) -> bool {
    match e {
        Expr::Int(..) | Expr::Float(..) => true,
        Expr::Name(n) => !coordinates.contains(&n.to_string()),
        Expr::Call(f, args, _) => f != "dt" && args.iter().all(|a| constant(a, coordinates)),
        Expr::Binary(_, a, b, _) => constant(a, coordinates) && constant(b, coordinates),
        Expr::Neg(a, _) => constant(a, coordinates),
        Expr::Axis(..) => false,
    }
}
