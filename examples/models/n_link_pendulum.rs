//! The n-link planar pendulum family for n = 2, 4, 8: point masses at the
//! ends of massless links, written out for each n (the derive needs the
//! mechanism at compile time).

use appell::Appell;

/// 2 point masses `m1..m2` at the ends of massless links `l1..l2`,
/// planar, absolute angles `q1..` from the downward vertical, gravity `g`.
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(coordinates(q1, q2), speeds(q1, q2))]
#[appell(point(P1 = O + l1 * sin(q1) * N.x - l1 * cos(q1) * N.y), particle(P1, mass = m1))]
#[appell(point(P2 = P1 + l2 * sin(q2) * N.x - l2 * cos(q2) * N.y), particle(P2, mass = m2))]
#[appell(gravity(-g * N.y))]
pub struct Pendulum2 {
    /// Mass 1 [kg].
    pub m1: f64,
    /// Mass 2 [kg].
    pub m2: f64,
    /// Link 1 [m].
    pub l1: f64,
    /// Link 2 [m].
    pub l2: f64,
    /// Gravity [m/s²].
    pub g: f64,
}

impl Default for Pendulum2 {
    /// Unit masses and links, g = 9.81.
    fn default() -> Self {
        Pendulum2 {
            m1: 1.0,
            m2: 1.0,
            l1: 1.0,
            l2: 1.0,
            g: 9.81,
        }
    }
}

/// 4 point masses `m1..m4` at the ends of massless links `l1..l4`,
/// planar, absolute angles `q1..` from the downward vertical, gravity `g`.
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(coordinates(q1, q2, q3, q4), speeds(q1, q2, q3, q4))]
#[appell(point(P1 = O + l1 * sin(q1) * N.x - l1 * cos(q1) * N.y), particle(P1, mass = m1))]
#[appell(point(P2 = P1 + l2 * sin(q2) * N.x - l2 * cos(q2) * N.y), particle(P2, mass = m2))]
#[appell(point(P3 = P2 + l3 * sin(q3) * N.x - l3 * cos(q3) * N.y), particle(P3, mass = m3))]
#[appell(point(P4 = P3 + l4 * sin(q4) * N.x - l4 * cos(q4) * N.y), particle(P4, mass = m4))]
#[appell(gravity(-g * N.y))]
pub struct Pendulum4 {
    /// Mass 1 [kg].
    pub m1: f64,
    /// Mass 2 [kg].
    pub m2: f64,
    /// Mass 3 [kg].
    pub m3: f64,
    /// Mass 4 [kg].
    pub m4: f64,
    /// Link 1 [m].
    pub l1: f64,
    /// Link 2 [m].
    pub l2: f64,
    /// Link 3 [m].
    pub l3: f64,
    /// Link 4 [m].
    pub l4: f64,
    /// Gravity [m/s²].
    pub g: f64,
}

impl Default for Pendulum4 {
    /// Unit masses and links, g = 9.81.
    fn default() -> Self {
        Pendulum4 {
            m1: 1.0,
            m2: 1.0,
            m3: 1.0,
            m4: 1.0,
            l1: 1.0,
            l2: 1.0,
            l3: 1.0,
            l4: 1.0,
            g: 9.81,
        }
    }
}

/// 8 point masses `m1..m8` at the ends of massless links `l1..l8`,
/// planar, absolute angles `q1..` from the downward vertical, gravity `g`.
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(
    coordinates(q1, q2, q3, q4, q5, q6, q7, q8),
    speeds(q1, q2, q3, q4, q5, q6, q7, q8)
)]
#[appell(point(P1 = O + l1 * sin(q1) * N.x - l1 * cos(q1) * N.y), particle(P1, mass = m1))]
#[appell(point(P2 = P1 + l2 * sin(q2) * N.x - l2 * cos(q2) * N.y), particle(P2, mass = m2))]
#[appell(point(P3 = P2 + l3 * sin(q3) * N.x - l3 * cos(q3) * N.y), particle(P3, mass = m3))]
#[appell(point(P4 = P3 + l4 * sin(q4) * N.x - l4 * cos(q4) * N.y), particle(P4, mass = m4))]
#[appell(point(P5 = P4 + l5 * sin(q5) * N.x - l5 * cos(q5) * N.y), particle(P5, mass = m5))]
#[appell(point(P6 = P5 + l6 * sin(q6) * N.x - l6 * cos(q6) * N.y), particle(P6, mass = m6))]
#[appell(point(P7 = P6 + l7 * sin(q7) * N.x - l7 * cos(q7) * N.y), particle(P7, mass = m7))]
#[appell(point(P8 = P7 + l8 * sin(q8) * N.x - l8 * cos(q8) * N.y), particle(P8, mass = m8))]
#[appell(gravity(-g * N.y))]
pub struct Pendulum8 {
    /// Mass 1 [kg].
    pub m1: f64,
    /// Mass 2 [kg].
    pub m2: f64,
    /// Mass 3 [kg].
    pub m3: f64,
    /// Mass 4 [kg].
    pub m4: f64,
    /// Mass 5 [kg].
    pub m5: f64,
    /// Mass 6 [kg].
    pub m6: f64,
    /// Mass 7 [kg].
    pub m7: f64,
    /// Mass 8 [kg].
    pub m8: f64,
    /// Link 1 [m].
    pub l1: f64,
    /// Link 2 [m].
    pub l2: f64,
    /// Link 3 [m].
    pub l3: f64,
    /// Link 4 [m].
    pub l4: f64,
    /// Link 5 [m].
    pub l5: f64,
    /// Link 6 [m].
    pub l6: f64,
    /// Link 7 [m].
    pub l7: f64,
    /// Link 8 [m].
    pub l8: f64,
    /// Gravity [m/s²].
    pub g: f64,
}

impl Default for Pendulum8 {
    /// Unit masses and links, g = 9.81.
    fn default() -> Self {
        Pendulum8 {
            m1: 1.0,
            m2: 1.0,
            m3: 1.0,
            m4: 1.0,
            m5: 1.0,
            m6: 1.0,
            m7: 1.0,
            m8: 1.0,
            l1: 1.0,
            l2: 1.0,
            l3: 1.0,
            l4: 1.0,
            l5: 1.0,
            l6: 1.0,
            l7: 1.0,
            l8: 1.0,
            g: 9.81,
        }
    }
}
