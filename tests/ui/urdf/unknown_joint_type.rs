//! trybuild compiles this case in `target/tests/trybuild/appell`, the
//! directory a relative path starts from: the path climbs back to the
//! workspace.

use appell::Appell;

#[derive(Appell)]
#[appell(urdf("unknown_joint_type.urdf"))]
struct Robot;

fn main() {}
