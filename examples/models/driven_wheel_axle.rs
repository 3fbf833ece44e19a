//! The paper's wheel-axle (`wheel_axle.rs`) with wheel 1's spin rate
//! commanded: a speed-controlled drive, `nonholonomic(dt(psi1) == w_cmd)`.
//! `tests/driven.rs` and `examples/driven_drives.rs` drive it.

use appell::Appell;

/// The wheel-axle with wheel 1's spin rate commanded instead of its motor
/// torque: psi1's rate is no longer a privileged speed.
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(coordinates(x1, y1, psi1, x2, y2, psi2, phi))]
#[appell(speeds(phi))]
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
         nonholonomic(a * dt(psi2) == a * dt(psi1) - l * dt(phi)),
         nonholonomic(dt(psi1) == w_cmd))]
#[appell(force(C1, mass * g * sin(alpha) * N.x, effect = gravity),
         force(C2, mass * g * sin(alpha) * N.x, effect = gravity))]
#[appell(inputs(w_cmd))]
pub struct DrivenWheelAxle {
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
