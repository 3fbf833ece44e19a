use appell::Appell;

// A point where a scalar is needed, and a constraint between a point and a
// scalar: each error says what to write instead.
#[derive(Appell)]
#[appell(coordinates(x, y), speeds(x))]
#[appell(point(P = O + x * N.x + y * N.y), particle(P, mass = P))]
#[appell(holonomic(P == l))]
struct Slider {
    m: f64,
    l: f64,
}

fn main() {}
