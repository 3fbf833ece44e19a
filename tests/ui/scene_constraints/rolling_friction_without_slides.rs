use appell::Appell;

// The friction a rolling contact slides with needs the effect it belongs
// to; and only a rigid body slides at a rolling contact.
#[derive(Appell)]
#[appell(coordinates(x, theta), speeds(theta))]
#[appell(frame(B = N.rotate_z(theta)))]
#[appell(point(C = O + x * N.x + r * N.y), point(P = O + x * N.x))]
#[appell(body(disc, center = C, frame = B, mass = m, inertia = principal(i0, i0, i0)))]
#[appell(rolls(disc, contact = P, effect = rolling, mu = mu, normal = m * g))]
pub struct Disc {
    m: f64,
    r: f64,
    i0: f64,
    g: f64,
    mu: f64,
}

#[derive(Appell)]
#[appell(coordinates(x, y), speeds(x))]
#[appell(point(P = O + x * N.x + y * N.y), particle(P, mass = m))]
#[appell(rolls(P, contact = P, effect = rolling, slides = sliding, mu = mu, normal = m * g))]
pub struct Bead {
    m: f64,
    g: f64,
    mu: f64,
}

// Sliding friction on a rolling contact that no scene can drop, and a
// friction property given twice.
#[derive(Appell)]
#[appell(coordinates(x, theta), speeds(theta))]
#[appell(frame(B = N.rotate_z(theta)))]
#[appell(point(C = O + x * N.x + r * N.y), point(P = O + x * N.x))]
#[appell(body(disc, center = C, frame = B, mass = m, inertia = principal(i0, i0, i0)))]
#[appell(rolls(disc, contact = P, slides = sliding, mu = mu, normal = m * g))]
pub struct Always {
    m: f64,
    r: f64,
    i0: f64,
    g: f64,
    mu: f64,
}

#[derive(Appell)]
#[appell(coordinates(x, theta), speeds(theta))]
#[appell(frame(B = N.rotate_z(theta)))]
#[appell(point(C = O + x * N.x + r * N.y), point(P = O + x * N.x))]
#[appell(body(disc, center = C, frame = B, mass = m, inertia = principal(i0, i0, i0)))]
#[appell(rolls(disc, contact = P, effect = rolling, slides = sliding, mu = mu, mu = 2.0 * mu, normal = m * g))]
pub struct Twice {
    m: f64,
    r: f64,
    i0: f64,
    g: f64,
    mu: f64,
}

fn main() {}
