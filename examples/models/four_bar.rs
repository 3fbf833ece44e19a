//! IFToMM benchmark A02: the N-four-bar mechanism for N = 2, whose
//! parallelogram passes through singular positions (every crank
//! horizontal), where the reduced equations' dependent block loses rank.

use appell::Appell;

/// IFToMM A02 with N = 2: cranks 0..2 pinned at (i, 0) with absolute angles
/// `t0..t2`, couplers 1..2 with angles `f1, f2` joining the crank tips; every
/// link a uniform 1 m, 1 kg rod (1/12 kg m² about its centre); the loops are
/// closed by holonomic constraints, the crank angle `t0` is the privileged
/// coordinate.
#[derive(Appell, Clone, Debug)]
#[appell(coordinates(t0, t1, t2, f1, f2), speeds(t0))]
#[appell(frame(C0 = N.rotate_z(t0)), frame(C1 = N.rotate_z(t1)), frame(C2 = N.rotate_z(t2)))]
#[appell(frame(K1 = N.rotate_z(f1)), frame(K2 = N.rotate_z(f2)))]
#[appell(point(A1 = O + a * N.x), point(A2 = A1 + a * N.x))]
#[appell(point(B0 = O + a * C0.x), point(B1 = A1 + a * C1.x), point(B2 = A2 + a * C2.x))]
#[appell(point(G0 = O + a / 2 * C0.x), point(G1 = A1 + a / 2 * C1.x), point(G2 = A2 + a / 2 * C2.x))]
#[appell(point(H1 = B0 + a / 2 * K1.x), point(H2 = B1 + a / 2 * K2.x))]
#[appell(body(crank0, center = G0, frame = C0, mass = m, inertia = principal(0, m * a * a / 12, m * a * a / 12)))]
#[appell(body(crank1, center = G1, frame = C1, mass = m, inertia = principal(0, m * a * a / 12, m * a * a / 12)))]
#[appell(body(crank2, center = G2, frame = C2, mass = m, inertia = principal(0, m * a * a / 12, m * a * a / 12)))]
#[appell(body(coupler1, center = H1, frame = K1, mass = m, inertia = principal(0, m * a * a / 12, m * a * a / 12)))]
#[appell(body(coupler2, center = H2, frame = K2, mass = m, inertia = principal(0, m * a * a / 12, m * a * a / 12)))]
#[appell(holonomic(dot(B0 + a * K1.x - B1, N.x) == 0), holonomic(dot(B0 + a * K1.x - B1, N.y) == 0))]
#[appell(holonomic(dot(B1 + a * K2.x - B2, N.x) == 0), holonomic(dot(B1 + a * K2.x - B2, N.y) == 0))]
#[appell(gravity(-g * N.y))]
pub struct FourBar2 {
    /// Link length [m].
    pub a: f64,
    /// Link mass [kg].
    pub m: f64,
    /// Gravity [m/s²].
    pub g: f64,
}
