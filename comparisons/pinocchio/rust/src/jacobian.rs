//! Twins of models whose derive writes no `rhs_jacobian` by default (the
//! derive writes it only where it is at most 4 times the rhs's size), with
//! `jacobian(on)` (the 16-, 32- and 64-link chains; the 8-link chain's is
//! now written by default, and its twin kept for the earlier runs' sake): the same robot, so the same states, for timing the
//! generated Jacobian against Pinocchio's `computeABADerivatives`
//! (`main.rs`'s `jacobians`). The rhs and the other functions are timed on
//! the models of `examples/models/` as before; these only add
//! `rhs_jacobian` and `rhs_jacobian_dual` to the same model's output.

use appell::Appell;

/// The Panda as `examples/models/panda.rs` has it (fingers welded), with
/// its Jacobian written.
#[derive(Appell, Clone, Debug, Default)]
#[appell(urdf(
    "examples/robots/panda/panda.urdf",
    weld(panda_finger_joint1, panda_finger_joint2)
))]
#[appell(gravity(-9.81 * N.z), jacobian(on))]
pub struct PandaJacobian;

/// The 8-link spatial chain as `examples/models/spatial_chain.rs` has it,
/// with its Jacobian written.
#[derive(Appell, Clone, Debug, Default)]
#[appell(joint(j[1], revolute(z), parent = N, child = link[1], actuated))]
#[appell(repeat(k in 2..=8,
    repeat(even in 0..1 - k % 2, joint(j[k], revolute(y), parent = link[k - 1], child = link[k], xyz = [0, 0, 0.5], actuated)),
    repeat(odd in 0..k % 2, joint(j[k], revolute(z), parent = link[k - 1], child = link[k], xyz = [0, 0, 0.5], actuated))))]
#[appell(repeat(k in 1..=8, body(link[k], frame = link[k], mass = 1 + 0.1 * k,
    center = origin(link[k]) + 0.05 * link[k].x + 0.02 * link[k].y + 0.25 * link[k].z,
    inertia = matrix(0.02 + 0.001 * k, 0.03 + 0.001 * k, 0.01 + 0.001 * k, 0.001, 0.0015, -0.002))))]
#[appell(gravity(-9.81 * N.z), jacobian(on))]
pub struct SpatialChain8Jacobian;

/// The 16-link spatial chain as `examples/models/spatial_chain.rs` has it,
/// with its Jacobian written.
#[derive(Appell, Clone, Debug, Default)]
#[appell(joint(j[1], revolute(z), parent = N, child = link[1], actuated))]
#[appell(repeat(k in 2..=16,
    repeat(even in 0..1 - k % 2, joint(j[k], revolute(y), parent = link[k - 1], child = link[k], xyz = [0, 0, 0.5], actuated)),
    repeat(odd in 0..k % 2, joint(j[k], revolute(z), parent = link[k - 1], child = link[k], xyz = [0, 0, 0.5], actuated))))]
#[appell(repeat(k in 1..=16, body(link[k], frame = link[k], mass = 1 + 0.1 * k,
    center = origin(link[k]) + 0.05 * link[k].x + 0.02 * link[k].y + 0.25 * link[k].z,
    inertia = matrix(0.02 + 0.001 * k, 0.03 + 0.001 * k, 0.01 + 0.001 * k, 0.001, 0.0015, -0.002))))]
#[appell(gravity(-9.81 * N.z), jacobian(on))]
pub struct SpatialChain16Jacobian;

/// The 32-link spatial chain as `examples/models/spatial_chain.rs` has it,
/// with its Jacobian written.
#[derive(Appell, Clone, Debug, Default)]
#[appell(joint(j[1], revolute(z), parent = N, child = link[1], actuated))]
#[appell(repeat(k in 2..=32,
    repeat(even in 0..1 - k % 2, joint(j[k], revolute(y), parent = link[k - 1], child = link[k], xyz = [0, 0, 0.5], actuated)),
    repeat(odd in 0..k % 2, joint(j[k], revolute(z), parent = link[k - 1], child = link[k], xyz = [0, 0, 0.5], actuated))))]
#[appell(repeat(k in 1..=32, body(link[k], frame = link[k], mass = 1 + 0.1 * k,
    center = origin(link[k]) + 0.05 * link[k].x + 0.02 * link[k].y + 0.25 * link[k].z,
    inertia = matrix(0.02 + 0.001 * k, 0.03 + 0.001 * k, 0.01 + 0.001 * k, 0.001, 0.0015, -0.002))))]
#[appell(gravity(-9.81 * N.z), jacobian(on))]
pub struct SpatialChain32Jacobian;

/// The 64-link spatial chain as `examples/models/spatial_chain.rs` has it,
/// with its Jacobian written.
#[cfg(feature = "large-models")]
#[derive(Appell, Clone, Debug, Default)]
#[appell(joint(j[1], revolute(z), parent = N, child = link[1], actuated))]
#[appell(repeat(k in 2..=64,
    repeat(even in 0..1 - k % 2, joint(j[k], revolute(y), parent = link[k - 1], child = link[k], xyz = [0, 0, 0.5], actuated)),
    repeat(odd in 0..k % 2, joint(j[k], revolute(z), parent = link[k - 1], child = link[k], xyz = [0, 0, 0.5], actuated))))]
#[appell(repeat(k in 1..=64, body(link[k], frame = link[k], mass = 1 + 0.1 * k,
    center = origin(link[k]) + 0.05 * link[k].x + 0.02 * link[k].y + 0.25 * link[k].z,
    inertia = matrix(0.02 + 0.001 * k, 0.03 + 0.001 * k, 0.01 + 0.001 * k, 0.001, 0.0015, -0.002))))]
#[appell(gravity(-9.81 * N.z), jacobian(on))]
pub struct SpatialChain64Jacobian;

/// Solo12 on a free base as `floating.rs` has it, with its Jacobian
/// written. Its A and B differentiate by the quaternion's four components
/// and the base's rates in the joint frame, not along Pinocchio's tangent:
/// timed, but their checksum is not compared with Pinocchio's.
#[derive(Appell, Clone, Debug, Default)]
#[appell(
    urdf("../../../tests/robots/solo/solo12.urdf", base = free),
    gravity(-9.81 * N.z),
    jacobian(on)
)]
pub struct Solo12Jacobian;
