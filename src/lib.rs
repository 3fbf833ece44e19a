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
#![cfg_attr(not(feature = "std"), no_std)]
#![warn(missing_docs)]

pub use appell_derive::Appell;
pub use appell_runtime::*;
/// The symbolic engine (interned expressions, differentiation, CSE, emission).
#[cfg(feature = "std")]
pub use appell_symbolic as symbolic;

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
