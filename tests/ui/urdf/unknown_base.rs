//! A relative path is looked for from the crate's manifest directory,
//! then from this file's directory, so the case passes wherever cargo
//! puts its output.

use appell::Appell;

/// `base = flaoting`: a misspelled base kind.
#[derive(Appell)]
#[appell(urdf("../../../examples/robots/ur5/ur5_robot.urdf", base = flaoting))]
struct Ur5;

fn main() {}
