//! The model as written: what the `#[appell(...)]` attributes say, with the
//! spans of every name and expression, before any name is resolved.

use proc_macro2::Span;
use syn::Ident;

/// A scalar or vector expression of the model language.
#[derive(Clone, Debug)]
pub enum Expr {
    /// An integer literal (stays exact).
    Int(i64, Span),
    /// A float literal.
    Float(f64, Span),
    /// A name: parameter, coordinate, input, `t`, point or frame.
    Name(Ident),
    /// `f(args)`: `dt`, the elementary functions, `atan2`, `powi`, `powf`,
    /// `min`, `max`, `select` (also written `if a > b { x } else { y }`),
    /// `dot`, `cross`, `norm`, `unit`, `omega`, `velocity`, `origin`.
    Call(Ident, Vec<Expr>, Span),
    /// `A.x`, `A.y`, `A.z`: a unit vector of frame `A`.
    Axis(Ident, usize, Span),
    /// A binary operation.
    Binary(BinOp, Box<Expr>, Box<Expr>, Span),
    /// `-e`.
    Neg(Box<Expr>, Span),
}

impl Expr {
    /// Where the expression stands in the source.
    pub fn span(&self) -> Span {
        match self {
            Expr::Int(_, s) | Expr::Float(_, s) => *s,
            Expr::Name(i) => i.span(),
            Expr::Call(_, _, s)
            | Expr::Axis(_, _, s)
            | Expr::Binary(_, _, _, s)
            | Expr::Neg(_, s) => *s,
        }
    }

    /// `a + b`, where `a` stands.
    pub fn sum(a: Expr, b: Expr) -> Expr {
        let span = a.span();
        Expr::Binary(BinOp::Add, Box::new(a), Box::new(b), span)
    }

    /// `a - b`, where `a` stands.
    pub fn difference(a: Expr, b: Expr) -> Expr {
        let span = a.span();
        Expr::Binary(BinOp::Sub, Box::new(a), Box::new(b), span)
    }

    /// `a * b`, where `a` stands.
    pub fn product(a: Expr, b: Expr) -> Expr {
        let span = a.span();
        Expr::Binary(BinOp::Mul, Box::new(a), Box::new(b), span)
    }

    /// `-e`, where `e` stands.
    pub fn negated(e: Expr) -> Expr {
        let span = e.span();
        Expr::Neg(Box::new(e), span)
    }
}

/// `+ - * /`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinOp {
    /// `+`.
    Add,
    /// `-`.
    Sub,
    /// `*`.
    Mul,
    /// `/`.
    Div,
}

/// The axis of a simple rotation.
#[derive(Clone, Debug)]
pub enum RotationAxis {
    /// About the parent's x, y or z axis (0, 1, 2).
    Parent(usize),
    /// About an arbitrary vector (normalized).
    Vector(Expr),
}

/// `frame(A = P.rotate_z(angle))`, or a three-angle body sequence
/// `frame(A = P.body_zxy(a, b, c))` (successive rotations about the new
/// frame's own axes; the intermediate frames are anonymous).
#[derive(Clone, Debug)]
pub struct FrameDef {
    /// The new frame.
    pub name: Ident,
    /// The frame it is rotated from.
    pub parent: Ident,
    /// The rotations, applied in order, each about the axis of the frame
    /// produced by the previous one.
    pub rotations: Vec<(RotationAxis, Expr)>,
    /// `P.quaternion(qw, qx, qy, qz)`: then turned by this unit quaternion
    /// (scalar first), the frame's orientation relative to the parent.
    pub quaternion: Option<Box<[Expr; 4]>>,
}

/// `point(P = Q + vector)`.
#[derive(Clone, Debug)]
pub struct PointDef {
    /// The new point.
    pub name: Ident,
    /// Its location (a point expression).
    pub location: Expr,
}

/// Inertia about the mass centre, in the body frame.
#[derive(Clone, Debug)]
pub enum Inertia {
    /// `principal(i1, i2, i3)`.
    Principal([Expr; 3]),
    /// `matrix(ixx, iyy, izz, ixy, iyz, izx)`.
    Matrix([Expr; 6]),
}

/// `body(name, center = P, frame = B, mass = m, inertia = ...)` or
/// `particle(P, mass = m)` (no frame, no inertia).
#[derive(Clone, Debug)]
pub struct BodyDef {
    /// The body's name (the point's for a particle).
    pub name: Ident,
    /// The mass centre.
    pub center: Ident,
    /// The body frame (None for a particle).
    pub frame: Option<Ident>,
    /// The mass.
    pub mass: Expr,
    /// The central inertia (None for a particle).
    pub inertia: Option<Inertia>,
    /// The whole attribute item, for errors.
    pub span: Span,
}

/// `holonomic(lhs == rhs)` or `nonholonomic(lhs == rhs)`.
#[derive(Clone, Debug)]
pub struct ConstraintDef {
    /// Left side.
    pub lhs: Expr,
    /// Right side.
    pub rhs: Expr,
    /// For an equation between points or vectors: the directions its
    /// components are taken along (`along = [N.x, N.y]`); N's axes when
    /// absent.
    pub along: Option<Vec<Expr>>,
    /// The effect it belongs to (`effect = name`): scenes that do not name
    /// it leave it out. None: every scene keeps it.
    pub effect: Option<Ident>,
    /// The whole constraint's tokens, for errors that underline it.
    pub at: proc_macro2::TokenStream,
}

/// A force on a point or a torque on a frame.
#[derive(Clone, Debug)]
pub struct LoadDef {
    /// The point (force) or frame (torque).
    pub target: Ident,
    /// The vector.
    pub vector: Expr,
    /// The effect it belongs to.
    pub effect: Ident,
}

/// `rolls(body, contact = P)` or `rolls(body, contact = P, along = [u, v])`:
/// the body's material point at P has zero velocity (along the given
/// directions only, when given).
#[derive(Clone, Debug)]
pub struct RollsDef {
    /// The rolling body.
    pub body: Ident,
    /// The contact point.
    pub contact: Ident,
    /// Directions of the velocity components constrained (default: N.x,
    /// N.y, N.z, identically zero ones dropped).
    pub along: Option<Vec<Expr>>,
    /// The effect it belongs to (`effect = name`), as for a constraint.
    pub effect: Option<Ident>,
    /// The sliding friction that takes the contact's place where a scene
    /// drops it (`slides = effect, mu = μ, normal = N, ...`).
    pub slides: Option<SlidesDef>,
    /// The item's tokens, for errors.
    pub at: proc_macro2::TokenStream,
}

/// `contact(link, point | flat, effect = name)`: a foot on the ground. A
/// point contact holds the origin of `link` (a frame a joint made) still,
/// three rows; a flat one holds the frame still, six rows. Unlike the
/// other constraints it is held only in the scenes that name its effect:
/// the model itself is the robot with every foot in the air.
#[derive(Clone, Debug)]
pub struct ContactDef {
    /// The frame in contact.
    pub link: Ident,
    /// Whether the frame's turning is held too (`flat`).
    pub flat: bool,
    /// The effect it belongs to (the link's name when not given).
    pub effect: Ident,
    /// The item's tokens, for errors.
    pub at: proc_macro2::TokenStream,
}

/// A rolling contact's sliding friction: `friction(P, ...)` at the
/// contact, on the rolling body, in effect `effect`.
#[derive(Clone, Debug)]
pub struct SlidesDef {
    /// The friction's effect (`slides = name`).
    pub effect: Ident,
    /// The friction's properties (`mu`, `normal`, `smoothing`, `viscous`,
    /// `plane`), by name.
    pub values: std::collections::BTreeMap<String, Expr>,
}

/// One privileged speed: a coordinate's name (its rate, Method II) or
/// `name = expression` (a quasi-velocity linear in the rates, Method III).
#[derive(Clone, Debug)]
pub struct SpeedDef {
    /// The coordinate, or the quasi-velocity's new name.
    pub name: Ident,
    /// The definition of a quasi-velocity.
    pub definition: Option<Expr>,
}

/// `scene(name, effects(a, b), outputs(quadrature(x1, y1)))`.
#[derive(Clone, Debug)]
pub struct SceneDef {
    /// The scene's name.
    pub name: Ident,
    /// The effects kept.
    pub effects: Vec<Ident>,
    /// Outputs: a kind and its arguments.
    pub outputs: Vec<(Ident, Vec<Ident>)>,
    /// `speeds(...)`: the scene's own privileged speeds (coordinates, or
    /// the model's quasi-velocities), with its tokens for errors.
    pub speeds: Option<(Vec<Ident>, proc_macro2::TokenStream)>,
}

/// One parameter: an `f64` field, or one element of an `[f64; N]` field.
#[derive(Clone, Debug)]
pub struct ParamDef {
    /// Its name in the model: the field's, or `m_3` for element 3 of `m`
    /// (written `m[3]`, see [`crate::parse`]).
    pub name: Ident,
    /// The struct field.
    pub field: Ident,
    /// The element, for an array field.
    pub index: Option<usize>,
}

/// The whole model as written.
#[derive(Clone, Debug)]
pub struct ModelAst {
    /// The struct's name.
    pub name: Ident,
    /// The parameters: each `f64` field, and each element of an
    /// `[f64; N]` field.
    pub fields: Vec<ParamDef>,
    /// `coordinates(...)`.
    pub coordinates: Vec<Ident>,
    /// `speeds(...)` and its tokens (for errors).
    pub speeds: Option<(Vec<SpeedDef>, proc_macro2::TokenStream)>,
    /// `inputs(...)`.
    pub inputs: Vec<Ident>,
    /// `positive(...)`: parameters known to be positive.
    pub positive: Vec<Ident>,
    /// Frames in order.
    pub frames: Vec<FrameDef>,
    /// Points in order.
    pub points: Vec<PointDef>,
    /// Bodies and particles in order.
    pub bodies: Vec<BodyDef>,
    /// Holonomic constraints.
    pub holonomic: Vec<ConstraintDef>,
    /// Nonholonomic constraints.
    pub nonholonomic: Vec<ConstraintDef>,
    /// Forces.
    pub forces: Vec<LoadDef>,
    /// Torques.
    pub torques: Vec<LoadDef>,
    /// `gravity(vector)`.
    pub gravity: Option<Expr>,
    /// `jacobian(on | off)`: whether the derive writes `rhs_jacobian`
    /// always, never, or (`None`) where it costs little.
    pub jacobian: Option<bool>,
    /// `rolls(body, contact = P)`.
    pub rolls: Vec<RollsDef>,
    /// `contact(link, point | flat)`: constraints held only in the scenes
    /// that name them.
    pub contacts: Vec<ContactDef>,
    /// `scene(name, effects(...), outputs(...))`.
    pub scenes: Vec<SceneDef>,
    /// Frames made by joints, with their origin points (`B`, `B_origin`).
    pub origins: Vec<(Ident, Ident)>,
    /// The joints as written (also lowered into frames, points,
    /// coordinates and loads above), for the kinematic tree.
    pub joints: Vec<JointDef>,
    /// The coordinates whose rates joints make privileged speeds, added
    /// after those of `speeds(...)` that are not among them (when parsing
    /// ends; kept for error messages).
    pub joint_speeds: Vec<Ident>,
    /// The struct's visibility (scene types get the same).
    pub vis: syn::Visibility,
    /// Files the model was read from (`urdf(...)`), absolute: the output
    /// includes each, so cargo builds the model again when one changes.
    pub files: Vec<String>,
    /// Names a URDF made, with the element that made each (`the URDF's
    /// link `forearm_link``), for errors about them.
    pub urdf_names: Vec<(String, String)>,
    /// The URDF's joint limits: joint, lower, upper, velocity, effort.
    pub joint_limits: Vec<(String, [f64; 4])>,
    /// URDF links without mass: frames, but not bodies (for the error of a
    /// `rolls(...)` that names one).
    pub massless_links: Vec<String>,
    /// URDF bodies whose inertia the model does not check: the URDF reader
    /// checked the rigid body each is part of (links fixed together), or
    /// `unchecked_inertia(...)` named it.
    pub unchecked_inertia: Vec<String>,
}

/// The direction a joint moves along or about, in the joint frame.
#[derive(Clone, Debug)]
pub enum JointAxis {
    /// `x`, `y`, `z` (0, 1, 2), negated with `-z`.
    Unit(usize, bool),
    /// `[ax, ay, az]`: components in the joint frame, any length.
    Components([Expr; 3]),
}

/// What a joint lets the child do relative to the joint frame.
#[derive(Clone, Debug)]
pub enum JointKind {
    /// Turn about the axis: one coordinate, the joint's name.
    Revolute(JointAxis),
    /// Slide along the axis: one coordinate, the joint's name.
    Prismatic(JointAxis),
    /// Turn about and slide along the axis: `{name}_angle`, `{name}_slide`.
    Cylindrical(JointAxis),
    /// Slide in the plane normal to a unit axis and turn about it:
    /// `{name}_x`, `{name}_y` (along the next two axes in cyclic order)
    /// and `{name}_angle`.
    Planar(usize),
    /// No motion: the child is fixed in the parent.
    Weld,
    /// Any rotation about the joint origin, by a unit quaternion
    /// `{name}_qw, _qx, _qy, _qz`; its speeds are the child's angular
    /// velocity relative to the joint frame, in the child's axes,
    /// `{name}_wx, _wy, _wz` (Method III); the unit norm is a holonomic
    /// constraint.
    Spherical,
    /// A spherical joint whose centre also moves: `{name}_x, _y, _z` along
    /// the joint frame's axes, their rates speeds too.
    Free,
}

/// `joint(...)` as written.
#[derive(Clone, Debug)]
pub struct JointDef {
    /// The joint's name (its coordinate's, for one degree of freedom).
    pub name: Ident,
    /// Its kind.
    pub kind: JointKind,
    /// The parent frame (`N` or a frame declared above).
    pub parent: Ident,
    /// The child frame it declares.
    pub child: Ident,
    /// The joint frame's origin before `xyz`: the parent's origin unless
    /// given.
    pub at: Option<Ident>,
    /// Offset of the joint frame in the parent frame.
    pub xyz: Option<[Expr; 3]>,
    /// Fixed-axis roll, pitch, yaw of the joint frame in the parent frame.
    pub rpy: Option<[Expr; 3]>,
    /// Declares the input `tau_{name}` and applies it (a torque about, or a
    /// force along, the axis, on the child, and its reaction on the parent).
    pub actuated: bool,
    /// The joint's rates are not privileged speeds (a joint a loop closure
    /// makes dependent, or a locked one).
    pub dependent: bool,
    /// `lock = effect`: the joint held still where `effect` acts.
    pub lock: Option<JointLock>,
    /// Springs, dampers, friction and the motor's saturation on the joint.
    pub elements: JointElements,
    /// The whole item, for errors.
    pub span: Span,
}

/// `lock = effect` on a one-axis joint: the velocity constraint
/// `dt(q) == 0` on its coordinate, belonging to `effect`, so only the
/// scenes that name the effect hold the joint still (a brake, a clutch).
#[derive(Clone, Debug)]
pub struct JointLock {
    /// The effect the constraint belongs to.
    pub effect: Ident,
    /// `lock = effect` as written, for errors about the constraint.
    pub at: proc_macro2::TokenStream,
}

/// The elements a revolute or prismatic joint may carry (`stiffness`,
/// `rest`, `damping`, `friction`, `friction_smoothing`, `saturation`).
#[derive(Clone, Debug, Default)]
pub struct JointElements {
    /// k of the spring torque (force) −k (q − rest).
    pub stiffness: Option<Expr>,
    /// The spring's rest position (0 when absent).
    pub rest: Option<Expr>,
    /// c of the viscous torque (force) −c q̇.
    pub damping: Option<Expr>,
    /// The Coulomb friction torque (force) magnitude T of −T q̇ / √(q̇² + ε²).
    pub friction: Option<Expr>,
    /// ε of the friction's regularisation (default 1e-3, in the rate's units).
    pub friction_smoothing: Option<Expr>,
    /// The actuation input is clamped to ±saturation.
    pub saturation: Option<Expr>,
}

impl JointElements {
    /// Whether any element is given.
    pub fn any(&self) -> bool {
        self.stiffness.is_some()
            || self.damping.is_some()
            || self.friction.is_some()
            || self.saturation.is_some()
            || self.rest.is_some()
            || self.friction_smoothing.is_some()
    }
}
