// `P[i - 1]` at i = 0 would be `P_-1`: indices start at 0.
use appell::Appell;

#[derive(Appell)]
#[appell(coordinates(q[0..3]), speeds(q[0..3]))]
#[appell(repeat(i in 0..3, point(P[i] = P[i - 1] + l * q[i] * N.x), particle(P[i], mass = m)))]
struct Chain {
    m: f64,
    l: f64,
}

fn main() {}
