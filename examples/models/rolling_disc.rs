//! A thin uniform disc rolling without slip on a horizontal plane.

use appell::Appell;

/// A thin uniform disc of radius `r` and mass `m` rolling without slip on
/// the horizontal plane z = 0 under gravity `g` (N.z up). `yaw` turns about
/// N.z, `lean` about the yawed x axis (from the vertical), `spin` about the
/// leaned y axis (the disc axis); (x, y) is the horizontal position of the
/// disc centre. The disc's own spin angle, its heading and its position
/// appear nowhere in the equations: only the lean is integrated.
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(
    coordinates(yaw, lean, spin, x, y),
    speeds(yaw, lean, spin),
    positive(r, m)
)]
#[appell(frame(A = N.rotate_z(yaw)), frame(B = A.rotate_x(lean)), frame(C = B.rotate_y(spin)))]
#[appell(point(D = O + x * N.x + y * N.y + r * cos(lean) * N.z), point(P = D - r * B.z))]
#[appell(body(disc, center = D, frame = C, mass = m, inertia = principal(m * r * r / 4, m * r * r / 2, m * r * r / 4)))]
#[appell(rolls(disc, contact = P))]
#[appell(gravity(-g * N.z))]
pub struct RollingDisc {
    /// Radius [m].
    pub r: f64,
    /// Mass [kg].
    pub m: f64,
    /// Gravity [m/s²].
    pub g: f64,
}

impl Default for RollingDisc {
    fn default() -> Self {
        RollingDisc {
            r: 0.15,
            m: 1.0,
            g: 9.81,
        }
    }
}
