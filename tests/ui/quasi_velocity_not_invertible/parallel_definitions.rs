use appell::Appell;

// Two quasi-velocities along the same direction: with the knife-edge
// constraint they cannot determine the three coordinate rates.
#[derive(Appell)]
#[appell(coordinates(x, y, theta))]
#[appell(speeds(v = dt(x) * cos(theta) + dt(y) * sin(theta), v2 = 2 * dt(x) * cos(theta) + 2 * dt(y) * sin(theta)))]
#[appell(frame(B = N.rotate_z(theta)))]
#[appell(point(P = O + x * N.x + y * N.y))]
#[appell(body(sleigh, center = P, frame = B, mass = m, inertia = principal(i0, i0, i0)))]
#[appell(nonholonomic(dt(y) * cos(theta) - dt(x) * sin(theta) == 0))]
struct Sleigh {
    m: f64,
    i0: f64,
}

fn main() {}
