//! The paper's wheel-axle assemblage (Wang & Pao 2003, Sec. IV C, Fig. 1):
//! two wheels of radius `a` on a rigid axle of length `l`, rolling without
//! slip on a plane inclined by `alpha`, with a drive torque `tau` on wheel 1.

use appell::Appell;

/// Two wheels of radius `a` on an axle of length `l` rolling without slip
/// on a plane inclined by `alpha`; `mass` (M in the paper) at each wheel
/// centre, rims of mass `rim` (m') with inertia m'a²/2 about a diameter and
/// m'a² about the axle; gravity `g`. Wheel 2 sits at +l along the axle.
///
/// Scenes: `WheelAxleCoasting` (gravity only), `WheelAxleDriven` (the drive
/// torque only: on level ground the heading drops out of the state) and
/// `WheelAxleTrack` (everything, plus the track of wheel 1 by quadrature),
/// `WheelAxleContactCheck` (coasting, reporting the constraint reactions
/// and the energies).
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(coordinates(x1, y1, psi1, x2, y2, psi2, phi))]
#[appell(speeds(phi, psi1))]
#[appell(positive(a))]
#[appell(frame(A = N.rotate_z(phi)))]
#[appell(frame(W1 = A.rotate_y(psi1)), frame(W2 = A.rotate_y(psi2)))]
#[appell(point(C1 = O + x1 * N.x + y1 * N.y), point(C2 = O + x2 * N.x + y2 * N.y))]
#[appell(body(wheel1, center = C1, frame = W1, mass = mass,
              inertia = principal(rim * a * a / 2, rim * a * a, rim * a * a / 2)))]
#[appell(body(wheel2, center = C2, frame = W2, mass = mass,
              inertia = principal(rim * a * a / 2, rim * a * a, rim * a * a / 2)))]
#[appell(nonholonomic(dt(x1) == a * dt(psi1) * cos(phi)),
         nonholonomic(dt(y1) == a * dt(psi1) * sin(phi)),
         nonholonomic(dt(x2) == a * dt(psi2) * cos(phi)),
         nonholonomic(dt(y2) == a * dt(psi2) * sin(phi)),
         nonholonomic(a * dt(psi2) == a * dt(psi1) - l * dt(phi)))]
#[appell(force(C1, mass * g * sin(alpha) * N.x, effect = gravity),
         force(C2, mass * g * sin(alpha) * N.x, effect = gravity))]
#[appell(inputs(tau), torque(W1, tau * A.y, effect = motor))]
// Scenes name the same effects; clippy's duplicated_attributes lint reads
// the repeated names inside `#[appell(...)]` as duplicate attributes.
#[allow(clippy::duplicated_attributes)]
#[appell(scene(coasting, effects(gravity)))]
#[appell(scene(driven, effects(motor)))]
#[appell(scene(track, effects(gravity, motor), outputs(quadrature(x1, y1))))]
#[appell(scene(contact_check, effects(gravity), outputs(contact_forces, energies)))]
pub struct WheelAxle {
    /// Wheel radius a [m].
    pub a: f64,
    /// Axle length l [m].
    pub l: f64,
    /// Mass M at each wheel centre [kg].
    pub mass: f64,
    /// Rim mass m' [kg].
    pub rim: f64,
    /// Gravitational acceleration g [m/s²].
    pub g: f64,
    /// Incline angle α [rad].
    pub alpha: f64,
}

impl Default for WheelAxle {
    fn default() -> Self {
        WheelAxle {
            a: 0.3,
            l: 1.2,
            mass: 2.0,
            rim: 0.5,
            g: 9.81,
            alpha: 0.2,
        }
    }
}
