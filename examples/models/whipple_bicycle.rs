//! The Whipple bicycle (Meijaard et al. 2007 benchmark) in Moore's 2012
//! formulation: eight coordinates, a holonomic constraint that fixes the
//! pitch, four rolling rows, three degrees of freedom.

use appell::Appell;

/// The benchmark bicycle: rear frame with rider C, rear wheel D, front frame
/// E (fork and handlebar), front wheel F; knife-edge wheels rolling without
/// slip on flat ground, z down. Coordinates: rear contact (q1, q2), yaw q3,
/// roll q4, pitch q5, rear wheel angle q6, steer q7, front wheel angle q8.
/// Privileged speeds: roll, rear wheel and steer rates; forward speed
/// v = −rr·q6'. Input: the rider's steer torque (effect `rider`). Scenes:
/// `WhippleBicycleCoasting` (gravity only, no input terms) and
/// `WhippleBicycleRidden` (gravity and steer torque).
#[derive(Appell, Clone, Debug, PartialEq)]
#[appell(coordinates(q1, q2, q3, q4, q5, q6, q7, q8), speeds(q4, q6, q7))]
#[appell(positive(rf, rr, mc, md, me, mf))]
#[appell(frame(A = N.rotate_z(q3)), frame(B = A.rotate_x(q4)), frame(C = B.rotate_y(q5)))]
#[appell(frame(D = C.rotate_y(q6)), frame(E = C.rotate_z(q7)), frame(F = E.rotate_y(q8)))]
#[appell(point(P = O + q1 * N.x + q2 * N.y), point(Do = P - rr * B.z))]
#[appell(point(Co = Do + l1 * C.x + l2 * C.z))]
#[appell(point(Fo = Do + d1 * C.x + d2 * E.z + d3 * E.x), point(Eo = Fo + l3 * E.x + l4 * E.z))]
#[appell(point(Q = Fo + rf * unit(cross(cross(E.y, A.z), E.y))))]
#[appell(body(rear_frame, center = Co, frame = C, mass = mc,
              inertia = matrix(ic11, ic22, ic33, 0, 0, ic31)))]
#[appell(body(rear_wheel, center = Do, frame = D, mass = md, inertia = principal(id11, id22, id11)))]
#[appell(body(front_frame, center = Eo, frame = E, mass = me,
              inertia = matrix(ie11, ie22, ie33, 0, 0, ie31)))]
#[appell(body(front_wheel, center = Fo, frame = F, mass = mf, inertia = principal(if11, if22, if11)))]
#[appell(holonomic(dot(Q - P, A.z) == 0))]
#[appell(rolls(rear_wheel, contact = P, along = [A.x, A.y]))]
#[appell(rolls(front_wheel, contact = Q, along = [A.x, A.y]))]
#[appell(gravity(g * N.z))]
// The rider's steer torque acts on the front frame about the steer axis, and
// back on the rear frame.
#[appell(inputs(steer_torque))]
#[appell(torque(E, steer_torque * C.z, effect = rider), torque(C, -steer_torque * C.z, effect = rider))]
// Scenes share effect names, which clippy's duplicated_attributes lint reads
// as duplicate attributes.
#[allow(clippy::duplicated_attributes)]
#[appell(scene(coasting, effects(gravity)))]
#[appell(scene(ridden, effects(gravity, rider)))]
// Its Jacobian (for the lean and steer eigenvalues) is larger than the
// derive writes by default.
#[appell(jacobian(on))]
pub struct WhippleBicycle {
    /// Front wheel radius [m].
    pub rf: f64,
    /// Rear wheel radius [m].
    pub rr: f64,
    /// Rear wheel centre to steer axis, along C.x [m].
    pub d1: f64,
    /// Along the steer axis between the offsets [m].
    pub d2: f64,
    /// Fork offset [m].
    pub d3: f64,
    /// Rear frame mass centre, C.x [m].
    pub l1: f64,
    /// Rear frame mass centre, C.z [m].
    pub l2: f64,
    /// Front frame mass centre, E.x [m].
    pub l3: f64,
    /// Front frame mass centre, E.z [m].
    pub l4: f64,
    /// Rear frame mass [kg].
    pub mc: f64,
    /// Rear wheel mass [kg].
    pub md: f64,
    /// Front frame mass [kg].
    pub me: f64,
    /// Front wheel mass [kg].
    pub mf: f64,
    /// Rear frame inertia [kg m²].
    pub ic11: f64,
    /// Rear frame inertia [kg m²].
    pub ic22: f64,
    /// Rear frame inertia [kg m²].
    pub ic33: f64,
    /// Rear frame inertia product [kg m²].
    pub ic31: f64,
    /// Rear wheel inertia about a diameter [kg m²].
    pub id11: f64,
    /// Rear wheel inertia about the axle [kg m²].
    pub id22: f64,
    /// Front frame inertia [kg m²].
    pub ie11: f64,
    /// Front frame inertia [kg m²].
    pub ie22: f64,
    /// Front frame inertia [kg m²].
    pub ie33: f64,
    /// Front frame inertia product [kg m²].
    pub ie31: f64,
    /// Front wheel inertia about a diameter [kg m²].
    pub if11: f64,
    /// Front wheel inertia about the axle [kg m²].
    pub if22: f64,
    /// Gravity, along +N.z [m/s²].
    pub g: f64,
}

impl Default for WhippleBicycle {
    /// The benchmark bicycle of Meijaard et al. (2007), converted to Moore's
    /// parameters.
    fn default() -> Self {
        WhippleBicycle {
            rf: 0.35,
            rr: 0.3,
            d1: 0.9534570696121849,
            d2: 0.2676445084476887,
            d3: 0.03207142672761929,
            l1: 0.4707271515135145,
            l2: -0.47792881146460797,
            l3: -0.00597083392418685,
            l4: -0.3699518200282974,
            mc: 85.0,
            md: 2.0,
            me: 4.0,
            mf: 3.0,
            ic11: 7.178169776497895,
            ic22: 11.0,
            ic33: 4.821830223502103,
            ic31: 3.8225535938357873,
            id11: 0.0603,
            id22: 0.12,
            ie11: 0.05841337700152972,
            ie22: 0.06,
            ie33: 0.007586622998470264,
            ie31: 0.009119225261946298,
            if11: 0.1405,
            if22: 0.28,
            g: 9.81,
        }
    }
}

/// Upright, straight-ahead running: roll and steer zero, the pitch solved
/// from the holonomic constraint (it equals the steer-axis tilt λ = π/10 for
/// the benchmark geometry).
pub fn operating_point(p: &WhippleBicycle) -> Result<[f64; 8], appell::linearize::LinearizeError> {
    let mut q = [0.0; 8];
    q[4] = std::f64::consts::PI / 10.0;
    appell::linearize::solve_holonomic(p, 0.0, &mut q, &[4], 1e-14, 30)?;
    Ok(q)
}

/// The lean and steer dynamics at forward speed `v` (the benchmark's
/// state [φ, δ, φ̇, δ̇] is our [q4, q7, q4', q7']): the reduced equations
/// linearized by their generated Jacobian, the pitch eliminated through the holonomic
/// constraint, the rear-wheel rate held at −v/rr.
pub fn lean_steer(
    p: &WhippleBicycle,
    v: f64,
) -> Result<appell::linearize::Linearization, appell::linearize::LinearizeError> {
    let q = operating_point(p)?;
    let u = [0.0, -v / p.rr, 0.0];
    appell::linearize::minimal_linearization(p, 0.0, &q, &u, &[0.0], &["q6"])
}

/// Eigenvalues (re, im) of the lean and steer dynamics at speed `v`.
pub fn eigenvalues(
    p: &WhippleBicycle,
    v: f64,
) -> Result<Vec<(f64, f64)>, appell::linearize::LinearizeError> {
    appell::linearize::eigenvalues(&lean_steer(p, v)?.a)
}

/// Largest real part among the oscillatory (weave) eigenvalues.
fn weave_growth(p: &WhippleBicycle, v: f64) -> Result<f64, appell::linearize::LinearizeError> {
    Ok(eigenvalues(p, v)?
        .iter()
        .filter(|e| e.1.abs() > 1e-9)
        .map(|e| e.0)
        .fold(f64::NEG_INFINITY, f64::max))
}

/// Largest real eigenvalue (the capsize mode between the critical speeds).
fn capsize_growth(p: &WhippleBicycle, v: f64) -> Result<f64, appell::linearize::LinearizeError> {
    Ok(eigenvalues(p, v)?
        .iter()
        .filter(|e| e.1.abs() <= 1e-9)
        .map(|e| e.0)
        .fold(f64::NEG_INFINITY, f64::max))
}

/// The root of `f` in `[lo, hi]` (a sign change) by bisection to 1e-13.
fn bisect(
    mut lo: f64,
    mut hi: f64,
    f: impl Fn(f64) -> Result<f64, appell::linearize::LinearizeError>,
) -> Result<f64, appell::linearize::LinearizeError> {
    let flo = f(lo)?;
    if flo.signum() == f(hi)?.signum() {
        return Err(appell::linearize::LinearizeError::InvalidArgument(format!(
            "no sign change in [{lo}, {hi}]"
        )));
    }
    while hi - lo > 1e-13 {
        let mid = 0.5 * (lo + hi);
        if f(mid)?.signum() == flo.signum() {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok(0.5 * (lo + hi))
}

/// The weave speed (the oscillatory pair becomes stable) and the capsize
/// speed (the real capsize eigenvalue becomes unstable), by root finding
/// between 3 and 5 m/s and between 5 and 8 m/s.
pub fn critical_speeds(
    p: &WhippleBicycle,
) -> Result<(f64, f64), appell::linearize::LinearizeError> {
    let weave = bisect(3.0, 5.0, |v| weave_growth(p, v))?;
    let capsize = bisect(5.0, 8.0, |v| capsize_growth(p, v))?;
    Ok((weave, capsize))
}
