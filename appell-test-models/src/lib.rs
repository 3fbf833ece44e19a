//! # appell-test-models
//!
//! Hand-written `Model` implementations with known closed forms, shared by
//! the integration tests of the integrators, the oracle, linearization and
//! the command line (the derive macro is not used here, so the oracle is
//! tested against independent hand derivations). Not published.
//!
//! Every model's `rhs` implements its closed-form reduced equations; the
//! kinematic description (`body_poses`, `constraint_rows`, `load_*`) is what
//! the oracle sees.
#![allow(dead_code)]

use appell_core::{check_len, BodyInfo, Model, ModelError, ModelInfo, OpCounts, Scalar};

/// Rotation about N.z by `a`, row-major, columns are the body axes in N.
pub fn rot_z<T: Scalar>(a: T) -> [T; 9] {
    let (c, s, z, o) = (a.cos(), a.sin(), T::zero(), T::one());
    [c, -s, z, s, c, z, z, z, o]
}

pub fn identity<T: Scalar>() -> [T; 9] {
    let (z, o) = (T::zero(), T::one());
    [o, z, z, z, o, z, z, z, o]
}

fn c<T: Scalar>(x: f64) -> T {
    T::from_f64(x)
}

fn positive(name: &'static str, value: f64) -> Result<(), ModelError> {
    if value > 0.0 {
        Ok(())
    } else {
        Err(ModelError::NonPositiveParameter { name, value })
    }
}

fn set(slot: &mut f64, value: f64) -> bool {
    *slot = value;
    true
}

// ---------------------------------------------------------------------------
// (a) Planar simple pendulum: a particle at (l sin θ, −l cos θ, 0).

/// θ̈ = −(g/l) sin θ.
#[derive(Clone, Copy, Debug)]
pub struct Pendulum {
    pub m: f64,
    pub l: f64,
    pub g: f64,
}

pub static PENDULUM_INFO: ModelInfo = ModelInfo {
    name: "Pendulum",
    parameters: &["m", "l", "g"],
    coordinates: &["theta"],
    speeds: &["theta"],
    dependent: &[],
    cyclic: &[],
    ignorable: &[],
    retained: &["theta"],
    inputs: &[],
    effects: &["gravity"],
    outputs: &[],
    row_sources: &[],
    contacts: &[],
    holonomic: 0,
    constraints: 0,
    bodies: &[BodyInfo {
        name: "P",
        rigid: false,
    }],
    force_points: 1,
    torques: 0,
    form: "closed form",
    symbolic_elimination: true,
    rhs_ops: OpCounts {
        add: 0,
        mul: 1,
        div: 0,
        calls: 1,
        total: 3,
    },
    jacobian: None,
    equations: "theta'' = -(g/l) sin(theta)",
};

impl Model for Pendulum {
    type Prepared<T: Scalar> = T;

    fn info() -> &'static ModelInfo {
        &PENDULUM_INFO
    }

    fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> {
        check_len("out", out, 3)?;
        out.copy_from_slice(&[self.m, self.l, self.g]);
        Ok(())
    }

    fn set_parameter(&mut self, name: &str, value: f64) -> bool {
        match name {
            "m" => set(&mut self.m, value),
            "l" => set(&mut self.l, value),
            "g" => set(&mut self.g, value),
            _ => false,
        }
    }

    fn prepare<T: Scalar>(&self) -> T {
        -(c::<T>(self.g) / c::<T>(self.l))
    }

    fn rhs<T: Scalar>(
        &self,
        p: &T,
        _t: T,
        state: &[T],
        inputs: &[T],
        dstate: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("state", state, 2)?;
        check_len("inputs", inputs, 0)?;
        check_len("dstate", dstate, 2)?;
        dstate[0] = state[1];
        dstate[1] = *p * state[0].sin();
        Ok(())
    }

    fn mass_matrix_and_forcing<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        u: &[T],
        inputs: &[T],
        m: &mut [T],
        f: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q", q, 1)?;
        check_len("u", u, 1)?;
        check_len("inputs", inputs, 0)?;
        check_len("m", m, 1)?;
        check_len("f", f, 1)?;
        m[0] = c::<T>(self.m * self.l * self.l);
        f[0] = -(c::<T>(self.m * self.g * self.l) * q[0].sin());
        Ok(())
    }

    fn speed_transform<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        cm: &mut [T],
        c0: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q", q, 1)?;
        check_len("c", cm, 1)?;
        check_len("c0", c0, 1)?;
        cm[0] = T::one();
        c0[0] = T::zero();
        Ok(())
    }

    fn coordinate_rates<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        u: &[T],
        qdot: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q", q, 1)?;
        check_len("u", u, 1)?;
        check_len("qdot", qdot, 1)?;
        qdot[0] = u[0];
        Ok(())
    }

    fn constraint_residuals<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        qdot: &[T],
        holonomic: &mut [T],
        velocity: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q", q, 1)?;
        check_len("qdot", qdot, 1)?;
        check_len("holonomic", holonomic, 0)?;
        check_len("velocity", velocity, 0)
    }

    fn kinetic_energy<T: Scalar>(&self, _t: T, q: &[T], u: &[T]) -> Result<T, ModelError> {
        check_len("q", q, 1)?;
        check_len("u", u, 1)?;
        Ok(c::<T>(0.5 * self.m * self.l * self.l) * u[0] * u[0])
    }

    fn mass_properties(
        &self,
        masses: &mut [f64],
        inertias: &mut [[f64; 9]],
    ) -> Result<(), ModelError> {
        check_len("masses", masses, 1)?;
        check_len("inertias", inertias, 1)?;
        positive("m", self.m)?;
        masses[0] = self.m;
        inertias[0] = [0.0; 9];
        Ok(())
    }

    fn body_poses<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        positions: &mut [[T; 3]],
        rotations: &mut [[T; 9]],
    ) -> Result<(), ModelError> {
        check_len("q", q, 1)?;
        check_len("positions", positions, 1)?;
        check_len("rotations", rotations, 1)?;
        let l = c::<T>(self.l);
        positions[0] = [l * q[0].sin(), -(l * q[0].cos()), T::zero()];
        rotations[0] = identity();
        Ok(())
    }

    fn constraint_rows<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        d: &mut [T],
        d0: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q", q, 1)?;
        check_len("d", d, 0)?;
        check_len("d0", d0, 0)
    }

    fn load_geometry<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        points: &mut [[T; 3]],
        frames: &mut [[T; 9]],
    ) -> Result<(), ModelError> {
        check_len("points", points, 1)?;
        check_len("frames", frames, 0)?;
        let mut rot = [identity(); 1];
        self.body_poses(t, q, points, &mut rot)
    }

    fn load_values<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        qdot: &[T],
        inputs: &[T],
        forces: &mut [[T; 3]],
        torques: &mut [[T; 3]],
    ) -> Result<(), ModelError> {
        check_len("q", q, 1)?;
        check_len("qdot", qdot, 1)?;
        check_len("inputs", inputs, 0)?;
        check_len("forces", forces, 1)?;
        check_len("torques", torques, 0)?;
        forces[0] = [T::zero(), c::<T>(-self.m * self.g), T::zero()];
        Ok(())
    }
}

// ---------------------------------------------------------------------------
// (b) A uniform rod of length L pivoted at one end; the pivot moves along N.x
// as x0(t) = a sin(w t); a torsional damper applies −k θ̇ about N.z to the rod.
// The rod's body frame is N rotated about z by θ; the rod lies along body −y.

/// θ̈ = [−m (L/2)(g sin θ + ẍ0 cos θ) − k θ̇] / (m L²/3).
#[derive(Clone, Copy, Debug)]
pub struct Rod {
    pub m: f64,
    pub len: f64,
    pub g: f64,
    pub a: f64,
    pub w: f64,
    pub k: f64,
}

pub static ROD_INFO: ModelInfo = ModelInfo {
    name: "Rod",
    parameters: &["m", "len", "g", "a", "w", "k"],
    coordinates: &["theta"],
    speeds: &["theta"],
    dependent: &[],
    cyclic: &[],
    ignorable: &[],
    retained: &["theta"],
    inputs: &[],
    effects: &["gravity", "damper"],
    outputs: &[],
    row_sources: &[],
    contacts: &[],
    holonomic: 0,
    constraints: 0,
    bodies: &[BodyInfo {
        name: "rod",
        rigid: true,
    }],
    force_points: 1,
    torques: 1,
    form: "closed form",
    symbolic_elimination: true,
    rhs_ops: OpCounts {
        add: 3,
        mul: 8,
        div: 1,
        calls: 3,
        total: 15,
    },
    jacobian: None,
    equations: "theta'' = (-m (L/2)(g sin(theta) + x0''(t) cos(theta)) - k theta') / (m L^2/3)",
};

impl Rod {
    fn pivot<T: Scalar>(&self, t: T) -> T {
        c::<T>(self.a) * (c::<T>(self.w) * t).sin()
    }

    fn pivot_rate<T: Scalar>(&self, t: T) -> T {
        c::<T>(self.a * self.w) * (c::<T>(self.w) * t).cos()
    }

    fn pivot_accel<T: Scalar>(&self, t: T) -> T {
        -(c::<T>(self.a * self.w * self.w) * (c::<T>(self.w) * t).sin())
    }

    /// The closed form θ̈.
    pub fn theta_ddot<T: Scalar>(&self, t: T, theta: T, omega: T) -> T {
        let half = c::<T>(self.m * self.len / 2.0);
        let num = -(half * (c::<T>(self.g) * theta.sin() + self.pivot_accel(t) * theta.cos()))
            - c::<T>(self.k) * omega;
        num / c::<T>(self.m * self.len * self.len / 3.0)
    }
}

impl Model for Rod {
    type Prepared<T: Scalar> = ();

    fn info() -> &'static ModelInfo {
        &ROD_INFO
    }

    fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> {
        check_len("out", out, 6)?;
        out.copy_from_slice(&[self.m, self.len, self.g, self.a, self.w, self.k]);
        Ok(())
    }

    fn set_parameter(&mut self, name: &str, value: f64) -> bool {
        match name {
            "m" => set(&mut self.m, value),
            "len" => set(&mut self.len, value),
            "g" => set(&mut self.g, value),
            "a" => set(&mut self.a, value),
            "w" => set(&mut self.w, value),
            "k" => set(&mut self.k, value),
            _ => false,
        }
    }

    fn prepare<T: Scalar>(&self) {}

    fn rhs<T: Scalar>(
        &self,
        _p: &(),
        t: T,
        state: &[T],
        inputs: &[T],
        dstate: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("state", state, 2)?;
        check_len("inputs", inputs, 0)?;
        check_len("dstate", dstate, 2)?;
        dstate[0] = state[1];
        dstate[1] = self.theta_ddot(t, state[0], state[1]);
        Ok(())
    }

    fn mass_matrix_and_forcing<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        u: &[T],
        inputs: &[T],
        m: &mut [T],
        f: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q", q, 1)?;
        check_len("u", u, 1)?;
        check_len("inputs", inputs, 0)?;
        check_len("m", m, 1)?;
        check_len("f", f, 1)?;
        m[0] = c::<T>(self.m * self.len * self.len / 3.0);
        f[0] = m[0] * self.theta_ddot(t, q[0], u[0]);
        Ok(())
    }

    fn speed_transform<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        cm: &mut [T],
        c0: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q", q, 1)?;
        check_len("c", cm, 1)?;
        check_len("c0", c0, 1)?;
        cm[0] = T::one();
        c0[0] = T::zero();
        Ok(())
    }

    fn coordinate_rates<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        u: &[T],
        qdot: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q", q, 1)?;
        check_len("u", u, 1)?;
        check_len("qdot", qdot, 1)?;
        qdot[0] = u[0];
        Ok(())
    }

    fn constraint_residuals<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        qdot: &[T],
        holonomic: &mut [T],
        velocity: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q", q, 1)?;
        check_len("qdot", qdot, 1)?;
        check_len("holonomic", holonomic, 0)?;
        check_len("velocity", velocity, 0)
    }

    fn kinetic_energy<T: Scalar>(&self, t: T, q: &[T], u: &[T]) -> Result<T, ModelError> {
        check_len("q", q, 1)?;
        check_len("u", u, 1)?;
        let h = c::<T>(self.len / 2.0);
        let vx = self.pivot_rate(t) + h * q[0].cos() * u[0];
        let vy = h * q[0].sin() * u[0];
        let i = c::<T>(self.m * self.len * self.len / 12.0);
        Ok(c::<T>(0.5 * self.m) * (vx * vx + vy * vy) + c::<T>(0.5) * i * u[0] * u[0])
    }

    fn mass_properties(
        &self,
        masses: &mut [f64],
        inertias: &mut [[f64; 9]],
    ) -> Result<(), ModelError> {
        check_len("masses", masses, 1)?;
        check_len("inertias", inertias, 1)?;
        positive("m", self.m)?;
        let i = self.m * self.len * self.len / 12.0;
        masses[0] = self.m;
        // Thin rod along body y: no inertia about its own axis.
        inertias[0] = [i, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, i];
        Ok(())
    }

    fn body_poses<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        positions: &mut [[T; 3]],
        rotations: &mut [[T; 9]],
    ) -> Result<(), ModelError> {
        check_len("q", q, 1)?;
        check_len("positions", positions, 1)?;
        check_len("rotations", rotations, 1)?;
        let h = c::<T>(self.len / 2.0);
        positions[0] = [self.pivot(t) + h * q[0].sin(), -(h * q[0].cos()), T::zero()];
        rotations[0] = rot_z(q[0]);
        Ok(())
    }

    fn constraint_rows<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        d: &mut [T],
        d0: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q", q, 1)?;
        check_len("d", d, 0)?;
        check_len("d0", d0, 0)
    }

    fn load_geometry<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        points: &mut [[T; 3]],
        frames: &mut [[T; 9]],
    ) -> Result<(), ModelError> {
        check_len("points", points, 1)?;
        self.body_poses(t, q, points, frames)
    }

    fn load_values<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        qdot: &[T],
        inputs: &[T],
        forces: &mut [[T; 3]],
        torques: &mut [[T; 3]],
    ) -> Result<(), ModelError> {
        check_len("q", q, 1)?;
        check_len("qdot", qdot, 1)?;
        check_len("inputs", inputs, 0)?;
        check_len("forces", forces, 1)?;
        check_len("torques", torques, 1)?;
        forces[0] = [T::zero(), c::<T>(-self.m * self.g), T::zero()];
        torques[0] = [T::zero(), T::zero(), -(c::<T>(self.k) * qdot[0])];
        Ok(())
    }
}

// ---------------------------------------------------------------------------
// (c) Knife edge (nonholonomic): a body at (x, y) rotated by φ about N.z, no
// lateral velocity −ẋ sin φ + ẏ cos φ = 0; a uniform field m·gx along N.x,
// viscous drag −c·(ẋ, ẏ) at the mass centre, an input torque τ about N.z.
// Privileged speeds ẋ and φ̇ (valid for cos φ ≠ 0); y is dependent and
// cyclic, x and y are ignorable.

/// ẍ = gx cos²φ − (c/m) ẋ − ẋ φ̇ tan φ, φ̈ = τ / i.
#[derive(Clone, Copy, Debug)]
pub struct KnifeEdge {
    pub m: f64,
    pub i: f64,
    pub gx: f64,
    pub c: f64,
}

pub static KNIFE_INFO: ModelInfo = ModelInfo {
    name: "KnifeEdge",
    parameters: &["m", "i", "gx", "c"],
    coordinates: &["x", "y", "phi"],
    speeds: &["x", "phi"],
    dependent: &["y"],
    cyclic: &["y"],
    ignorable: &["x", "y"],
    retained: &["phi"],
    inputs: &["tau"],
    effects: &["field", "drag", "motor"],
    outputs: &[],
    row_sources: &[],
    contacts: &[],
    holonomic: 0,
    constraints: 1,
    bodies: &[BodyInfo {
        name: "B",
        rigid: true,
    }],
    force_points: 1,
    torques: 1,
    form: "closed form",
    symbolic_elimination: true,
    rhs_ops: OpCounts {
        add: 2,
        mul: 7,
        div: 2,
        calls: 3,
        total: 14,
    },
    jacobian: None,
    equations: "x'' = gx cos(phi)^2 - (c/m) x' - x' phi' tan(phi)\nphi'' = tau / i",
};

impl KnifeEdge {
    fn check_cos<T: Scalar>(phi: T) -> Result<T, ModelError> {
        let cphi = phi.cos();
        if cphi.re().abs() < 1e-12 {
            Err(ModelError::SingularConstraints {
                column: 0,
                pivot: cphi.re().abs(),
            })
        } else {
            Ok(cphi)
        }
    }

    /// The closed-form (ẍ, φ̈).
    pub fn accelerations<T: Scalar>(&self, phi: T, ux: T, uphi: T, tau: T) -> (T, T) {
        let cphi = phi.cos();
        let xdd =
            c::<T>(self.gx) * cphi * cphi - c::<T>(self.c / self.m) * ux - ux * uphi * phi.tan();
        (xdd, tau / c::<T>(self.i))
    }
}

impl Model for KnifeEdge {
    type Prepared<T: Scalar> = ();

    fn info() -> &'static ModelInfo {
        &KNIFE_INFO
    }

    fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> {
        check_len("out", out, 4)?;
        out.copy_from_slice(&[self.m, self.i, self.gx, self.c]);
        Ok(())
    }

    fn set_parameter(&mut self, name: &str, value: f64) -> bool {
        match name {
            "m" => set(&mut self.m, value),
            "i" => set(&mut self.i, value),
            "gx" => set(&mut self.gx, value),
            "c" => set(&mut self.c, value),
            _ => false,
        }
    }

    fn prepare<T: Scalar>(&self) {}

    fn rhs<T: Scalar>(
        &self,
        _p: &(),
        _t: T,
        state: &[T],
        inputs: &[T],
        dstate: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("state", state, 3)?;
        check_len("inputs", inputs, 1)?;
        check_len("dstate", dstate, 3)?;
        positive("m", self.m)?;
        positive("i", self.i)?;
        Self::check_cos(state[0])?;
        let (xdd, phidd) = self.accelerations(state[0], state[1], state[2], inputs[0]);
        dstate[0] = state[2];
        dstate[1] = xdd;
        dstate[2] = phidd;
        Ok(())
    }

    fn mass_matrix_and_forcing<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        u: &[T],
        inputs: &[T],
        m: &mut [T],
        f: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q", q, 3)?;
        check_len("u", u, 2)?;
        check_len("inputs", inputs, 1)?;
        check_len("m", m, 4)?;
        check_len("f", f, 2)?;
        let cphi = Self::check_cos(q[2])?;
        let (xdd, phidd) = self.accelerations(q[2], u[0], u[1], inputs[0]);
        m[0] = c::<T>(self.m) / (cphi * cphi);
        m[1] = T::zero();
        m[2] = T::zero();
        m[3] = c::<T>(self.i);
        f[0] = m[0] * xdd;
        f[1] = m[3] * phidd;
        Ok(())
    }

    fn speed_transform<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        cm: &mut [T],
        c0: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q", q, 3)?;
        check_len("c", cm, 6)?;
        check_len("c0", c0, 3)?;
        Self::check_cos(q[2])?;
        let (z, o) = (T::zero(), T::one());
        cm.copy_from_slice(&[o, z, q[2].tan(), z, z, o]);
        c0.copy_from_slice(&[z, z, z]);
        Ok(())
    }

    fn coordinate_rates<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        u: &[T],
        qdot: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q", q, 3)?;
        check_len("u", u, 2)?;
        check_len("qdot", qdot, 3)?;
        Self::check_cos(q[2])?;
        qdot[0] = u[0];
        qdot[1] = u[0] * q[2].tan();
        qdot[2] = u[1];
        Ok(())
    }

    fn constraint_residuals<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        qdot: &[T],
        holonomic: &mut [T],
        velocity: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q", q, 3)?;
        check_len("qdot", qdot, 3)?;
        check_len("holonomic", holonomic, 0)?;
        check_len("velocity", velocity, 1)?;
        velocity[0] = -(qdot[0] * q[2].sin()) + qdot[1] * q[2].cos();
        Ok(())
    }

    fn kinetic_energy<T: Scalar>(&self, _t: T, q: &[T], u: &[T]) -> Result<T, ModelError> {
        check_len("q", q, 3)?;
        check_len("u", u, 2)?;
        Self::check_cos(q[2])?;
        let ydot = u[0] * q[2].tan();
        Ok(c::<T>(0.5 * self.m) * (u[0] * u[0] + ydot * ydot) + c::<T>(0.5 * self.i) * u[1] * u[1])
    }

    fn mass_properties(
        &self,
        masses: &mut [f64],
        inertias: &mut [[f64; 9]],
    ) -> Result<(), ModelError> {
        check_len("masses", masses, 1)?;
        check_len("inertias", inertias, 1)?;
        positive("m", self.m)?;
        masses[0] = self.m;
        // Unequal transverse moments: only the z one may matter in planar motion.
        inertias[0] = [
            0.7 * self.i,
            0.0,
            0.0,
            0.0,
            0.4 * self.i,
            0.0,
            0.0,
            0.0,
            self.i,
        ];
        Ok(())
    }

    fn body_poses<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        positions: &mut [[T; 3]],
        rotations: &mut [[T; 9]],
    ) -> Result<(), ModelError> {
        check_len("q", q, 3)?;
        check_len("positions", positions, 1)?;
        check_len("rotations", rotations, 1)?;
        positions[0] = [q[0], q[1], T::zero()];
        rotations[0] = rot_z(q[2]);
        Ok(())
    }

    fn constraint_rows<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        d: &mut [T],
        d0: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q", q, 3)?;
        check_len("d", d, 3)?;
        check_len("d0", d0, 1)?;
        d.copy_from_slice(&[-q[2].sin(), q[2].cos(), T::zero()]);
        d0[0] = T::zero();
        Ok(())
    }

    fn load_geometry<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        points: &mut [[T; 3]],
        frames: &mut [[T; 9]],
    ) -> Result<(), ModelError> {
        self.body_poses(t, q, points, frames)
    }

    fn load_values<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        qdot: &[T],
        inputs: &[T],
        forces: &mut [[T; 3]],
        torques: &mut [[T; 3]],
    ) -> Result<(), ModelError> {
        check_len("q", q, 3)?;
        check_len("qdot", qdot, 3)?;
        check_len("inputs", inputs, 1)?;
        check_len("forces", forces, 1)?;
        check_len("torques", torques, 1)?;
        let drag = c::<T>(self.c);
        forces[0] = [
            c::<T>(self.m * self.gx) - drag * qdot[0],
            -(drag * qdot[1]),
            T::zero(),
        ];
        torques[0] = [T::zero(), T::zero(), inputs[0]];
        Ok(())
    }
}

// ---------------------------------------------------------------------------
// (d) Pendulum in Cartesian coordinates: a particle at (x, y, 0) held at the
// distance ℓ(t) = l + b sin(w t) from the origin (x² + y² = ℓ², differentiated:
// x ẋ + y ẏ − ℓ ℓ̇ = 0, so d = −ℓ ℓ̇ is time-dependent), gravity −m g along
// N.y. Privileged speed ẋ, dependent ẏ = (ℓ ℓ̇ − x ẋ) / y (valid for y ≠ 0).

/// ẍ = x λ/m, λ/m = (g y − v² + ℓ̇² + ℓ ℓ̈) / r², v² = ẋ² + ẏ², r² = x² + y².
#[derive(Clone, Copy, Debug)]
pub struct CartesianPendulum {
    pub m: f64,
    pub l: f64,
    pub g: f64,
    pub b: f64,
    pub w: f64,
}

pub static CARTESIAN_INFO: ModelInfo = ModelInfo {
    name: "CartesianPendulum",
    parameters: &["m", "l", "g", "b", "w"],
    coordinates: &["x", "y"],
    speeds: &["x"],
    dependent: &["y"],
    cyclic: &[],
    ignorable: &[],
    retained: &["x", "y"],
    inputs: &[],
    effects: &["gravity"],
    outputs: &[],
    row_sources: &[],
    contacts: &[],
    holonomic: 1,
    constraints: 1,
    bodies: &[BodyInfo {
        name: "P",
        rigid: false,
    }],
    force_points: 1,
    torques: 0,
    form: "closed form",
    symbolic_elimination: false,
    rhs_ops: OpCounts {
        add: 6,
        mul: 14,
        div: 3,
        calls: 2,
        total: 26,
    },
    jacobian: None,
    equations: "x'' = x (g y - v^2 + L'^2 + L L'') / (x^2 + y^2)",
};

impl CartesianPendulum {
    fn check_y<T: Scalar>(y: T) -> Result<(), ModelError> {
        if y.re().abs() < 1e-12 {
            Err(ModelError::SingularConstraints {
                column: 0,
                pivot: y.re().abs(),
            })
        } else {
            Ok(())
        }
    }

    /// ℓ, ℓ̇, ℓ̈ at `t`.
    pub fn length<T: Scalar>(&self, t: T) -> (T, T, T) {
        let arg = c::<T>(self.w) * t;
        (
            c::<T>(self.l) + c::<T>(self.b) * arg.sin(),
            c::<T>(self.b * self.w) * arg.cos(),
            -(c::<T>(self.b * self.w * self.w) * arg.sin()),
        )
    }

    /// The dependent rate ẏ.
    pub fn ydot<T: Scalar>(&self, t: T, x: T, y: T, ux: T) -> T {
        let (l, ld, _) = self.length(t);
        (l * ld - x * ux) / y
    }

    /// The closed-form ẍ and the multiplier λ.
    pub fn xddot_and_lambda<T: Scalar>(&self, t: T, x: T, y: T, ux: T) -> (T, T) {
        let (l, ld, ldd) = self.length(t);
        let uy = self.ydot(t, x, y, ux);
        let r2 = x * x + y * y;
        let v2 = ux * ux + uy * uy;
        let lm = (c::<T>(self.g) * y - v2 + ld * ld + l * ldd) / r2;
        (x * lm, c::<T>(self.m) * lm)
    }
}

impl Model for CartesianPendulum {
    type Prepared<T: Scalar> = ();

    fn info() -> &'static ModelInfo {
        &CARTESIAN_INFO
    }

    fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> {
        check_len("out", out, 5)?;
        out.copy_from_slice(&[self.m, self.l, self.g, self.b, self.w]);
        Ok(())
    }

    fn set_parameter(&mut self, name: &str, value: f64) -> bool {
        match name {
            "m" => set(&mut self.m, value),
            "l" => set(&mut self.l, value),
            "g" => set(&mut self.g, value),
            "b" => set(&mut self.b, value),
            "w" => set(&mut self.w, value),
            _ => false,
        }
    }

    fn prepare<T: Scalar>(&self) {}

    fn rhs<T: Scalar>(
        &self,
        _p: &(),
        t: T,
        state: &[T],
        inputs: &[T],
        dstate: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("state", state, 3)?;
        check_len("inputs", inputs, 0)?;
        check_len("dstate", dstate, 3)?;
        let (x, y, ux) = (state[0], state[1], state[2]);
        Self::check_y(y)?;
        dstate[0] = ux;
        dstate[1] = self.ydot(t, x, y, ux);
        dstate[2] = self.xddot_and_lambda(t, x, y, ux).0;
        Ok(())
    }

    fn mass_matrix_and_forcing<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        u: &[T],
        inputs: &[T],
        m: &mut [T],
        f: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q", q, 2)?;
        check_len("u", u, 1)?;
        check_len("inputs", inputs, 0)?;
        check_len("m", m, 1)?;
        check_len("f", f, 1)?;
        Self::check_y(q[1])?;
        m[0] = c::<T>(self.m) * (q[0] * q[0] + q[1] * q[1]) / (q[1] * q[1]);
        f[0] = m[0] * self.xddot_and_lambda(t, q[0], q[1], u[0]).0;
        Ok(())
    }

    fn speed_transform<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        cm: &mut [T],
        c0: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q", q, 2)?;
        check_len("c", cm, 2)?;
        check_len("c0", c0, 2)?;
        Self::check_y(q[1])?;
        let (l, ld, _) = self.length(t);
        cm[0] = T::one();
        cm[1] = -(q[0] / q[1]);
        c0[0] = T::zero();
        c0[1] = l * ld / q[1];
        Ok(())
    }

    fn coordinate_rates<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        u: &[T],
        qdot: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q", q, 2)?;
        check_len("u", u, 1)?;
        check_len("qdot", qdot, 2)?;
        Self::check_y(q[1])?;
        qdot[0] = u[0];
        qdot[1] = self.ydot(t, q[0], q[1], u[0]);
        Ok(())
    }

    fn constraint_residuals<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        qdot: &[T],
        holonomic: &mut [T],
        velocity: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q", q, 2)?;
        check_len("qdot", qdot, 2)?;
        check_len("holonomic", holonomic, 1)?;
        check_len("velocity", velocity, 1)?;
        let (l, ld, _) = self.length(t);
        holonomic[0] = q[0] * q[0] + q[1] * q[1] - l * l;
        velocity[0] = q[0] * qdot[0] + q[1] * qdot[1] - l * ld;
        Ok(())
    }

    fn kinetic_energy<T: Scalar>(&self, t: T, q: &[T], u: &[T]) -> Result<T, ModelError> {
        check_len("q", q, 2)?;
        check_len("u", u, 1)?;
        Self::check_y(q[1])?;
        let ydot = self.ydot(t, q[0], q[1], u[0]);
        Ok(c::<T>(0.5 * self.m) * (u[0] * u[0] + ydot * ydot))
    }

    fn mass_properties(
        &self,
        masses: &mut [f64],
        inertias: &mut [[f64; 9]],
    ) -> Result<(), ModelError> {
        check_len("masses", masses, 1)?;
        check_len("inertias", inertias, 1)?;
        positive("m", self.m)?;
        masses[0] = self.m;
        inertias[0] = [0.0; 9];
        Ok(())
    }

    fn body_poses<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        positions: &mut [[T; 3]],
        rotations: &mut [[T; 9]],
    ) -> Result<(), ModelError> {
        check_len("q", q, 2)?;
        check_len("positions", positions, 1)?;
        check_len("rotations", rotations, 1)?;
        positions[0] = [q[0], q[1], T::zero()];
        rotations[0] = identity();
        Ok(())
    }

    fn constraint_rows<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        d: &mut [T],
        d0: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q", q, 2)?;
        check_len("d", d, 2)?;
        check_len("d0", d0, 1)?;
        let (l, ld, _) = self.length(t);
        d[0] = q[0];
        d[1] = q[1];
        d0[0] = -(l * ld);
        Ok(())
    }

    fn load_geometry<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        points: &mut [[T; 3]],
        frames: &mut [[T; 9]],
    ) -> Result<(), ModelError> {
        check_len("points", points, 1)?;
        check_len("frames", frames, 0)?;
        let mut rot = [identity(); 1];
        self.body_poses(t, q, points, &mut rot)
    }

    fn load_values<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        qdot: &[T],
        inputs: &[T],
        forces: &mut [[T; 3]],
        torques: &mut [[T; 3]],
    ) -> Result<(), ModelError> {
        check_len("q", q, 2)?;
        check_len("qdot", qdot, 2)?;
        check_len("inputs", inputs, 0)?;
        check_len("forces", forces, 1)?;
        check_len("torques", torques, 0)?;
        forces[0] = [T::zero(), c::<T>(-self.m * self.g), T::zero()];
        Ok(())
    }
}

// ---------------------------------------------------------------------------
// (e) A rigid body spinning about its fixed mass centre, in a frame turning at
// the prescribed rate Ω about N.z: R = Rz(ψ + Ω t) Ry(θ) Rx(φ) (ZYX angles).
// A full (non-diagonal) central inertia, an input torque L (N components) on
// the body and a constant force F (N components) at the body point p (body
// components). Euler's equations in the body frame:
//   I ω̇ + ω × I ω = Rᵀ (L + (R p) × F),
// with ω = E(θ, φ) (ψ̇ + Ω, θ̇, φ̇) as below.

pub fn mat3_mul<T: Scalar>(a: &[T; 9], b: &[T; 9]) -> [T; 9] {
    let mut out = [T::zero(); 9];
    for i in 0..3 {
        for j in 0..3 {
            let mut s = T::zero();
            for k in 0..3 {
                s += a[3 * i + k] * b[3 * k + j];
            }
            out[3 * i + j] = s;
        }
    }
    out
}

pub fn mat3_vec<T: Scalar>(a: &[T; 9], v: &[T; 3]) -> [T; 3] {
    [
        a[0] * v[0] + a[1] * v[1] + a[2] * v[2],
        a[3] * v[0] + a[4] * v[1] + a[5] * v[2],
        a[6] * v[0] + a[7] * v[1] + a[8] * v[2],
    ]
}

pub fn mat3_t_vec<T: Scalar>(a: &[T; 9], v: &[T; 3]) -> [T; 3] {
    [
        a[0] * v[0] + a[3] * v[1] + a[6] * v[2],
        a[1] * v[0] + a[4] * v[1] + a[7] * v[2],
        a[2] * v[0] + a[5] * v[1] + a[8] * v[2],
    ]
}

pub fn cross3<T: Scalar>(a: &[T; 3], b: &[T; 3]) -> [T; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Solves `a x = b` (3×3, row-major) by Cramer's rule.
pub fn solve3<T: Scalar>(a: &[T; 9], b: &[T; 3]) -> [T; 3] {
    let det = |m: &[T; 9]| {
        m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6])
            + m[2] * (m[3] * m[7] - m[4] * m[6])
    };
    let d = det(a);
    let mut x = [T::zero(); 3];
    for (col, xc) in x.iter_mut().enumerate() {
        let mut m = *a;
        for row in 0..3 {
            m[3 * row + col] = b[row];
        }
        *xc = det(&m) / d;
    }
    x
}

fn rot_y<T: Scalar>(a: T) -> [T; 9] {
    let (c, s, z, o) = (a.cos(), a.sin(), T::zero(), T::one());
    [c, z, s, z, o, z, -s, z, c]
}

fn rot_x<T: Scalar>(a: T) -> [T; 9] {
    let (c, s, z, o) = (a.cos(), a.sin(), T::zero(), T::one());
    [o, z, z, z, c, -s, z, s, c]
}

#[derive(Clone, Copy, Debug)]
pub struct Gyro {
    pub spin: f64,
    pub inertia: [f64; 9],
    pub force: [f64; 3],
    pub arm: [f64; 3],
}

pub const GYRO: Gyro = Gyro {
    spin: 0.8,
    inertia: [0.3, 0.02, -0.01, 0.02, 0.5, 0.03, -0.01, 0.03, 0.7],
    force: [0.4, -1.1, 0.6],
    arm: [0.1, 0.2, -0.3],
};

pub static GYRO_INFO: ModelInfo = ModelInfo {
    name: "Gyro",
    parameters: &["spin"],
    coordinates: &["psi", "theta", "phi"],
    speeds: &["psi", "theta", "phi"],
    dependent: &[],
    cyclic: &[],
    ignorable: &[],
    retained: &["psi", "theta", "phi"],
    inputs: &["lx", "ly", "lz"],
    effects: &["pull", "motor"],
    outputs: &[],
    row_sources: &[],
    contacts: &[],
    holonomic: 0,
    constraints: 0,
    bodies: &[BodyInfo {
        name: "rotor",
        rigid: true,
    }],
    force_points: 1,
    torques: 1,
    form: "closed form",
    symbolic_elimination: true,
    rhs_ops: OpCounts {
        add: 100,
        mul: 150,
        div: 10,
        calls: 12,
        total: 272,
    },
    jacobian: None,
    equations: "Euler's equations through ZYX angles",
};

impl Gyro {
    pub fn rotation<T: Scalar>(&self, t: T, q: &[T]) -> [T; 9] {
        let yaw = q[0] + c::<T>(self.spin) * t;
        mat3_mul(&mat3_mul(&rot_z(yaw), &rot_y(q[1])), &rot_x(q[2]))
    }

    /// Body-frame angular velocity from the angles and their rates.
    pub fn omega_body<T: Scalar>(&self, q: &[T], qdot: &[T]) -> [T; 3] {
        let yawd = qdot[0] + c::<T>(self.spin);
        let (th, ph) = (q[1], q[2]);
        [
            qdot[2] - yawd * th.sin(),
            qdot[1] * ph.cos() + yawd * th.cos() * ph.sin(),
            -(qdot[1] * ph.sin()) + yawd * th.cos() * ph.cos(),
        ]
    }

    /// The applied moment about the mass centre in body components.
    pub fn moment_body<T: Scalar>(&self, t: T, q: &[T], torque_n: &[T; 3]) -> [T; 3] {
        let r = self.rotation(t, q);
        let arm = mat3_vec(&r, &self.arm.map(c::<T>));
        let fm = cross3(&arm, &self.force.map(c::<T>));
        mat3_t_vec(
            &r,
            &[
                torque_n[0] + fm[0],
                torque_n[1] + fm[1],
                torque_n[2] + fm[2],
            ],
        )
    }

    /// q̈ from Euler's equations (closed form through the ZYX rate map).
    pub fn qddot<T: Scalar>(&self, t: T, q: &[T], qdot: &[T], torque_n: &[T; 3]) -> [T; 3] {
        let inertia = self.inertia.map(c::<T>);
        let w = self.omega_body(q, qdot);
        let iw = mat3_vec(&inertia, &w);
        let gyro = cross3(&w, &iw);
        let tau = self.moment_body(t, q, torque_n);
        let wdot = solve3(
            &inertia,
            &[tau[0] - gyro[0], tau[1] - gyro[1], tau[2] - gyro[2]],
        );
        let yawd = qdot[0] + c::<T>(self.spin);
        let (thd, phd) = (qdot[1], qdot[2]);
        let (st, ct, sp, cp) = (q[1].sin(), q[1].cos(), q[2].sin(), q[2].cos());
        // ω̇ = E q̈ + Ė q̇ with E q̈ = [φ̈ − ψ̈ sθ, θ̈ cφ + ψ̈ cθ sφ, −θ̈ sφ + ψ̈ cθ cφ].
        let edot = [
            -(yawd * thd * ct),
            -(thd * phd * sp) - yawd * thd * st * sp + yawd * phd * ct * cp,
            -(thd * phd * cp) - yawd * thd * st * cp - yawd * phd * ct * sp,
        ];
        let r = [wdot[0] - edot[0], wdot[1] - edot[1], wdot[2] - edot[2]];
        let psidd = (r[1] * sp + r[2] * cp) / ct;
        let thdd = r[1] * cp - r[2] * sp;
        let phdd = r[0] + psidd * st;
        [psidd, thdd, phdd]
    }
}

impl Model for Gyro {
    type Prepared<T: Scalar> = ();

    fn info() -> &'static ModelInfo {
        &GYRO_INFO
    }

    fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> {
        check_len("out", out, 1)?;
        out[0] = self.spin;
        Ok(())
    }

    fn set_parameter(&mut self, name: &str, value: f64) -> bool {
        name == "spin" && set(&mut self.spin, value)
    }

    fn prepare<T: Scalar>(&self) {}

    fn rhs<T: Scalar>(
        &self,
        _p: &(),
        t: T,
        state: &[T],
        inputs: &[T],
        dstate: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("state", state, 6)?;
        check_len("inputs", inputs, 3)?;
        check_len("dstate", dstate, 6)?;
        if state[1].cos().re().abs() < 1e-12 {
            return Err(ModelError::SingularMassMatrix {
                index: 0,
                pivot: 0.0,
            });
        }
        let qdd = self.qddot(
            t,
            &state[..3],
            &state[3..],
            &[inputs[0], inputs[1], inputs[2]],
        );
        dstate[..3].copy_from_slice(&state[3..]);
        dstate[3..].copy_from_slice(&qdd);
        Ok(())
    }

    fn mass_matrix_and_forcing<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        u: &[T],
        inputs: &[T],
        m: &mut [T],
        f: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q", q, 3)?;
        check_len("u", u, 3)?;
        check_len("inputs", inputs, 3)?;
        check_len("m", m, 9)?;
        check_len("f", f, 3)?;
        // M = Eᵀ I E (E maps rates to body angular velocity), f = M q̈.
        let inertia = self.inertia.map(c::<T>);
        let (z, o) = (T::zero(), T::one());
        let (st, ct, sp, cp) = (q[1].sin(), q[1].cos(), q[2].sin(), q[2].cos());
        let e = [-st, z, o, ct * sp, cp, z, ct * cp, -sp, z];
        let ie = mat3_mul(&inertia, &e);
        for i in 0..3 {
            for j in 0..3 {
                let mut s = T::zero();
                for k in 0..3 {
                    s += e[3 * k + i] * ie[3 * k + j];
                }
                m[3 * i + j] = s;
            }
        }
        let qdd = self.qddot(t, q, u, &[inputs[0], inputs[1], inputs[2]]);
        let mm = [m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8]];
        f.copy_from_slice(&mat3_vec(&mm, &qdd));
        Ok(())
    }

    fn speed_transform<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        cm: &mut [T],
        c0: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q", q, 3)?;
        check_len("c", cm, 9)?;
        check_len("c0", c0, 3)?;
        cm.copy_from_slice(&identity());
        c0.copy_from_slice(&[T::zero(); 3]);
        Ok(())
    }

    fn coordinate_rates<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        u: &[T],
        qdot: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q", q, 3)?;
        check_len("u", u, 3)?;
        check_len("qdot", qdot, 3)?;
        qdot.copy_from_slice(u);
        Ok(())
    }

    fn constraint_residuals<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        qdot: &[T],
        holonomic: &mut [T],
        velocity: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q", q, 3)?;
        check_len("qdot", qdot, 3)?;
        check_len("holonomic", holonomic, 0)?;
        check_len("velocity", velocity, 0)
    }

    fn kinetic_energy<T: Scalar>(&self, _t: T, q: &[T], u: &[T]) -> Result<T, ModelError> {
        check_len("q", q, 3)?;
        check_len("u", u, 3)?;
        let w = self.omega_body(q, u);
        let iw = mat3_vec(&self.inertia.map(c::<T>), &w);
        Ok(c::<T>(0.5) * (w[0] * iw[0] + w[1] * iw[1] + w[2] * iw[2]))
    }

    fn mass_properties(
        &self,
        masses: &mut [f64],
        inertias: &mut [[f64; 9]],
    ) -> Result<(), ModelError> {
        check_len("masses", masses, 1)?;
        check_len("inertias", inertias, 1)?;
        masses[0] = 2.0;
        inertias[0] = self.inertia;
        Ok(())
    }

    fn body_poses<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        positions: &mut [[T; 3]],
        rotations: &mut [[T; 9]],
    ) -> Result<(), ModelError> {
        check_len("q", q, 3)?;
        check_len("positions", positions, 1)?;
        check_len("rotations", rotations, 1)?;
        positions[0] = [T::zero(); 3];
        rotations[0] = self.rotation(t, q);
        Ok(())
    }

    fn constraint_rows<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        d: &mut [T],
        d0: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q", q, 3)?;
        check_len("d", d, 0)?;
        check_len("d0", d0, 0)
    }

    fn load_geometry<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        points: &mut [[T; 3]],
        frames: &mut [[T; 9]],
    ) -> Result<(), ModelError> {
        check_len("q", q, 3)?;
        check_len("points", points, 1)?;
        check_len("frames", frames, 1)?;
        let r = self.rotation(t, q);
        points[0] = mat3_vec(&r, &self.arm.map(c::<T>));
        frames[0] = r;
        Ok(())
    }

    fn load_values<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        qdot: &[T],
        inputs: &[T],
        forces: &mut [[T; 3]],
        torques: &mut [[T; 3]],
    ) -> Result<(), ModelError> {
        check_len("q", q, 3)?;
        check_len("qdot", qdot, 3)?;
        check_len("inputs", inputs, 3)?;
        check_len("forces", forces, 1)?;
        check_len("torques", torques, 1)?;
        forces[0] = self.force.map(c::<T>);
        torques[0] = [inputs[0], inputs[1], inputs[2]];
        Ok(())
    }
}

// ---------------------------------------------------------------------------
// A model whose description is inconsistent: its speed is not a coordinate.
// Everything else delegates to the pendulum.

pub struct BadSpeedName(pub Pendulum);

pub static BAD_SPEED_INFO: ModelInfo = ModelInfo {
    name: "BadSpeedName",
    speeds: &["phi"],
    ..PENDULUM_INFO
};

impl Model for BadSpeedName {
    type Prepared<T: Scalar> = T;

    fn info() -> &'static ModelInfo {
        &BAD_SPEED_INFO
    }
    fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> {
        self.0.parameter_values(out)
    }
    fn set_parameter(&mut self, name: &str, value: f64) -> bool {
        self.0.set_parameter(name, value)
    }
    fn prepare<T: Scalar>(&self) -> T {
        self.0.prepare()
    }
    fn rhs<T: Scalar>(
        &self,
        p: &T,
        t: T,
        state: &[T],
        inputs: &[T],
        dstate: &mut [T],
    ) -> Result<(), ModelError> {
        self.0.rhs(p, t, state, inputs, dstate)
    }
    fn mass_matrix_and_forcing<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        u: &[T],
        inputs: &[T],
        m: &mut [T],
        f: &mut [T],
    ) -> Result<(), ModelError> {
        self.0.mass_matrix_and_forcing(t, q, u, inputs, m, f)
    }
    fn speed_transform<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        cm: &mut [T],
        c0: &mut [T],
    ) -> Result<(), ModelError> {
        self.0.speed_transform(t, q, cm, c0)
    }
    fn coordinate_rates<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        u: &[T],
        qdot: &mut [T],
    ) -> Result<(), ModelError> {
        self.0.coordinate_rates(t, q, u, qdot)
    }
    fn constraint_residuals<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        qdot: &[T],
        holonomic: &mut [T],
        velocity: &mut [T],
    ) -> Result<(), ModelError> {
        self.0.constraint_residuals(t, q, qdot, holonomic, velocity)
    }
    fn kinetic_energy<T: Scalar>(&self, t: T, q: &[T], u: &[T]) -> Result<T, ModelError> {
        self.0.kinetic_energy(t, q, u)
    }
    fn mass_properties(
        &self,
        masses: &mut [f64],
        inertias: &mut [[f64; 9]],
    ) -> Result<(), ModelError> {
        self.0.mass_properties(masses, inertias)
    }
    fn body_poses<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        positions: &mut [[T; 3]],
        rotations: &mut [[T; 9]],
    ) -> Result<(), ModelError> {
        self.0.body_poses(t, q, positions, rotations)
    }
    fn constraint_rows<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        d: &mut [T],
        d0: &mut [T],
    ) -> Result<(), ModelError> {
        self.0.constraint_rows(t, q, d, d0)
    }
    fn load_geometry<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        points: &mut [[T; 3]],
        frames: &mut [[T; 9]],
    ) -> Result<(), ModelError> {
        self.0.load_geometry(t, q, points, frames)
    }
    fn load_values<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        qdot: &[T],
        inputs: &[T],
        forces: &mut [[T; 3]],
        torques: &mut [[T; 3]],
    ) -> Result<(), ModelError> {
        self.0.load_values(t, q, qdot, inputs, forces, torques)
    }
}

/// A small deterministic generator for test states (uniform in [lo, hi)).
pub struct Rng(pub u64);

impl Rng {
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let unit = (self.0 >> 11) as f64 / (1u64 << 53) as f64;
        lo + (hi - lo) * unit
    }
}

pub fn assert_close(a: f64, b: f64, tol: f64, what: &str) {
    let scale = 1.0_f64.max(a.abs()).max(b.abs());
    assert!(
        (a - b).abs() <= tol * scale,
        "{what}: {a} vs {b} (difference {:e})",
        (a - b).abs()
    );
}
