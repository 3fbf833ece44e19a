//! Second-order fixed steps and the adaptive Dormand–Prince integrator:
//! orders of convergence, tolerance proportionality, dense output, events,
//! typed errors, and integration of a hand-written `Model`.

use appell_core::{Model, ModelError};
use appell_integrate::{
    heun_step, heun_step_fn, midpoint_step, midpoint_step_fn, rk4_step_fn, Dopri5, IntegrateError,
    Stats,
};
use appell_test_models::*;
use num_dual::Dual64;
use std::f64::consts::PI;

type Rhs2 = fn(f64, &[f64; 2], &mut [f64; 2]) -> Result<(), ModelError>;

/// x'' = −x.
fn oscillator(_t: f64, x: &[f64; 2], dx: &mut [f64; 2]) -> Result<(), ModelError> {
    dx[0] = x[1];
    dx[1] = -x[0];
    Ok(())
}

/// Exact solution with x(0) = 1, x'(0) = 0.
fn oscillator_exact(t: f64) -> [f64; 2] {
    [t.cos(), -t.sin()]
}

fn err2(a: &[f64; 2], b: &[f64; 2]) -> f64 {
    (a[0] - b[0]).abs().max((a[1] - b[1]).abs())
}

type Step = fn(&mut Rhs2, f64, f64, &[f64; 2]) -> Result<[f64; 2], ModelError>;

fn fixed_error(step: Step, n: usize) -> f64 {
    let t_end = 2.0;
    let h = t_end / n as f64;
    let mut f: Rhs2 = oscillator;
    let mut x = [1.0, 0.0];
    for k in 0..n {
        x = step(&mut f, k as f64 * h, h, &x).unwrap();
    }
    err2(&x, &oscillator_exact(t_end))
}

/// Observed orders log2(e(N) / e(2N)) for N = 20, 40, 80.
fn observed_orders(step: Step) -> Vec<f64> {
    let errs: Vec<f64> = [20, 40, 80, 160]
        .iter()
        .map(|&n| fixed_error(step, n))
        .collect();
    errs.windows(2).map(|w| (w[0] / w[1]).log2()).collect()
}

fn assert_order(name: &str, step: Step, nominal: f64) {
    let orders = observed_orders(step);
    println!("{name}: observed orders {orders:?}");
    for p in &orders {
        assert!((p - nominal).abs() < 0.3, "{name}: order {p} vs {nominal}");
    }
}

#[test]
fn rk4_is_fourth_order() {
    assert_order("rk4", |f, t, h, x| rk4_step_fn(f, t, h, x), 4.0);
}

#[test]
fn heun_is_second_order() {
    assert_order("heun", |f, t, h, x| heun_step_fn(f, t, h, x), 2.0);
}

#[test]
fn midpoint_is_second_order() {
    assert_order("midpoint", |f, t, h, x| midpoint_step_fn(f, t, h, x), 2.0);
}

#[test]
fn dopri5_fixed_steps_are_fifth_order() {
    let t_end = 16.0;
    let error = |n: usize| {
        let sol = Dopri5::new()
            .adaptive(false)
            .h_init(Some(t_end / n as f64))
            .solve(oscillator, 0.0, &[1.0, 0.0], t_end)
            .unwrap();
        assert_eq!((sol.stats.accepted, sol.stats.rejected), (n, 0));
        err2(&sol.x, &oscillator_exact(t_end))
    };
    let ns = [32, 64, 128, 256];
    let errs: Vec<f64> = ns.iter().map(|&n| error(n)).collect();
    for i in 1..ns.len() {
        let p = (errs[i - 1] / errs[i]).log2();
        println!("dopri5 N = {} -> {}: order {p:.3}", ns[i - 1], ns[i]);
        assert!((p - 5.0).abs() < 0.3, "dopri5: order {p} vs 5");
    }
    // Fixed steps need h_init.
    assert!(matches!(
        Dopri5::new()
            .adaptive(false)
            .solve(oscillator, 0.0, &[1.0, 0.0], 1.0),
        Err(IntegrateError::InvalidInput { .. })
    ));
}

#[test]
fn second_order_steps_report_non_finite_and_model_errors() {
    let mut nan = |_t: f64, _x: &[f64; 1], dx: &mut [f64; 1]| -> Result<(), ModelError> {
        dx[0] = f64::NAN;
        Ok(())
    };
    let e = Err(ModelError::NonFinite { what: "state" });
    assert_eq!(heun_step_fn(&mut nan, 0.0, 0.1, &[1.0]), e);
    assert_eq!(midpoint_step_fn(&mut nan, 0.0, 0.1, &[1.0]), e);
    let p = PENDULUM.prepare::<f64>();
    assert!(heun_step(&PENDULUM, &p, 0.0, 0.1, &[0.1, 0.0, 0.0], &[]).is_err());
    assert!(midpoint_step(&PENDULUM, &p, 0.0, 0.1, &[0.1, 0.0, 0.0], &[]).is_err());
}

const PENDULUM: Pendulum = Pendulum {
    m: 1.0,
    l: 1.0,
    g: 9.81,
};

#[test]
fn model_second_order_steps_match_the_closure_steps() {
    let p = PENDULUM.prepare::<f64>();
    let mut f = |t: f64, x: &[f64; 2], dx: &mut [f64; 2]| PENDULUM.rhs(&p, t, x, &[], dx);
    let x0 = [0.3, -0.2];
    assert_eq!(
        heun_step(&PENDULUM, &p, 0.1, 0.01, &x0, &[]).unwrap(),
        heun_step_fn(&mut f, 0.1, 0.01, &x0).unwrap()
    );
    assert_eq!(
        midpoint_step(&PENDULUM, &p, 0.1, 0.01, &x0, &[]).unwrap(),
        midpoint_step_fn(&mut f, 0.1, 0.01, &x0).unwrap()
    );
}

// ---------------------------------------------------------------------------
// Dopri5.

#[test]
fn dopri5_error_is_proportional_to_tolerance() {
    let t_end = 10.0 * 2.0 * PI;
    let exact = oscillator_exact(t_end);
    let mut prev: Option<(f64, f64)> = None;
    for k in 4..=12 {
        let tol = 10f64.powi(-k);
        let sol = Dopri5::new()
            .rtol(tol)
            .atol(tol)
            .solve(oscillator, 0.0, &[1.0, 0.0], t_end)
            .unwrap();
        let e = err2(&sol.x, &exact);
        println!(
            "tol {tol:.0e}: error {e:.3e} (error/tol {:.2}), {:?}",
            e / tol,
            sol.stats
        );
        assert_eq!(sol.t, t_end);
        // Global error over 10 periods within a modest factor of the tolerance.
        assert!(e < 50.0 * tol, "tol {tol:e}: error {e:e}");
        assert!(
            e > 1e-3 * tol,
            "tol {tol:e}: error {e:e} suspiciously small"
        );
        if let Some((pe, ptol)) = prev {
            // A tenfold tighter tolerance gives a roughly tenfold smaller error.
            let ratio = pe / e;
            assert!(
                (2.0..60.0).contains(&ratio),
                "tol {ptol:e} -> {tol:e}: error ratio {ratio}"
            );
        }
        prev = Some((e, tol));
    }
}

#[test]
fn dopri5_work_at_1e10_and_fsal_accounting() {
    let t_end = 10.0 * 2.0 * PI;
    let sol = Dopri5::new()
        .rtol(1e-10)
        .atol(1e-10)
        .solve(oscillator, 0.0, &[1.0, 0.0], t_end)
        .unwrap();
    let e = err2(&sol.x, &oscillator_exact(t_end));
    println!(
        "oscillator, 10 periods, tol 1e-10: error {e:.3e}, {:?}",
        sol.stats
    );
    let Stats {
        rhs_calls,
        accepted,
        rejected,
    } = sol.stats;
    // FSAL: one initial call, one for the initial step, 6 per step.
    assert_eq!(rhs_calls, 2 + 6 * (accepted + rejected));
    assert!(rhs_calls < 12_000, "{rhs_calls}");
    assert!(e < 1e-8);
    // A given first step skips the estimate.
    let sol = Dopri5::new()
        .rtol(1e-10)
        .atol(1e-10)
        .h_init(Some(1e-3))
        .solve(oscillator, 0.0, &[1.0, 0.0], t_end)
        .unwrap();
    assert_eq!(
        sol.stats.rhs_calls,
        1 + 6 * (sol.stats.accepted + sol.stats.rejected)
    );
}

#[test]
fn dopri5_elementary_controller_also_works() {
    let t_end = 10.0 * 2.0 * PI;
    let sol = Dopri5::new()
        .rtol(1e-8)
        .atol(1e-8)
        .beta(0.0)
        .solve(oscillator, 0.0, &[1.0, 0.0], t_end)
        .unwrap();
    assert!(err2(&sol.x, &oscillator_exact(t_end)) < 1e-6);
}

/// x' = −λ (x − cos t), x(0) = 0: exact solution known.
const LAMBDA: f64 = 1000.0;

fn stiff(t: f64, x: &[f64; 1], dx: &mut [f64; 1]) -> Result<(), ModelError> {
    dx[0] = -LAMBDA * (x[0] - t.cos());
    Ok(())
}

fn stiff_exact(t: f64) -> f64 {
    let l2 = LAMBDA * LAMBDA;
    LAMBDA * (LAMBDA * t.cos() + t.sin()) / (l2 + 1.0) - (-LAMBDA * t).exp() * l2 / (l2 + 1.0)
}

#[test]
fn dopri5_rejects_steps_on_a_stiff_problem_without_failing() {
    let sol = Dopri5::new()
        .rtol(1e-6)
        .atol(1e-9)
        .solve(stiff, 0.0, &[0.0], 5.0)
        .unwrap();
    let e = (sol.x[0] - stiff_exact(5.0)).abs();
    println!("stiff λ = {LAMBDA}: error {e:.3e}, {:?}", sol.stats);
    assert!(sol.stats.rejected > 0, "{:?}", sol.stats);
    assert!(e < 1e-5, "{e}");
    // Stability bounds the step near 3.3/λ: about 5 / 3.3e-3 ≈ 1500 steps.
    assert!(sol.stats.accepted > 1000, "{:?}", sol.stats);
}

#[test]
fn dense_output_is_as_accurate_as_the_steps() {
    let tol = 1e-8;
    let solver = Dopri5::new().rtol(tol).atol(tol);
    let t_end = 4.0 * PI;
    let mut out: Vec<(f64, [f64; 2])> = (0..=400)
        .map(|i| (t_end * i as f64 / 400.0, [f64::NAN; 2]))
        .collect();
    let sol = solver
        .solve_at(oscillator, 0.0, &[1.0, 0.0], &mut out)
        .unwrap();
    assert_eq!(sol.outputs, out.len());
    assert_eq!(sol.t, t_end);
    let end_error = err2(&sol.x, &oscillator_exact(t_end));
    let dense_error = out
        .iter()
        .map(|(t, x)| err2(x, &oscillator_exact(*t)))
        .fold(0.0, f64::max);
    println!(
        "dense output: max error {dense_error:.3e}, step-end error {end_error:.3e}, {} steps",
        sol.stats.accepted
    );
    assert!(dense_error < 10.0 * tol, "{dense_error}");
    assert!(dense_error < 20.0 * end_error.max(tol / 10.0));
    // Many more outputs than steps: outputs are interpolated, not stepped to.
    assert!(sol.stats.accepted < 200);
    // The same with a callback.
    let times: Vec<f64> = out.iter().map(|o| o.0).collect();
    let mut seen = Vec::new();
    let sol2 = solver
        .solve_with(
            oscillator,
            0.0,
            &[1.0, 0.0],
            t_end,
            &times,
            &mut |t, x| seen.push((t, *x)),
            None,
        )
        .unwrap();
    assert_eq!(sol2.x, sol.x);
    assert_eq!(seen, out);
}

#[test]
fn event_locates_a_falling_body_hitting_the_ground() {
    let (g, h0) = (9.81, 20.0);
    let f = |_t: f64, x: &[f64; 2], dx: &mut [f64; 2]| -> Result<(), ModelError> {
        dx[0] = x[1];
        dx[1] = -g;
        Ok(())
    };
    let sol = Dopri5::new()
        .event_tol(1e-12)
        .solve_until(f, |_t, x: &[f64; 2]| x[0], 0.0, &[h0, 0.0], 100.0)
        .unwrap();
    let exact = (2.0 * h0 / g).sqrt();
    println!(
        "falling body: t = {} (exact {exact}, diff {:.2e}), {:?}",
        sol.t,
        sol.t - exact,
        sol.stats
    );
    assert!(sol.event);
    assert!((sol.t - exact).abs() < 1e-11);
    assert!(sol.x[0].abs() < 1e-9 && sol.x[0] <= 0.0);
    assert!((sol.x[1] + (2.0 * g * h0).sqrt()).abs() < 1e-9);
}

#[test]
fn event_on_a_non_polynomial_solution_stops_outputs() {
    // The oscillator's velocity −sin t turns positive at t = π.
    let times = [1.0, 2.0, 3.0, 4.0, 5.0];
    let mut seen = Vec::new();
    let mut g = |_t: f64, x: &[f64; 2]| x[1];
    // g is 0 at t0: not an event.
    let sol = Dopri5::new()
        .rtol(1e-10)
        .atol(1e-12)
        .solve_with(
            oscillator,
            0.0,
            &[1.0, 0.0],
            10.0,
            &times,
            &mut |t, _x| seen.push(t),
            Some(&mut g),
        )
        .unwrap();
    assert!(sol.event);
    assert!((sol.t - PI).abs() < 1e-9, "{}", sol.t - PI);
    assert_eq!(seen, [1.0, 2.0, 3.0]);
    assert_eq!(sol.outputs, 3);
    // No sign change: runs to the end.
    let sol = Dopri5::new()
        .solve_until(oscillator, |_t, _x: &[f64; 2]| 1.0, 0.0, &[1.0, 0.0], 1.0)
        .unwrap();
    assert!(!sol.event);
    assert_eq!(sol.t, 1.0);
}

#[test]
fn backward_integration() {
    let f = |_t: f64, x: &[f64; 1], dx: &mut [f64; 1]| -> Result<(), ModelError> {
        dx[0] = -x[0];
        Ok(())
    };
    let e1 = (-1.0f64).exp();
    let mut out = [(0.5, [0.0]), (0.0, [0.0])];
    let sol = Dopri5::new()
        .rtol(1e-10)
        .atol(1e-12)
        .solve_at(f, 1.0, &[e1], &mut out)
        .unwrap();
    assert_eq!(sol.t, 0.0);
    assert!((sol.x[0] - 1.0).abs() < 1e-9);
    assert!((out[0].1[0] - (-0.5f64).exp()).abs() < 1e-9);
}

#[test]
fn f32_and_dual_states() {
    // f32 state.
    let f = |_t: f32, x: &[f32; 1], dx: &mut [f32; 1]| -> Result<(), ModelError> {
        dx[0] = -x[0];
        Ok(())
    };
    let sol = Dopri5::new()
        .rtol(1e-5)
        .atol(1e-6)
        .solve(f, 0.0, &[1.0f32], 2.0)
        .unwrap();
    assert!((sol.x[0] as f64 - (-2.0f64).exp()).abs() < 1e-4);
    // Dual numbers: d x(t) / d x0 for x' = −x is exp(−t).
    let f = |_t: Dual64, x: &[Dual64; 1], dx: &mut [Dual64; 1]| -> Result<(), ModelError> {
        dx[0] = -x[0];
        Ok(())
    };
    let sol = Dopri5::new()
        .rtol(1e-10)
        .atol(1e-12)
        .solve(f, 0.0, &[Dual64::new(2.0, 1.0)], 2.0)
        .unwrap();
    assert!((sol.x[0].re - 2.0 * (-2.0f64).exp()).abs() < 1e-9);
    assert!((sol.x[0].eps - (-2.0f64).exp()).abs() < 1e-9);
}

// ---------------------------------------------------------------------------
// Typed errors.

#[test]
fn nan_rhs_is_non_finite() {
    let nan = |_t: f64, _x: &[f64; 1], dx: &mut [f64; 1]| -> Result<(), ModelError> {
        dx[0] = f64::NAN;
        Ok(())
    };
    assert_eq!(
        Dopri5::new().solve(nan, 0.0, &[1.0], 1.0),
        Err(IntegrateError::NonFinite { t: 0.0 })
    );
    // NaN only past t = 0.5: the step is shrunk, then the failure reported
    // at the last good time.
    let late = |t: f64, x: &[f64; 1], dx: &mut [f64; 1]| -> Result<(), ModelError> {
        dx[0] = if t > 0.5 { f64::NAN } else { -x[0] };
        Ok(())
    };
    match Dopri5::new().solve(late, 0.0, &[1.0], 1.0) {
        Err(IntegrateError::NonFinite { t }) => assert!(t <= 0.5 && t > 0.49, "{t}"),
        other => panic!("{other:?}"),
    }
    // A non-finite initial state.
    assert_eq!(
        Dopri5::new().solve(oscillator, 0.0, &[f64::NAN, 0.0], 1.0),
        Err(IntegrateError::NonFinite { t: 0.0 })
    );
    // Blow-up in finite time (x' = x², singular at t = 1): an error near
    // t = 1, no panic.
    let blow = |_t: f64, x: &[f64; 1], dx: &mut [f64; 1]| -> Result<(), ModelError> {
        dx[0] = x[0] * x[0];
        Ok(())
    };
    let r = Dopri5::new().solve(blow, 0.0, &[1.0], 2.0);
    println!("blow-up: {r:?}");
    assert!(matches!(
        r,
        Err(IntegrateError::StepSizeTooSmall { t, .. } | IntegrateError::NonFinite { t }) if (t - 1.0).abs() < 1e-3
    ));
}

#[test]
fn step_underflow_and_too_many_steps() {
    let r = Dopri5::new()
        .rtol(1e-10)
        .h_min(0.5)
        .solve(oscillator, 0.0, &[1.0, 0.0], 10.0);
    assert!(
        matches!(r, Err(IntegrateError::StepSizeTooSmall { h, .. }) if h < 0.5),
        "{r:?}"
    );
    let r = Dopri5::new()
        .max_steps(10)
        .solve(oscillator, 0.0, &[1.0, 0.0], 1000.0);
    assert!(
        matches!(r, Err(IntegrateError::TooManySteps { steps: 10, t }) if t > 0.0),
        "{r:?}"
    );
}

#[test]
fn model_and_input_errors_are_typed() {
    // rhs errors are passed on.
    let failing = |_t: f64, _x: &[f64; 1], _dx: &mut [f64; 1]| -> Result<(), ModelError> {
        Err(ModelError::UnknownScene { index: 3 })
    };
    assert_eq!(
        Dopri5::new().solve(failing, 0.0, &[1.0], 1.0),
        Err(IntegrateError::Model(ModelError::UnknownScene { index: 3 }))
    );
    // Wrong state length for the model.
    assert!(matches!(
        Dopri5::new().solve_model(&PENDULUM, &[], 0.0, &[0.1, 0.0, 0.0], 1.0),
        Err(IntegrateError::Model(ModelError::Length { .. }))
    ));
    // Invalid settings and output times.
    let bad = |s: Dopri5| s.solve(oscillator, 0.0, &[1.0, 0.0], 1.0);
    for s in [
        Dopri5::new().rtol(-1.0),
        Dopri5::new().rtol(0.0).atol(0.0),
        Dopri5::new().atol(f64::NAN),
        Dopri5::new().h_init(Some(0.0)),
        Dopri5::new().h_max(Some(-1.0)),
        Dopri5::new().beta(0.5),
    ] {
        assert!(matches!(bad(s), Err(IntegrateError::InvalidInput { .. })));
    }
    assert!(matches!(
        Dopri5::new().solve(oscillator, 0.0, &[1.0, 0.0], f64::INFINITY),
        Err(IntegrateError::InvalidInput { .. })
    ));
    let mut out = [(1.0, [0.0; 2]), (0.5, [0.0; 2])];
    assert!(matches!(
        Dopri5::new().solve_at(oscillator, 0.0, &[1.0, 0.0], &mut out),
        Err(IntegrateError::InvalidInput { .. })
    ));
    // Errors display.
    let e = IntegrateError::StepSizeTooSmall { t: 1.0, h: 1e-20 };
    assert!(e.to_string().contains("too small"));
}

// ---------------------------------------------------------------------------
// A hand-written Model.

/// The exact period of the pendulum from amplitude θ0 (by the AGM).
fn pendulum_period(theta0: f64) -> f64 {
    let (mut a, mut b) = (1.0f64, (theta0 / 2.0).cos());
    for _ in 0..20 {
        (a, b) = ((a + b) / 2.0, (a * b).sqrt());
    }
    2.0 * PI * (PENDULUM.l / PENDULUM.g).sqrt() / a
}

#[test]
fn dopri5_integrates_a_model() {
    let theta0 = 1.0;
    let energy = |x: &[f64; 2]| 0.5 * x[1] * x[1] - PENDULUM.g / PENDULUM.l * x[0].cos();
    let x0 = [theta0, 0.0];
    let period = pendulum_period(theta0);
    let solver = Dopri5::new().rtol(1e-10).atol(1e-12);

    // After one exact period the state returns.
    let sol = solver
        .solve_model(&PENDULUM, &[], 0.0, &x0, period)
        .unwrap();
    println!("pendulum, one period: {:?} {:?}", sol.x, sol.stats);
    assert!((sol.x[0] - theta0).abs() < 1e-8 && sol.x[1].abs() < 1e-7);
    assert!((energy(&sol.x) - energy(&x0)).abs() < 1e-8);

    // The quarter period as an event (θ = 0).
    let sol = solver
        .solve_model_until(&PENDULUM, &[], |_t, x: &[f64; 2]| x[0], 0.0, &x0, 10.0)
        .unwrap();
    assert!(sol.event);
    assert!(
        (sol.t - period / 4.0).abs() < 1e-9,
        "{}",
        sol.t - period / 4.0
    );

    // Outputs at times agree with the fine fixed-step RK4.
    let mut out = [(0.3, [0.0; 2]), (0.7, [0.0; 2]), (1.3, [0.0; 2])];
    solver
        .solve_model_at(&PENDULUM, &[], 0.0, &x0, &mut out)
        .unwrap();
    let p = PENDULUM.prepare::<f64>();
    for (t, x) in out {
        let r = appell_integrate::rk4(&PENDULUM, &p, 0.0, &x0, t / 2000.0, 2000, &[]).unwrap();
        assert!(err2(&x, &r) < 1e-9, "t = {t}: {x:?} vs {r:?}");
    }
}

#[test]
fn dopri5_van_der_pol_mu_100_rejects_and_succeeds() {
    // Van der Pol with μ = 100 over one relaxation cycle: stiff on the slow
    // branches, fast jumps between them; the controller rejects steps at
    // the stability limit and after every jump.
    let mu = 100.0;
    let f = move |_t: f64, x: &[f64; 2], dx: &mut [f64; 2]| -> Result<(), ModelError> {
        dx[0] = x[1];
        dx[1] = mu * (1.0 - x[0] * x[0]) * x[1] - x[0];
        Ok(())
    };
    let sol = Dopri5::new()
        .rtol(1e-6)
        .atol(1e-6)
        .solve(f, 0.0, &[2.0, 0.0], 200.0)
        .unwrap();
    println!("van der Pol μ = 100: x = {:?}, {:?}", sol.x, sol.stats);
    assert!(sol.stats.rejected > 10, "{:?}", sol.stats);
    assert!(sol.x[0].abs() < 2.1);
    // The period is T ≈ (3 − 2 ln 2) μ ≈ 161.4; starting at x = 2 on the
    // slow branch, x first jumps through 0 near T/2 ≈ 81 (an event).
    let sol80 = Dopri5::new()
        .rtol(1e-6)
        .atol(1e-6)
        .solve_until(f, |_t, x: &[f64; 2]| x[0], 0.0, &[2.0, 0.0], 200.0)
        .unwrap();
    assert!(sol80.event);
    println!("first zero of x at t = {}", sol80.t);
    assert!((sol80.t - 80.0).abs() < 3.0, "{}", sol80.t);
}
