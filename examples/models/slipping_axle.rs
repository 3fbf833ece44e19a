//! The paper's wheel-axle built in three dimensions, on a slope, with a
//! drive torque on each wheel and wheel 1 on ice. As in the paper, the
//! drive's reaction goes to the vehicle it belongs to, which is not
//! modelled. (The coordinates hold the axle level, so a reaction on the
//! axle would be taken by that hold, a reaction at no contact.) Where the
//! torque asks more than the ice gives, wheel 1 slides while wheel 2 keeps
//! rolling, and it grips again where its slip dies out.
//!
//! The ground is z = 0 and gravity is tilted by the slope: g (sin α N.x −
//! cos α N.z), downhill along +x. The axle (half-track `h`) carries the
//! wheels (radius `a`) at its ends. The coordinates keep both wheels on the
//! ground, so neither contact's normal force is carried by a multiplier:
//! the momentum balances decide them (`appell::sliding`).
//!
//! The two wheels' sideways rows are one constraint on a rigid axle, so
//! only wheel 2 declares it (`along = [A.x, A.y]`) and wheel 1 rolls along
//! A.x alone. Where both grip, the axle's sideways reaction is therefore
//! put at wheel 2. How a rigid axle splits it between its wheels is
//! statically indeterminate. Where wheel 1 slides, its friction is
//! Coulomb's against its whole slip, and wheel 2 carries the sideways
//! constraint, as it does physically.
//! `tests/sliding_contacts.rs` and `examples/slipping_axle.rs` run it.

use appell::constraint_forces::contact_forces;
use appell::hybrid::{Guard, Phase};
use appell::sliding::{normal_inputs, sliding_normals, SlidingContact};
use appell::{Appell, DynModel, ModelError};

/// The wheel-axle on a slope, driven by the torque `tau` on each wheel,
/// its wheel 1 gripping (`grip1`) or sliding (`slide1`, Coulomb friction
/// μ N₁ with N₁ the input `n1`).
#[allow(clippy::duplicated_attributes)] // the scenes name effects alike
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(
    coordinates(phi, psi1, psi2, x, y),
    speeds(phi, psi1),
    positive(a, h, m_w, m_a)
)]
#[appell(frame(A = N.rotate_z(phi)), frame(W1 = A.rotate_y(psi1)), frame(W2 = A.rotate_y(psi2)))]
#[appell(point(M = O + x * N.x + y * N.y + a * N.z))]
#[appell(point(C1 = M - h * A.y), point(C2 = M + h * A.y))]
#[appell(point(P1 = C1 - a * N.z), point(P2 = C2 - a * N.z))]
#[appell(body(axle, center = M, frame = A, mass = m_a,
              inertia = principal(m_a * h * h / 3, m_a * a * a / 50, m_a * h * h / 3)))]
#[appell(body(wheel1, center = C1, frame = W1, mass = m_w,
              inertia = principal(m_w * a * a / 4, m_w * a * a / 2, m_w * a * a / 4)))]
#[appell(body(wheel2, center = C2, frame = W2, mass = m_w,
              inertia = principal(m_w * a * a / 4, m_w * a * a / 2, m_w * a * a / 4)))]
#[appell(rolls(wheel1, contact = P1, along = [A.x], effect = grip1,
               slides = slide1, mu = mu, normal = n1, smoothing = eps))]
#[appell(rolls(wheel2, contact = P2, along = [A.x, A.y]))]
#[appell(gravity(g * sin(alpha) * N.x - g * cos(alpha) * N.z))]
#[appell(inputs(tau, n1))]
#[appell(torque(W1, tau * A.y, effect = motor), torque(W2, tau * A.y, effect = motor))]
#[appell(scene(gripping, effects(gravity, motor, grip1)))]
#[appell(scene(slipping, effects(gravity, motor, slide1), speeds(phi, psi1, psi2)))]
pub struct SlippingAxle {
    /// Wheel radius a [m].
    pub a: f64,
    /// Half the track: each wheel's distance from the axle's centre [m].
    pub h: f64,
    /// Each wheel's mass [kg].
    pub m_w: f64,
    /// The axle's mass [kg].
    pub m_a: f64,
    /// Gravity [m/s²].
    pub g: f64,
    /// The slope α [rad], downhill along +x.
    pub alpha: f64,
    /// Friction coefficient.
    pub mu: f64,
    /// The friction law's regularisation [m/s].
    pub eps: f64,
}

/// A 0.3 m wheel-axle, 0.6 m between its wheels, on a 0.2 rad slope,
/// wheel 1 on ice (μ = 0.15).
pub const AXLE: SlippingAxle = SlippingAxle {
    a: 0.3,
    h: 0.3,
    m_w: 2.0,
    m_a: 1.0,
    g: 9.81,
    alpha: 0.2,
    mu: 0.15,
    eps: 1e-3,
};

/// Wheel 2's friction coefficient (dry ground): it must grip throughout,
/// since no scene has it sliding.
pub const WHEEL_2_MU: f64 = 0.8;

/// The slip speed below which wheel 1 grips again [m/s].
pub const GRIP_SPEED: f64 = 1e-2;

/// Ground normal.
const UP: [f64; 3] = [0.0, 0.0, 1.0];

/// The drive torque on each wheel along a run: τ0 sin(ω t), beyond what
/// wheel 1's friction takes (about 1.08 N m) near its peaks.
pub fn torque(t: f64) -> f64 {
    const TAU0: f64 = 1.6;
    const OMEGA: f64 = 2.0;
    TAU0 * (OMEGA * t).sin()
}

/// Each wheel's friction margin μ N − |F_t| (positive while it can grip;
/// μ = [`WHEEL_2_MU`] for wheel 2) at a state of the gripping scene, with
/// the drive torque `tau`.
pub fn margins(
    axle: &SlippingAxle,
    t: f64,
    q: &[f64],
    u: &[f64],
    tau: f64,
) -> Result<[f64; 2], ModelError> {
    let scene = SlippingAxleGripping::from_ref(axle);
    let fail = |what: &'static str| move |_| ModelError::Contact { what };
    // Wheel 1 declares no normal: a support there; wheel 2's joins itself.
    let support = SlidingContact::support_named(axle, "P1", UP).map_err(ModelError::from)?;
    let found = sliding_normals(scene, t, q, u, &[tau], &[support]).map_err(ModelError::from)?;
    let (n1, n2) = (found.forces[0], found.rolling[0]);
    let forces = contact_forces(scene, t, q, u, &[tau]).map_err(fail("the contact forces"))?;
    let tangential = |c: usize| {
        let f = forces.contacts[c].rolling;
        f[0].hypot(f[1])
    };
    Ok([
        axle.mu * n1 - tangential(0),
        WHEEL_2_MU * n2 - tangential(1),
    ])
}

/// Wheel 1's slip, the velocity of its material point at the contact
/// (N.x, N.y), at the coordinate rates of the sliding scene.
pub fn slip(axle: &SlippingAxle, t: f64, q: &[f64], u: &[f64]) -> Result<[f64; 2], ModelError> {
    let scene = SlippingAxleSlipping::from_ref(axle);
    let mut qdot = [0.0; 5];
    scene.dyn_coordinate_rates(t, q, u, &mut qdot)?;
    Ok(slip_at(axle, q, &qdot))
}

/// Wheel 1's slip at coordinate rates `qdot`: v_P1 = v_C1 + ω_W1 × (P1 −
/// C1) with ω_W1 = φ̇ N.z + ψ̇1 A.y and P1 − C1 = −a N.z.
pub fn slip_at(axle: &SlippingAxle, q: &[f64], qdot: &[f64]) -> [f64; 2] {
    let (phi, phid, psi1d) = (q[0], qdot[0], qdot[1]);
    let (c, s) = (phi.cos(), phi.sin());
    // C1 = M − h A.y, A.y = (−sin φ, cos φ, 0): v_C1 = (ẋ, ẏ) + h φ̇ (cos φ, sin φ).
    let v_c1 = [qdot[3] + axle.h * phid * c, qdot[4] + axle.h * phid * s];
    // ψ̇1 A.y × (−a N.z) = −a ψ̇1 A.x = −a ψ̇1 (cos φ, sin φ).
    [v_c1[0] - axle.a * psi1d * c, v_c1[1] - axle.a * psi1d * s]
}

/// The two phases: gripping (0), left where wheel 1 needs more friction
/// than μ N₁, and slipping (1), wheel 1's normal force (and wheel 2's)
/// found at every evaluation, left where wheel 1's slip comes down to
/// [`GRIP_SPEED`]. The drive torque follows [`torque`].
pub fn phases(axle: &SlippingAxle) -> Vec<Phase<'_>> {
    let slipping = SlippingAxleSlipping::from_ref(axle);
    let sliding = SlidingContact::named(axle, "P1", slipping, "n1", UP)
        .expect("wheel 1 rolls at P1 and the slipping scene reads `n1`");
    let normal = normal_inputs(slipping, vec![sliding]);
    vec![
        Phase::new("gripping", SlippingAxleGripping::from_ref(axle))
            .state_inputs(Box::new(|t, _, _, inputs: &mut [f64]| {
                inputs[0] = torque(t);
                Ok(())
            }))
            .guard(Guard::new(
                "wheel 1 slips",
                1,
                move |t, q: &[f64], u: &[f64]| Ok(margins(axle, t, q, u, torque(t))?[0]),
            )),
        Phase::new("slipping", slipping)
            .state_inputs(Box::new(move |t, q, u, inputs: &mut [f64]| {
                inputs[0] = torque(t);
                // A wheel lifting off is an error: no scene here has it.
                normal(t, q, u, inputs)
            }))
            .guard(
                Guard::new("wheel 1 grips", 0, move |t, q: &[f64], u: &[f64]| {
                    let [vx, vy] = slip(axle, t, q, u)?;
                    Ok(vx.hypot(vy) - GRIP_SPEED)
                })
                .after_rising(),
            ),
    ]
}
