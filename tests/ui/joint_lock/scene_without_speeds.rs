use appell::Appell;

// A scene without the lock's effect lets the elbow turn: it has one more
// degree of freedom than the model, so it names its speeds.
#[derive(Appell)]
#[appell(joint(shoulder, revolute(z), parent = N, child = L1))]
#[appell(joint(elbow, revolute(z), parent = L1, child = L2, xyz = [0.5, 0, 0], lock = brake))]
#[appell(body(upper, frame = L1, mass = 1, center = origin(L1) + 0.25 * L1.x, inertia = principal(0.01, 0.02, 0.02)))]
#[appell(body(lower, frame = L2, mass = 1, center = origin(L2) + 0.25 * L2.x, inertia = principal(0.01, 0.02, 0.02)))]
#[appell(scene(free, effects()))]
struct Arm;

fn main() {}
