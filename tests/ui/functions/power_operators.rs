use appell::Appell;

// `^` and `**` are not powers in Rust's syntax: the errors point to powi/powf.
#[derive(Appell)]
#[appell(coordinates(x), speeds(x))]
#[appell(point(P = O + x * N.x), particle(P, mass = m))]
#[appell(force(P, -k * x^3 * N.x))]
struct Stiffening {
    m: f64,
    k: f64,
}

#[derive(Appell)]
#[appell(coordinates(x), speeds(x))]
#[appell(point(P = O + x * N.x), particle(P, mass = m))]
#[appell(force(P, -k * x**3 * N.x))]
struct Stiffening2 {
    m: f64,
    k: f64,
}

fn main() {}
