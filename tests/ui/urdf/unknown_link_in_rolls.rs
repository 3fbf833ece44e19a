//! A relative path is looked for from the crate's manifest directory,
//! then from this file's directory, so the case passes wherever cargo
//! puts its output.

use appell::Appell;

#[derive(Appell)]
#[appell(urdf("../../../examples/robots/ur5/ur5_robot.urdf"), gravity(-9.81 * N.z))]
#[appell(point(P = O), rolls(forearm, contact = P), rolls(tool0, contact = P))]
struct Ur5;

fn main() {}
