use appell::Appell;

// The scene names an effect no load declares; the scene type still exists,
// so only that mistake is reported.
#[derive(Appell)]
#[appell(coordinates(x), speeds(x))]
#[appell(point(P = O + x * N.x), particle(P, mass = m))]
#[appell(force(P, -k * x * N.x, effect = spring))]
#[appell(scene(quiet, effects(sprng)))]
pub struct Oscillator {
    m: f64,
    k: f64,
}

fn main() {
    let _scene: Option<OscillatorQuiet> = None;
}
