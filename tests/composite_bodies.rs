//! Bodies whose mass centres are fixed in one rigid body's frame may share
//! one translational term (the composite mass centre, with the parallel-axis
//! inertia turning with the frame); the derivation keeps whichever of the
//! two forms costs fewer operations. The same gyroscope is written twice,
//! once with its masses declared `positive` (the composite is considered)
//! and once without (each body keeps its own term): the two rhs agree, and
//! considering the composite never costs operations. (The bicycle, whose
//! wheels do form composites, is checked against the multiplier oracle in
//! `tests/whipple.rs`.)

mod common;
use appell::{Appell, Model};
use common::{agree, close, Rng};

/// A gimbal B (yaw, then pitch) on a fixed pivot, carrying a rotor D that
/// spins about B.y; the rotor's centre is fixed in B. `$extra` holds the
/// attributes that differ between the two versions.
macro_rules! gyroscope {
    ($(#[$extra:meta])* $name:ident) => {
        #[derive(Appell, Clone)]
        #[appell(coordinates(yaw, pitch, spin), speeds(yaw, pitch, spin))]
        $(#[$extra])*
        #[appell(frame(A = N.rotate_z(yaw)), frame(B = A.rotate_x(pitch)), frame(D = B.rotate_y(spin)))]
        #[appell(point(Bo = O + a * B.z + c * B.x), point(Do = O + h * B.z))]
        #[appell(body(gimbal, center = Bo, frame = B, mass = mb, inertia = matrix(i11, i22, i33, 0, 0, i31)))]
        #[appell(body(rotor, center = Do, frame = D, mass = md, inertia = principal(j1, j2, j1)))]
        #[appell(gravity(-g * N.z))]
        pub struct $name {
            pub a: f64,
            pub c: f64,
            pub h: f64,
            pub mb: f64,
            pub md: f64,
            pub i11: f64,
            pub i22: f64,
            pub i33: f64,
            pub i31: f64,
            pub j1: f64,
            pub j2: f64,
            pub g: f64,
        }
    };
}

gyroscope!(
    #[appell(positive(mb, md))]
    Composite
);
// The same gyroscope without `positive`: no composite.
gyroscope!(Separate);

#[test]
fn composite_and_separate_bodies_give_the_same_rhs() {
    let mut rng = Rng(17);
    let mut worst: f64 = 0.0;
    for _ in 0..1000 {
        let (a, c, h) = (
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
        );
        let (mb, md) = (rng.uniform(0.5, 3.0), rng.uniform(0.5, 3.0));
        let (i11, i22, i33) = (
            rng.uniform(1.0, 2.0),
            rng.uniform(1.0, 2.0),
            rng.uniform(1.0, 2.0),
        );
        let i31 = rng.uniform(-0.3, 0.3);
        let (j1, j2) = (rng.uniform(0.2, 1.0), rng.uniform(0.2, 1.0));
        // The same values in both structs.
        macro_rules! with_values {
            ($name:ident) => {
                $name {
                    a,
                    c,
                    h,
                    mb,
                    md,
                    i11,
                    i22,
                    i33,
                    i31,
                    j1,
                    j2,
                    g: 9.81,
                }
            };
        }
        let p = with_values!(Composite);
        let q = with_values!(Separate);
        let n = Composite::info().retained.len() + 3;
        assert_eq!(n, Separate::info().retained.len() + 3);
        let s: Vec<f64> = (0..n).map(|_| rng.uniform(-2.0, 2.0)).collect();
        let mut d1 = vec![0.0; n];
        let mut d2 = vec![0.0; n];
        p.rhs(&p.prepare::<f64>(), 0.0, &s, &[], &mut d1).unwrap();
        q.rhs(&q.prepare::<f64>(), 0.0, &s, &[], &mut d2).unwrap();
        let scale = d2.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        for (x, y) in d1.iter().zip(&d2) {
            assert!(
                close(*x, *y, 1e-10) || (x - y).abs() <= 1e-12 * scale,
                "{d1:?} vs {d2:?}"
            );
            worst = worst.max((x - y).abs() / scale);
        }
    }
    assert!(worst < 1e-12, "worst relative difference {worst:e}");
}

#[test]
fn considering_the_composite_never_costs_operations() {
    let composite = Composite::info().rhs_ops.total;
    let separate = Separate::info().rhs_ops.total;
    assert!(composite <= separate, "{composite} vs {separate}");
}

#[test]
fn folded_gyroscopes_agree_with_the_oracle() {
    let mut rng = Rng(29);
    macro_rules! with_values {
        ($name:ident) => {
            $name {
                a: 0.3,
                c: -0.2,
                h: 0.5,
                mb: 2.0,
                md: 1.5,
                i11: 1.2,
                i22: 1.5,
                i33: 1.1,
                i31: 0.2,
                j1: 0.4,
                j2: 0.7,
                g: 9.81,
            }
        };
    }
    // The oracle works body by body from `mass_properties` and
    // `body_poses`, without any folding.
    let composite = agree(&with_values!(Composite), &mut rng, 1000, 2.0);
    let separate = agree(&with_values!(Separate), &mut rng, 1000, 2.0);
    assert!(composite < 1e-9, "{composite:e}");
    assert!(separate < 1e-9, "{separate:e}");
}
