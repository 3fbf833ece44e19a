use appell::Appell;

// A scene that leaves the grip out has a degree of freedom more and must
// name its speeds; another names a speed that is not a coordinate.
#[derive(Appell)]
#[appell(coordinates(x, y, theta), speeds(x, theta))]
#[appell(frame(B = N.rotate_z(theta)))]
#[appell(point(P = O + x * N.x + y * N.y), point(C = P + b * B.x))]
#[appell(body(sleigh, center = C, frame = B, mass = m, inertia = principal(i0, i0, i0)))]
#[appell(nonholonomic(dt(y) * cos(theta) - dt(x) * sin(theta) == 0, effect = grip))]
#[appell(scene(skidding, effects()))]
#[appell(scene(sliding, effects(), speeds(x, yy, theta)))]
pub struct Sleigh {
    m: f64,
    i0: f64,
    b: f64,
}

fn main() {}
