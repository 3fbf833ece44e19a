use appell::Appell;

#[derive(Appell)]
#[appell(coordinates(q1, q2, q1), speeds(q1, q2))]
#[appell(point(P = O + l * sin(q1) * N.x), particle(P, mass = m))]
struct Chain {
    m: f64,
    l: f64,
}

fn main() {}
