//! A contact is `point` or `flat`.

use appell::Appell;

#[derive(Appell)]
#[appell(urdf("../../data/one_leg.urdf", base = free), gravity(-9.81 * N.z))]
#[appell(contact(foot, pointy))]
struct OneLeg;

fn main() {}
