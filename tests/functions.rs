//! The functions of friction laws, drives and one-sided contacts in a
//! model's loads (`tanh sinh cosh asin acos atan powf min max sign` and the
//! conditional): the generated rhs equals the laws written by hand, and its
//! derivative by dual numbers equals central differences away from the
//! switches.

use appell::num_dual::Dual64;
use appell::{Appell, Model, Scalar};

/// A block on a line: a one-sided spring (pushes only when x < 0), Coulomb
/// friction regularised by tanh, a saturated motor, a stiffening spring and
/// a few smooth functions that only have to be carried through.
#[derive(Appell)]
#[appell(coordinates(x), speeds(x), inputs(u), positive(m, k, mu, eps, tau_max))]
#[appell(point(P = O + x * N.x), particle(P, mass = m))]
#[appell(force(P, (if x < 0 { -k * x } else { 0 }) * N.x))]
#[appell(force(P, -mu * m * 9.81 * tanh(dt(x) / eps) * N.x))]
#[appell(force(P, max(-tau_max, min(tau_max, u)) * N.x))]
#[appell(force(P, -(powf(abs(x) + 1, 1.5) - 1) * sign(x) * N.x))]
#[appell(force(P, 0.01 * (sinh(x / 4) + cosh(x / 4) + asin(tanh(x)) + acos(tanh(x) / 2) + atan(dt(x))) * N.x))]
struct Block {
    m: f64,
    k: f64,
    mu: f64,
    eps: f64,
    tau_max: f64,
}

fn block() -> Block {
    Block {
        m: 2.0,
        k: 50.0,
        mu: 0.3,
        eps: 0.05,
        tau_max: 4.0,
    }
}

/// The force on the block, written by hand.
fn force(p: &Block, x: f64, v: f64, u: f64) -> f64 {
    let spring = if x < 0.0 { -p.k * x } else { 0.0 };
    let friction = -p.mu * p.m * 9.81 * (v / p.eps).tanh();
    let motor = u.clamp(-p.tau_max, p.tau_max);
    let sign = if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    };
    let stiffening = -((x.abs() + 1.0).powf(1.5) - 1.0) * sign;
    let smooth = 0.01
        * ((x / 4.0).sinh()
            + (x / 4.0).cosh()
            + x.tanh().asin()
            + (x.tanh() / 2.0).acos()
            + v.atan());
    spring + friction + motor + stiffening + smooth
}

fn rhs<T: Scalar>(p: &Block, x: T, v: T, u: T) -> T {
    let prepared = p.prepare::<T>();
    let mut d = [T::zero(); 2];
    p.rhs(&prepared, T::zero(), &[x, v], &[u], &mut d).unwrap();
    d[1]
}

#[test]
fn the_generated_rhs_is_the_law_written_by_hand() {
    let p = block();
    let mut worst: f64 = 0.0;
    for i in 0..41 {
        for (v, u) in [
            (-0.3, -9.0),
            (-0.01, 1.0),
            (0.0, 0.0),
            (0.02, 3.9),
            (1.0, 12.0),
        ] {
            let x = -1.0 + 0.05 * i as f64;
            let a = rhs(&p, x, v, u);
            let expected = force(&p, x, v, u) / p.m;
            worst = worst.max((a - expected).abs() / (1.0 + expected.abs()));
        }
    }
    assert!(worst < 1e-13, "{worst}");
}

#[test]
fn derivatives_through_the_generated_code_match_differences_away_from_switches() {
    let p = block();
    for (x, v, u) in [
        (-0.4, 0.1, 1.0),
        (0.3, -0.02, -2.0),
        (0.7, 0.5, 5.0),
        (-0.2, -1.0, -5.0),
    ] {
        let h = 1e-6;
        let dx = rhs(&p, Dual64::new(x, 1.0), Dual64::from(v), Dual64::from(u)).eps;
        let dv = rhs(&p, Dual64::from(x), Dual64::new(v, 1.0), Dual64::from(u)).eps;
        let fx = (rhs(&p, x + h, v, u) - rhs(&p, x - h, v, u)) / (2.0 * h);
        let fv = (rhs(&p, x, v + h, u) - rhs(&p, x, v - h, u)) / (2.0 * h);
        assert!(
            (dx - fx).abs() < 1e-6 * (1.0 + fx.abs()),
            "∂/∂x at {x}: {dx} vs {fx}"
        );
        assert!(
            (dv - fv).abs() < 1e-6 * (1.0 + fv.abs()),
            "∂/∂v at {v}: {dv} vs {fv}"
        );
    }
    // The saturated motor: no effect of u beyond the limit, full effect inside.
    let du = |u: f64| {
        rhs(
            &p,
            Dual64::from(0.1),
            Dual64::from(0.0),
            Dual64::new(u, 1.0),
        )
        .eps
    };
    assert_eq!(du(9.0), 0.0);
    assert!((du(1.0) - 1.0 / p.m).abs() < 1e-15);
}

#[test]
fn the_equations_name_the_functions() {
    let text = Block::info().equations;
    for f in [
        "tanh", "select", "powf", "sign", "asin", "acos", "atan", "sinh", "cosh",
    ] {
        assert!(text.contains(f), "{f} missing from {text}");
    }
}
