use appell::Appell;

// Scene outputs: an unknown name lists the available ones; `energies` takes
// no arguments; `contact_forces` needs constraints. All three are reported.
#[derive(Appell)]
#[appell(coordinates(x), speeds(x))]
#[appell(point(P = O + x * N.x), particle(P, mass = m))]
#[appell(force(P, -k * x * N.x, effect = spring))]
#[appell(scene(a, effects(spring), outputs(contact_force)))]
#[appell(scene(b, effects(spring), outputs(energies(x))))]
#[appell(scene(c, effects(spring), outputs(contact_forces)))]
pub struct Oscillator {
    m: f64,
    k: f64,
}

fn main() {}
