use appell::Appell;

/// A point placed by a division whose divisor is written as zero.
#[derive(Appell)]
#[appell(coordinates(x), speeds(x))]
#[appell(point(P = O + x * N.x + (l / (2 - 2)) * N.y), particle(P, mass = m))]
struct Slider {
    m: f64,
    l: f64,
}

fn main() {}
