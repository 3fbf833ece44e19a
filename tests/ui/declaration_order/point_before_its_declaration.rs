use appell::Appell;

// P2 is located from P1, which is declared after it.
#[derive(Appell)]
#[appell(coordinates(q1, q2), speeds(q1, q2))]
#[appell(point(P2 = P1 + l * sin(q2) * N.x - l * cos(q2) * N.y))]
#[appell(point(P1 = O + l * sin(q1) * N.x - l * cos(q1) * N.y))]
#[appell(particle(P1, mass = m), particle(P2, mass = m))]
struct Pendulum {
    m: f64,
    l: f64,
}

fn main() {}
