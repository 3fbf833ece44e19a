//! A planar double pendulum: point masses at the ends of massless links,
//! absolute angles from the downward vertical.

use appell::Appell;

/// Point masses `m1`, `m2` at the ends of massless links `l1`, `l2`; the
/// angles `q1`, `q2` are measured from the downward vertical; gravity `g`.
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(coordinates(q1, q2), speeds(q1, q2))]
#[appell(point(P1 = O + l1 * sin(q1) * N.x - l1 * cos(q1) * N.y))]
#[appell(point(P2 = P1 + l2 * sin(q2) * N.x - l2 * cos(q2) * N.y))]
#[appell(particle(P1, mass = m1), particle(P2, mass = m2))]
#[appell(gravity(-g * N.y))]
pub struct DoublePendulum {
    /// First mass [kg].
    pub m1: f64,
    /// Second mass [kg].
    pub m2: f64,
    /// First link [m].
    pub l1: f64,
    /// Second link [m].
    pub l2: f64,
    /// Gravity [m/s²].
    pub g: f64,
}

impl Default for DoublePendulum {
    fn default() -> Self {
        DoublePendulum {
            m1: 1.0,
            m2: 1.0,
            l1: 1.0,
            l2: 1.0,
            g: 9.81,
        }
    }
}
