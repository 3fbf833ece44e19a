//! A disc standing on a line, pushed at its centre by a force that swings
//! back and forth, F = F0 sin(ω t): it rolls while the friction rolling
//! needs stays within μ N, and slides (forward or backward, kinetic
//! friction μ N against the slip) where it does not. The disc's height is
//! fixed by construction, so the normal force is its weight, N = m g.
//! `tests/rolling_sliding.rs` and `examples/pushed_disc.rs` switch between
//! the three scenes with [`phases`].

use appell::constraint_forces::contact_forces;
use appell::hybrid::{Guard, Phase};
use appell::{Appell, ModelError};

/// The pushed disc: rolling (`rolls(..., effect = rolling)`) or sliding,
/// with the friction of the sliding direction (a force μ m g at the
/// contact, written as the same force at the centre and its moment).
#[allow(clippy::duplicated_attributes)] // the scenes name effects alike
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(coordinates(x, theta), speeds(theta), positive(m, r))]
#[appell(frame(B = N.rotate_z(theta)))]
#[appell(point(C = O + x * N.x + r * N.y), point(P = O + x * N.x))]
#[appell(body(disc, center = C, frame = B, mass = m,
              inertia = principal(m * r * r / 4, m * r * r / 4, m * r * r / 2)))]
#[appell(rolls(disc, contact = P, effect = rolling))]
#[appell(force(C, push * sin(omega * t) * N.x, effect = push))]
#[appell(force(C, -mu * m * g * N.x, effect = slide_forward),
         torque(B, -r * mu * m * g * N.z, effect = slide_forward))]
#[appell(force(C, mu * m * g * N.x, effect = slide_backward),
         torque(B, r * mu * m * g * N.z, effect = slide_backward))]
#[appell(scene(rolling, effects(push, rolling)))]
#[appell(scene(sliding_forward, effects(push, slide_forward), speeds(x, theta)))]
#[appell(scene(sliding_backward, effects(push, slide_backward), speeds(x, theta)))]
pub struct PushedDisc {
    /// Mass [kg].
    pub m: f64,
    /// Radius [m].
    pub r: f64,
    /// Gravity [m/s²].
    pub g: f64,
    /// Friction coefficient.
    pub mu: f64,
    /// The push's amplitude F0 [N].
    pub push: f64,
    /// The push's angular frequency ω [rad/s].
    pub omega: f64,
}

/// The disc the test and the example push: F0 = 3.6 μ m g, beyond the
/// 3 μ m g it can take rolling for a stretch of each swing.
pub const DISC: PushedDisc = PushedDisc {
    m: 1.0,
    r: 0.2,
    g: 9.81,
    mu: 0.3,
    push: 3.6 * 0.3 * 1.0 * 9.81,
    omega: 2.0,
};

/// The friction force along N.x that rolling needs on `disc` (the
/// rolling row's reaction).
pub fn needed_friction(disc: &PushedDisc, t: f64, q: &[f64], u: &[f64]) -> Result<f64, ModelError> {
    let rolling = PushedDiscRolling::from_ref(disc);
    contact_forces(rolling, t, q, u, &[])
        .map(|f| f.contacts[0].rolling[0])
        .map_err(|_| ModelError::NonFinite {
            what: "the friction",
        })
}

/// The slip velocity of the disc's material point at the contact.
pub fn slip(disc: &PushedDisc, u: &[f64]) -> f64 {
    u[0] + disc.r * u[1]
}

/// The three phases: rolling (0), left forward (1) or backward (2) where
/// the friction rolling needs reaches μ m g, and sliding forward or
/// backward, left where the slip dies.
pub fn phases(disc: &PushedDisc) -> Vec<Phase<'_>> {
    let limit = disc.mu * disc.m * disc.g;
    let grips = |sign: f64| {
        Guard::new("grips", 0, move |_, _: &[f64], u: &[f64]| {
            Ok(sign * slip(disc, u))
        })
    };
    vec![
        Phase::new("rolling", PushedDiscRolling::from_ref(disc))
            .guard(Guard::new(
                "slips forward",
                1,
                move |t, q: &[f64], u: &[f64]| Ok(needed_friction(disc, t, q, u)? + limit),
            ))
            .guard(Guard::new(
                "slips backward",
                2,
                move |t, q: &[f64], u: &[f64]| Ok(limit - needed_friction(disc, t, q, u)?),
            )),
        Phase::new("sliding forward", PushedDiscSlidingForward::from_ref(disc)).guard(grips(1.0)),
        Phase::new(
            "sliding backward",
            PushedDiscSlidingBackward::from_ref(disc),
        )
        .guard(grips(-1.0)),
    ]
}
