//! Rigid bodies oriented by unit quaternions: no orientation is singular.

use appell::Appell;

/// A rigid body moving freely in space (no gravity), oriented by the unit
/// quaternion `pose_qw, pose_qx, pose_qy, pose_qz`; its speeds are the body
/// components of its angular velocity `pose_wx, pose_wy, pose_wz` and the
/// rates of its centre's position `pose_x, pose_y, pose_z`. With distinct
/// principal moments, spin about the intermediate axis flips over and over
/// (the Dzhanibekov effect).
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(joint(pose, free, parent = N, child = B))]
#[appell(body(handle, center = B_origin, frame = B, mass = m, inertia = principal(i1, i2, i3)))]
pub struct FreeBody {
    /// Mass [kg].
    pub m: f64,
    /// Principal moments of inertia about B.x, B.y, B.z [kg m²].
    pub i1: f64,
    /// About B.y (the intermediate one by default).
    pub i2: f64,
    /// About B.z.
    pub i3: f64,
}

impl Default for FreeBody {
    /// A T-handle: moments 1, 2, 3 kg m².
    fn default() -> Self {
        FreeBody {
            m: 1.0,
            i1: 1.0,
            i2: 2.0,
            i3: 3.0,
        }
    }
}

/// The Chaplygin ball: a sphere of radius `r` whose mass centre is its
/// geometric centre but whose principal moments differ, rolling without
/// slipping on the horizontal plane; oriented by a unit quaternion, so it
/// rolls through every orientation (Euler angles are singular where the
/// second angle vanishes). The centre's `x`, `y` are dependent on the
/// angular velocity `roll_wx, roll_wy, roll_wz` (body axes).
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(coordinates(x, y), positive(r))]
#[appell(point(G = O + x * N.x + y * N.y + r * N.z))]
#[appell(joint(roll, spherical, parent = N, child = B, at = G))]
#[appell(point(C = G - r * N.z))]
#[appell(body(ball, center = B_origin, frame = B, mass = m, inertia = principal(i1, i2, i3)))]
#[appell(rolls(ball, contact = C), gravity(-g * N.z))]
pub struct ChaplyginBall {
    /// Mass [kg].
    pub m: f64,
    /// Radius [m].
    pub r: f64,
    /// Principal moments of inertia about B.x, B.y, B.z [kg m²].
    pub i1: f64,
    /// About B.y.
    pub i2: f64,
    /// About B.z.
    pub i3: f64,
    /// Gravity [m/s²].
    pub g: f64,
}

impl Default for ChaplyginBall {
    /// A unit ball with moments 0.3, 0.4, 0.5 kg m².
    fn default() -> Self {
        ChaplyginBall {
            m: 1.0,
            r: 1.0,
            i1: 0.3,
            i2: 0.4,
            i3: 0.5,
            g: 9.81,
        }
    }
}
