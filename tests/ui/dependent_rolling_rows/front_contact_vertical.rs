use appell::Appell;

// A disc rolling on a plane while also constrained to keep its contact on
// the plane by a holonomic constraint: the vertical rolling row is the time
// derivative of the holonomic one, so the rows are dependent.
#[derive(Appell)]
#[appell(coordinates(yaw, lean, spin, x, y, z), speeds(yaw, lean, spin))]
#[appell(frame(A = N.rotate_z(yaw)), frame(B = A.rotate_x(lean)), frame(C = B.rotate_y(spin)))]
#[appell(point(D = O + x * N.x + y * N.y + z * N.z), point(P = D - r * B.z))]
#[appell(body(disc, center = D, frame = C, mass = m, inertia = principal(i1, i2, i1)))]
#[appell(holonomic(dot(P - O, N.z) == 0))]
#[appell(rolls(disc, contact = P, along = [N.x, N.y, N.z]))]
struct Disc {
    r: f64,
    m: f64,
    i1: f64,
    i2: f64,
}

fn main() {}
