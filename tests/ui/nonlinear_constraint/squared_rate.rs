use appell::Appell;

#[derive(Appell)]
#[appell(coordinates(x, y), speeds(x))]
#[appell(point(P = O + x * N.x + y * N.y), particle(P, mass = m))]
#[appell(nonholonomic(dt(y) * dt(y) == dt(x)))]
struct Skate {
    m: f64,
}

fn main() {}
