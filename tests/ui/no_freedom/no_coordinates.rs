use appell::Appell;

/// A particle fixed in space: no coordinate at all.
#[derive(Appell)]
#[appell(point(P = O + l * N.x), particle(P, mass = m))]
struct Still {
    m: f64,
    l: f64,
}

fn main() {}
