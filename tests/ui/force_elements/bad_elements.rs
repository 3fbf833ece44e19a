use appell::Appell;

// A spring given two laws, a friction without its normal force, a damper
// without damping, a saturation without actuation and a spring on a ball
// joint: each an error at its item.
#[derive(Appell)]
#[appell(coordinates(x), speeds(x))]
#[appell(point(P = O + x * N.x), particle(P, mass = m))]
#[appell(spring(O, P, stiffness = k, tension = 3))]
#[appell(friction(P, mu = 0.3))]
#[appell(damper(O, P, stiffness = k))]
struct Block {
    m: f64,
    k: f64,
}

#[derive(Appell)]
#[appell(joint(elbow, revolute(z), parent = N, child = A, saturation = 2))]
#[appell(joint(wrist, spherical, parent = A, child = B, stiffness = 3))]
#[appell(body(b, center = B_origin, frame = B, mass = 1, inertia = principal(1, 1, 1)))]
struct Arm;

fn main() {}
