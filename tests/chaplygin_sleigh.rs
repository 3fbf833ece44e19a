//! The Chaplygin sleigh: the closed-form equations in (v, ω), energy, and
//! the decay to straight-line motion.

#[path = "../examples/models/chaplygin_sleigh.rs"]
mod chaplygin_sleigh;
mod common;

use appell::Model;
use chaplygin_sleigh::ChaplyginSleigh;
use common::{close, Rng};

#[test]
fn matches_the_forward_speed_equations() {
    // v = ẋ / cos θ along the blade, ω = θ̇:  v̇ = b ω²,  (I + m b²) ω̇ = −m b v ω.
    let p = ChaplyginSleigh {
        m: 1.7,
        i0: 0.08,
        b: 0.25,
    };
    let prepared = p.prepare::<f64>();
    let mut rng = Rng(41);
    for _ in 0..1000 {
        let theta = rng.uniform(-1.3, 1.3);
        let (xd, w) = (rng.uniform(-2.0, 2.0), rng.uniform(-3.0, 3.0));
        let mut d = [0.0; 3];
        p.rhs(&prepared, 0.0, &[theta, xd, w], &[], &mut d).unwrap();
        let c = theta.cos();
        let v = xd / c;
        let vdot = d[1] / c + xd * theta.sin() * w / (c * c);
        assert!(
            close(vdot, p.b * w * w, 1e-11),
            "v' {vdot} vs {}",
            p.b * w * w
        );
        let wdot = -p.m * p.b * v * w / (p.i0 + p.m * p.b * p.b);
        assert!(close(d[2], wdot, 1e-11), "w' {} vs {wdot}", d[2]);
    }
}

#[test]
fn turning_decays_to_straight_line_motion_at_constant_energy() {
    let p = ChaplyginSleigh::default();
    let prepared = p.prepare::<f64>();
    let energy = |s: &[f64; 3]| p.kinetic_energy(0.0, &[0.0, 0.0, s[0]], &s[1..]).unwrap();
    let s0 = [0.0, 1.0, 1.0];
    let e0 = energy(&s0);
    let s = appell::integrate::rk4(&p, &prepared, 0.0, &s0, 1e-3, 30_000, &[]).unwrap();
    let drift = ((energy(&s) - e0) / e0).abs();
    let v = s[1] / s[0].cos();
    let v_final = (2.0 * e0 / p.m).sqrt();
    println!(
        "after 30 s: omega = {:.2e}, v = {v:.9} (limit {v_final:.9}), energy drift {drift:.2e}",
        s[2]
    );
    assert!(drift < 1e-10);
    assert!(
        s[2].abs() < 1e-3 * s0[2],
        "the turning rate decays: {}",
        s[2]
    );
    assert!(
        (v - v_final).abs() < 1e-5 * v_final,
        "all energy ends up in translation"
    );
}

#[test]
fn controller_functions_agree_with_the_equations() {
    let mut rng = Rng(47);
    let worst = common::controller_agrees(&ChaplyginSleigh::default(), &mut rng, 50, 3.0);
    assert!(worst < 1e-9, "{worst:.2e}"); // M is ill-conditioned at some states: ÿ carries cond(M) ε
}
