//! The UR5 on a differential-drive base, with the model command line:
//! `cargo run --release --example mobile_manipulator -- info`, `eval`
//! (JSON lines with `q`, `u` and `inputs` keyed by the joint names,
//! `tau_<joint>`, `tau_left` and `tau_right` for the torques), `bench`.
//! The default action lets the arm fall for 2 s on the free-rolling base.

#[path = "common/robot_demo.rs"]
mod demo;
#[path = "models/mobile_manipulator.rs"]
mod model;

use std::process::ExitCode;

fn main() -> ExitCode {
    appell::cli::run(model::MobileManipulator::default(), demo::demonstrate)
}
