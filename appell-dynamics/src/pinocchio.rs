//! A robot's state in Pinocchio's conventions, and back.
//!
//! A model made from a URDF with `base = free` (or a `free` joint written
//! by hand) has the coordinates and speeds of the model language:
//!
//! | | appell | Pinocchio (`JointModelFreeFlyer`) |
//! |---|---|---|
//! | base orientation | `b_qw, b_qx, b_qy, b_qz` (scalar first) | `q[3..7] = [qx, qy, qz, qw]` (scalar last) |
//! | base position | `b_x, b_y, b_z` (in N) | `q[0..3]` (in the world) |
//! | base angular velocity | `b_wx, b_wy, b_wz` (in the base's axes) | `v[3..6]` (in the base's axes) |
//! | base linear velocity | `b_x, b_y, b_z`: ṗ in N's axes | `v[0..3] = Rᵀ ṗ`, in the base's axes |
//! | joints | one coordinate and speed each, named as the joint | after the base, in Pinocchio's joint order |
//!
//! where `b` is the free joint's name (`root_joint` from the URDF option,
//! as Pinocchio names it) and R the base's rotation (its axes in N's).
//! Pinocchio's accelerations are the rates of its `v`: the base's linear
//! one is `Rᵀ p̈ − ω × v`. Its generalized forces are dual to `v`: the
//! base's force in the base's axes, then the moment, where appell's are
//! dual to its speeds (the moment, then the force in N's axes). A
//! `base = planar` model maps to `JointModelPlanar` (`q = [x, y, cos θ,
//! sin θ]`, `v` = the base's velocity in its own axes and θ̇), a fixed base
//! to the joints alone.
//!
//! [`PinocchioMap`] converts each of q, v, a, τ and M both ways, so that
//! Pinocchio's reference values can be compared state for state. Every
//! conversion is exact (rotations and cross products) and generic over
//! the scalar.
//!
//! ```
//! use appell_dynamics::pinocchio::PinocchioMap;
//!
//! // A free base named `root_joint` carrying one joint `hip`, as a model's
//! // `info()` lists them.
//! let coordinates = ["root_joint_qw", "root_joint_qx", "root_joint_qy", "root_joint_qz",
//!                    "root_joint_x", "root_joint_y", "root_joint_z", "hip"];
//! let speeds = ["root_joint_wx", "root_joint_wy", "root_joint_wz",
//!               "root_joint_x", "root_joint_y", "root_joint_z", "hip"];
//! let map = PinocchioMap::free("root_joint", &coordinates, &speeds, &["hip"]).unwrap();
//! assert_eq!((map.nq(), map.nv()), (8, 7));
//!
//! // A quarter turn about z, moving along N.x at 1 m/s.
//! let h = std::f64::consts::FRAC_1_SQRT_2;
//! let q = [h, 0.0, 0.0, h, 1.0, 2.0, 3.0, 0.5];
//! let u = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
//! let mut q_pin = [0.0; 8];
//! map.q_to_pinocchio(&q, &mut q_pin).unwrap();
//! assert_eq!(q_pin, [1.0, 2.0, 3.0, 0.0, 0.0, h, h, 0.5]);
//! // In the base's axes, N.x is −y.
//! let mut v = [0.0; 7];
//! map.v_to_pinocchio(&q, &u, &mut v).unwrap();
//! assert!((v[1] + 1.0).abs() < 1e-15 && v[0].abs() < 1e-15);
//! let mut back = [0.0; 7];
//! map.v_from_pinocchio(&q, &v, &mut back).unwrap();
//! assert!(back.iter().zip(&u).all(|(a, b)| (a - b).abs() < 1e-15));
//! ```

use std::fmt;
use std::string::String;
use std::vec::Vec;

use appell_core::check_len;
use appell_core::{ModelError, Scalar};

/// Why a map cannot be made from a model's names.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MapError {
    /// A name the base or a joint needs is not among the model's
    /// coordinates or speeds.
    Missing {
        /// The name looked for.
        name: String,
        /// `"coordinate"` or `"speed"`.
        kind: &'static str,
    },
    /// Coordinates the map leaves out: every one must be the base's or a
    /// joint's.
    Unmapped {
        /// Their names.
        names: Vec<String>,
    },
}

impl fmt::Display for MapError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MapError::Missing { name, kind } => {
                write!(f, "the model has no {kind} `{name}`")
            }
            MapError::Unmapped { names } => write!(
                f,
                "the model's coordinates {} are neither the base's nor a listed joint's",
                names.join(", ")
            ),
        }
    }
}

impl std::error::Error for MapError {}

/// Where the base's values sit in the model's coordinates and speeds.
#[derive(Clone, Copy, Debug)]
enum Base {
    /// No base joint.
    Fixed,
    /// A free joint: the index of `qw` (then `qx`, `qy`, `qz`) and of `x`
    /// (then `y`, `z`) among the coordinates; of `wx` and of `x` among the
    /// speeds.
    Free {
        quaternion: usize,
        position: usize,
        angular: usize,
        linear: usize,
    },
    /// A planar joint about N.z: the indices of `x`, `y`, `angle` among the
    /// coordinates and the speeds.
    Planar { q: [usize; 3], u: [usize; 3] },
}

/// The conversion between a model's coordinates and speeds and
/// Pinocchio's `q` and `v` of the same robot (see the [module](self)).
#[derive(Clone, Debug)]
pub struct PinocchioMap {
    base: Base,
    /// Each joint's coordinate and speed index, in Pinocchio's order.
    joints: Vec<(usize, usize)>,
    /// The model's numbers of coordinates and speeds.
    n: usize,
    l: usize,
}

fn find(names: &[&str], name: &str, kind: &'static str) -> Result<usize, MapError> {
    names
        .iter()
        .position(|c| *c == name)
        .ok_or_else(|| MapError::Missing {
            name: name.into(),
            kind,
        })
}

impl PinocchioMap {
    /// A fixed base: the `joints` (names of one-degree-of-freedom joints,
    /// each a coordinate and a speed of the model) in Pinocchio's order.
    pub fn fixed(
        coordinates: &[&str],
        speeds: &[&str],
        joints: &[&str],
    ) -> Result<PinocchioMap, MapError> {
        Self::with_base(Base::Fixed, coordinates, speeds, joints, &[])
    }

    /// A free base on the joint named `base` (`root_joint` for
    /// `urdf(..., base = free)`), then `joints` in Pinocchio's order.
    pub fn free(
        base: &str,
        coordinates: &[&str],
        speeds: &[&str],
        joints: &[&str],
    ) -> Result<PinocchioMap, MapError> {
        let c = |s: &str| find(coordinates, &format!("{base}_{s}"), "coordinate");
        let u = |s: &str| find(speeds, &format!("{base}_{s}"), "speed");
        let (quaternion, position) = (c("qw")?, c("x")?);
        for (k, s) in ["qx", "qy", "qz"].iter().enumerate() {
            Self::consecutive(c(s)?, quaternion + k + 1, base, s)?;
        }
        for (k, s) in ["y", "z"].iter().enumerate() {
            Self::consecutive(c(s)?, position + k + 1, base, s)?;
        }
        let (angular, linear) = (u("wx")?, u("x")?);
        for (k, s) in ["wy", "wz"].iter().enumerate() {
            Self::consecutive(u(s)?, angular + k + 1, base, s)?;
        }
        for (k, s) in ["y", "z"].iter().enumerate() {
            Self::consecutive(u(s)?, linear + k + 1, base, s)?;
        }
        let taken: Vec<usize> = (quaternion..quaternion + 4)
            .chain(position..position + 3)
            .collect();
        let b = Base::Free {
            quaternion,
            position,
            angular,
            linear,
        };
        Self::with_base(b, coordinates, speeds, joints, &taken)
    }

    /// A planar base on the joint named `base` (`urdf(..., base =
    /// planar)`: `x`, `y` and the heading about N.z), then `joints`.
    pub fn planar(
        base: &str,
        coordinates: &[&str],
        speeds: &[&str],
        joints: &[&str],
    ) -> Result<PinocchioMap, MapError> {
        let mut q = [0; 3];
        let mut u = [0; 3];
        for (k, s) in ["x", "y", "angle"].iter().enumerate() {
            let name = format!("{base}_{s}");
            q[k] = find(coordinates, &name, "coordinate")?;
            u[k] = find(speeds, &name, "speed")?;
        }
        Self::with_base(Base::Planar { q, u }, coordinates, speeds, joints, &q)
    }

    /// An error unless the base's names lie in the order the map reads.
    fn consecutive(found: usize, expected: usize, base: &str, s: &str) -> Result<(), MapError> {
        if found == expected {
            Ok(())
        } else {
            Err(MapError::Missing {
                name: format!("{base}_{s} in its place after the base's others"),
                kind: "coordinate or speed",
            })
        }
    }

    fn with_base(
        base: Base,
        coordinates: &[&str],
        speeds: &[&str],
        joints: &[&str],
        taken: &[usize],
    ) -> Result<PinocchioMap, MapError> {
        let mut map = Vec::with_capacity(joints.len());
        for j in joints {
            map.push((
                find(coordinates, j, "coordinate")?,
                find(speeds, j, "speed")?,
            ));
        }
        let unmapped: Vec<String> = (0..coordinates.len())
            .filter(|r| !taken.contains(r) && !map.iter().any(|(c, _)| c == r))
            .map(|r| coordinates[r].to_string())
            .collect();
        if !unmapped.is_empty() {
            return Err(MapError::Unmapped { names: unmapped });
        }
        Ok(PinocchioMap {
            base,
            joints: map,
            n: coordinates.len(),
            l: speeds.len(),
        })
    }

    /// The length of Pinocchio's `q`.
    pub fn nq(&self) -> usize {
        self.base_nq() + self.joints.len()
    }

    /// The length of Pinocchio's `v` (and of its `a` and `τ`).
    pub fn nv(&self) -> usize {
        self.base_nv() + self.joints.len()
    }

    fn base_nq(&self) -> usize {
        match self.base {
            Base::Fixed => 0,
            Base::Free { .. } => 7,
            Base::Planar { .. } => 4,
        }
    }

    fn base_nv(&self) -> usize {
        match self.base {
            Base::Fixed => 0,
            Base::Free { .. } => 6,
            Base::Planar { .. } => 3,
        }
    }

    /// Pinocchio's `q` from the model's coordinates `q`.
    pub fn q_to_pinocchio<T: Scalar>(&self, q: &[T], out: &mut [T]) -> Result<(), ModelError> {
        check_len("q", q, self.n)?;
        check_len("q_pinocchio", out, self.nq())?;
        match self.base {
            Base::Fixed => {}
            Base::Free {
                quaternion,
                position,
                ..
            } => {
                out[..3].copy_from_slice(&q[position..position + 3]);
                out[3..6].copy_from_slice(&q[quaternion + 1..quaternion + 4]);
                out[6] = q[quaternion];
            }
            Base::Planar { q: at, .. } => {
                out[0] = q[at[0]];
                out[1] = q[at[1]];
                out[2] = q[at[2]].cos();
                out[3] = q[at[2]].sin();
            }
        }
        let b = self.base_nq();
        for (k, &(c, _)) in self.joints.iter().enumerate() {
            out[b + k] = q[c];
        }
        Ok(())
    }

    /// The model's coordinates from Pinocchio's `q`.
    pub fn q_from_pinocchio<T: Scalar>(
        &self,
        q_pinocchio: &[T],
        out: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q_pinocchio", q_pinocchio, self.nq())?;
        check_len("q", out, self.n)?;
        let p = q_pinocchio;
        match self.base {
            Base::Fixed => {}
            Base::Free {
                quaternion,
                position,
                ..
            } => {
                out[position..position + 3].copy_from_slice(&p[..3]);
                out[quaternion] = p[6];
                out[quaternion + 1..quaternion + 4].copy_from_slice(&p[3..6]);
            }
            Base::Planar { q: at, .. } => {
                out[at[0]] = p[0];
                out[at[1]] = p[1];
                out[at[2]] = p[3].atan2(p[2]);
            }
        }
        let b = self.base_nq();
        for (k, &(c, _)) in self.joints.iter().enumerate() {
            out[c] = p[b + k];
        }
        Ok(())
    }

    /// The base's rotation at `q`: its axes (columns) in N's.
    fn rotation<T: Scalar>(&self, q: &[T]) -> [[T; 3]; 3] {
        match self.base {
            Base::Free { quaternion: k, .. } => {
                let e = [q[k], q[k + 1], q[k + 2], q[k + 3]];
                quaternion_matrix(e)
            }
            Base::Planar { q: at, .. } => {
                let (c, s) = (q[at[2]].cos(), q[at[2]].sin());
                let (z, o) = (T::zero(), T::one());
                [[c, -s, z], [s, c, z], [z, z, o]]
            }
            Base::Fixed => {
                let (z, o) = (T::zero(), T::one());
                [[o, z, z], [z, o, z], [z, z, o]]
            }
        }
    }

    /// The base's (linear, angular) slots among the model's speeds: three
    /// each for a free base, (x, y) and the heading for a planar one.
    fn base_speeds(&self) -> (Vec<usize>, Vec<usize>) {
        match self.base {
            Base::Fixed => (Vec::new(), Vec::new()),
            Base::Free {
                angular, linear, ..
            } => (
                (linear..linear + 3).collect(),
                (angular..angular + 3).collect(),
            ),
            Base::Planar { u, .. } => (vec![u[0], u[1]], vec![u[2]]),
        }
    }

    /// Pinocchio's `v` at `q` from the model's speeds `u`.
    pub fn v_to_pinocchio<T: Scalar>(
        &self,
        q: &[T],
        u: &[T],
        out: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q", q, self.n)?;
        check_len("u", u, self.l)?;
        check_len("v_pinocchio", out, self.nv())?;
        let r = self.rotation(q);
        let (linear, angular) = self.base_speeds();
        let world = vec3(u, &linear);
        let local = turn_back(&r, world);
        out[..linear.len()].copy_from_slice(&local[..linear.len()]);
        for (k, &s) in angular.iter().enumerate() {
            out[linear.len() + k] = u[s];
        }
        self.joints_to(u, out);
        Ok(())
    }

    /// The model's speeds at `q` from Pinocchio's `v`.
    pub fn v_from_pinocchio<T: Scalar>(
        &self,
        q: &[T],
        v: &[T],
        out: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q", q, self.n)?;
        check_len("v_pinocchio", v, self.nv())?;
        check_len("u", out, self.l)?;
        let r = self.rotation(q);
        let (linear, angular) = self.base_speeds();
        let local = padded(&v[..linear.len()]);
        let world = turn(&r, local);
        for (k, &s) in linear.iter().enumerate() {
            out[s] = world[k];
        }
        for (k, &s) in angular.iter().enumerate() {
            out[s] = v[linear.len() + k];
        }
        self.joints_from(v, out);
        Ok(())
    }

    /// Pinocchio's `a` (the rates of its `v`) at `q` and the model's speeds
    /// `u`, from the model's accelerations `u_dot`.
    pub fn a_to_pinocchio<T: Scalar>(
        &self,
        q: &[T],
        u: &[T],
        u_dot: &[T],
        out: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("u_dot", u_dot, self.l)?;
        let mut v = vec![T::zero(); self.nv()];
        self.v_to_pinocchio(q, u, &mut v)?;
        // Rᵀ p̈ − ω × (Rᵀ ṗ): the classical acceleration less the frame's turn.
        self.v_to_pinocchio(q, u_dot, out)?;
        let (linear, _) = self.base_speeds();
        let (lin, ang) = self.base_split(&v);
        let w_cross_v = cross(ang, lin);
        for (k, x) in out[..linear.len()].iter_mut().enumerate() {
            *x -= w_cross_v[k];
        }
        Ok(())
    }

    /// The model's accelerations at `q` from Pinocchio's `v` and `a`.
    pub fn a_from_pinocchio<T: Scalar>(
        &self,
        q: &[T],
        v: &[T],
        a: &[T],
        out: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("v_pinocchio", v, self.nv())?;
        check_len("a_pinocchio", a, self.nv())?;
        let (linear, _) = self.base_speeds();
        let (lin, ang) = self.base_split(v);
        let w_cross_v = cross(ang, lin);
        let mut classical = a.to_vec();
        for (k, x) in classical[..linear.len()].iter_mut().enumerate() {
            *x += w_cross_v[k];
        }
        self.v_from_pinocchio(q, &classical, out)
    }

    /// Pinocchio's generalized forces (dual to its `v`) at `q` from the
    /// model's (dual to its speeds): τ_pin = Tᵀ τ for u = T v.
    pub fn tau_to_pinocchio<T: Scalar>(
        &self,
        q: &[T],
        tau: &[T],
        out: &mut [T],
    ) -> Result<(), ModelError> {
        // The base's force turns like its velocity: F_base = Rᵀ F_N.
        self.v_to_pinocchio(q, tau, out)
    }

    /// The model's generalized forces at `q` from Pinocchio's.
    pub fn tau_from_pinocchio<T: Scalar>(
        &self,
        q: &[T],
        tau: &[T],
        out: &mut [T],
    ) -> Result<(), ModelError> {
        self.v_from_pinocchio(q, tau, out)
    }

    /// Pinocchio's mass matrix (nv × nv, row-major) at `q` from the model's
    /// (l × l, row-major): M_pin = Tᵀ M T.
    pub fn mass_to_pinocchio<T: Scalar>(
        &self,
        q: &[T],
        mass: &[T],
        out: &mut [T],
    ) -> Result<(), ModelError> {
        let (l, nv) = (self.l, self.nv());
        check_len("mass", mass, l * l)?;
        check_len("mass_pinocchio", out, nv * nv)?;
        let (mut unit, mut column) = (vec![T::zero(); nv], vec![T::zero(); l]);
        let (mut product, mut result) = (vec![T::zero(); l], vec![T::zero(); nv]);
        for j in 0..nv {
            unit.iter_mut().for_each(|x| *x = T::zero());
            unit[j] = T::one();
            self.v_from_pinocchio(q, &unit, &mut column)?;
            for (i, p) in product.iter_mut().enumerate() {
                *p = (0..l).fold(T::zero(), |s, k| s + mass[i * l + k] * column[k]);
            }
            self.tau_to_pinocchio(q, &product, &mut result)?;
            for i in 0..nv {
                out[i * nv + j] = result[i];
            }
        }
        Ok(())
    }

    /// The base's (linear, angular) velocity in Pinocchio's `v`, padded to
    /// three components (a planar base's angular one along z).
    fn base_split<T: Scalar>(&self, v: &[T]) -> ([T; 3], [T; 3]) {
        let z = T::zero();
        match self.base {
            Base::Fixed => ([z; 3], [z; 3]),
            Base::Free { .. } => ([v[0], v[1], v[2]], [v[3], v[4], v[5]]),
            Base::Planar { .. } => ([v[0], v[1], z], [z, z, v[2]]),
        }
    }

    fn joints_to<T: Scalar>(&self, u: &[T], out: &mut [T]) {
        let b = self.base_nv();
        for (k, &(_, s)) in self.joints.iter().enumerate() {
            out[b + k] = u[s];
        }
    }

    fn joints_from<T: Scalar>(&self, v: &[T], out: &mut [T]) {
        let b = self.base_nv();
        for (k, &(_, s)) in self.joints.iter().enumerate() {
            out[s] = v[b + k];
        }
    }
}

/// The rotation of the quaternion e = (w, x, y, z): its frame's axes in
/// the parent's, as the model writes it.
fn quaternion_matrix<T: Scalar>(e: [T; 4]) -> [[T; 3]; 3] {
    let two = T::from_f64(2.0);
    let [w, x, y, z] = e;
    [
        [
            w * w + x * x - y * y - z * z,
            two * (x * y - w * z),
            two * (x * z + w * y),
        ],
        [
            two * (x * y + w * z),
            w * w - x * x + y * y - z * z,
            two * (y * z - w * x),
        ],
        [
            two * (x * z - w * y),
            two * (y * z + w * x),
            w * w - x * x - y * y + z * z,
        ],
    ]
}

/// The values of `u` at `slots`, padded with zeros to three.
fn vec3<T: Scalar>(u: &[T], slots: &[usize]) -> [T; 3] {
    let mut out = [T::zero(); 3];
    for (k, &s) in slots.iter().enumerate() {
        out[k] = u[s];
    }
    out
}

fn padded<T: Scalar>(v: &[T]) -> [T; 3] {
    let mut out = [T::zero(); 3];
    out[..v.len()].copy_from_slice(v);
    out
}

/// R x.
fn turn<T: Scalar>(r: &[[T; 3]; 3], x: [T; 3]) -> [T; 3] {
    core::array::from_fn(|i| r[i][0] * x[0] + r[i][1] * x[1] + r[i][2] * x[2])
}

/// Rᵀ x.
fn turn_back<T: Scalar>(r: &[[T; 3]; 3], x: [T; 3]) -> [T; 3] {
    core::array::from_fn(|i| r[0][i] * x[0] + r[1][i] * x[1] + r[2][i] * x[2])
}

fn cross<T: Scalar>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn free_map() -> PinocchioMap {
        let c = [
            "b_qw", "b_qx", "b_qy", "b_qz", "b_x", "b_y", "b_z", "j1", "j2",
        ];
        let s = ["b_wx", "b_wy", "b_wz", "b_x", "b_y", "b_z", "j1", "j2"];
        PinocchioMap::free("b", &c, &s, &["j2", "j1"]).unwrap()
    }

    fn state() -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let e = [0.3_f64, -0.5, 0.7, 0.1];
        let n = e.iter().map(|x| x * x).sum::<f64>().sqrt();
        let mut q: Vec<f64> = e.iter().map(|x| x / n).collect();
        q.extend([0.4, -1.2, 0.9, 0.25, -0.75]);
        let u = vec![0.3, -0.2, 0.5, 1.1, -0.4, 0.6, 0.8, -1.3];
        let u_dot = vec![-0.6, 0.9, 0.1, 0.2, 0.35, -0.45, 1.5, 0.05];
        (q, u, u_dot)
    }

    #[test]
    fn every_conversion_round_trips() {
        let map = free_map();
        let (q, u, u_dot) = state();
        let mut qp = [0.0; 9];
        map.q_to_pinocchio(&q, &mut qp).unwrap();
        assert_eq!(qp[7..], [q[8], q[7]]);
        let mut q2 = [0.0; 9];
        map.q_from_pinocchio(&qp, &mut q2).unwrap();
        assert_eq!(q2[..], q[..]);
        let (mut v, mut u2) = ([0.0; 8], [0.0; 8]);
        map.v_to_pinocchio(&q, &u, &mut v).unwrap();
        map.v_from_pinocchio(&q, &v, &mut u2).unwrap();
        let (mut a, mut u_dot2) = ([0.0; 8], [0.0; 8]);
        map.a_to_pinocchio(&q, &u, &u_dot, &mut a).unwrap();
        map.a_from_pinocchio(&q, &v, &a, &mut u_dot2).unwrap();
        for k in 0..8 {
            assert!((u2[k] - u[k]).abs() < 1e-14 && (u_dot2[k] - u_dot[k]).abs() < 1e-14);
        }
    }

    #[test]
    fn the_linear_acceleration_is_the_rate_of_the_base_velocity() {
        // d/dt (Rᵀ ṗ) by central differences along the motion.
        let map = free_map();
        let (q, u, u_dot) = state();
        let h = 1e-6;
        let at = |s: f64| {
            let e = &q[..4];
            let w = &u[..3];
            // ė = ½ e ⊗ (0, ω).
            let rate = [
                -0.5 * (e[1] * w[0] + e[2] * w[1] + e[3] * w[2]),
                0.5 * (e[0] * w[0] + e[2] * w[2] - e[3] * w[1]),
                0.5 * (e[0] * w[1] + e[3] * w[0] - e[1] * w[2]),
                0.5 * (e[0] * w[2] + e[1] * w[1] - e[2] * w[0]),
            ];
            let mut qs = q.clone();
            for k in 0..4 {
                qs[k] += s * rate[k];
            }
            let us: Vec<f64> = u.iter().zip(&u_dot).map(|(x, d)| x + s * d).collect();
            let mut v = [0.0; 8];
            map.v_to_pinocchio(&qs, &us, &mut v).unwrap();
            v
        };
        let (plus, minus) = (at(h), at(-h));
        let mut a = [0.0; 8];
        map.a_to_pinocchio(&q, &u, &u_dot, &mut a).unwrap();
        for k in 0..8 {
            let fd = (plus[k] - minus[k]) / (2.0 * h);
            assert!((fd - a[k]).abs() < 1e-8, "{k}: {fd} {}", a[k]);
        }
    }

    #[test]
    fn forces_are_dual_to_velocities_and_the_mass_matrix_congruent() {
        let map = free_map();
        let (q, u, _) = state();
        let tau = [0.7, -0.1, 0.4, 2.0, -3.0, 1.5, 0.2, -0.6];
        let (mut v, mut tp) = ([0.0; 8], [0.0; 8]);
        map.v_to_pinocchio(&q, &u, &mut v).unwrap();
        map.tau_to_pinocchio(&q, &tau, &mut tp).unwrap();
        let power: f64 = tau.iter().zip(&u).map(|(a, b)| a * b).sum();
        let power_pin: f64 = tp.iter().zip(&v).map(|(a, b)| a * b).sum();
        assert!((power - power_pin).abs() < 1e-13);
        // ½ uᵀ M u is the same kinetic energy in both.
        let m: Vec<f64> = (0..64)
            .map(|k| {
                let (i, j) = (k / 8, k % 8);
                1.0 / (1.0 + i as f64 + j as f64) + if i == j { 2.0 } else { 0.0 }
            })
            .collect();
        let mut mp = [0.0; 64];
        map.mass_to_pinocchio(&q, &m, &mut mp).unwrap();
        let quad = |m: &[f64], x: &[f64]| -> f64 {
            (0..8)
                .map(|i| (0..8).map(|j| x[i] * m[i * 8 + j] * x[j]).sum::<f64>())
                .sum()
        };
        assert!((quad(&m, &u) - quad(&mp, &v)).abs() < 1e-12);
    }

    #[test]
    fn a_planar_base_and_missing_names() {
        let c = ["b_x", "b_y", "b_angle", "j"];
        let map = PinocchioMap::planar("b", &c, &c, &["j"]).unwrap();
        let q = [1.0, 2.0, 0.3, -0.4];
        let mut qp = [0.0; 5];
        map.q_to_pinocchio(&q, &mut qp).unwrap();
        assert_eq!(qp, [1.0, 2.0, 0.3f64.cos(), 0.3f64.sin(), -0.4]);
        let mut back = [0.0; 4];
        map.q_from_pinocchio(&qp, &mut back).unwrap();
        assert!((back[2] - 0.3).abs() < 1e-15);
        let err = PinocchioMap::planar("b", &c, &c, &[]).unwrap_err();
        assert_eq!(
            err,
            MapError::Unmapped {
                names: vec!["j".into()]
            }
        );
        let err = PinocchioMap::fixed(&c, &c, &["k"]).unwrap_err();
        assert!(err.to_string().contains("no coordinate `k`"), "{err}");
        let mut short = [0.0; 3];
        assert!(matches!(
            map.q_to_pinocchio(&q, &mut short),
            Err(ModelError::Length { .. })
        ));
    }
}
