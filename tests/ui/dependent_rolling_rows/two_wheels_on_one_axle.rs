use appell::Appell;

// Two wheels on one axle, each told to roll without slipping sideways: the
// two sideways rows say the same thing (the axle's centre does not slide
// along the axle), so the rows are dependent.
#[derive(Appell)]
#[appell(coordinates(x, y, phi, psi1, psi2), speeds(psi1, psi2))]
#[appell(frame(A = N.rotate_z(phi)), frame(W1 = A.rotate_y(psi1)), frame(W2 = A.rotate_y(psi2)))]
#[appell(point(C = O + x * N.x + y * N.y + a * N.z))]
#[appell(point(D1 = C + l * A.y), point(D2 = C - l * A.y))]
#[appell(point(P1 = D1 - a * N.z), point(P2 = D2 - a * N.z))]
#[appell(body(wheel1, center = D1, frame = W1, mass = m, inertia = principal(i, 2 * i, i)))]
#[appell(body(wheel2, center = D2, frame = W2, mass = m, inertia = principal(i, 2 * i, i)))]
#[appell(rolls(wheel1, contact = P1, along = [A.x, A.y]))]
#[appell(rolls(wheel2, contact = P2, along = [A.x, A.y]))]
struct Axle {
    a: f64,
    l: f64,
    m: f64,
    i: f64,
}

fn main() {}
