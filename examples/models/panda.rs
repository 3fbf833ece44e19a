//! The Franka Emika Panda arm, read from its URDF at compile time
//! (`examples/robots/panda/panda.urdf`, from example-robot-data), its two
//! finger joints welded at 0.

use appell::Appell;

/// The Panda: seven revolute joints `panda_joint1` ... `panda_joint7` (the
/// coordinates, and their rates the speeds), each driven by the torque
/// `tau_<joint>`; the hand and both fingers are bodies welded to link 7
/// (`weld(...)` fixes the prismatic finger joints at 0, and with them the
/// mimic joint's constraint goes); gravity 9.81 m/s² along −z.
#[derive(Appell, Clone, Debug, Default, PartialEq)]
#[appell(urdf(
    "examples/robots/panda/panda.urdf",
    weld(panda_finger_joint1, panda_finger_joint2)
))]
#[appell(gravity(-9.81 * N.z))]
pub struct Panda;
