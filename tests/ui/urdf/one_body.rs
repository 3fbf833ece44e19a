//! A robot of one rigid body on a fixed base moves nothing: the error
//! says to give it a base of its own.

use appell::Appell;

#[derive(Appell)]
#[appell(urdf("one_body.urdf"), gravity(-9.81 * N.z))]
struct Quadrotor;

fn main() {}
