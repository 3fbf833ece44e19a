//! # appell-dynamics
//!
//! A derived model's dynamics at one state, computed numerically over the
//! interface of `appell-core` ([`Model`](appell_core::Model) through
//! [`DynModel`](appell_core::DynModel)) rather than generated:
//!
//! * [`oracle`]: the independent multiplier solver (Wang & Pao eqs.
//!   69-70) that checks every derivation, in full coordinates;
//! * [`constraint_forces`]: the constraints' forces and the contacts'
//!   normal and friction forces;
//! * [`augmented`]: motion through singular configurations in full
//!   coordinates;
//! * [`motion`]: every coordinate's rate and acceleration at an instant;
//! * [`energy`]: kinetic and potential energy and the power of the loads;
//! * [`switch`]: the state map between two scenes of a model;
//! * [`pinocchio`]: a robot's state in Pinocchio's conventions and back.
//!
//! The integrators, the hybrid driver and the tools build on this crate.
//! It needs `std`. Use it through the facade `appell`, which re-exports
//! these modules at its root.
#![warn(missing_docs)]

pub mod augmented;
pub mod constraint_forces;
pub mod energy;
pub mod motion;
pub mod oracle;
pub mod pinocchio;
pub mod switch;
