use appell::Appell;

#[derive(Appell)]
#[appell(coordinates(theta), speeds(theta))]
#[appell(frame(B = N.rotate_z(theta)))]
#[appell(body(rotor, center = O, frame = B, inertia = principal(i1, i1, i3)))]
struct Rotor {
    i1: f64,
    i3: f64,
}

fn main() {}
