use appell::Appell;

// `lock` on a ball joint and on a cylindrical one (each with what to
// write instead), a lock that is not an effect's name, a lock without its
// effect and a joint locked twice: each an error at the property.
#[derive(Appell)]
#[appell(joint(wrist, spherical, parent = N, child = B, lock = brake))]
#[appell(body(b, center = B_origin, frame = B, mass = 1, inertia = principal(1, 1, 1)))]
struct Ball;

#[derive(Appell)]
#[appell(joint(sleeve, cylindrical(z), parent = N, child = B, lock = brake))]
#[appell(body(b, center = B_origin, frame = B, mass = 1, inertia = principal(1, 1, 1)))]
struct Sleeve;

#[derive(Appell)]
#[appell(joint(elbow, revolute(z), parent = N, child = A, lock = brake.on))]
#[appell(body(a, center = A_origin + A.x, frame = A, mass = 1, inertia = principal(1, 1, 1)))]
struct Path;

#[derive(Appell)]
#[appell(joint(elbow, revolute(z), parent = N, child = A, lock))]
#[appell(body(a, center = A_origin + A.x, frame = A, mass = 1, inertia = principal(1, 1, 1)))]
struct Flag;

#[derive(Appell)]
#[appell(joint(slide, prismatic(x), parent = N, child = A, lock = brake, lock = clutch))]
#[appell(particle(A_origin, mass = 1))]
struct Twice;

fn main() {}
