//! Models written by hand, for the runtime's documentation examples: the
//! runtime cannot use the derive, and models shared by the examples are
//! easier to trust than ones hidden in each. Not part of the API.

use crate::{JacobianInfo, Model, ModelError, ModelInfo, OpCounts, Scalar};

/// A driven pendulum, θ̈ = −(g/l) sin θ + τ: coordinate θ, speed θ̇, input
/// τ (a torque per unit inertia), parameter `g_over_l`.
#[derive(Clone, Copy, Debug)]
pub struct Pendulum {
    /// g / l.
    pub g_over_l: f64,
}

static INFO: ModelInfo = ModelInfo {
    name: "Pendulum",
    parameters: &["g_over_l"],
    coordinates: &["theta"],
    speeds: &["theta"],
    dependent: &[],
    cyclic: &[],
    ignorable: &[],
    retained: &["theta"],
    inputs: &["tau"],
    effects: &[],
    outputs: &[],
    holonomic: 0,
    constraints: 0,
    row_sources: &[],
    contacts: &[],
    bodies: &[],
    force_points: 0,
    torques: 0,
    form: "closed form, written by hand",
    symbolic_elimination: true,
    rhs_ops: OpCounts {
        add: 1,
        mul: 1,
        div: 0,
        calls: 1,
        total: 4,
    },
    jacobian: Some(JacobianInfo {
        form: "closed form, written by hand",
        ops: OpCounts {
            add: 1,
            mul: 2,
            div: 0,
            calls: 2,
            total: 7,
        },
    }),
    equations: "theta'' = -g_over_l sin(theta) + tau",
};

/// M = 1 and f = −(g/l) sin θ + τ at (q, u, inputs).
fn forcing<T: Scalar>(g_over_l: T, q: &[T], inputs: &[T]) -> T {
    -g_over_l * q[0].sin() + inputs[0]
}

/// The methods both models share: one coordinate whose rate is the one
/// speed (q̇ = u), the kinetic energy ½ u² of a unit mass on it, and no
/// constraints, bodies or loads to describe.
macro_rules! one_free_coordinate {
    () => {
        fn speed_transform<T: Scalar>(
            &self,
            _t: T,
            _q: &[T],
            c: &mut [T],
            c0: &mut [T],
        ) -> Result<(), ModelError> {
            crate::check_len("c", c, 1)?;
            crate::check_len("c0", c0, 1)?;
            c[0] = T::one();
            c0[0] = T::zero();
            Ok(())
        }

        fn coordinate_rates<T: Scalar>(
            &self,
            _t: T,
            _q: &[T],
            u: &[T],
            qdot: &mut [T],
        ) -> Result<(), ModelError> {
            crate::check_len("u", u, 1)?;
            crate::check_len("qdot", qdot, 1)?;
            qdot[0] = u[0];
            Ok(())
        }

        fn constraint_residuals<T: Scalar>(
            &self,
            _t: T,
            _q: &[T],
            _qdot: &[T],
            _position: &mut [T],
            _velocity: &mut [T],
        ) -> Result<(), ModelError> {
            Ok(())
        }

        fn kinetic_energy<T: Scalar>(&self, _t: T, _q: &[T], u: &[T]) -> Result<T, ModelError> {
            crate::check_len("u", u, 1)?;
            Ok(T::from_f64(0.5) * u[0] * u[0])
        }

        fn mass_properties(
            &self,
            _masses: &mut [f64],
            _inertias: &mut [[f64; 9]],
        ) -> Result<(), ModelError> {
            Ok(())
        }

        fn body_poses<T: Scalar>(
            &self,
            _t: T,
            _q: &[T],
            _positions: &mut [[T; 3]],
            _rotations: &mut [[T; 9]],
        ) -> Result<(), ModelError> {
            Ok(())
        }

        fn constraint_rows<T: Scalar>(
            &self,
            _t: T,
            _q: &[T],
            _d: &mut [T],
            _d0: &mut [T],
        ) -> Result<(), ModelError> {
            Ok(())
        }

        /// No forces or torques are declared: nothing to write.
        fn load_geometry<T: Scalar>(
            &self,
            _t: T,
            _q: &[T],
            _points: &mut [[T; 3]],
            _frames: &mut [[T; 9]],
        ) -> Result<(), ModelError> {
            Ok(())
        }

        /// No forces or torques are declared: nothing to write.
        fn load_values<T: Scalar>(
            &self,
            _t: T,
            _q: &[T],
            _qdot: &[T],
            _inputs: &[T],
            _forces: &mut [[T; 3]],
            _torques: &mut [[T; 3]],
        ) -> Result<(), ModelError> {
            Ok(())
        }
    };
}

impl Model for Pendulum {
    type Prepared<T: Scalar> = T;

    fn info() -> &'static ModelInfo {
        &INFO
    }

    fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> {
        crate::check_len("out", out, 1)?;
        out[0] = self.g_over_l;
        Ok(())
    }

    fn set_parameter(&mut self, name: &str, value: f64) -> bool {
        let known = name == "g_over_l";
        if known {
            self.g_over_l = value;
        }
        known
    }

    fn prepare<T: Scalar>(&self) -> T {
        T::from_f64(self.g_over_l)
    }

    fn rhs<T: Scalar>(
        &self,
        g_over_l: &T,
        _t: T,
        state: &[T],
        inputs: &[T],
        dstate: &mut [T],
    ) -> Result<(), ModelError> {
        crate::check_len("state", state, 2)?;
        crate::check_len("inputs", inputs, 1)?;
        crate::check_len("dstate", dstate, 2)?;
        dstate[0] = state[1];
        dstate[1] = forcing(*g_over_l, state, inputs);
        Ok(())
    }

    fn rhs_jacobian<T: Scalar>(
        &self,
        t: T,
        state: &[T],
        inputs: &[T],
        dstate: &mut [T],
        a: &mut [T],
        b: &mut [T],
    ) -> Result<(), ModelError> {
        let g_over_l = T::from_f64(self.g_over_l);
        self.rhs(&g_over_l, t, state, inputs, dstate)?;
        crate::check_len("a", a, 4)?;
        crate::check_len("b", b, 2)?;
        a.copy_from_slice(&[T::zero(), T::one(), -g_over_l * state[0].cos(), T::zero()]);
        b.copy_from_slice(&[T::zero(), T::one()]);
        Ok(())
    }

    fn mass_matrix_and_forcing<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        _u: &[T],
        inputs: &[T],
        m: &mut [T],
        f: &mut [T],
    ) -> Result<(), ModelError> {
        crate::check_len("q", q, 1)?;
        crate::check_len("inputs", inputs, 1)?;
        crate::check_len("m", m, 1)?;
        crate::check_len("f", f, 1)?;
        m[0] = T::one();
        f[0] = forcing(T::from_f64(self.g_over_l), q, inputs);
        Ok(())
    }

    fn inverse_dynamics<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        u: &[T],
        accel: &[T],
        forces: &mut [T],
    ) -> Result<(), ModelError> {
        crate::check_len("q", q, 1)?;
        crate::check_len("u", u, 1)?;
        crate::check_len("accel", accel, 1)?;
        crate::check_len("forces", forces, 1)?;
        forces[0] = accel[0] - forcing(T::from_f64(self.g_over_l), q, &[T::zero()]);
        Ok(())
    }

    fn mass_matrix<T: Scalar>(&self, _t: T, q: &[T], m: &mut [T]) -> Result<(), ModelError> {
        crate::check_len("q", q, 1)?;
        crate::check_len("m", m, 1)?;
        m[0] = T::one();
        Ok(())
    }

    one_free_coordinate!();
}

/// A harmonic oscillator, x'' = −w² x: coordinate x, speed ẋ, parameter
/// `w`, no inputs; a particle of unit mass on a spring of stiffness w².
/// With `w = 0` it is a free particle.
#[derive(Clone, Copy, Debug)]
pub struct Oscillator {
    /// The angular frequency.
    pub w: f64,
}

static OSCILLATOR: ModelInfo = ModelInfo {
    name: "Oscillator",
    parameters: &["w"],
    coordinates: &["x"],
    speeds: &["x"],
    dependent: &[],
    cyclic: &[],
    ignorable: &[],
    retained: &["x"],
    inputs: &[],
    effects: &[],
    outputs: &[],
    holonomic: 0,
    constraints: 0,
    row_sources: &[],
    contacts: &[],
    bodies: &[],
    force_points: 0,
    torques: 0,
    form: "closed form, written by hand",
    symbolic_elimination: true,
    rhs_ops: OpCounts {
        add: 0,
        mul: 2,
        div: 0,
        calls: 0,
        total: 3,
    },
    jacobian: None,
    equations: "x'' = -w^2 x",
};

impl Model for Oscillator {
    /// −w².
    type Prepared<T: Scalar> = T;

    fn info() -> &'static ModelInfo {
        &OSCILLATOR
    }

    fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> {
        crate::check_len("out", out, 1)?;
        out[0] = self.w;
        Ok(())
    }

    fn set_parameter(&mut self, name: &str, value: f64) -> bool {
        let known = name == "w";
        if known {
            self.w = value;
        }
        known
    }

    fn prepare<T: Scalar>(&self) -> T {
        let w = T::from_f64(self.w);
        -(w * w)
    }

    fn rhs<T: Scalar>(
        &self,
        minus_w2: &T,
        _t: T,
        state: &[T],
        _inputs: &[T],
        dstate: &mut [T],
    ) -> Result<(), ModelError> {
        crate::check_len("state", state, 2)?;
        crate::check_len("dstate", dstate, 2)?;
        dstate[0] = state[1];
        dstate[1] = *minus_w2 * state[0];
        Ok(())
    }

    fn mass_matrix_and_forcing<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        _u: &[T],
        _inputs: &[T],
        m: &mut [T],
        f: &mut [T],
    ) -> Result<(), ModelError> {
        crate::check_len("q", q, 1)?;
        crate::check_len("m", m, 1)?;
        crate::check_len("f", f, 1)?;
        m[0] = T::one();
        f[0] = self.prepare::<T>() * q[0];
        Ok(())
    }

    one_free_coordinate!();

    fn potential_energy<T: Scalar>(&self, _t: T, q: &[T]) -> Result<T, ModelError> {
        crate::check_len("q", q, 1)?;
        let w = T::from_f64(self.w);
        Ok(T::from_f64(0.5) * w * w * q[0] * q[0])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_oscillator_s_rhs_is_its_m_and_f_and_its_force_derives_from_v() {
        let model = Oscillator { w: 3.0 };
        let (x, u) = (0.4, -1.5);
        let mut dx = [0.0; 2];
        model
            .rhs(&model.prepare::<f64>(), 0.0, &[x, u], &[], &mut dx)
            .unwrap();
        let (mut m, mut f) = ([0.0], [0.0]);
        model
            .mass_matrix_and_forcing(0.0, &[x], &[u], &[], &mut m, &mut f)
            .unwrap();
        assert_eq!(dx, [u, f[0] / m[0]]);
        assert_eq!(f[0], -9.0 * x);
        // f = −dV/dx (central difference; V is quadratic, so it is exact
        // up to rounding).
        let v = |x: f64| model.potential_energy(0.0, &[x]).unwrap();
        let h = 1e-3;
        assert!(((v(x + h) - v(x - h)) / (2.0 * h) + f[0]).abs() < 1e-9);
        let t = model.kinetic_energy(0.0, &[x], &[u]).unwrap();
        assert_eq!(t, 0.5 * u * u);
    }
}
