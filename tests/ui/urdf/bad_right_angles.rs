//! `right_angles` takes a tolerance in radians, at most 1e-3: not an
//! angle.

use appell::Appell;

#[derive(Appell)]
#[appell(urdf("../../../examples/robots/ur5/ur5_robot.urdf", right_angles = 0.5))]
struct Ur5;

fn main() {}
