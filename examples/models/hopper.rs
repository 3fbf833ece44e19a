//! A hopping leg: a body on a spring leg with a foot, in stance (the foot
//! held on the ground, a constraint of effect `stance`) or in flight (the
//! constraint left out, the foot free). `tests/hybrid.rs` and
//! `examples/hopping.rs` switch between the two scenes.

use appell::constraint_forces::contact_forces;
use appell::hybrid::{Guard, Phase};
use appell::{Appell, ModelError};

/// A body of mass `big_m` at height z on a massless spring leg (stiffness
/// k, rest length l0) ending in a foot of mass m at height f.
#[allow(clippy::duplicated_attributes)] // the scenes name effects alike
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(coordinates(z, f), speeds(z), positive(big_m, m, k))]
#[appell(point(B = O + z * N.z), point(F = O + f * N.z))]
#[appell(particle(B, mass = big_m), particle(F, mass = m))]
#[appell(gravity(-g * N.z))]
#[appell(spring(B, F, stiffness = k, length = l0))]
#[appell(holonomic(f == 0, effect = stance))]
#[appell(scene(stance, effects(gravity, springs, stance)))]
#[appell(scene(flight, effects(gravity, springs), speeds(z, f)))]
pub struct Hopper {
    /// The body's mass [kg].
    pub big_m: f64,
    /// The foot's mass [kg].
    pub m: f64,
    /// The leg's stiffness [N/m].
    pub k: f64,
    /// The leg's rest length [m].
    pub l0: f64,
    /// Gravity [m/s²].
    pub g: f64,
}

/// The leg the test and the example hop with.
pub const HOPPER: Hopper = Hopper {
    big_m: 2.0,
    m: 0.2,
    k: 800.0,
    l0: 0.5,
    g: 9.81,
};

/// The ground's push on the foot in stance: the stance row's multiplier
/// (from the constraint-force output), positive while the foot presses on
/// the ground.
pub fn normal_force(leg: &Hopper, t: f64, q: &[f64], u: &[f64]) -> Result<f64, ModelError> {
    contact_forces(HopperStance::from_ref(leg), t, q, u, &[])
        .map(|forces| forces.multipliers[0])
        .map_err(|_| ModelError::NonFinite {
            what: "the normal force",
        })
}

/// The two phases of a hop: stance (phase 0), left at lift-off where the
/// normal force vanishes, and flight (phase 1), left at touchdown where the
/// foot's height reaches zero.
pub fn phases(leg: &Hopper) -> Vec<Phase<'_>> {
    vec![
        Phase {
            name: "stance",
            model: HopperStance::from_ref(leg),
            inputs: Vec::new(),
            state_inputs: None,
            guards: vec![Guard::new("lift-off", 1, move |t, q: &[f64], u: &[f64]| {
                normal_force(leg, t, q, u)
            })],
        },
        Phase {
            name: "flight",
            model: HopperFlight::from_ref(leg),
            inputs: Vec::new(),
            state_inputs: None,
            guards: vec![Guard::new("touchdown", 0, |_, q: &[f64], _: &[f64]| {
                Ok(q[1])
            })],
        },
    ]
}
