//! # appell
//!
//! Equations of motion of constrained multibody systems by Appell's method
//! (Wang & Pao, Am. J. Phys. 71, 2003), derived at compile time by
//! `#[derive(Appell)]`.
//!
//! This facade re-exports the runtime that generated code runs on, the
//! derive, and (with `std`) the symbolic engine.
//!
//! ```
//! use appell::Scalar;
//! fn f<T: Scalar>(x: T) -> T { x.sin() * x.cos() }
//! assert_eq!(f(0.0_f64), 0.0);
//! ```
#![cfg_attr(not(feature = "std"), no_std)]
#![warn(missing_docs)]

pub use appell_derive::Appell;
pub use appell_runtime::*;
/// The symbolic engine (interned expressions, differentiation, CSE, emission).
#[cfg(feature = "std")]
pub use appell_symbolic as symbolic;
