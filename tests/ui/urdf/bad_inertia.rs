//! A relative path is looked for from the crate's manifest directory,
//! then from this file's directory, so the case passes wherever cargo
//! puts its output.

use appell::Appell;

#[derive(Appell)]
#[appell(urdf("bad_inertia.urdf"))]
struct Robot;

fn main() {}
