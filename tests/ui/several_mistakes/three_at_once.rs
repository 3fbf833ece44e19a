use appell::Appell;

// Three independent mistakes: all three are reported in one build.
#[derive(Appell)]
#[appell(coordinates(x, y), speeds(x, y))]
#[appell(point(P = O + x * N.x + y * N.y), particle(P, mass = mas))]
#[appell(force(P, -k * xx * N.x, effect = spring))]
#[appell(torque(B, k * N.z, effect = motor))]
struct Planar {
    mass: f64,
    k: f64,
}

fn main() {}
