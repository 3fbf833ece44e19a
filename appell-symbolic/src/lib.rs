//! # appell-symbolic
//!
//! The symbolic engine behind `#[derive(Appell)]`: an interned expression
//! graph with canonical forms, differentiation, substitution, linear
//! structure, a small safe linear solve, dependency sets, and emission of
//! straight-line Rust code with shared subexpressions.
//!
//! It runs inside every user's `cargo build`, so all of it is bounded
//! ([`Limits`]) and deterministic: the same input gives the same nodes and
//! byte-identical emitted code.
//!
//! ```
//! use appell_symbolic::Graph;
//!
//! let mut g = Graph::new();
//! // Position of a pendulum bob; its velocity by the total time derivative.
//! let th = g.coordinate("theta").unwrap();
//! let l = g.parameter("l").unwrap();
//! let x = g.parse("l*sin(theta)").unwrap();
//! let vx = g.time_derivative(x, &appell_symbolic::RateRules::coordinates()).unwrap();
//! assert_eq!(g.display(vx).to_string(), "l*theta_dot*cos(theta)");
//! # let _ = (th, l);
//! ```
#![warn(missing_docs)]

mod construct;
pub mod deps;
mod diff;
mod display;
pub mod emit;
pub mod error;
pub mod eval;
pub mod graph;
mod handles;
pub mod linear;
pub mod number;
mod parse;
mod subst;
pub mod workloads;

#[cfg(test)]
mod proptests;
#[cfg(test)]
mod rule_tests;

pub use deps::SymbolSet;
pub use diff::RateRules;
pub use display::DisplayExpr;
pub use emit::{
    ConstantForm, EmitOptions, Inst, LowerOptions, OpCount, Pass, PassReport, Program, ProgramSize,
    RustCode, RustPath, RustTokens, ScalarType,
};
pub use error::{Result, SymbolicError};
pub use eval::{Tape, Value};
pub use graph::{Coordinate, Func, Graph, Id, Limits, Node, Stats, Symbol, SymbolInfo, SymbolKind};
pub use linear::{Assumptions, LinearForm, LinearSolution, PartialSolution, Sign, SymMatrix};
pub use number::Number;
pub use parse::UnknownNames;
pub use subst::Substitution;
