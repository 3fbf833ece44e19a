//! The Chaplygin sleigh: a rigid body on a knife edge.

use appell::Appell;

/// A rigid body of mass `m` and inertia `i0` about its mass centre C, resting
/// on a knife edge at P = (x, y) that cannot slide sideways; C lies a
/// distance `b` ahead of the edge along the heading θ. The sleigh's turning
/// decays and it ends up moving in a straight line (v̇ = b ω²,
/// (I + m b²) ω̇ = −m b v ω).
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(coordinates(x, y, theta), speeds(x, theta), positive(m, b))]
#[appell(frame(B = N.rotate_z(theta)))]
#[appell(point(P = O + x * N.x + y * N.y), point(C = P + b * B.x))]
#[appell(body(sleigh, center = C, frame = B, mass = m, inertia = principal(i0, i0, i0)))]
#[appell(nonholonomic(dt(y) * cos(theta) - dt(x) * sin(theta) == 0))]
pub struct ChaplyginSleigh {
    /// Mass [kg].
    pub m: f64,
    /// Inertia about the mass centre [kg m²].
    pub i0: f64,
    /// Distance from the knife edge to the mass centre [m].
    pub b: f64,
}

impl Default for ChaplyginSleigh {
    fn default() -> Self {
        ChaplyginSleigh {
            m: 1.0,
            i0: 0.05,
            b: 0.3,
        }
    }
}
