use appell::Appell;

// q1 and q2 are both privileged, yet a holonomic constraint ties them.
#[derive(Appell)]
#[appell(coordinates(q1, q2, s, w), speeds(q1, q2))]
#[appell(point(P = O + l * sin(q1) * N.x - l * cos(q1) * N.y + s * N.z + w * N.x), particle(P, mass = m))]
#[appell(holonomic(q1 == 2 * q2))]
#[appell(nonholonomic(dt(s) == dt(q1) + dt(w)))]
struct Tied {
    m: f64,
    l: f64,
}

fn main() {}
