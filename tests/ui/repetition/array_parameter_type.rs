// Parameters are `f64` or arrays of them with a literal length.
use appell::Appell;

const N: usize = 3;

#[derive(Appell)]
#[appell(coordinates(q), speeds(q), point(P = O + q * N.x), particle(P, mass = m[0]))]
struct Chain {
    m: [f64; N],
}

fn main() {}
