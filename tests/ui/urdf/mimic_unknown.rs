//! A mimic tag naming no joint of the file: the error names the joint, its
//! line, and `mimic = false`, with which Pinocchio's default reads it.

use appell::Appell;

#[derive(Appell)]
#[appell(urdf("mimic_unknown.urdf"))]
struct Hand;

/// The same file with mimic tags ignored compiles.
#[derive(Appell)]
#[appell(urdf("mimic_unknown.urdf", mimic = false))]
struct Fingers;

fn main() {
    let _ = Fingers;
}
