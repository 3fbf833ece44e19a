//! trybuild compiles this case in `target/tests/trybuild/appell`, the
//! directory a relative path starts from: the path climbs back to the
//! workspace.

use appell::Appell;

#[derive(Appell)]
#[appell(urdf("../../../examples/robots/ur5/ur5_robot.urdf", welds(shoulder_pan_joint)))]
struct Ur5;

fn main() {}
