use appell::Appell;

/// A bead on a wire held at one place: the constraint fixes the only
/// coordinate, so nothing moves.
#[derive(Appell)]
#[appell(coordinates(x), speeds(x))]
#[appell(point(P = O + x * N.x), particle(P, mass = m))]
#[appell(holonomic(x == l))]
struct Held {
    m: f64,
    l: f64,
}

fn main() {}
