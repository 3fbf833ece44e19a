//! The rolling disc: ignorable coordinates, steady turning, energy, and the
//! independent solver.

mod common;
#[path = "../examples/models/rolling_disc.rs"]
mod rolling_disc;

use appell::integrate::rk4;
use appell::Model;
use common::{close, Rng};
use rolling_disc::RollingDisc;

#[test]
fn only_the_lean_is_integrated() {
    let info = RollingDisc::info();
    println!("{}", info.equations);
    assert_eq!(
        info.constraints, 2,
        "the vertical rolling row is identically zero and dropped"
    );
    assert_eq!(info.retained, &["lean"]);
    assert_eq!(info.cyclic, &["x", "y"]);
    assert_eq!(info.ignorable, &["yaw", "spin", "x", "y"]);
}

#[test]
fn steady_turning_is_an_equilibrium() {
    // Euler's equation about the centre for steady turning at lean θ, yaw
    // rate Ω, with W = Ω sin θ + ω the total axial rate (thin disc):
    //   −(3/2) r Ω W cos θ + (1/4) r Ω² cos θ sin θ − g sin θ = 0.
    let p = RollingDisc::default();
    let prepared = p.prepare::<f64>();
    let mut rng = Rng(17);
    for _ in 0..200 {
        let theta = rng.uniform(-1.2, 1.2);
        let omega_yaw = rng.uniform(0.5, 6.0)
            * if rng.uniform(0.0, 1.0) < 0.5 {
                -1.0
            } else {
                1.0
            };
        let (s, c) = theta.sin_cos();
        let w =
            (0.25 * p.r * omega_yaw * omega_yaw * c * s - p.g * s) / (1.5 * p.r * omega_yaw * c);
        let spin = w - omega_yaw * s;
        let mut d = [0.0; 4];
        p.rhs(&prepared, 0.0, &[theta, omega_yaw, 0.0, spin], &[], &mut d)
            .unwrap();
        for (k, v) in d.iter().enumerate() {
            let scale = 1.0 + omega_yaw.abs() * spin.abs() + p.g / p.r;
            assert!(
                v.abs() < 1e-12 * scale,
                "d[{k}] = {v} at theta {theta}, yaw rate {omega_yaw}"
            );
        }
    }
}

#[test]
fn energy_is_conserved() {
    let p = RollingDisc::default();
    let prepared = p.prepare::<f64>();
    let energy = |s: &[f64; 4]| {
        let q = [0.0, s[0], 0.0, 0.0, 0.0];
        p.kinetic_energy(0.0, &q, &s[1..]).unwrap() + p.m * p.g * p.r * s[0].cos()
    };
    let s0 = [0.3, 1.5, 0.2, 12.0];
    let e0 = energy(&s0);
    let s = rk4(&p, &prepared, 0.0, &s0, 1e-4, 20_000, &[]).unwrap();
    let drift = ((energy(&s) - e0) / e0).abs();
    println!("energy drift over 2 s with h = 1e-4: {drift:.2e}");
    assert!(drift < 1e-10, "relative energy drift {drift:e}");
}

#[test]
fn agrees_with_the_oracle() {
    let p = RollingDisc::default();
    let prepared = p.prepare::<f64>();
    let mut rng = Rng(18);
    let mut worst: f64 = 0.0;
    for _ in 0..1000 {
        let q: Vec<f64> = (0..5).map(|_| rng.uniform(-1.3, 1.3)).collect();
        let u: Vec<f64> = (0..3).map(|_| rng.uniform(-5.0, 5.0)).collect();
        let mut d = [0.0; 4];
        p.rhs(&prepared, 0.0, &[q[1], u[0], u[1], u[2]], &[], &mut d)
            .unwrap();
        let o = appell::oracle::reduced_rhs(&p, 0.0, &q, &u, &[]).unwrap();
        for (a, b) in d.iter().zip(&o) {
            worst = worst.max((a - b).abs() / (1.0 + a.abs().max(b.abs())));
            assert!(close(*a, *b, 1e-9), "{a} vs {b}");
        }
    }
    println!("rolling disc vs oracle: largest relative difference {worst:.2e}");
}

#[test]
fn potential_energy_is_the_gravity_potential() {
    let p = RollingDisc::default();
    let q = [0.3, 0.7, -1.1, 0.2, 0.4];
    let v = p.potential_energy(0.0, &q).unwrap();
    // V = m g z of the centre, z = r cos(lean) (N.z up, gravity −g N.z).
    assert!(close(v, p.m * p.g * p.r * q[1].cos(), 1e-15), "{v}");
}

#[test]
fn controller_functions_agree_with_the_equations() {
    let mut rng = Rng(43);
    let worst = common::controller_agrees(&RollingDisc::default(), &mut rng, 50, 1.2);
    assert!(worst < 1e-12, "{worst:.2e}");
}
