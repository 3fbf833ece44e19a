//! The Panda arm from its URDF (fingers welded), with the model command
//! line: `cargo run --release --example panda -- info`, `eval` (JSON lines
//! with `q`, `u` and `inputs` keyed by the joint names, `tau_<joint>` for
//! the torques), `bench`. The default action lets the arm fall for 2 s.

#[path = "common/robot_demo.rs"]
mod demo;
#[path = "models/panda.rs"]
mod model;

use std::process::ExitCode;

fn main() -> ExitCode {
    appell::cli::run(model::Panda, demo::demonstrate)
}
