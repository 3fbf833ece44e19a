//! Contacts written wrong, reported together: a link no joint made (with
//! the nearest name), and a scene whose contact has no joints above it to
//! give way (`kind.rs`: a kind that is neither `point` nor `flat`).

use appell::Appell;

#[derive(Appell)]
#[appell(urdf("../../data/one_leg.urdf", base = free), gravity(-9.81 * N.z))]
#[appell(contact(foto, point), contact(base, point, effect = sitting))]
#[appell(scene(sitting, effects(gravity, actuation, sitting)))]
struct OneLeg;

fn main() {}
