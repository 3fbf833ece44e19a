use appell::Appell;

// A misspelled function: a suggestion and the list of functions; an `if`
// without `else` and a condition that is not a comparison.
#[derive(Appell)]
#[appell(coordinates(x), speeds(x))]
#[appell(point(P = O + x * N.x), particle(P, mass = m))]
#[appell(force(P, -mu * sgn(dt(x)) * N.x))]
struct Friction {
    m: f64,
    mu: f64,
}

#[derive(Appell)]
#[appell(coordinates(x), speeds(x))]
#[appell(point(P = O + x * N.x), particle(P, mass = m))]
#[appell(force(P, (if x < 0 { -k * x }) * N.x))]
struct OneSided {
    m: f64,
    k: f64,
}

#[derive(Appell)]
#[appell(coordinates(x), speeds(x))]
#[appell(point(P = O + x * N.x), particle(P, mass = m))]
#[appell(force(P, (if x == 0 { k } else { 0 }) * N.x))]
struct Equal {
    m: f64,
    k: f64,
}

fn main() {}
