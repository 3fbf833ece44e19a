//! Whether a link's `<inertial>` can be a rigid body's: a positive mass and
//! a central inertia that [`crate::physical`] accepts; and the inertia of
//! links fixed together, merged into one rigid body as Pinocchio merges
//! them, so the rules apply to the bodies the dynamics sees.

pub(super) use crate::physical::check_matrix;

/// What a link's inertial describes.
#[derive(Debug, PartialEq)]
pub(super) enum Mass {
    /// No mass and no inertia: a frame, not a body.
    None,
    /// A body.
    Body,
}

/// The inertia matrix from the URDF's six numbers.
fn matrix(i: &urdf_rs::Inertia) -> [[f64; 3]; 3] {
    [
        [i.ixx, i.ixy, i.ixz],
        [i.ixy, i.iyy, i.iyz],
        [i.ixz, i.iyz, i.izz],
    ]
}

/// Checks a link's mass and inertia as written; `Err` says what is wrong.
/// A zero inertia with a positive mass is a point mass, and allowed.
pub(super) fn check(mass: f64, inertia: &urdf_rs::Inertia) -> Result<Mass, String> {
    let m = matrix(inertia);
    let entries = m.iter().flatten();
    if !mass.is_finite() || entries.clone().any(|x| !x.is_finite()) {
        return Err("its mass or inertia is not a finite number".into());
    }
    let zero = entries.clone().all(|x| *x == 0.0);
    if mass < 0.0 {
        return Err(format!("its mass {mass} is negative"));
    }
    if mass == 0.0 {
        return if zero {
            Ok(Mass::None)
        } else {
            Err("its mass is zero but its inertia is not: a body needs a positive mass".into())
        };
    }
    if zero {
        return Ok(Mass::Body);
    }
    check_matrix(&m)?;
    Ok(Mass::Body)
}

/// A 3×3 matrix, rows first.
pub(super) type Mat = [[f64; 3]; 3];

/// A frame's place in another: its origin and its axes (columns).
#[derive(Clone, Copy, Debug)]
pub(super) struct Pose {
    pub origin: [f64; 3],
    pub axes: Mat,
}

const IDENTITY: Mat = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

impl Pose {
    pub(super) const IDENTITY: Pose = Pose {
        origin: [0.0; 3],
        axes: IDENTITY,
    };

    /// The pose of a frame placed in this one by URDF's `xyz` and `rpy`.
    pub(super) fn then(&self, xyz: [f64; 3], rpy: [f64; 3]) -> Pose {
        let moved = mul_vec(&self.axes, xyz);
        Pose {
            origin: [0, 1, 2].map(|k| self.origin[k] + moved[k]),
            axes: mul(&self.axes, &rotation(rpy)),
        }
    }
}

/// URDF's rpy as a rotation matrix: Rz(yaw) Ry(pitch) Rx(roll).
pub(super) fn rotation([r, p, y]: [f64; 3]) -> Mat {
    let (sr, cr) = r.sin_cos();
    let (sp, cp) = p.sin_cos();
    let (sy, cy) = y.sin_cos();
    [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]
}

fn mul(a: &Mat, b: &Mat) -> Mat {
    let mut out = [[0.0; 3]; 3];
    for r in 0..3 {
        for c in 0..3 {
            out[r][c] = (0..3).map(|k| a[r][k] * b[k][c]).sum();
        }
    }
    out
}

fn mul_vec(a: &Mat, v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|r| (0..3).map(|k| a[r][k] * v[k]).sum())
}

fn transpose(a: &Mat) -> Mat {
    let mut out = [[0.0; 3]; 3];
    for r in 0..3 {
        for c in 0..3 {
            out[r][c] = a[c][r];
        }
    }
    out
}

/// `rot · i · rotᵀ`: an inertia given along `rot`'s axes, along the axes
/// `rot` is written in.
pub(super) fn turned(rot: &Mat, i: &Mat) -> Mat {
    mul(&mul(rot, i), &transpose(rot))
}

/// The inertia matrix of URDF's six numbers ixx, iyy, izz, ixy, iyz, ixz.
pub(super) fn from_six([xx, yy, zz, xy, yz, xz]: [f64; 6]) -> Mat {
    [[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]
}

/// A link's inertial along a common frame: its mass, its centre, and its
/// inertia about the centre along the common frame's axes.
#[derive(Clone, Copy, Debug)]
pub(super) struct Part {
    pub mass: f64,
    pub center: [f64; 3],
    pub inertia: Mat,
}

/// The part of an inertial (`xyz`, `rpy`, inertia along the inertial's
/// axes) of a link at `link` in the common frame.
pub(super) fn part(link: &Pose, mass: f64, xyz: [f64; 3], rpy: [f64; 3], inertia: &Mat) -> Part {
    let at = link.then(xyz, rpy);
    Part {
        mass,
        center: at.origin,
        inertia: turned(&at.axes, inertia),
    }
}

/// Parts fixed together as one body: the total mass, the centre of mass
/// (the first part's centre when there is no mass) and the inertia about
/// it (Steiner's theorem for each part).
pub(super) fn merged(parts: &[Part]) -> Part {
    let mass: f64 = parts.iter().map(|p| p.mass).sum();
    let center = if mass > 0.0 {
        [0, 1, 2].map(|k| parts.iter().map(|p| p.mass * p.center[k]).sum::<f64>() / mass)
    } else {
        parts.first().map_or([0.0; 3], |p| p.center)
    };
    let mut inertia = [[0.0; 3]; 3];
    for p in parts {
        let d = [0, 1, 2].map(|k| p.center[k] - center[k]);
        let dd: f64 = d.iter().map(|x| x * x).sum();
        for r in 0..3 {
            for c in 0..3 {
                let delta = if r == c { dd } else { 0.0 };
                inertia[r][c] += p.inertia[r][c] + p.mass * (delta - d[r] * d[c]);
            }
        }
    }
    Part {
        mass,
        center,
        inertia,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn inertia(ixx: f64, iyy: f64, izz: f64, ixy: f64, iyz: f64, ixz: f64) -> urdf_rs::Inertia {
        urdf_rs::Inertia {
            ixx,
            iyy,
            izz,
            ixy,
            iyz,
            ixz,
        }
    }

    #[test]
    fn real_links_pass() {
        // The UR5's wrist (izz close to ixx + iyy) and a Panda link.
        assert_eq!(
            check(
                1.219,
                &inertia(0.111172755531, 0.111172755531, 0.21942, 0.0, 0.0, 0.0)
            ),
            Ok(Mass::Body)
        );
        assert_eq!(
            check(
                4.970684,
                &inertia(0.70337, 0.70661, 0.009117, -0.000139, 0.019169, 0.006772)
            ),
            Ok(Mass::Body)
        );
        assert_eq!(
            check(0.0, &inertia(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)),
            Ok(Mass::None)
        );
        assert_eq!(
            check(2.0, &inertia(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)),
            Ok(Mass::Body)
        );
    }

    #[test]
    fn bad_inertials_fail() {
        let e = check(-1.0, &inertia(1.0, 1.0, 1.0, 0.0, 0.0, 0.0)).unwrap_err();
        assert!(e.contains("negative"), "{e}");
        let e = check(0.0, &inertia(1.0, 1.0, 1.0, 0.0, 0.0, 0.0)).unwrap_err();
        assert!(e.contains("zero"), "{e}");
        let e = check(1.0, &inertia(1.0, 1.0, 1.0, 2.0, 0.0, 0.0)).unwrap_err();
        assert!(e.contains("not positive semidefinite"), "{e}");
        let e = check(1.0, &inertia(1.0, 1.0, 3.0, 0.0, 0.0, 0.0)).unwrap_err();
        assert!(e.contains("triangle"), "{e}");
        // Positive definite, but off-diagonal terms make a principal moment
        // too large: eigenvalues of [[1, .9, 0], [.9, 1, 0], [0, 0, .15]]
        // are 1.9, 0.1, 0.15.
        let e = check(1.0, &inertia(1.0, 1.0, 0.15, 0.9, 0.0, 0.0)).unwrap_err();
        assert!(e.contains("triangle"), "{e}");
    }

    #[test]
    fn two_halves_make_the_whole() {
        // A 2 kg box 0.2 × 0.4 × 0.6 m as two 1 kg halves along z, the
        // upper one given in a frame turned a quarter turn about z.
        let box_inertia = |m: f64, a: f64, b: f64, c: f64| {
            [
                [m * (b * b + c * c) / 12.0, 0.0, 0.0],
                [0.0, m * (a * a + c * c) / 12.0, 0.0],
                [0.0, 0.0, m * (a * a + b * b) / 12.0],
            ]
        };
        let lower = part(
            &Pose::IDENTITY,
            1.0,
            [0.0, 0.0, -0.15],
            [0.0; 3],
            &box_inertia(1.0, 0.2, 0.4, 0.3),
        );
        let up = Pose::IDENTITY.then([0.0, 0.0, 0.15], [0.0, 0.0, std::f64::consts::FRAC_PI_2]);
        // Along the turned frame, the box's x and y sides swap.
        let upper = part(
            &up,
            1.0,
            [0.0; 3],
            [0.0; 3],
            &box_inertia(1.0, 0.4, 0.2, 0.3),
        );
        let whole = merged(&[lower, upper]);
        let want = box_inertia(2.0, 0.2, 0.4, 0.6);
        assert_eq!(whole.mass, 2.0);
        assert!(whole.center.iter().all(|x| x.abs() < 1e-15));
        for r in 0..3 {
            for c in 0..3 {
                assert!(
                    (whole.inertia[r][c] - want[r][c]).abs() < 1e-15,
                    "{whole:?}"
                );
            }
        }
    }

    #[test]
    fn rpy_is_fixed_axes_roll_pitch_yaw() {
        // Roll a quarter turn, then yaw a quarter turn: x goes to y, y to
        // z (by the roll), z to -y then to x.
        let r = rotation([
            std::f64::consts::FRAC_PI_2,
            0.0,
            std::f64::consts::FRAC_PI_2,
        ]);
        let col = |c: usize| [r[0][c], r[1][c], r[2][c]].map(|x: f64| x.round());
        assert_eq!(col(0), [0.0, 1.0, 0.0]);
        assert_eq!(col(1), [0.0, 0.0, 1.0]);
        assert_eq!(col(2), [1.0, 0.0, 0.0]);
    }
}
