//! A joint that moves no link with mass: the error names it, its line and
//! the option that fixes it.

use appell::Appell;

#[derive(Appell)]
#[appell(urdf("massless_leaf.urdf"))]
struct Robot;

fn main() {}
