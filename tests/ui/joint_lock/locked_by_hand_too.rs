use appell::Appell;

// The lock already holds the elbow still where `brake` acts: the same
// constraint written again by hand is a second, dependent row (the later
// row is the one reported).
#[derive(Appell)]
#[appell(joint(shoulder, revolute(z), parent = N, child = L1))]
#[appell(joint(elbow, revolute(z), parent = L1, child = L2, xyz = [0.5, 0, 0], lock = brake))]
#[appell(body(upper, frame = L1, mass = 1, center = origin(L1) + 0.25 * L1.x, inertia = principal(0.01, 0.02, 0.02)))]
#[appell(body(lower, frame = L2, mass = 1, center = origin(L2) + 0.25 * L2.x, inertia = principal(0.01, 0.02, 0.02)))]
#[appell(nonholonomic(dt(elbow) == 0, effect = brake))]
#[appell(scene(free, effects(), speeds(shoulder, elbow)))]
struct Arm;

// A holonomic constraint fixes the elbow already, and its row comes
// before the lock's: the lock is the dependent row.
#[derive(Appell)]
#[appell(joint(shoulder, revolute(z), parent = N, child = L1))]
#[appell(joint(elbow, revolute(z), parent = L1, child = L2, xyz = [0.5, 0, 0], lock = brake))]
#[appell(body(upper, frame = L1, mass = 1, center = origin(L1) + 0.25 * L1.x, inertia = principal(0.01, 0.02, 0.02)))]
#[appell(body(lower, frame = L2, mass = 1, center = origin(L2) + 0.25 * L2.x, inertia = principal(0.01, 0.02, 0.02)))]
#[appell(holonomic(elbow == 0.3))]
struct Fixed;

fn main() {}
