use appell::Appell;

#[derive(Appell)]
#[appell(coordinates(x), speeds(x))]
#[appell(point(P = O + x * N.x))]
#[appell(particle(Q, mass = m))]
struct Slider {
    m: f64,
}

fn main() {}
