//! A relative path is looked for from the crate's manifest directory,
//! then from this file's directory, so the case passes wherever cargo
//! puts its output.
//!
//! A joint of unknown type and a link `urdf-rs` cannot read: both are
//! reported in one build.

use appell::Appell;

#[derive(Appell)]
#[appell(urdf("bad_type_and_bad_element.urdf"))]
struct Robot;

fn main() {}
