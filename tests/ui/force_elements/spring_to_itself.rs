use appell::Appell;

// A spring and a damper from a point to itself have no direction.
#[derive(Appell)]
#[appell(coordinates(x), speeds(x))]
#[appell(point(P = O + x * N.x), particle(P, mass = m))]
#[appell(spring(P, P, stiffness = k))]
#[appell(damper(P, P, damping = 0.1))]
struct Block {
    m: f64,
    k: f64,
}

fn main() {}
