//! The n-link pendulum family: small oscillations, energy, and the oracle.

mod common;
#[path = "../examples/models/n_link_pendulum.rs"]
mod n_link_pendulum;

use appell::Model;
use common::Rng;
use n_link_pendulum::{Pendulum16, Pendulum2, Pendulum4, Pendulum8};

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
    assert!(oracle_agreement(&Pendulum16::default(), 5) < 1e-9);
}

/// The four-link pendulum with every link written out by hand, as the
/// family was before `repeat`.
#[derive(appell::Appell, Clone, Debug, PartialEq)]
#[appell(coordinates(q1, q2, q3, q4), speeds(q1, q2, q3, q4))]
#[appell(point(P1 = O + l1 * sin(q1) * N.x - l1 * cos(q1) * N.y), particle(P1, mass = m1))]
#[appell(point(P2 = P1 + l2 * sin(q2) * N.x - l2 * cos(q2) * N.y), particle(P2, mass = m2))]
#[appell(point(P3 = P2 + l3 * sin(q3) * N.x - l3 * cos(q3) * N.y), particle(P3, mass = m3))]
#[appell(point(P4 = P3 + l4 * sin(q4) * N.x - l4 * cos(q4) * N.y), particle(P4, mass = m4))]
#[appell(gravity(-g * N.y))]
struct WrittenOut4 {
    m1: f64,
    m2: f64,
    m3: f64,
    m4: f64,
    l1: f64,
    l2: f64,
    l3: f64,
    l4: f64,
    g: f64,
}

#[test]
fn the_repeated_declaration_is_the_chain_written_out() {
    let info = Pendulum4::info();
    assert_eq!(info.coordinates, ["q_0", "q_1", "q_2", "q_3"]);
    assert_eq!(
        info.parameters,
        ["m_0", "m_1", "m_2", "m_3", "l_0", "l_1", "l_2", "l_3", "g"]
    );
    assert_eq!(info.rhs_ops.total, WrittenOut4::info().rhs_ops.total);
    let mut rng = Rng(6);
    for _ in 0..200 {
        let m: [f64; 4] = core::array::from_fn(|_| rng.uniform(0.5, 3.0));
        let l: [f64; 4] = core::array::from_fn(|_| rng.uniform(0.5, 2.0));
        let repeated = Pendulum4 { m, l, g: 9.81 };
        let written = WrittenOut4 {
            m1: m[0],
            m2: m[1],
            m3: m[2],
            m4: m[3],
            l1: l[0],
            l2: l[1],
            l3: l[2],
            l4: l[3],
            g: 9.81,
        };
        let s: [f64; 8] = core::array::from_fn(|_| rng.uniform(-3.0, 3.0));
        let (mut a, mut b) = ([0.0; 8], [0.0; 8]);
        repeated
            .rhs(&repeated.prepare::<f64>(), 0.0, &s, &[], &mut a)
            .unwrap();
        written
            .rhs(&written.prepare::<f64>(), 0.0, &s, &[], &mut b)
            .unwrap();
        assert_eq!(a, b);
    }
}

#[test]
fn an_element_of_an_array_parameter_is_checked_by_name() {
    let mut p = Pendulum2::default();
    p.m[1] = f64::NAN;
    let mut d = [0.0; 4];
    let err = p
        .rhs(&p.prepare::<f64>(), 0.0, &[0.1; 4], &[], &mut d)
        .unwrap_err();
    assert!(err.to_string().contains("m[1]"), "{err}");
    assert!(p.set_parameter("m_1", 2.0));
    assert_eq!(p.m[1], 2.0);
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
            m: [rng.uniform(0.5, 3.0), rng.uniform(0.5, 3.0)],
            l: [rng.uniform(0.5, 2.0), rng.uniform(0.5, 2.0)],
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
        let (a1, a2) =
            common::double_pendulum_accelerations(p.m[0], p.m[1], p.l[0], p.l[1], p.g, s);
        assert!(common::close(d[2], a1, 1e-12) && common::close(d[3], a2, 1e-12));
    }
}
