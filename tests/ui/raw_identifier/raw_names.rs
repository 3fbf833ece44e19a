use appell::Appell;

// Raw identifiers cannot name what the generated code binds as locals or
// builds names from: a parameter, a coordinate, a scene.
#[derive(Appell)]
#[appell(coordinates(r#loop), speeds(r#loop))]
#[appell(point(P = O + l * sin(r#loop) * N.x), particle(P, mass = r#type))]
#[appell(gravity(-g * N.y), scene(r#ref, effects(gravity)))]
struct Raw {
    r#type: f64,
    l: f64,
    g: f64,
}

fn main() {}
