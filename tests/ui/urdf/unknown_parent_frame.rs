//! A relative path is looked for from the crate's manifest directory,
//! then from this file's directory, so the case passes wherever cargo
//! puts its output.

use appell::Appell;

/// The robot's base frame is misspelled.
#[derive(Appell)]
#[appell(coordinates(yaw), speeds(yaw))]
#[appell(frame(Base = N.rotate_z(yaw)))]
#[appell(urdf("../../../examples/robots/ur5/ur5_robot.urdf", parent = Bse))]
struct Ur5OnATurntable;

fn main() {}
