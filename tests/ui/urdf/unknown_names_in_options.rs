//! trybuild compiles this case in `target/tests/trybuild/appell`, the
//! directory a relative path starts from: the path climbs back to the
//! workspace.

use appell::Appell;

#[derive(Appell)]
#[appell(urdf("../../../examples/robots/ur5/ur5_robot.urdf", weld(elbow, world_joint), parameters(wrist_3_link.mas = payload, forarm_link.mass = payload)))]
struct Ur5 { payload: f64 }

fn main() {}
