//! # appell-linearize
//!
//! Linearization of a model's reduced equations, exactly, by dual numbers
//! through the generic generated code: no symbolic Jacobian, no finite
//! differences.
//!
//! * [`linearize`]: A = ∂rhs/∂state and B = ∂rhs/∂inputs of [`Model::rhs`]
//!   at an operating point, one [`Dual64`] evaluation per column.
//! * [`eigenvalues`]: the complex eigenvalues of a real square matrix, sorted.
//! * [`solve_holonomic`]: Newton (Gauss-Newton when the counts differ) on the
//!   holonomic residuals of [`Model::constraint_residuals`], to put a
//!   configuration on the constraint manifold; [`holonomic_unknowns`] picks
//!   the dependent coordinates the residuals involve; [`project_holonomic`]
//!   and [`check_holonomic`] do it for a reduced state. A model with driven
//!   coordinates (constraints that read inputs) takes the `driven_` forms
//!   ([`driven_solve_holonomic`], [`driven_holonomic_unknowns`],
//!   [`driven_project_holonomic`], [`driven_check_holonomic`]), which
//!   evaluate the residuals at the inputs.
//! * [`minimal_linearization`]: the linearization in a minimal state, with
//!   the retained coordinates fixed by holonomic constraints eliminated and
//!   the privileged speeds an operating point holds fixed dropped.
//! * [`fixed_step`] and [`step_jacobian`]: one step of RK4 or semi-implicit
//!   Euler as a discrete-time map x⁺ = Φ(t, x, u), and its Jacobians
//!   ∂x⁺/∂x and ∂x⁺/∂u in one call, for discrete-time MPC and DDP.
//!
//! # Example
//!
//! A particle on a circle x² + y² = l² in Cartesian coordinates (privileged
//! speed ẋ, y dependent), pushed along N.x by an input force `f`, written by
//! hand here. Its reduced state is (x, y, ẋ), but y is fixed by x and the
//! constraint, so the minimal linearization at the bottom is the pendulum's
//! 2×2 system in (x, ẋ):
//!
//! ```
//! use appell_linearize::{
//!     eigenvalues, holonomic_unknowns, linearize, minimal_linearization, solve_holonomic,
//! };
//! # use appell_core::{check_len, BodyInfo, Model, ModelError, ModelInfo, OpCounts, Scalar};
//! # struct Ring { m: f64, l: f64, g: f64 }
//! # static INFO: ModelInfo = ModelInfo {
//! #     name: "Ring", parameters: &["m", "l", "g"], coordinates: &["x", "y"],
//! #     speeds: &["x"], dependent: &["y"], cyclic: &[], ignorable: &[],
//! #     retained: &["x", "y"], inputs: &["f"], effects: &["gravity", "push"], outputs: &[], row_sources: &[], contacts: &[], holonomic: 1,
//! #     constraints: 1, bodies: &[BodyInfo { name: "P", rigid: false }],
//! #     force_points: 1, torques: 0, form: "closed form", symbolic_elimination: true,
//! #     rhs_ops: OpCounts { add: 5, mul: 9, div: 3, calls: 0, total: 18 },
//! #     jacobian: None,
//! #     equations: "x'' = f/m + x (g y - x f/m - x'^2 - y'^2) / (x^2 + y^2)",
//! # };
//! # fn unused() -> Result<(), ModelError> { Err(ModelError::NonFinite { what: "unused" }) }
//! # impl Model for Ring {
//! #     type Prepared<T: Scalar> = ();
//! #     fn info() -> &'static ModelInfo { &INFO }
//! #     fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> {
//! #         check_len("out", out, 3)?; out.copy_from_slice(&[self.m, self.l, self.g]); Ok(())
//! #     }
//! #     fn set_parameter(&mut self, _: &str, _: f64) -> bool { false }
//! #     fn prepare<T: Scalar>(&self) {}
//! #     fn rhs<T: Scalar>(&self, _: &(), _t: T, s: &[T], i: &[T], ds: &mut [T]) -> Result<(), ModelError> {
//! #         check_len("state", s, 3)?; check_len("inputs", i, 1)?; check_len("dstate", ds, 3)?;
//! #         let (x, y, u) = (s[0], s[1], s[2]);
//! #         if y.re() == 0.0 { return Err(ModelError::SingularConstraints { column: 0, pivot: 0.0 }); }
//! #         let ydot = -(x * u) / y;
//! #         let a = i[0] / T::from_f64(self.m);
//! #         let mu = (T::from_f64(self.g) * y - x * a - u * u - ydot * ydot) / (x * x + y * y);
//! #         ds[0] = u; ds[1] = ydot; ds[2] = a + x * mu; Ok(())
//! #     }
//! #     fn constraint_residuals<T: Scalar>(&self, _: T, q: &[T], qd: &[T], h: &mut [T], v: &mut [T]) -> Result<(), ModelError> {
//! #         check_len("q", q, 2)?; check_len("qdot", qd, 2)?;
//! #         check_len("holonomic", h, 1)?; check_len("velocity", v, 1)?;
//! #         h[0] = q[0] * q[0] + q[1] * q[1] - T::from_f64(self.l * self.l);
//! #         v[0] = q[0] * qd[0] + q[1] * qd[1]; Ok(())
//! #     }
//! #     fn mass_matrix_and_forcing<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
//! #     fn speed_transform<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
//! #     fn coordinate_rates<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { unused() }
//! #     fn kinetic_energy<T: Scalar>(&self, _: T, _: &[T], _: &[T]) -> Result<T, ModelError> { unused().map(|_| T::zero()) }
//! #     fn mass_properties(&self, _: &mut [f64], _: &mut [[f64; 9]]) -> Result<(), ModelError> { unused() }
//! #     fn body_poses<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
//! #     fn constraint_rows<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
//! #     fn load_geometry<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
//! #     fn load_values<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [[T; 3]], _: &mut [[T; 3]]) -> Result<(), ModelError> { unused() }
//! # }
//! let (m, l, g) = (0.5, 2.0, 9.81);
//! let model = Ring { m, l, g };
//!
//! // The reduced state (x, y, ẋ) at the bottom, at rest, with no push.
//! let lin = linearize(&model, 0.0, &[0.0, -l, 0.0], &[0.0]).unwrap();
//! assert_eq!(lin.state_names, ["x", "y", "x_dot"]);
//! assert_eq!(lin.input_names, ["f"]);
//! assert!((lin.a[(2, 0)] + g / l).abs() < 1e-14); // ∂ẍ/∂x = −g/l
//! assert!((lin.b[(2, 0)] - 1.0 / m).abs() < 1e-14); // ∂ẍ/∂f = 1/m
//!
//! // Put a configuration on the circle: y is the coordinate to adjust.
//! let mut q = [0.6, -1.7];
//! let unknowns = holonomic_unknowns(&model, 0.0, &q).unwrap();
//! assert_eq!(unknowns, [1]);
//! let iterations = solve_holonomic(&model, 0.0, &mut q, &unknowns, 1e-13, 20).unwrap();
//! assert!(iterations <= 6);
//! assert!((q[1] + (l * l - 0.6 * 0.6_f64).sqrt()).abs() < 1e-14);
//!
//! // The minimal system in (x, ẋ): y is eliminated through the constraint.
//! let min = minimal_linearization(&model, 0.0, &[0.0, -l], &[0.0], &[0.0], &[]).unwrap();
//! assert_eq!(min.state_names, ["x", "x_dot"]);
//! let w = (g / l).sqrt();
//! let eig = eigenvalues(&min.a).unwrap();
//! assert_eq!(eig.len(), 2);
//! assert!(eig[0].0.abs() < 1e-14 && (eig[0].1 + w).abs() < 1e-14);
//! assert!(eig[1].0.abs() < 1e-14 && (eig[1].1 - w).abs() < 1e-14);
//! assert!((min.b[(1, 0)] - 1.0 / m).abs() < 1e-14);
//!
//! // Bad input is an error, never a panic.
//! assert!(linearize(&model, 0.0, &[0.0, -l], &[0.0]).is_err());
//! assert!(linearize(&model, 0.0, &[f64::NAN, -l, 0.0], &[0.0]).is_err());
//! assert!(minimal_linearization(&model, 0.0, &[0.0, -l], &[0.0], &[0.0], &["z"]).is_err());
//! ```
//!
//! # Cost
//!
//! [`linearize`] evaluates [`Model::rhs`] once per state component and input
//! in [`Dual64`] (one instantiation of the generated code). num-dual's
//! vector dual number `DualSVec64<W>`, carrying W columns per pass, shares
//! the real parts and the function calls, but every operation carries W
//! derivatives behind an `Option`: it gains on a large rhs only when W is
//! the exact column count (a compile-time constant, one more instantiation
//! of the generated rhs per width), and is even or slower on small models.
//! The columns are therefore Dual64 (the measurements are in
//! `docs/log.md`; `tests/linearize.rs` repeats the comparison on
//! hand-written models in the ignored test `dual64_vs_dualsvec64_timing`).
#![warn(missing_docs)]

// Items the documentation links to.
#[cfg(doc)]
use appell_core::Model;
#[cfg(doc)]
use num_dual::Dual64;

mod checks;
// Shared with the command line; not part of the API.
#[doc(hidden)]
pub mod discrete;
mod eigen;
mod error;
mod holonomic;
// Shared with the command line; not part of the API.
#[doc(hidden)]
pub mod jacobian;
mod minimal;
// Shared with the command line; not part of the API.
#[doc(hidden)]
pub mod newton_dyn;

pub use discrete::{fixed_step, step_jacobian, FixedStep, StepLinearization};
pub use eigen::eigenvalues;
pub use error::LinearizeError;
pub use holonomic::{
    check_holonomic, driven_check_holonomic, driven_holonomic_unknowns, driven_project_holonomic,
    driven_solve_holonomic, holonomic_unknowns, project_holonomic, solve_holonomic,
};
pub use jacobian::{dual_linearize, linearize, Linearization};
pub use minimal::minimal_linearization;
