//! A relative path is looked for from the crate's manifest directory,
//! then from this file's directory, so the case passes wherever cargo
//! puts its output.

use appell::Appell;

#[derive(Appell)]
#[appell(urdf("../../../examples/robots/ur5/ur5_robot.urdf", weld(elbow, world_joint), parameters(wrist_3_link.mas = payload, forarm_link.mass = payload)))]
struct Ur5 { payload: f64 }

fn main() {}
