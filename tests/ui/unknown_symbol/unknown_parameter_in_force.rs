use appell::Appell;

#[derive(Appell)]
#[appell(coordinates(x), speeds(x))]
#[appell(point(P = O + x * N.x), particle(P, mass = m))]
#[appell(force(P, -stiffnes * x * N.x, effect = spring))]
struct Oscillator {
    m: f64,
    stiffness: f64,
}

fn main() {}
