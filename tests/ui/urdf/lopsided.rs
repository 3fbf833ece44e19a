//! An inertia no rigid body has, alone and merged with a part fixed to its
//! link: each error names the link, its line and `unchecked_inertia`; a
//! link that option names must be one of the file.

use appell::Appell;

#[derive(Appell)]
#[appell(urdf("lopsided.urdf"), gravity(-9.81 * N.z))]
struct Alone;

#[derive(Appell)]
#[appell(urdf("lopsided_parts.urdf"), gravity(-9.81 * N.z))]
struct Merged;

#[derive(Appell)]
#[appell(urdf("lopsided.urdf", unchecked_inertia(arms)), gravity(-9.81 * N.z))]
struct Misspelled;

#[derive(Appell)]
#[appell(urdf("lopsided.urdf", mimic = no), gravity(-9.81 * N.z))]
struct BadMimic;

fn main() {}
