use appell::Appell;

#[derive(Appell)]
#[appell(coordinates(x, y, theta), speeds(x, y, theta))]
#[appell(frame(B = N.rotate_z(theta)))]
#[appell(point(P = O + x * N.x + y * N.y))]
#[appell(body(sleigh, center = P, frame = B, mass = m, inertia = principal(i0, i0, i0)))]
#[appell(nonholonomic(dt(y) * cos(theta) == dt(x) * sin(theta)))]
struct Sleigh {
    m: f64,
    i0: f64,
}

fn main() {}
