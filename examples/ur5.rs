//! The UR5 arm from its URDF, with the model command line:
//! `cargo run --release --example ur5 -- info`, `eval` (JSON lines with
//! `q`, `u` and `inputs` keyed by the joint names, `tau_<joint>` for the
//! torques), `bench`. The default action lets the arm fall for 2 s.

#[path = "common/robot_demo.rs"]
mod demo;
#[path = "models/ur5.rs"]
mod model;

use std::process::ExitCode;

fn main() -> ExitCode {
    appell::cli::run(model::Ur5, demo::demonstrate)
}
