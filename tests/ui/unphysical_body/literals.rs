use appell::Appell;

// A negative mass, principal moments that break the triangle inequality and
// a matrix inertia that is not positive definite: all three reported.
#[derive(Appell)]
#[appell(coordinates(theta, phi, psi), speeds(theta, phi, psi))]
#[appell(frame(A = N.rotate_z(theta)), frame(B = N.rotate_x(phi)), frame(C = N.rotate_y(psi)))]
#[appell(body(a, center = O, frame = A, mass = -2.0, inertia = principal(1, 1, 1)))]
#[appell(body(b, center = O, frame = B, mass = 1, inertia = principal(1, 1, 5)))]
#[appell(body(c, center = O, frame = C, mass = 1, inertia = matrix(1, 1, 1, 2, 0, 0)))]
struct Unphysical;

fn main() {}
