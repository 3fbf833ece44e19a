//! The floating-base robots of the comparison, read at compile time from
//! the repository's copies of example-robot-data 6.0.0's URDFs
//! (`tests/robots/`, unchanged; `tests/robots/MANIFEST.json`), each on a
//! free joint `root_joint` (`base = free`), as Pinocchio's
//! `buildModel(urdf, JointModelFreeFlyer())` puts them. The paths are
//! relative to this crate's directory (`comparisons/pinocchio/rust`).

use appell::Appell;

/// Solo12: a 12-joint quadruped (ODRI), 18 speeds.
#[derive(Appell, Clone, Debug, Default)]
#[appell(
    urdf("../../../tests/robots/solo/solo12.urdf", base = free),
    gravity(-9.81 * N.z)
)]
pub struct Solo12;

/// ANYmal B (the `anymal_b_simple` description): 12 joints.
#[derive(Appell, Clone, Debug, Default)]
#[appell(
    urdf("../../../tests/robots/anymal_b_simple/anymal.urdf", base = free),
    gravity(-9.81 * N.z)
)]
pub struct AnymalB;

/// Unitree Go1: 12 joints.
#[derive(Appell, Clone, Debug, Default)]
#[appell(
    urdf("../../../tests/robots/go1/go1.urdf", base = free),
    gravity(-9.81 * N.z)
)]
pub struct Go1;

/// HyQ (`hyq_no_sensors`): 12 joints.
#[derive(Appell, Clone, Debug, Default)]
#[appell(
    urdf("../../../tests/robots/hyq/hyq_no_sensors.urdf", base = free),
    gravity(-9.81 * N.z)
)]
pub struct Hyq;

/// HyQ with its right angles read as exact (`right_angles = 1e-10`; the
/// file writes π/2 as 1.57079632679): the same robot to 4.9e-12, with
/// frames turned by permutations.
#[derive(Appell, Clone, Debug, Default)]
#[appell(
    urdf(
        "../../../tests/robots/hyq/hyq_no_sensors.urdf",
        base = free,
        right_angles = 1e-10
    ),
    gravity(-9.81 * N.z)
)]
pub struct HyqRightAngles;

/// Unitree G1, the 29-joint humanoid (`g1_29dof_rev_1_0`): 35 speeds.
#[derive(Appell, Clone, Debug, Default)]
#[appell(
    urdf("../../../tests/robots/g1/g1_29dof_rev_1_0.urdf", base = free),
    gravity(-9.81 * N.z)
)]
pub struct G1;
