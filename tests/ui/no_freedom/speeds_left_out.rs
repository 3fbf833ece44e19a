use appell::Appell;

/// A pendulum whose author forgot `speeds(...)`: the derive says how many
/// to name.
#[derive(Appell)]
#[appell(coordinates(theta))]
#[appell(point(P = O + l * sin(theta) * N.x - l * cos(theta) * N.y))]
#[appell(particle(P, mass = m), gravity(-g * N.y))]
struct Pendulum {
    m: f64,
    l: f64,
    g: f64,
}

fn main() {}
