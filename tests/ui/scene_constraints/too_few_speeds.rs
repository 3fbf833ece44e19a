use appell::Appell;

// A scene that leaves the grip out names too few speeds: its own
// derivation finds the rates undetermined and says so at its speeds.
#[derive(Appell)]
#[appell(coordinates(x, y, theta), speeds(x, theta))]
#[appell(frame(B = N.rotate_z(theta)))]
#[appell(point(P = O + x * N.x + y * N.y), point(C = P + b * B.x))]
#[appell(body(sleigh, center = C, frame = B, mass = m, inertia = principal(i0, i0, i0)))]
#[appell(nonholonomic(dt(y) * cos(theta) - dt(x) * sin(theta) == 0, effect = grip))]
#[appell(scene(short, effects(), speeds(x, theta)))]
pub struct Sleigh {
    m: f64,
    i0: f64,
    b: f64,
}

fn main() {}
