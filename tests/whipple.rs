//! The Whipple bicycle benchmark.

#[path = "../examples/models/whipple_bicycle.rs"]
mod whipple_bicycle;

use appell::Model;
use whipple_bicycle::WhippleBicycle;

#[test]
fn derives() {
    let info = WhippleBicycle::info();
    println!("{}", &info.equations[..info.equations.len().min(3000)]);
    println!("ops {:?}", info.rhs_ops);
}

#[test]
fn agrees_with_the_oracle() {
    let p = WhippleBicycle::default();
    let prepared = p.prepare::<f64>();
    let mut seed = 0x5eed_u64;
    let mut next = |lo: f64, hi: f64| {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        lo + (hi - lo) * ((seed >> 11) as f64 / (1u64 << 53) as f64)
    };
    let mut worst: f64 = 0.0;
    for _ in 0..1000 {
        let mut q: Vec<f64> = (0..8).map(|_| next(-1.0, 1.0)).collect();
        q[4] = std::f64::consts::PI / 10.0 + next(-0.2, 0.2); // pitch near the steer-axis tilt
        q[3] = next(-0.6, 0.6); // roll
        q[6] = next(-0.8, 0.8); // steer
        let u = [next(-2.0, 2.0), next(-20.0, 0.0), next(-2.0, 2.0)];
        let state = [q[3], q[4], q[6], u[0], u[1], u[2]];
        let mut d = [0.0; 6];
        p.rhs(&prepared, 0.0, &state, &[], &mut d).unwrap();
        let o = appell::oracle::reduced_rhs(&p, 0.0, &q, &u, &[]).unwrap();
        for (a, b) in d.iter().zip(&o) {
            worst = worst.max((a - b).abs() / (1.0 + a.abs().max(b.abs())));
        }
    }
    println!("bicycle vs oracle: largest relative difference {worst:.2e}");
    assert!(worst < 1e-9, "{worst:e}");
}

#[test]
fn critical_speeds_match_the_benchmark() {
    let p = WhippleBicycle::default();
    let (weave, capsize) = whipple_bicycle::critical_speeds(&p).unwrap();
    println!("weave {weave:.14} m/s, capsize {capsize:.14} m/s");
    assert!(
        (weave - 4.29238253634111).abs() < 1e-8,
        "weave speed {weave}"
    );
    assert!(
        (capsize - 6.02426201538837).abs() < 1e-8,
        "capsize speed {capsize}"
    );
}

#[test]
fn upright_pitch_is_the_steer_axis_tilt() {
    let q = whipple_bicycle::operating_point(&WhippleBicycle::default()).unwrap();
    assert!(
        (q[4] - std::f64::consts::PI / 10.0).abs() < 1e-12,
        "pitch {}",
        q[4]
    );
}
