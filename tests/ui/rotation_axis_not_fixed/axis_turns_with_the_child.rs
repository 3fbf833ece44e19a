use appell::Appell;

// B turns about an axis drawn with the unit vectors of C, a frame that
// itself turns relative to A: the axis is not fixed in A, so the angular
// velocity θ̇ (axis) would be wrong.
#[derive(Appell)]
#[appell(coordinates(psi, theta), speeds(psi, theta))]
#[appell(frame(A = N.rotate_z(psi)), frame(C = A.rotate_x(theta)))]
#[appell(frame(B = A.rotate(C.y + C.z, theta)))]
#[appell(point(P = O + l * B.x))]
#[appell(body(arm, center = P, frame = B, mass = m, inertia = principal(i0, i0, i0)))]
struct Arm {
    l: f64,
    m: f64,
    i0: f64,
}

fn main() {}
