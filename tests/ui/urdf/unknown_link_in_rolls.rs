//! trybuild compiles this case in `target/tests/trybuild/appell`, the
//! directory a relative path starts from: the path climbs back to the
//! workspace.

use appell::Appell;

#[derive(Appell)]
#[appell(urdf("../../../examples/robots/ur5/ur5_robot.urdf"), gravity(-9.81 * N.z))]
#[appell(point(P = O), rolls(forearm, contact = P), rolls(tool0, contact = P))]
struct Ur5;

fn main() {}
