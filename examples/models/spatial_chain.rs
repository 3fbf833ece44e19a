//! The n-link spatial chain for n = 2, 4, 8, 16, 32 (64 with the cargo
//! feature `large-models`): revolute joints `j_1` ... `j_n` about z for odd k and y
//! for even k, each link's mass centre off its axis and its inertia matrix
//! full. The same mechanism as `examples/robots/spatial_chain/*.urdf`
//! (written by `make_urdf.py`), here written with `joint(...)` and
//! `repeat(...)`: changing n is one edit of the literal.
//!
//! Joint `j_k` turns link k (frame `link_k`, origin point `link_k_origin`)
//! relative to link k − 1 (N for k = 1), its origin 0.5 m along the parent's
//! z for k > 1. The axis alternates by two nested repeats whose ranges hold
//! one index or none with the parity of k. Link k's mass centre is at
//! (0.05, 0.02, 0.25) in its frame, its mass 1 + 0.1 k, its central inertia
//! ixx = 0.02 + 0.001 k, iyy = 0.03 + 0.001 k, izz = 0.01 + 0.001 k,
//! ixy = 0.001, iyz = 0.0015, ixz = −0.002. Each joint is driven by the
//! torque `tau_j_k`; gravity 9.81 m/s² along −z.

use appell::Appell;

/// Two links.
#[derive(Appell, Clone, Debug, Default, PartialEq)]
#[appell(joint(j[1], revolute(z), parent = N, child = link[1], actuated))]
#[appell(repeat(k in 2..=2,
    repeat(even in 0..1 - k % 2, joint(j[k], revolute(y), parent = link[k - 1], child = link[k], xyz = [0, 0, 0.5], actuated)),
    repeat(odd in 0..k % 2, joint(j[k], revolute(z), parent = link[k - 1], child = link[k], xyz = [0, 0, 0.5], actuated))))]
#[appell(repeat(k in 1..=2, body(link[k], frame = link[k], mass = 1 + 0.1 * k,
    center = origin(link[k]) + 0.05 * link[k].x + 0.02 * link[k].y + 0.25 * link[k].z,
    inertia = matrix(0.02 + 0.001 * k, 0.03 + 0.001 * k, 0.01 + 0.001 * k, 0.001, 0.0015, -0.002))))]
#[appell(gravity(-9.81 * N.z))]
pub struct SpatialChain2;

/// Four links.
#[derive(Appell, Clone, Debug, Default, PartialEq)]
#[appell(joint(j[1], revolute(z), parent = N, child = link[1], actuated))]
#[appell(repeat(k in 2..=4,
    repeat(even in 0..1 - k % 2, joint(j[k], revolute(y), parent = link[k - 1], child = link[k], xyz = [0, 0, 0.5], actuated)),
    repeat(odd in 0..k % 2, joint(j[k], revolute(z), parent = link[k - 1], child = link[k], xyz = [0, 0, 0.5], actuated))))]
#[appell(repeat(k in 1..=4, body(link[k], frame = link[k], mass = 1 + 0.1 * k,
    center = origin(link[k]) + 0.05 * link[k].x + 0.02 * link[k].y + 0.25 * link[k].z,
    inertia = matrix(0.02 + 0.001 * k, 0.03 + 0.001 * k, 0.01 + 0.001 * k, 0.001, 0.0015, -0.002))))]
#[appell(gravity(-9.81 * N.z))]
pub struct SpatialChain4;

/// Eight links.
#[derive(Appell, Clone, Debug, Default, PartialEq)]
#[appell(joint(j[1], revolute(z), parent = N, child = link[1], actuated))]
#[appell(repeat(k in 2..=8,
    repeat(even in 0..1 - k % 2, joint(j[k], revolute(y), parent = link[k - 1], child = link[k], xyz = [0, 0, 0.5], actuated)),
    repeat(odd in 0..k % 2, joint(j[k], revolute(z), parent = link[k - 1], child = link[k], xyz = [0, 0, 0.5], actuated))))]
#[appell(repeat(k in 1..=8, body(link[k], frame = link[k], mass = 1 + 0.1 * k,
    center = origin(link[k]) + 0.05 * link[k].x + 0.02 * link[k].y + 0.25 * link[k].z,
    inertia = matrix(0.02 + 0.001 * k, 0.03 + 0.001 * k, 0.01 + 0.001 * k, 0.001, 0.0015, -0.002))))]
#[appell(gravity(-9.81 * N.z))]
pub struct SpatialChain8;

/// Sixteen links.
#[derive(Appell, Clone, Debug, Default, PartialEq)]
#[appell(joint(j[1], revolute(z), parent = N, child = link[1], actuated))]
#[appell(repeat(k in 2..=16,
    repeat(even in 0..1 - k % 2, joint(j[k], revolute(y), parent = link[k - 1], child = link[k], xyz = [0, 0, 0.5], actuated)),
    repeat(odd in 0..k % 2, joint(j[k], revolute(z), parent = link[k - 1], child = link[k], xyz = [0, 0, 0.5], actuated))))]
#[appell(repeat(k in 1..=16, body(link[k], frame = link[k], mass = 1 + 0.1 * k,
    center = origin(link[k]) + 0.05 * link[k].x + 0.02 * link[k].y + 0.25 * link[k].z,
    inertia = matrix(0.02 + 0.001 * k, 0.03 + 0.001 * k, 0.01 + 0.001 * k, 0.001, 0.0015, -0.002))))]
#[appell(gravity(-9.81 * N.z))]
pub struct SpatialChain16;

/// Thirty-two links (the structured form only: see `info().form`).
#[derive(Appell, Clone, Debug, Default, PartialEq)]
#[appell(joint(j[1], revolute(z), parent = N, child = link[1], actuated))]
#[appell(repeat(k in 2..=32,
    repeat(even in 0..1 - k % 2, joint(j[k], revolute(y), parent = link[k - 1], child = link[k], xyz = [0, 0, 0.5], actuated)),
    repeat(odd in 0..k % 2, joint(j[k], revolute(z), parent = link[k - 1], child = link[k], xyz = [0, 0, 0.5], actuated))))]
#[appell(repeat(k in 1..=32, body(link[k], frame = link[k], mass = 1 + 0.1 * k,
    center = origin(link[k]) + 0.05 * link[k].x + 0.02 * link[k].y + 0.25 * link[k].z,
    inertia = matrix(0.02 + 0.001 * k, 0.03 + 0.001 * k, 0.01 + 0.001 * k, 0.001, 0.0015, -0.002))))]
#[appell(gravity(-9.81 * N.z))]
pub struct SpatialChain32;

/// Sixty-four links: behind the feature `large-models` (a release build
/// of its expansion takes about a minute).
#[cfg(feature = "large-models")]
#[derive(Appell, Clone, Debug, Default, PartialEq)]
#[appell(joint(j[1], revolute(z), parent = N, child = link[1], actuated))]
#[appell(repeat(k in 2..=64,
    repeat(even in 0..1 - k % 2, joint(j[k], revolute(y), parent = link[k - 1], child = link[k], xyz = [0, 0, 0.5], actuated)),
    repeat(odd in 0..k % 2, joint(j[k], revolute(z), parent = link[k - 1], child = link[k], xyz = [0, 0, 0.5], actuated))))]
#[appell(repeat(k in 1..=64, body(link[k], frame = link[k], mass = 1 + 0.1 * k,
    center = origin(link[k]) + 0.05 * link[k].x + 0.02 * link[k].y + 0.25 * link[k].z,
    inertia = matrix(0.02 + 0.001 * k, 0.03 + 0.001 * k, 0.01 + 0.001 * k, 0.001, 0.0015, -0.002))))]
#[appell(gravity(-9.81 * N.z))]
pub struct SpatialChain64;
