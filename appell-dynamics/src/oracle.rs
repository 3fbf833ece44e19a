//! The independent solver: accelerations by the full-coordinate multiplier
//! route (Wang & Pao 2003, eqs. 69-70), used as an oracle for the equations
//! `#[derive(Appell)]` derives.
//!
//! Nothing here shares derivation code with the macro. Only the *kinematic
//! description* of a [`Model`] is used ([`Model::mass_properties`],
//! [`Model::body_poses`], [`Model::constraint_rows`],
//! [`Model::load_geometry`], [`Model::load_values`]) and its [`ModelInfo`];
//! every derivative is taken numerically-exactly with dual numbers, and the
//! equations
//!
//! ```text
//! M_full(q) q̈ + h(q, q̇, t) = Q(q, q̇, t) + Dᵀ λ,
//! D q̈ + (Ḋ q̇ + ḋ) = 0
//! ```
//!
//! are solved together as one dense KKT system by LU with partial pivoting.
//!
//! For body j with mass m_j, body-frame central inertia I_j, mass-centre
//! position r_j(q, t) and rotation R_j(q, t):
//!
//! * J_j = ∂r_j/∂q and the angular-velocity Jacobian G_j (column r is
//!   vee((∂R_j/∂q_r) R_jᵀ)) come from [`Dual64`] seeds on one coordinate at a
//!   time;
//! * the velocity v_j, angular velocity ω_j and the acceleration remainders
//!   a_j, α_j (the accelerations when q̈ = 0, including every time-explicit
//!   term) come from second-order [`Dual2_64`] seeds along the path
//!   s ↦ (q + s q̇, t + s): v_j and Ṙ_j are the first derivatives, a_j and
//!   R̈_j the second ones, ω̃_j = Ṙ_j R_jᵀ and α̃_j = skew(R̈_j R_jᵀ);
//! * M_full = Σ_j m_j J_jᵀ J_j + G_jᵀ I_N G_j with I_N = R_j I_j R_jᵀ (no
//!   rotational part for particles);
//! * h = Σ_j m_j J_jᵀ a_j + G_jᵀ (I_N α_j + ω_j × I_N ω_j);
//! * Q = Σ_P J_Pᵀ F_P + Σ_F G_Fᵀ L_F over the force application points and
//!   torque frames of [`Model::load_geometry`], with the loads of
//!   [`Model::load_values`];
//! * Ḋ q̇ + ḋ is the derivative part of D(q + ε q̇, t + ε) q̇ + d(q + ε q̇, t + ε).
//!
//! The privileged accelerations are the entries of q̈ at the coordinates named
//! in [`ModelInfo::speeds`]. [`reduced_rhs`] produces the same layout as
//! [`Model::rhs`], computing the dependent rates from the constraint rows
//! itself (never through [`Model::coordinate_rates`]).
//!
//! # Example
//!
//! A planar pendulum (a particle at (l sin θ, −l cos θ, 0) under gravity),
//! written by hand here:
//!
//! ```
//! use appell_dynamics::oracle::{accelerations, coordinate_rates, full_dynamics, reduced_rhs};
//! use appell_core::{check_len, BodyInfo, Model, ModelError, ModelInfo, OpCounts, Scalar};
//! # struct Pendulum { m: f64, l: f64, g: f64 }
//! # static INFO: ModelInfo = ModelInfo {
//! #     name: "Pendulum", parameters: &["m", "l", "g"], coordinates: &["theta"],
//! #     speeds: &["theta"], dependent: &[], cyclic: &[], ignorable: &[],
//! #     retained: &["theta"], inputs: &[], effects: &["gravity"], outputs: &[], row_sources: &[], contacts: &[], holonomic: 0,
//! #     constraints: 0, bodies: &[BodyInfo { name: "P", rigid: false }],
//! #     force_points: 1, torques: 0, form: "closed form", symbolic_elimination: true,
//! #     rhs_ops: OpCounts { add: 0, mul: 1, div: 1, calls: 1, total: 4 },
//! #     jacobian: None,
//! #     equations: "theta'' = -(g/l) sin(theta)",
//! # };
//! # fn unused() -> Result<(), ModelError> { Err(ModelError::NonFinite { what: "unused" }) }
//! # impl Model for Pendulum {
//! #     type Prepared<T: Scalar> = ();
//! #     fn info() -> &'static ModelInfo { &INFO }
//! #     fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> {
//! #         check_len("out", out, 3)?; out.copy_from_slice(&[self.m, self.l, self.g]); Ok(())
//! #     }
//! #     fn set_parameter(&mut self, _: &str, _: f64) -> bool { false }
//! #     fn prepare<T: Scalar>(&self) {}
//! #     fn rhs<T: Scalar>(&self, _: &(), _t: T, s: &[T], _i: &[T], ds: &mut [T]) -> Result<(), ModelError> {
//! #         check_len("state", s, 2)?; check_len("dstate", ds, 2)?;
//! #         ds[0] = s[1]; ds[1] = -(T::from_f64(self.g / self.l) * s[0].sin()); Ok(())
//! #     }
//! #     fn mass_matrix_and_forcing<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
//! #     fn speed_transform<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
//! #     fn coordinate_rates<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { unused() }
//! #     fn constraint_residuals<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
//! #     fn kinetic_energy<T: Scalar>(&self, _: T, _: &[T], _: &[T]) -> Result<T, ModelError> { unused().map(|_| T::zero()) }
//! #     fn mass_properties(&self, m: &mut [f64], i: &mut [[f64; 9]]) -> Result<(), ModelError> {
//! #         check_len("masses", m, 1)?; check_len("inertias", i, 1)?; m[0] = self.m; i[0] = [0.0; 9]; Ok(())
//! #     }
//! #     fn body_poses<T: Scalar>(&self, _t: T, q: &[T], p: &mut [[T; 3]], r: &mut [[T; 9]]) -> Result<(), ModelError> {
//! #         check_len("q", q, 1)?; check_len("positions", p, 1)?; check_len("rotations", r, 1)?;
//! #         let l = T::from_f64(self.l);
//! #         p[0] = [l * q[0].sin(), -(l * q[0].cos()), T::zero()];
//! #         let (o, z) = (T::one(), T::zero());
//! #         r[0] = [o, z, z, z, o, z, z, z, o]; Ok(())
//! #     }
//! #     fn constraint_rows<T: Scalar>(&self, _: T, q: &[T], d: &mut [T], d0: &mut [T]) -> Result<(), ModelError> {
//! #         check_len("q", q, 1)?; check_len("d", d, 0)?; check_len("d0", d0, 0)
//! #     }
//! #     fn load_geometry<T: Scalar>(&self, t: T, q: &[T], p: &mut [[T; 3]], f: &mut [[T; 9]]) -> Result<(), ModelError> {
//! #         check_len("frames", f, 0)?;
//! #         let mut r = [[T::zero(); 9]];
//! #         self.body_poses(t, q, p, &mut r)
//! #     }
//! #     fn load_values<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], f: &mut [[T; 3]], l: &mut [[T; 3]]) -> Result<(), ModelError> {
//! #         check_len("forces", f, 1)?; check_len("torques", l, 0)?;
//! #         f[0] = [T::zero(), T::from_f64(-self.m * self.g), T::zero()]; Ok(())
//! #     }
//! # }
//! let model = Pendulum { m: 2.0, l: 1.5, g: 9.81 };
//! let (theta, omega) = (0.4, 1.3);
//!
//! // θ̈ = −(g/l) sin θ.
//! let sol = accelerations(&model, 0.0, &[theta], &[omega], &[]).unwrap();
//! let exact = -(9.81 / 1.5) * f64::sin(theta);
//! assert!((sol.privileged[0] - exact).abs() < 1e-12);
//! assert!(sol.multipliers.is_empty());
//!
//! // Same layout as Model::rhs: [θ̇, θ̈].
//! let d = reduced_rhs(&model, 0.0, &[theta], &[omega], &[]).unwrap();
//! assert!((d[0] - omega).abs() < 1e-15 && (d[1] - exact).abs() < 1e-12);
//! assert_eq!(coordinate_rates(&model, 0.0, &[theta], &[omega]).unwrap(), vec![omega]);
//!
//! // The assembled equations: M_full = m l², T = m l² θ̇² / 2.
//! let full = full_dynamics(&model, 0.0, &[theta], &[omega], &[]).unwrap();
//! assert!((full.mass[0] - 2.0 * 1.5 * 1.5).abs() < 1e-12);
//! assert!((full.kinetic_energy - 0.5 * 2.0 * 1.5 * 1.5 * omega * omega).abs() < 1e-12);
//!
//! // Bad input is an error, never a panic.
//! assert!(accelerations(&model, 0.0, &[theta, 0.0], &[omega], &[]).is_err());
//! assert!(accelerations(&model, 0.0, &[f64::NAN], &[omega], &[]).is_err());
//! ```

// Items the documentation links to.
#[cfg(doc)]
use appell_core::{Model, ModelInfo};
#[cfg(doc)]
use num_dual::{Dual2_64, Dual64};

mod assembly;
mod error;
mod kkt;
mod layout;
mod rates;
mod vec3;

pub use assembly::{full_dynamics, FullDynamics};
pub use error::OracleError;
pub(crate) use kkt::accelerations_dyn;
pub use kkt::{accelerations, OracleSolution};
pub(crate) use layout::finite_all;
pub(crate) use rates::driven_coordinate_rates_dyn;
#[doc(hidden)]
pub use rates::reduced_rhs_dyn;
pub use rates::{coordinate_rates, reduced_rhs};
pub(crate) use vec3::{mul, mul_bt, vee};
