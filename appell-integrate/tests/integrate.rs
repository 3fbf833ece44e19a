//! Fixed-step RK4 over hand-written models: order of accuracy, exact
//! solutions, scalar genericity and error reporting.

use appell_core::{Model, ModelError};
use appell_integrate::{rk4, rk4_step, rk4_step_fn};
use appell_test_models::*;
use num_dual::Dual64;

const PENDULUM: Pendulum = Pendulum {
    m: 1.0,
    l: 1.0,
    g: 9.81,
};

fn pendulum_at(t_end: f64, steps: usize, theta0: f64) -> [f64; 2] {
    let p = PENDULUM.prepare::<f64>();
    rk4(
        &PENDULUM,
        &p,
        0.0,
        &[theta0, 0.0],
        t_end / steps as f64,
        steps,
        &[],
    )
    .unwrap()
}

#[test]
fn fourth_order_convergence() {
    let reference = pendulum_at(2.0, 4096, 1.2);
    let err = |steps| {
        let x = pendulum_at(2.0, steps, 1.2);
        (x[0] - reference[0]).abs() + (x[1] - reference[1]).abs()
    };
    let (e1, e2, e3) = (err(64), err(128), err(256));
    for ratio in [e1 / e2, e2 / e3] {
        assert!(
            (13.0..19.0).contains(&ratio),
            "error ratio {ratio} for halved steps (errors {e1:e}, {e2:e}, {e3:e})"
        );
    }
}

#[test]
fn energy_is_nearly_conserved() {
    let x = pendulum_at(10.0, 10_000, 2.0);
    let energy = |s: [f64; 2]| 0.5 * s[1] * s[1] - PENDULUM.g * s[0].cos();
    let drift = (energy(x) - energy([2.0, 0.0])).abs();
    assert!(drift < 1e-9, "energy drift {drift:e}");
}

#[test]
fn knife_edge_coasting_is_exact_circle_motion() {
    // No field, no drag, no torque: φ = φ0 + ω t, ẋ = v cos φ with v fixed.
    let k = KnifeEdge {
        m: 2.0,
        i: 0.5,
        gx: 0.0,
        c: 0.0,
    };
    let (phi0, w, v): (f64, f64, f64) = (0.2, 0.5, 1.5);
    let t_end = 2.0;
    let x = rk4(&k, &(), 0.0, &[phi0, v * phi0.cos(), w], 1e-3, 2000, &[0.0]).unwrap();
    let phi = phi0 + w * t_end;
    assert!((x[0] - phi).abs() < 1e-12);
    assert!(
        (x[1] - v * phi.cos()).abs() < 1e-10,
        "{} vs {}",
        x[1],
        v * phi.cos()
    );
    assert!((x[2] - w).abs() < 1e-14);
}

#[test]
fn time_dependent_model_uses_step_times() {
    // The driven rod: integrating [0, 1] in one call or as [0, 0.5] then
    // [0.5, 1] must agree exactly (each step sees its own time).
    let r = Rod {
        m: 1.0,
        len: 0.8,
        g: 9.81,
        a: 0.3,
        w: 4.0,
        k: 0.1,
    };
    let whole = rk4(&r, &(), 0.0_f64, &[0.3, 0.0], 0.01, 100, &[]).unwrap();
    let half = rk4(&r, &(), 0.0_f64, &[0.3, 0.0], 0.01, 50, &[]).unwrap();
    let rest = rk4(&r, &(), 0.5, &half, 0.01, 50, &[]).unwrap();
    assert!((whole[0] - rest[0]).abs() < 1e-13 && (whole[1] - rest[1]).abs() < 1e-13);
    // And the drive matters: the undriven rod ends elsewhere.
    let still = Rod { a: 0.0, ..r };
    let other = rk4(&still, &(), 0.0_f64, &[0.3, 0.0], 0.01, 100, &[]).unwrap();
    assert!((other[0] - whole[0]).abs() > 1e-3);
}

#[test]
fn f32_agrees_with_f64() {
    let p32 = PENDULUM.prepare::<f32>();
    let x32 = rk4(&PENDULUM, &p32, 0.0f32, &[1.0f32, 0.0], 0.01, 100, &[]).unwrap();
    let x64 = pendulum_at(1.0, 100, 1.0);
    assert!((x32[0] as f64 - x64[0]).abs() < 1e-4);
    assert!((x32[1] as f64 - x64[1]).abs() < 1e-4);
}

#[test]
fn dual_numbers_give_the_trajectory_sensitivity() {
    let theta0 = 0.9;
    let p = PENDULUM.prepare::<Dual64>();
    let x = rk4(
        &PENDULUM,
        &p,
        Dual64::from(0.0),
        &[Dual64::new(theta0, 1.0), Dual64::from(0.0)],
        Dual64::from(0.01),
        150,
        &[],
    )
    .unwrap();
    let step = 1e-6;
    let fd = (pendulum_at(1.5, 150, theta0 + step)[0] - pendulum_at(1.5, 150, theta0 - step)[0])
        / (2.0 * step);
    assert!((x[0].eps - fd).abs() < 1e-7, "{} vs {fd}", x[0].eps);
    assert_eq!(x[0].re, pendulum_at(1.5, 150, theta0)[0]);
}

#[test]
fn one_step_matches_the_closure_form_and_zero_steps_is_identity() {
    let p = PENDULUM.prepare::<f64>();
    let s0 = [0.4, -0.3];
    let a = rk4_step(&PENDULUM, &p, 0.0, 0.05, &s0, &[]).unwrap();
    let mut f = |_t: f64, x: &[f64; 2], dx: &mut [f64; 2]| -> Result<(), ModelError> {
        dx[0] = x[1];
        dx[1] = -PENDULUM.g / PENDULUM.l * x[0].sin();
        Ok(())
    };
    let b = rk4_step_fn(&mut f, 0.0, 0.05, &s0).unwrap();
    assert!((a[0] - b[0]).abs() < 1e-15 && (a[1] - b[1]).abs() < 1e-15);
    assert_eq!(rk4(&PENDULUM, &p, 0.0, &s0, 0.05, 0, &[]).unwrap(), s0);
}

#[test]
fn wrong_state_length_is_an_error() {
    let p = PENDULUM.prepare::<f64>();
    let e = rk4(&PENDULUM, &p, 0.0, &[0.1, 0.0, 0.0], 0.01, 10, &[]).unwrap_err();
    assert_eq!(
        e,
        ModelError::Length {
            argument: "state",
            expected: 2,
            found: 3
        }
    );
    let e = rk4_step(
        &KnifeEdge {
            m: 1.0,
            i: 1.0,
            gx: 0.0,
            c: 0.0,
        },
        &(),
        0.0,
        0.1,
        &[0.0; 2],
        &[0.0],
    )
    .unwrap_err();
    assert!(matches!(
        e,
        ModelError::Length {
            expected: 3,
            found: 2,
            ..
        }
    ));
}

#[test]
fn rhs_errors_pass_through() {
    let k = KnifeEdge {
        m: 1.0,
        i: 1.0,
        gx: 0.0,
        c: 0.0,
    };
    // Missing input.
    let e = rk4(&k, &(), 0.0, &[0.0; 3], 0.1, 3, &[]).unwrap_err();
    assert!(matches!(
        e,
        ModelError::Length {
            argument: "inputs",
            ..
        }
    ));
    // A non-positive parameter the rhs checks.
    let bad = KnifeEdge { i: 0.0, ..k };
    let e = rk4(&bad, &(), 0.0, &[0.0; 3], 0.1, 3, &[0.0]).unwrap_err();
    assert!(matches!(
        e,
        ModelError::NonPositiveParameter { name: "i", .. }
    ));
}

#[test]
fn blow_up_is_reported_as_non_finite() {
    let wild = Pendulum {
        m: 1.0,
        l: 1e-300,
        g: 1e300,
    };
    let p = wild.prepare::<f64>();
    let e = rk4(&wild, &p, 0.0, &[1.0, 0.0], 1.0, 5, &[]).unwrap_err();
    assert_eq!(e, ModelError::NonFinite { what: "state" });
    let e = rk4(
        &PENDULUM,
        &PENDULUM.prepare::<f64>(),
        0.0,
        &[f64::NAN, 0.0],
        0.1,
        1,
        &[],
    )
    .unwrap_err();
    assert_eq!(e, ModelError::NonFinite { what: "state" });
}
