//! # appell
//!
//! Equations of motion of constrained multibody systems by Appell's method
//! (Wang & Pao, Am. J. Phys. 71, 2003), generated at compile time.
//!
//! This facade re-exports the runtime that generated code runs on and the
//! symbolic engine that derives it.
//!
//! ```
//! use appell::Scalar;
//! fn f<T: Scalar>(x: T) -> T { x.sin() * x.cos() }
//! assert_eq!(f(0.0_f64), 0.0);
//! ```
#![warn(missing_docs)]

pub use appell_runtime::*;
/// The symbolic engine (interned expressions, differentiation, CSE, emission).
pub use appell_symbolic as symbolic;
