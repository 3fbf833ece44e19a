use appell::Appell;

#[derive(Appell)]
#[appell(coordinates(q), speeds(q))]
#[appell(point(P = O + l * sin(q) * N.x), particle(P, mass = m))]
#[appell(jacobian(maybe))]
struct Pendulum {
    m: f64,
    l: f64,
}

fn main() {}
