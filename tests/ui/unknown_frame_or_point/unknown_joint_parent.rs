use appell::Appell;

/// The elbow's parent is misspelled: the frame is unknown, not "not made by
/// a joint".
#[derive(Appell)]
#[appell(joint(shoulder, revolute(z), parent = N, child = L1))]
#[appell(joint(elbow, revolute(z), parent = L, child = L2, xyz = [0.5, 0, 0]))]
#[appell(body(link1, center = origin(L1), frame = L1, mass = 1, inertia = principal(1, 1, 1)))]
#[appell(body(link2, center = origin(L2), frame = L2, mass = 1, inertia = principal(1, 1, 1)))]
struct Arm;

fn main() {}
