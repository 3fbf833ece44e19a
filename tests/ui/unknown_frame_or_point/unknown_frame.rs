use appell::Appell;

#[derive(Appell)]
#[appell(coordinates(phi, psi), speeds(phi, psi))]
#[appell(frame(A = N.rotate_z(phi)), frame(W = Aa.rotate_y(psi)))]
#[appell(body(wheel, center = O, frame = W, mass = m, inertia = principal(i1, i2, i1)))]
struct Wheel {
    m: f64,
    i1: f64,
    i2: f64,
}

fn main() {}
