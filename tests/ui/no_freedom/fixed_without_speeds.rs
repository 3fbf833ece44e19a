use appell::Appell;

/// Two coordinates, two constraints, no `speeds(...)`: the derive says
/// there is nothing to name instead of asking for speeds.
#[derive(Appell)]
#[appell(coordinates(x, y))]
#[appell(point(P = O + x * N.x + y * N.y), particle(P, mass = m))]
#[appell(holonomic(x == l), holonomic(y == 2 * l))]
struct Pinned {
    m: f64,
    l: f64,
}

fn main() {}
