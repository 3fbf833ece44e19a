//! The n-link pendulum family: small oscillations, energy, and the oracle.

mod common;
#[path = "../examples/models/n_link_pendulum.rs"]
mod n_link_pendulum;

use appell::Model;
use common::Rng;
use n_link_pendulum::{Pendulum2, Pendulum4, Pendulum8};

fn oracle_agreement<M: Model>(model: &M, seed: u64) -> f64 {
    let info = M::info();
    let n = info.coordinates.len();
    let prepared = model.prepare::<f64>();
    let mut rng = Rng(seed);
    let mut worst: f64 = 0.0;
    for _ in 0..1000 {
        let q: Vec<f64> = (0..n).map(|_| rng.uniform(-3.0, 3.0)).collect();
        let u: Vec<f64> = (0..n).map(|_| rng.uniform(-2.0, 2.0)).collect();
        let mut s = q.clone();
        s.extend(&u);
        let mut d = vec![0.0; 2 * n];
        model.rhs(&prepared, 0.0, &s, &[], &mut d).unwrap();
        let o = appell::oracle::reduced_rhs(model, 0.0, &q, &u, &[]).unwrap();
        for (a, b) in d.iter().zip(&o) {
            worst = worst.max((a - b).abs() / (1.0 + a.abs().max(b.abs())));
        }
    }
    println!(
        "{}: largest relative difference to the oracle {worst:.2e}",
        info.name
    );
    worst
}

#[test]
fn all_sizes_agree_with_the_oracle() {
    assert!(oracle_agreement(&Pendulum2::default(), 1) < 1e-9);
    assert!(oracle_agreement(&Pendulum4::default(), 2) < 1e-9);
    assert!(oracle_agreement(&Pendulum8::default(), 3) < 1e-9);
}

#[test]
fn two_links_oscillate_at_the_textbook_frequencies() {
    // Equal links and masses: ω² = (2 ± √2) g / l, eigenvalues ±iω of the
    // linearization at rest.
    let p = Pendulum2::default();
    let lin = appell::linearize::linearize(&p, 0.0, &[0.0; 4], &[]).unwrap();
    let mut w2: Vec<f64> = appell::linearize::eigenvalues(&lin.a)
        .unwrap()
        .iter()
        .filter(|e| e.1 > 0.0)
        .map(|e| e.1 * e.1)
        .collect();
    w2.sort_by(f64::total_cmp);
    let expected = [(2.0 - 2f64.sqrt()) * 9.81, (2.0 + 2f64.sqrt()) * 9.81];
    for (a, b) in w2.iter().zip(expected) {
        assert!((a - b).abs() < 1e-10 * b, "{a} vs {b}");
    }
}

#[test]
fn four_links_conserve_energy() {
    let p = Pendulum4::default();
    let prepared = p.prepare::<f64>();
    let energy = |s: &[f64; 8]| {
        let t = p.kinetic_energy(0.0, &s[..4], &s[4..]).unwrap();
        // V = −g Σ_i m_i y_i with y_i = −Σ_{j≤i} l_j cos q_j.
        let mut y = 0.0;
        let mut v = 0.0;
        for q in &s[..4] {
            y -= q.cos();
            v += 9.81 * y;
        }
        t + v
    };
    let s0 = [0.6, -0.3, 0.9, 0.2, 0.0, 0.5, -0.4, 0.1];
    let e0 = energy(&s0);
    let s = appell::integrate::rk4(&p, &prepared, 0.0, &s0, 1e-4, 20_000, &[]).unwrap();
    let drift = ((energy(&s) - e0) / e0).abs();
    println!("4 links, 2 s of RK4 at h = 1e-4: relative energy drift {drift:.2e}");
    assert!(drift < 1e-9, "{drift:e}");
}

#[test]
fn two_links_match_the_textbook_formula() {
    let mut rng = Rng(4);
    for _ in 0..1000 {
        let p = Pendulum2 {
            m1: rng.uniform(0.5, 3.0),
            m2: rng.uniform(0.5, 3.0),
            l1: rng.uniform(0.5, 2.0),
            l2: rng.uniform(0.5, 2.0),
            g: 9.81,
        };
        let s = [
            rng.uniform(-3.0, 3.0),
            rng.uniform(-3.0, 3.0),
            rng.uniform(-3.0, 3.0),
            rng.uniform(-3.0, 3.0),
        ];
        let mut d = [0.0; 4];
        p.rhs(&p.prepare::<f64>(), 0.0, &s, &[], &mut d).unwrap();
        let (a1, a2) = common::double_pendulum_accelerations(p.m1, p.m2, p.l1, p.l2, p.g, s);
        assert!(common::close(d[2], a1, 1e-12) && common::close(d[3], a2, 1e-12));
    }
}
