//! The rolling disc of `rolling_disc.rs`, pushed along its heading by a
//! force that swings back and forth, F = F0 sin(ω t). It rolls while the
//! friction rolling needs stays within μ N. Where it does not, it slides,
//! and it grips again where the slip dies out.
//!
//! In the sliding scene, the friction at the contact is the regularised
//! Coulomb law of `friction(...)` against the slip of the disc's material
//! point there. Its normal force N is an input, `normal`: the coordinates
//! keep the disc on the ground, so N is what the vertical momentum balance
//! needs, m (g + z̈). z̈ depends on the friction, so the equations are
//! implicit in N. At run time `appell::sliding` finds N at every
//! evaluation.
//!
//! `SlidingDisc` is the same disc written with the sliding constraint set
//! alone: no rolling contact, no scenes. Its equations are the sliding
//! scene's. `tests/sliding_contacts.rs` and `examples/sliding_disc.rs` use
//! both.

use appell::constraint_forces::{contact_forces, Friction};
use appell::hybrid::{Guard, Phase};
use appell::sliding::{normal_inputs, SlidingContact};
use appell::{Appell, Model, ModelError};

/// The pushed disc, rolling (`rolls(..., effect = rolling)`) or sliding
/// with Coulomb friction μ N at the contact (`slides = sliding`: the
/// contact's friction, in effect `sliding`, where a scene drops the
/// rolling).
#[allow(clippy::duplicated_attributes)] // the scenes name effects alike
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(
    coordinates(yaw, lean, spin, x, y),
    speeds(yaw, lean, spin),
    positive(r, m)
)]
#[appell(frame(A = N.rotate_z(yaw)), frame(B = A.rotate_x(lean)), frame(C = B.rotate_y(spin)))]
#[appell(point(D = O + x * N.x + y * N.y + r * cos(lean) * N.z), point(P = D - r * B.z))]
#[appell(body(disc, center = D, frame = C, mass = m, inertia = principal(m * r * r / 4, m * r * r / 2, m * r * r / 4)))]
#[appell(rolls(disc, contact = P, effect = rolling,
               slides = sliding, mu = mu, normal = normal, smoothing = eps))]
#[appell(gravity(-g * N.z))]
#[appell(force(D, push * sin(omega * t) * A.x, effect = push))]
#[appell(inputs(normal))]
#[appell(scene(rolling, effects(gravity, push, rolling)))]
#[appell(scene(
    sliding,
    effects(gravity, push, sliding),
    speeds(yaw, lean, spin, x, y)
))]
pub struct PushedRollingDisc {
    /// Radius [m].
    pub r: f64,
    /// Mass [kg].
    pub m: f64,
    /// Gravity [m/s²].
    pub g: f64,
    /// Friction coefficient.
    pub mu: f64,
    /// The friction law's regularisation: the slip speed [m/s] below
    /// which friction falls off linearly.
    pub eps: f64,
    /// The push's amplitude F0 [N].
    pub push: f64,
    /// The push's angular frequency ω [rad/s].
    pub omega: f64,
}

/// The sliding disc alone: the same disc, push and friction (written out
/// as `friction(P, ...)` on the disc at its contact), with the sliding
/// constraint set (none besides the ground's height) and all five speeds.
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(
    coordinates(yaw, lean, spin, x, y),
    speeds(yaw, lean, spin, x, y),
    positive(r, m)
)]
#[appell(frame(A = N.rotate_z(yaw)), frame(B = A.rotate_x(lean)), frame(C = B.rotate_y(spin)))]
#[appell(point(D = O + x * N.x + y * N.y + r * cos(lean) * N.z), point(P = D - r * B.z))]
#[appell(body(disc, center = D, frame = C, mass = m, inertia = principal(m * r * r / 4, m * r * r / 2, m * r * r / 4)))]
#[appell(gravity(-g * N.z))]
#[appell(force(D, push * sin(omega * t) * A.x, effect = push))]
#[appell(inputs(normal))]
#[appell(friction(P, mu = mu, normal = normal, smoothing = eps, frame = C, center = D, effect = sliding))]
pub struct SlidingDisc {
    /// Radius [m].
    pub r: f64,
    /// Mass [kg].
    pub m: f64,
    /// Gravity [m/s²].
    pub g: f64,
    /// Friction coefficient.
    pub mu: f64,
    /// The friction law's regularisation [m/s].
    pub eps: f64,
    /// The push's amplitude F0 [N].
    pub push: f64,
    /// The push's angular frequency ω [rad/s].
    pub omega: f64,
}

/// The disc the test and the example push: 0.15 m, 1 kg, μ = 0.3, pushed
/// with F0 = 3.6 μ m g, beyond the about 3 μ m g it can take rolling
/// upright.
pub const DISC: PushedRollingDisc = PushedRollingDisc {
    r: 0.15,
    m: 1.0,
    g: 9.81,
    mu: 0.3,
    eps: 1e-3,
    push: 3.6 * 0.3 * 1.0 * 9.81,
    omega: 2.0,
};

impl PushedRollingDisc {
    /// The same disc written with the sliding constraint set alone.
    pub fn sliding_alone(&self) -> SlidingDisc {
        SlidingDisc {
            r: self.r,
            m: self.m,
            g: self.g,
            mu: self.mu,
            eps: self.eps,
            push: self.push,
            omega: self.omega,
        }
    }
}

/// The slip speed below which a sliding disc grips again [m/s]: the
/// regularised friction no longer decides the motion there.
pub const GRIP_SPEED: f64 = 1e-2;

/// The velocity of the disc's material point at the contact, (v_x, v_y):
/// the full model's rolling rows D q̇ + d at the coordinate rates `qdot`.
pub fn slip(
    disc: &PushedRollingDisc,
    t: f64,
    q: &[f64],
    qdot: &[f64],
) -> Result<[f64; 2], ModelError> {
    let mut rows = [0.0; 2];
    disc.constraint_residuals(t, q, qdot, &mut [], &mut rows)?;
    Ok(rows)
}

/// μ N less the friction rolling needs, at a state of the rolling scene
/// (positive while the disc can roll).
pub fn friction_margin(
    disc: &PushedRollingDisc,
    t: f64,
    q: &[f64],
    u: &[f64],
) -> Result<f64, ModelError> {
    let rolling = PushedRollingDiscRolling::from_ref(disc);
    let forces = contact_forces(rolling, t, q, u, &[]).map_err(|_| ModelError::Contact {
        what: "the rolling contact's forces could not be found",
    })?;
    match forces.contacts[0].friction() {
        Friction::Required {
            normal, tangential, ..
        } => Ok(disc.mu * normal - tangential),
        Friction::LiftOff { .. } => Err(ModelError::Contact {
            what: "the disc lifts off",
        }),
        Friction::NormalUnavailable(_) => Err(ModelError::Contact {
            what: "no normal force",
        }),
    }
}

/// The two phases: rolling (0), left where the friction it needs reaches
/// μ N, and sliding (1), its normal force found at every evaluation, left
/// where the slip speed comes down to [`GRIP_SPEED`].
pub fn phases(disc: &PushedRollingDisc) -> Vec<Phase<'_>> {
    let sliding = PushedRollingDiscSliding::from_ref(disc);
    let contact = SlidingContact::named(disc, "P", sliding, "normal", [0.0, 0.0, 1.0])
        .expect("the disc rolls at P and its sliding scene reads `normal`");
    vec![
        Phase::new("rolling", PushedRollingDiscRolling::from_ref(disc)).guard(Guard::new(
            "slips",
            1,
            move |t, q: &[f64], u: &[f64]| friction_margin(disc, t, q, u),
        )),
        Phase::new("sliding", sliding)
            .state_inputs(normal_inputs(sliding, vec![contact]))
            .guard(
                Guard::new("grips", 0, move |t, q: &[f64], u: &[f64]| {
                    let [vx, vy] = slip(disc, t, q, u)?;
                    Ok(vx.hypot(vy) - GRIP_SPEED)
                })
                .after_rising(),
            ),
    ]
}
