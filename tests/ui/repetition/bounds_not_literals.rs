// The number of links is fixed at compile time: a repeat's bounds are
// literals (or indices of enclosing repeats), never a parameter.
use appell::Appell;

#[derive(Appell)]
#[appell(coordinates(q[0..3]), speeds(q[0..3]), point(P[0] = O + l * q[0] * N.x))]
#[appell(repeat(i in 1..n, point(P[i] = P[i - 1] + l * q[i] * N.x), particle(P[i], mass = m)))]
struct Chain {
    m: f64,
    l: f64,
    n: f64,
}

fn main() {}
