//! # appell
//!
//! Equations of motion of constrained multibody systems by Appell's method
//! (Wang & Pao, Am. J. Phys. 71, 2003), derived at compile time by
//! `#[derive(Appell)]`: describe the mechanism on a struct whose fields are
//! its parameters, and the derive forms Appell's equations, eliminates the
//! dependent speeds and the cyclic coordinates, and implements [`Model`]
//! with a closed-form, allocation-free reduced rhs generic over the scalar.
//!
//! ```
//! use appell::{Appell, Model};
//!
//! /// A pendulum of length `l` hanging from a cart that slides freely.
//! #[derive(Appell)]
//! #[appell(coordinates(x, theta), speeds(x, theta), positive(m_cart, m_bob, l))]
//! #[appell(point(C = O + x * N.x))]
//! #[appell(point(P = C + l * sin(theta) * N.x - l * cos(theta) * N.y))]
//! #[appell(particle(C, mass = m_cart), particle(P, mass = m_bob))]
//! #[appell(gravity(-g * N.y))]
//! struct CartPendulum { m_cart: f64, m_bob: f64, l: f64, g: f64 }
//!
//! let model = CartPendulum { m_cart: 2.0, m_bob: 0.5, l: 1.0, g: 9.81 };
//! let info = CartPendulum::info();
//! // x appears nowhere in the equations: it is left out of the state.
//! assert_eq!(info.ignorable, &["x"]);
//! assert_eq!(info.state_len(), 3); // (theta, x_dot, theta_dot)
//!
//! let prepared = model.prepare::<f64>(); // parameter-only work, once
//! let mut d = [0.0; 3];
//! model.rhs(&prepared, 0.0, &[0.3, 0.0, 0.0], &[], &mut d).unwrap();
//! // Released at rest: θ̈ = −(M + m) g sin θ / (l (M + m sin²θ)).
//! let (m_c, m_b, s) = (2.0, 0.5, 0.3f64.sin());
//! let expected = -(m_c + m_b) * 9.81 * s / (1.0 * (m_c + m_b * s * s));
//! assert!((d[2] - expected).abs() < 1e-12);
//! ```
//!
//! ## Contact forces
//!
//! The multipliers of eqs. 69-70 and the reaction at each rolling contact
//! ([`constraint_forces`]): a thin disc rolling upright in a straight line
//! at constant speed rests its weight on the ground and needs no friction.
//!
//! ```
//! use appell::constraint_forces::{contact_forces, Friction, Normal};
//! use appell::Appell;
//!
//! #[derive(Appell)]
//! #[appell(coordinates(yaw, lean, spin, x, y), speeds(yaw, lean, spin), positive(r, m))]
//! #[appell(frame(A = N.rotate_z(yaw)), frame(B = A.rotate_x(lean)), frame(C = B.rotate_y(spin)))]
//! #[appell(point(D = O + x * N.x + y * N.y + r * cos(lean) * N.z), point(P = D - r * B.z))]
//! #[appell(body(disc, center = D, frame = C, mass = m,
//!               inertia = principal(m * r * r / 4, m * r * r / 2, m * r * r / 4)))]
//! #[appell(rolls(disc, contact = P))]
//! #[appell(gravity(-g * N.z))]
//! struct Disc { r: f64, m: f64, g: f64 }
//!
//! let disc = Disc { r: 0.3, m: 2.0, g: 9.81 };
//! // q = (yaw, lean, spin, x, y), u = (yaw', lean', spin').
//! let f = contact_forces(&disc, 0.0, &[0.0; 5], &[0.0, 0.0, 4.0], &[]).unwrap();
//! let contact = &f.contacts[0];
//! assert!((contact.force[2] - 2.0 * 9.81).abs() < 1e-12); // the weight, on the disc
//! assert!(matches!(contact.normal, Normal::Available { .. }));
//! match contact.friction() {
//!     Friction::Required { mu, .. } => assert!(mu < 1e-12),
//!     other => panic!("{other:?}"),
//! }
//! ```
//!
//! ## Contact watch
//!
//! `rolls` (like every constraint) is a two-sided equality: the equations
//! hold whatever force it takes, pulling included. Every `solve_model*` of
//! a model with contacts therefore watches them ([`contact_watch`]): the
//! same disc released at rest at lean 1.5 rad falls flat, and the
//! integration stops where its centre reaches the floor instead of going
//! on through it.
//!
//! ```
//! use appell::integrate::{Dop853, IntegrateError};
//! use appell::{Appell, ContactViolation};
//!
//! #[derive(Appell)]
//! #[appell(coordinates(yaw, lean, spin, x, y), speeds(yaw, lean, spin), positive(r, m))]
//! #[appell(frame(A = N.rotate_z(yaw)), frame(B = A.rotate_x(lean)), frame(C = B.rotate_y(spin)))]
//! #[appell(point(D = O + x * N.x + y * N.y + r * cos(lean) * N.z), point(P = D - r * B.z))]
//! #[appell(body(disc, center = D, frame = C, mass = m,
//!               inertia = principal(m * r * r / 4, m * r * r / 2, m * r * r / 4)))]
//! #[appell(rolls(disc, contact = P))]
//! #[appell(gravity(-g * N.z))]
//! struct Disc { r: f64, m: f64, g: f64 }
//!
//! let disc = Disc { r: 0.3, m: 2.0, g: 9.81 };
//! // The reduced state: lean, then the rates of yaw, lean and spin.
//! let err = Dop853::new()
//!     .h_max(Some(1e-3))
//!     .solve_model(&disc, &[], 0.0, &[1.5, 0.0, 0.0, 0.0], 2.0)
//!     .unwrap_err();
//! let IntegrateError::Contact(event) = err else { panic!("{err}") };
//! assert_eq!((event.body, event.point), ("disc", "P"));
//! assert!(matches!(event.kind, ContactViolation::LeftRegion { .. } | ContactViolation::Singular));
//! ```
//!
//! The model language is described in `docs/model-language.md`; every
//! example in `examples/` gets the model command line ([`cli`]) for free.
//!
//! ## Where things are
//!
//! [`prelude`] imports the names most programs use. Each group of modules
//! below is a crate of its own, re-exported here:
//!
//! - the interface (`appell-core`, also without `std`): [`Model`],
//!   [`Scalar`], [`ModelInfo`], [`ModelError`], [`linalg`], [`dual`],
//!   [`precision`], and with `std` [`DynModel`] ([`dynamic`]);
//! - the dynamics at one state (`appell-dynamics`): [`oracle`],
//!   [`constraint_forces`], [`augmented`], [`motion`], [`energy`],
//!   [`switch`], [`pinocchio`];
//! - the integrators (`appell-integrate`, the explicit ones also without
//!   `std`): [`integrate`] (RK4, Heun, midpoint, Dopri5, DOP853, TR-BDF2,
//!   Radau5), with [`contact_watch`] and [`conditioning`];
//! - [`linearize`] (`appell-linearize`), [`hybrid`] and [`sliding`]
//!   (`appell-hybrid`);
//! - the tools (`appell-tools`): [`cli`], [`animate`], [`accuracy`].
#![cfg_attr(not(feature = "std"), no_std)]
#![warn(missing_docs)]

#[doc(hidden)]
pub use appell_core::__doc_model;
pub use appell_core::{
    check_len, BodyInfo, ContactEvent, ContactInfo, ContactViolation, JacobianInfo, JointLimit,
    Model, ModelError, ModelInfo, OpCounts, RowSource, Scalar, SceneVisitor, StateName,
};
pub use appell_core::{dual, linalg, physical, precision};
#[cfg(feature = "std")]
pub use appell_core::{dynamic, DynModel, DynRhs};
pub use appell_derive::Appell;

// The dynamics at one state.
#[cfg(feature = "std")]
pub use appell_dynamics::{
    augmented, constraint_forces, energy, motion, oracle, pinocchio, switch,
};

// Over time: integration (with its watches), hybrid runs, linearization.
#[cfg(feature = "std")]
pub use appell_hybrid as hybrid;
#[cfg(feature = "std")]
pub use appell_hybrid::sliding;
pub use appell_integrate as integrate;
#[cfg(feature = "std")]
pub use appell_integrate::{conditioning, contact_watch};
#[cfg(feature = "std")]
pub use appell_linearize as linearize;

// The tools.
#[cfg(feature = "std")]
pub use appell_tools::{accuracy, animate, cli};

/// nalgebra, the matrices of [`linearize`] and of the oracle, re-exported so
/// that a user needs no dependency line of their own (nor to match its
/// version).
///
/// ```
/// use appell::nalgebra::DMatrix;
/// let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -4.0, 0.0]);
/// let eig = appell::linearize::eigenvalues(&a).unwrap();
/// assert!(eig.iter().all(|&(re, im)| re.abs() < 1e-12 && (im.abs() - 2.0).abs() < 1e-12));
/// ```
#[cfg(feature = "std")]
pub use nalgebra;

/// num-dual, the dual numbers [`Scalar`] is implemented for (derivatives of
/// every generated function), re-exported for the same reason.
///
/// ```
/// use appell::{num_dual::Dual64, Scalar};
/// let x = Dual64::new(0.5, 1.0);
/// let y = x.sin();
/// assert!((y.eps - 0.5_f64.cos()).abs() < 1e-15);
/// ```
#[cfg(feature = "std")]
pub use num_dual;

/// Items the generated code refers to; not a stable API.
#[doc(hidden)]
pub mod __private {
    pub use crate::check_len;
    pub use crate::dual::{inverse_dynamics_derivatives_by_duals, rhs_jacobian_by_duals};
    pub use crate::linalg::{
        check_pivot, constraint_scale, ldlt_solve, lu_factor, lu_solve, lu_substitute, max_abs,
        pivot_margin, substitute_row,
    };
    pub use crate::physical::check_body;
    pub use crate::{
        BodyInfo, ContactInfo, JacobianInfo, JointLimit, Model, ModelError, ModelInfo, OpCounts,
        RowSource, Scalar, SceneVisitor,
    };
    pub use core::result::Result::{self, Err, Ok};
}

/// The symbolic engine (interned expressions, differentiation, CSE, emission).
#[cfg(feature = "std")]
pub use appell_symbolic as symbolic;

/// The names most programs use, in one import: the derive, the [`Model`]
/// trait, its object-safe face [`DynModel`] and the [`Scalar`] trait, what
/// a model says about itself and how its calls fail, and the integrators
/// with their error.
///
/// ```
/// use appell::prelude::*;
///
/// #[derive(Appell)]
/// #[appell(coordinates(theta), speeds(theta), positive(l, m))]
/// #[appell(point(P = O + l * sin(theta) * N.x - l * cos(theta) * N.y))]
/// #[appell(particle(P, mass = m))]
/// #[appell(gravity(-g * N.y))]
/// struct Pendulum { l: f64, m: f64, g: f64 }
///
/// // A small swing for one period comes back where it started.
/// let p = Pendulum { l: 1.0, m: 1.0, g: 9.81 };
/// let period = 2.0 * std::f64::consts::PI * (1.0f64 / 9.81).sqrt();
/// let end = Dop853::new().solve_model(&p, &[], 0.0, &[1e-3, 0.0], period).unwrap();
/// assert!((end.x[0] - 1e-3).abs() < 1e-6);
/// assert_eq!(Pendulum::info().state_len(), 2);
/// ```
pub mod prelude {
    pub use crate::integrate::{Dop853, Dopri5, IntegrateError};
    #[cfg(feature = "std")]
    pub use crate::integrate::{Radau5, TrBdf2};
    #[cfg(feature = "std")]
    pub use crate::DynModel;
    pub use crate::{Appell, Model, ModelError, ModelInfo, Scalar};
}

/// The task guides of `docs/guide/`, compiled here so that `cargo test`
/// runs every code block on those pages.
#[cfg(doctest)]
pub mod guide {
    #[doc = include_str!("../README.md")]
    pub struct Readme;
    #[doc = include_str!("../docs/guide/writing-a-model.md")]
    pub struct WritingAModel;
    #[doc = include_str!("../docs/guide/joints-and-urdf.md")]
    pub struct JointsAndUrdf;
    #[doc = include_str!("../docs/guide/scenes.md")]
    pub struct Scenes;
    #[doc = include_str!("../docs/guide/integrators.md")]
    pub struct Integrators;
    #[doc = include_str!("../docs/guide/constraint-forces.md")]
    pub struct ConstraintForces;
    #[doc = include_str!("../docs/guide/linearization-and-control.md")]
    pub struct LinearizationAndControl;
    #[doc = include_str!("../docs/guide/command-line.md")]
    pub struct CommandLine;
    #[doc = include_str!("../docs/guide/compile-errors.md")]
    pub struct CompileErrors;
    #[doc = include_str!("../docs/guide/pictures.md")]
    pub struct Pictures;
    #[doc = include_str!("../docs/guide/building.md")]
    pub struct Building;
}
