//! The file's numbers as the model writes them: a joint's origin, a link's
//! inertial (expressions, so that `parameters(...)` can replace one), and
//! the fields `parameters(...)` may name.

use proc_macro2::Span;

use crate::ast::Expr;

/// A joint's numbers the model uses: its origin.
pub(super) struct JointNumbers {
    pub xyz: [Expr; 3],
    pub rpy: [Expr; 3],
}

/// A link's numbers: its inertial. `inertia` is ixx, iyy, izz, ixy, iyz,
/// ixz.
pub(super) struct LinkNumbers {
    pub mass: Expr,
    pub xyz: [Expr; 3],
    pub rpy: [Expr; 3],
    pub inertia: [Expr; 6],
    /// The fields `parameters(...)` replaced.
    pub promoted: Vec<String>,
}

/// The fields `parameters(...)` may name, on a joint and on a link.
pub(super) const JOINT_FIELDS: &[&str] = &[
    "xyz.x",
    "xyz.y",
    "xyz.z",
    "rpy.roll",
    "rpy.pitch",
    "rpy.yaw",
];
pub(super) const LINK_FIELDS: &[&str] = &[
    "mass",
    "ixx",
    "iyy",
    "izz",
    "ixy",
    "iyz",
    "ixz",
    "xyz.x",
    "xyz.y",
    "xyz.z",
    "rpy.roll",
    "rpy.pitch",
    "rpy.yaw",
];

/// The number a joint's or link's origin field (`xyz.x`, `rpy.yaw`, ...)
/// names.
pub(super) fn slot<'a>(
    xyz: &'a mut [Expr; 3],
    rpy: &'a mut [Expr; 3],
    field: &str,
) -> Option<&'a mut Expr> {
    Some(match field {
        "xyz.x" => &mut xyz[0],
        "xyz.y" => &mut xyz[1],
        "xyz.z" => &mut xyz[2],
        "rpy.roll" => &mut rpy[0],
        "rpy.pitch" => &mut rpy[1],
        "rpy.yaw" => &mut rpy[2],
        _ => return None,
    })
}

impl LinkNumbers {
    /// The number `parameters(...)` names by `field`, if the link has it.
    pub(super) fn slot(&mut self, field: &str) -> Option<&mut Expr> {
        let inertia = ["ixx", "iyy", "izz", "ixy", "iyz", "ixz"];
        if field == "mass" {
            return Some(&mut self.mass);
        }
        match inertia.iter().position(|f| *f == field) {
            Some(k) => Some(&mut self.inertia[k]),
            None => slot(&mut self.xyz, &mut self.rpy, field),
        }
    }
}

/// Three numbers of the file as float constants.
pub(super) fn floats(v: &[f64; 3], span: Span) -> [Expr; 3] {
    v.map(|x| Expr::Float(x, span))
}
