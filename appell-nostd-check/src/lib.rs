//! A `#![no_std]` crate with a derived model. It builds only if the code
//! `#[derive(Appell)]` emits uses `core` alone (no `std::` path, no
//! allocation); `cargo build -p appell-nostd-check` also builds the runtime
//! without its `std` feature (plain-float math from `libm`).
#![no_std]

use appell::{Appell, Model, ModelError};

/// A pendulum hanging from a cart that rolls on a horizontal rail.
#[derive(Appell, Clone, Copy)]
#[appell(coordinates(x, theta), speeds(x, theta), positive(m_cart, m_bob, l))]
#[appell(point(C = O + x * N.x), point(P = C + l * sin(theta) * N.x - l * cos(theta) * N.y))]
#[appell(particle(C, mass = m_cart), particle(P, mass = m_bob))]
#[appell(gravity(-g * N.y))]
#[appell(inputs(push), force(C, push * N.x, effect = actuator))]
pub struct CartPendulum {
    /// Cart mass.
    pub m_cart: f64,
    /// Bob mass.
    pub m_bob: f64,
    /// Rod length.
    pub l: f64,
    /// Gravity.
    pub g: f64,
}

/// One explicit Euler step on `f32`, with fixed-size arrays only: the kind
/// of loop a microcontroller runs. The cart position is cyclic, so the
/// reduced state is (θ, ẋ, θ̇).
pub fn euler_step(
    model: &CartPendulum,
    state: [f32; 3],
    push: f32,
    h: f32,
) -> Result<[f32; 3], ModelError> {
    let prepared = model.prepare::<f32>();
    let mut d = [0.0f32; 3];
    model.rhs(&prepared, 0.0, &state, &[push], &mut d)?;
    let mut next = state;
    for (x, dx) in next.iter_mut().zip(d) {
        *x += h * dx;
    }
    Ok(next)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hanging_at_rest_stays_at_rest() {
        let m = CartPendulum {
            m_cart: 1.0,
            m_bob: 0.2,
            l: 0.5,
            g: 9.81,
        };
        let s = euler_step(&m, [0.0; 3], 0.0, 0.01).unwrap();
        assert_eq!(s, [0.0; 3]);
        assert_eq!(CartPendulum::info().ignorable, &["x"]);
    }

    #[test]
    fn a_push_accelerates_the_cart() {
        let m = CartPendulum {
            m_cart: 1.0,
            m_bob: 0.2,
            l: 0.5,
            g: 9.81,
        };
        let s = euler_step(&m, [0.0; 3], 1.2, 0.1).unwrap();
        // At rest with the rod vertical, ẍ = F / m_cart: the bob exerts no
        // horizontal force at that instant.
        assert!((s[1] - 0.1 * 1.2 / 1.0).abs() < 1e-6, "{s:?}");
    }
}
