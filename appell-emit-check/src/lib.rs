//! Rust emitted by `appell-symbolic` at build time (see `build.rs`), compiled
//! here so the tests can check that the emitted text computes exactly what
//! the engine's lowered program computes, for `f64`, `f32` and dual numbers.
#![allow(missing_docs)] // generated functions

include!(concat!(env!("OUT_DIR"), "/generated.rs"));
