use appell::Appell;

// An input may drive a constraint, not a quasi-velocity's definition.
#[derive(Appell)]
#[appell(coordinates(x, y), speeds(v = dt(x) - w))]
#[appell(point(P = O + x * N.x + y * N.y), particle(P, mass = m))]
#[appell(nonholonomic(dt(y) == w), inputs(w))]
struct Slider {
    m: f64,
}

fn main() {}
