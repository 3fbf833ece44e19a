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

/// Three angles of the file (an rpy) as float constants; with a
/// `right_angles` tolerance, one within it of a multiple k of π/2 is k π/2
/// in floating point, which the symbolic engine turns into an exact turn (a
/// permutation of axes, sines and cosines 0 and ±1).
pub(super) fn angles(v: &[f64; 3], span: Span, right_angles: Option<f64>) -> [Expr; 3] {
    v.map(|x| Expr::Float(right_angle(x, right_angles), span))
}

/// `x`, or the multiple of π/2 within `tolerance` of it.
fn right_angle(x: f64, tolerance: Option<f64>) -> f64 {
    let Some(tolerance) = tolerance else {
        return x;
    };
    let k = (x / std::f64::consts::FRAC_PI_2).round();
    let nearest = k * std::f64::consts::FRAC_PI_2;
    if (nearest - x).abs() <= tolerance {
        nearest
    } else {
        x
    }
}

/// Three numbers of the file as float constants.
pub(super) fn floats(v: &[f64; 3], span: Span) -> [Expr; 3] {
    v.map(|x| Expr::Float(x, span))
}

#[cfg(test)]
#[allow(clippy::approx_constant)] // π/2 and π as URDF files write them
mod tests {
    use super::right_angle;
    use std::f64::consts::{FRAC_PI_2, PI};

    #[test]
    fn right_angles_within_the_tolerance_are_exact() {
        let tol = Some(1e-10);
        assert_eq!(right_angle(1.57079632679, tol), FRAC_PI_2);
        assert_eq!(right_angle(-1.57079632679, tol), -FRAC_PI_2);
        assert_eq!(right_angle(3.14159265359, tol), PI);
        assert_eq!(right_angle(-3.14159265359, tol), -PI);
        assert_eq!(right_angle(4.71238898038, tol), 3.0 * FRAC_PI_2);
        assert_eq!(right_angle(1e-12, tol), 0.0);
    }

    #[test]
    fn other_angles_are_kept() {
        assert_eq!(right_angle(1.5708, Some(1e-10)), 1.5708);
        assert_eq!(right_angle(0.3, Some(1e-3)), 0.3);
        assert_eq!(right_angle(1.57079632679, None), 1.57079632679);
        assert_eq!(right_angle(1.5708, Some(1e-3)), FRAC_PI_2);
    }
}
