//! Random mechanisms, drawn with a fixed seed and written through the real
//! derive when this crate builds (`build/`), each with a function that
//! checks its generated code against the multiplier oracle: the rhs, the
//! inverse dynamics, the constraint reactions, the generated Jacobian
//! against dual numbers and, where the loads are conservative, the energy
//! balance (see [`check`]). The test in `tests/`
//! runs them all and reports how many were generated, derived and agreed.
#![allow(missing_docs, clippy::all, unused, nonstandard_style)] // generated models

pub mod check;

/// A derived mechanism and its check.
pub struct Case {
    /// The struct's name.
    pub name: &'static str,
    /// The model as written (attributes and struct).
    pub source: &'static str,
    /// The families of subsystems it was made of.
    pub families: &'static [&'static str],
    /// Checks the generated code at random states.
    pub check: fn(&mut check::Rng) -> Result<check::Report, String>,
}

/// A mechanism the derive refused or panicked on.
pub struct Unchecked {
    pub name: &'static str,
    pub source: &'static str,
    pub families: &'static [&'static str],
    /// The derive's first message (or the panic's).
    pub message: &'static str,
}

include!(concat!(env!("OUT_DIR"), "/models.rs"));
