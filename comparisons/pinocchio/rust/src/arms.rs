//! Arms read with options the example models do not use. The paths are
//! relative to this crate's directory (`comparisons/pinocchio/rust`).

use appell::Appell;

/// The UR5 of `examples/models/ur5.rs` with its file's right angles
/// (`1.57079632679`, `3.14159265359`) read as exact
/// (`right_angles = 1e-10`); Pinocchio reads the file as written.
#[derive(Appell, Clone, Debug, Default)]
#[appell(
    urdf("../../../examples/robots/ur5/ur5_robot.urdf", right_angles = 1e-10),
    gravity(-9.81 * N.z)
)]
pub struct Ur5RightAngles;
