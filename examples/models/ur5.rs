//! The UR5 arm, read from its URDF at compile time
//! (`examples/robots/ur5/ur5_robot.urdf`, from example-robot-data).

use appell::Appell;

/// Universal Robots' UR5: six revolute joints `shoulder_pan_joint`,
/// `shoulder_lift_joint`, `elbow_joint`, `wrist_1_joint`, `wrist_2_joint`,
/// `wrist_3_joint` (the coordinates, and their rates the speeds), each
/// driven by the torque `tau_<joint>`; gravity 9.81 m/s² along −z. The
/// numbers are the file's, folded into the code; the URDF's
/// `1.57079632679` stays as written (π/2 rounded, 4.9e-12 below it).
#[derive(Appell, Clone, Debug, Default, PartialEq)]
#[appell(urdf("examples/robots/ur5/ur5_robot.urdf"), gravity(-9.81 * N.z))]
pub struct Ur5;
