use appell::Appell;

// The constraint relates x and theta only; choosing x and theta as the
// privileged speeds leaves y's rate undetermined.
#[derive(Appell)]
#[appell(coordinates(x, y, theta), speeds(x, theta))]
#[appell(frame(B = N.rotate_z(theta)))]
#[appell(point(P = O + x * N.x + y * N.y))]
#[appell(body(disk, center = P, frame = B, mass = m, inertia = principal(i0, i0, i0)))]
#[appell(nonholonomic(dt(x) == r * dt(theta)))]
struct Roller {
    m: f64,
    i0: f64,
    r: f64,
}

fn main() {}
