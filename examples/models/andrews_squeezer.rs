//! Andrews' squeezer mechanism: the seven-body planar mechanism of the IVP
//! Test Set (problem "andrews"; Hairer & Wanner, *Solving Ordinary
//! Differential Equations II*, Sec. VII.7; Schiehlen's multibody benchmarks),
//! driven by a constant torque on its crank against a spring.
//!
//! Source of every number: the IVP Test Set's `andrews.f` (revision 1.2,
//! 2006/10/02), as carried by the R package deTestSet in repository
//! `rforge/bvpsolve`: the equations in `pkg/deTestSet/src/Ex_andrews.f`
//! (subroutine `andfunc`), the parameter values and the initial values in
//! `pkg/deTestSet/R/ex_andrews.R`, the reference solution at t = 0.03 s in
//! `Ex_andrews.f` (subroutine `andsoln`; kept in
//! `tests/reference/andrews/andrews.txt`).
//!
//! The Test Set writes the equations in the seven angles with a 7×7 mass
//! matrix and six constraints g(q) = 0; here the mechanism is described by
//! its geometry and the derive forms the equations. The body geometry below
//! was read off the Test Set's formulas: the constraint rows fix where the
//! joints are, the mass-matrix entries where the mass centres are.
//! `tests/hard_cases/cases.rs` (`andrews_squeezer`) checks the model's
//! full-coordinate M, forcing and constraint Jacobian against the Test
//! Set's and integrates to the published reference at t = 0.03 s.

use appell::Appell;

/// Declares the squeezer as a model named `$name` whose privileged speed is
/// the rate of the angle `$speed` (the other six rates are dependent), with
/// the Test Set's parameter values as its `Default`. The mechanism is the
/// same whichever rate is privileged; the choice decides where the
/// dependent block D′ is singular (see `docs/hard-cases.md`).
macro_rules! squeezer {
    ($(#[$doc:meta])* $name:ident, speed = $speed:ident) => {
        $(#[$doc])*
        #[derive(Appell, Clone, Debug, PartialEq)]
        #[appell(
            coordinates(beta, theta, gamma, phi, delta, omega, epsilon),
            speeds($speed)
        )]
        #[appell(frame(K1 = N.rotate_z(beta)), frame(K2 = K1.rotate_z(theta)))]
        #[appell(frame(K3 = N.rotate_z(gamma)))]
        #[appell(frame(K5 = N.rotate_z(delta)), frame(K4 = K5.rotate_z(phi)))]
        #[appell(frame(K7 = N.rotate_z(epsilon)), frame(K6 = K7.rotate_z(omega)))]
        #[appell(
            point(A = O + xa * N.x + ya * N.y),
            point(B = O + xb * N.x + yb * N.y),
            point(C = O + xc * N.x + yc * N.y)
        )]
        #[appell(point(P = O + rr * K1.x), point(E2 = P - d * K2.x))]
        #[appell(point(E3 = B - ss * K3.y), point(D = B + sd * K3.x - sc * K3.y))]
        #[appell(point(Q = A + zt * K5.x), point(E4 = Q - e * K4.y))]
        #[appell(point(G = A - u * K7.y), point(E6 = G + zf * K6.x))]
        #[appell(
            point(S1 = O + ra * K1.x),
            point(S2 = P - da * K2.x),
            point(S3 = B + sb * K3.x - sa * K3.y),
            point(S4 = Q - (e - ea) * K4.y),
            point(S5 = A + ta * K5.x + tb * K5.y),
            point(S6 = G + (zf - fa) * K6.x),
            point(S7 = A + ub * K7.x - ua * K7.y)
        )]
        #[appell(
            body(crank, center = S1, frame = K1, mass = m1, inertia = principal(i1 / 2, i1 / 2, i1)),
            body(body2, center = S2, frame = K2, mass = m2, inertia = principal(i2 / 2, i2 / 2, i2)),
            body(body3, center = S3, frame = K3, mass = m3, inertia = principal(i3 / 2, i3 / 2, i3)),
            body(body4, center = S4, frame = K4, mass = m4, inertia = principal(i4 / 2, i4 / 2, i4)),
            body(body5, center = S5, frame = K5, mass = m5, inertia = principal(i5 / 2, i5 / 2, i5)),
            body(body6, center = S6, frame = K6, mass = m6, inertia = principal(i6 / 2, i6 / 2, i6)),
            body(body7, center = S7, frame = K7, mass = m7, inertia = principal(i7 / 2, i7 / 2, i7))
        )]
        #[appell(holonomic(E2 == E3), holonomic(E2 == E4), holonomic(E2 == E6))]
        #[appell(
            torque(K1, mom * N.z, effect = drive),
            force(D, -c0 * (norm(D - C) - lo) / norm(D - C) * (D - C), effect = spring)
        )]
        pub struct $name {
            /// Mass of body 1, the crank [kg].
            pub m1: f64,
            /// Mass of body 2 [kg].
            pub m2: f64,
            /// Mass of body 3 [kg].
            pub m3: f64,
            /// Mass of body 4 [kg].
            pub m4: f64,
            /// Mass of body 5 [kg].
            pub m5: f64,
            /// Mass of body 6 [kg].
            pub m6: f64,
            /// Mass of body 7 [kg].
            pub m7: f64,
            /// Central moment of inertia of body 1 about the normal [kg m²].
            pub i1: f64,
            /// Central moment of inertia of body 2 [kg m²].
            pub i2: f64,
            /// Central moment of inertia of body 3 [kg m²].
            pub i3: f64,
            /// Central moment of inertia of body 4 [kg m²].
            pub i4: f64,
            /// Central moment of inertia of body 5 [kg m²].
            pub i5: f64,
            /// Central moment of inertia of body 6 [kg m²].
            pub i6: f64,
            /// Central moment of inertia of body 7 [kg m²].
            pub i7: f64,
            /// x of the fixed pivot A of bodies 5 and 7 [m].
            pub xa: f64,
            /// y of A [m].
            pub ya: f64,
            /// x of the fixed pivot B of body 3 [m].
            pub xb: f64,
            /// y of B [m].
            pub yb: f64,
            /// x of the spring's fixed end C [m].
            pub xc: f64,
            /// y of C [m].
            pub yc: f64,
            /// Spring stiffness [N/m].
            pub c0: f64,
            /// Spring rest length [m].
            pub lo: f64,
            /// Crank: O to its mass centre [m].
            pub ra: f64,
            /// Crank: O to the pin P of body 2 [m].
            pub rr: f64,
            /// Body 2: P to the joint E [m].
            pub d: f64,
            /// Body 2: P to its mass centre [m].
            pub da: f64,
            /// Body 4: the pin Q to the joint E [m].
            pub e: f64,
            /// Body 4: E to its mass centre [m].
            pub ea: f64,
            /// Body 3: B to E [m].
            pub ss: f64,
            /// Body 3: mass centre's offset along −y [m].
            pub sa: f64,
            /// Body 3: mass centre's offset along x [m].
            pub sb: f64,
            /// Body 3: spring attachment D's offset along −y [m].
            pub sc: f64,
            /// Body 3: spring attachment D's offset along x [m].
            pub sd: f64,
            /// Body 5: mass centre's offset along x [m].
            pub ta: f64,
            /// Body 5: mass centre's offset along y [m].
            pub tb: f64,
            /// Body 7: A to the pin G of body 6 [m].
            pub u: f64,
            /// Body 7: mass centre's offset along −y [m].
            pub ua: f64,
            /// Body 7: mass centre's offset along x [m].
            pub ub: f64,
            /// Body 6: G to E [m].
            pub zf: f64,
            /// Body 5: A to the pin Q of body 4 [m].
            pub zt: f64,
            /// Body 6: E to its mass centre [m].
            pub fa: f64,
            /// Driving torque on the crank [N m].
            pub mom: f64,
        }

        impl Default for $name {
            /// The Test Set's parameter values (`ex_andrews.R`).
            fn default() -> Self {
                $name {
                    m1: 0.04325,
                    m2: 0.00365,
                    m3: 0.02373,
                    m4: 0.00706,
                    m5: 0.07050,
                    m6: 0.00706,
                    m7: 0.05498,
                    i1: 2.194e-6,
                    i2: 4.410e-7,
                    i3: 5.255e-6,
                    i4: 5.667e-7,
                    i5: 1.169e-5,
                    i6: 5.667e-7,
                    i7: 1.912e-5,
                    xa: -0.06934,
                    ya: -0.00227,
                    xb: -0.03635,
                    yb: 0.03273,
                    xc: 0.014,
                    yc: 0.072,
                    c0: 4530.0,
                    lo: 0.07785,
                    ra: 0.00092,
                    rr: 0.007,
                    d: 0.028,
                    da: 0.0115,
                    e: 0.02,
                    ea: 0.01421,
                    ss: 0.035,
                    sa: 0.01874,
                    sb: 0.01043,
                    sc: 0.018,
                    sd: 0.02,
                    ta: 0.02308,
                    tb: 0.00916,
                    u: 0.04,
                    ua: 0.01228,
                    ub: 0.00449,
                    zf: 0.02,
                    zt: 0.04,
                    fa: 0.01421,
                    mom: 0.033,
                }
            }
        }
    };
}
#[allow(unused_imports)]
pub(crate) use squeezer;

squeezer! {
    /// Andrews' squeezer: seven rigid bodies in the plane, with the angles of
    /// the Test Set (all absolute about N.z except θ, φ, Ω, which are relative
    /// to the body they are pinned to):
    ///
    /// * body 1, the crank: turns by `beta` about the origin O; driven by the
    ///   torque `mom`. Its mass centre is `ra` from O (towards P, the pin of
    ///   body 2, `rr` from O).
    /// * body 2: pinned to the crank at P, turned by `theta` relative to it
    ///   (absolute angle β + Θ); the joint E, where bodies 3, 4 and 6 meet it,
    ///   is `d` from P along its −x axis, its mass centre `da` from P the same
    ///   way.
    /// * body 3: turns by `gamma` about the fixed point B = (xb, yb); E is `ss`
    ///   from B along its −y axis; the spring is attached at D, `sd` along its
    ///   x axis and `sc` along its −y axis from B. Its mass centre is at
    ///   (sb, −sa) in its frame (the Test Set fixes only its distance
    ///   √(sa² + sb²) from B).
    /// * body 5: turns by `delta` about the fixed point A = (xa, ya); body 4 is
    ///   pinned to it at Q, `zt` along its x axis. Mass centre at (ta, tb) in
    ///   its frame (only the distance matters).
    /// * body 4: pinned to body 5 at Q, turned by `phi` relative to it (absolute
    ///   angle φ + δ); E is `e` from Q along its −y axis, its mass centre
    ///   `e − ea` from Q the same way (`ea` from E).
    /// * body 7: turns by `epsilon` about A; body 6 is pinned to it at G, `u`
    ///   along its −y axis. Mass centre at (ub, −ua) in its frame (only the
    ///   distance matters).
    /// * body 6: pinned to body 7 at G, turned by `omega` relative to it
    ///   (absolute angle Ω + ε); E is `zf` from G along its x axis, its mass
    ///   centre `zf − fa` from G the same way (`fa` from E).
    ///
    /// The three loops close at E (two rows each, as the Test Set's g1..g6, in
    /// the same order and sign). The spring joins D to the fixed point
    /// C = (xc, yc), with rest length `lo` and stiffness `c0`: the force on D is
    /// −c0 (L − lo) (D − C)/L, L = |D − C|. There is no gravity. Each body's
    /// central moment of inertia about the normal is `i1`..`i7` (the in-plane
    /// moments, which do not enter planar motion, are set to half of it).
    ///
    /// One degree of freedom: β's rate is the privileged speed, the other six
    /// angles are dependent.
    AndrewsSqueezer, speed = beta
}
