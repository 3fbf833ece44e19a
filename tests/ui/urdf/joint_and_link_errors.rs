//! A relative path is looked for from the crate's manifest directory,
//! then from this file's directory, so the case passes wherever cargo
//! puts its output.
//!
//! A joint whose parent link is unknown and a link of negative mass: both
//! are reported in one build.

use appell::Appell;

#[derive(Appell)]
#[appell(urdf("joint_and_link_errors.urdf"))]
struct Robot;

fn main() {}
