//! The n-link planar pendulum family for n = 2, 4, 8, 16: point masses at
//! the ends of massless links, each one declaration repeated over its links
//! (the derive needs the number of links at compile time; changing it is
//! one edit of the literal).

use appell::Appell;

/// 2 point masses `m[0..2]` at the ends of massless links `l[0..2]`,
/// planar, absolute angles `q_0..q_1` from the downward vertical,
/// gravity `g`.
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(coordinates(q[0..2]), speeds(q[0..2]), gravity(-g * N.y))]
#[appell(point(P[0] = O + l[0] * sin(q[0]) * N.x - l[0] * cos(q[0]) * N.y))]
#[appell(repeat(i in 1..2, point(P[i] = P[i - 1] + l[i] * sin(q[i]) * N.x - l[i] * cos(q[i]) * N.y)))]
#[appell(repeat(i in 0..2, particle(P[i], mass = m[i])))]
pub struct Pendulum2 {
    /// Masses [kg].
    pub m: [f64; 2],
    /// Links [m].
    pub l: [f64; 2],
    /// Gravity [m/s²].
    pub g: f64,
}

impl Default for Pendulum2 {
    /// Unit masses and links, g = 9.81.
    fn default() -> Self {
        Pendulum2 {
            m: [1.0; 2],
            l: [1.0; 2],
            g: 9.81,
        }
    }
}

/// 4 point masses `m[0..4]` at the ends of massless links `l[0..4]`,
/// planar, absolute angles `q_0..q_3` from the downward vertical,
/// gravity `g`.
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(coordinates(q[0..4]), speeds(q[0..4]), gravity(-g * N.y))]
#[appell(point(P[0] = O + l[0] * sin(q[0]) * N.x - l[0] * cos(q[0]) * N.y))]
#[appell(repeat(i in 1..4, point(P[i] = P[i - 1] + l[i] * sin(q[i]) * N.x - l[i] * cos(q[i]) * N.y)))]
#[appell(repeat(i in 0..4, particle(P[i], mass = m[i])))]
pub struct Pendulum4 {
    /// Masses [kg].
    pub m: [f64; 4],
    /// Links [m].
    pub l: [f64; 4],
    /// Gravity [m/s²].
    pub g: f64,
}

impl Default for Pendulum4 {
    /// Unit masses and links, g = 9.81.
    fn default() -> Self {
        Pendulum4 {
            m: [1.0; 4],
            l: [1.0; 4],
            g: 9.81,
        }
    }
}

/// 8 point masses `m[0..8]` at the ends of massless links `l[0..8]`,
/// planar, absolute angles `q_0..q_7` from the downward vertical,
/// gravity `g`.
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(coordinates(q[0..8]), speeds(q[0..8]), gravity(-g * N.y))]
#[appell(point(P[0] = O + l[0] * sin(q[0]) * N.x - l[0] * cos(q[0]) * N.y))]
#[appell(repeat(i in 1..8, point(P[i] = P[i - 1] + l[i] * sin(q[i]) * N.x - l[i] * cos(q[i]) * N.y)))]
#[appell(repeat(i in 0..8, particle(P[i], mass = m[i])))]
pub struct Pendulum8 {
    /// Masses [kg].
    pub m: [f64; 8],
    /// Links [m].
    pub l: [f64; 8],
    /// Gravity [m/s²].
    pub g: f64,
}

impl Default for Pendulum8 {
    /// Unit masses and links, g = 9.81.
    fn default() -> Self {
        Pendulum8 {
            m: [1.0; 8],
            l: [1.0; 8],
            g: 9.81,
        }
    }
}

/// 16 point masses `m[0..16]` at the ends of massless links `l[0..16]`,
/// planar, absolute angles `q_0..q_15` from the downward vertical,
/// gravity `g`.
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(coordinates(q[0..16]), speeds(q[0..16]), gravity(-g * N.y))]
#[appell(point(P[0] = O + l[0] * sin(q[0]) * N.x - l[0] * cos(q[0]) * N.y))]
#[appell(repeat(i in 1..16, point(P[i] = P[i - 1] + l[i] * sin(q[i]) * N.x - l[i] * cos(q[i]) * N.y)))]
#[appell(repeat(i in 0..16, particle(P[i], mass = m[i])))]
pub struct Pendulum16 {
    /// Masses [kg].
    pub m: [f64; 16],
    /// Links [m].
    pub l: [f64; 16],
    /// Gravity [m/s²].
    pub g: f64,
}

impl Default for Pendulum16 {
    /// Unit masses and links, g = 9.81.
    fn default() -> Self {
        Pendulum16 {
            m: [1.0; 16],
            l: [1.0; 16],
            g: 9.81,
        }
    }
}
