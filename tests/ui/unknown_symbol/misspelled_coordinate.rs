use appell::Appell;

#[derive(Appell)]
#[appell(coordinates(theta), speeds(theta))]
#[appell(point(P = O + l * sin(theat) * N.x - l * cos(theta) * N.y))]
#[appell(particle(P, mass = m), gravity(-g * N.y))]
struct Pendulum {
    m: f64,
    l: f64,
    g: f64,
}

fn main() {}
