//! The adaptive Dormand–Prince 8(5,3) integrator `Dop853`: order of
//! convergence, tolerance proportionality, dense output of order 7, events,
//! typed errors, work compared with `Dopri5`, and integration of a
//! hand-written `Model`.

use appell_core::{Model, ModelError};
use appell_integrate::{Dop853, Dopri5, IntegrateError, Stats};
use appell_test_models::*;
use num_dual::Dual64;
use std::f64::consts::PI;

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

/// Kepler problem (μ = 1), state (q1, q2, p1, p2).
fn kepler(_t: f64, x: &[f64; 4], dx: &mut [f64; 4]) -> Result<(), ModelError> {
    let r2 = x[0] * x[0] + x[1] * x[1];
    let r3 = r2 * r2.sqrt();
    dx[0] = x[2];
    dx[1] = x[3];
    dx[2] = -x[0] / r3;
    dx[3] = -x[1] / r3;
    Ok(())
}

/// Initial state of an orbit of eccentricity `e` starting at pericentre
/// (period 2π).
fn kepler_start(e: f64) -> [f64; 4] {
    [1.0 - e, 0.0, 0.0, ((1.0 + e) / (1.0 - e)).sqrt()]
}

fn err4(a: &[f64; 4], b: &[f64; 4]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// x' = x (1 − x) (logistic), x(0) = 1/10: a nonlinear problem with a
/// known solution.
fn logistic(_t: f64, x: &[f64; 1], dx: &mut [f64; 1]) -> Result<(), ModelError> {
    dx[0] = x[0] * (1.0 - x[0]);
    Ok(())
}

fn logistic_exact(t: f64) -> f64 {
    1.0 / (1.0 + 9.0 * (-t).exp())
}

const PENDULUM: Pendulum = Pendulum {
    m: 1.0,
    l: 1.0,
    g: 9.81,
};

// ---------------------------------------------------------------------------
// Order.

fn fixed_step_error(n: usize) -> f64 {
    let t_end = 16.0;
    let h = t_end / n as f64;
    let sol = Dop853::new()
        .adaptive(false)
        .h_init(Some(h))
        .solve(oscillator, 0.0, &[1.0, 0.0], t_end)
        .unwrap();
    assert_eq!(sol.t, t_end);
    assert_eq!(sol.stats.accepted, n);
    assert_eq!(sol.stats.rejected, 0);
    err2(&sol.x, &oscillator_exact(t_end))
}

#[test]
fn fixed_steps_converge_with_order_8() {
    let ns = [16, 24, 32, 48, 64];
    let errs: Vec<f64> = ns.iter().map(|&n| fixed_step_error(n)).collect();
    println!("fixed steps N {ns:?}: errors {errs:?}");
    for i in 1..ns.len() {
        let p = (errs[i - 1] / errs[i]).ln() / (ns[i] as f64 / ns[i - 1] as f64).ln();
        println!("  order between N = {} and {}: {p:.3}", ns[i - 1], ns[i]);
        assert!((p - 8.0).abs() < 0.3, "observed order {p}");
    }
    // The same on a nonlinear problem.
    let t_end = 8.0;
    let lerr = |n: usize| {
        let sol = Dop853::new()
            .adaptive(false)
            .h_init(Some(t_end / n as f64))
            .solve(logistic, 0.0, &[0.1], t_end)
            .unwrap();
        (sol.x[0] - logistic_exact(t_end)).abs()
    };
    let (e1, e2) = (lerr(8), lerr(16));
    let p = (e1 / e2).log2();
    println!("logistic: errors {e1:.3e} {e2:.3e}, order {p:.3}");
    assert!((p - 8.0).abs() < 0.3, "observed order {p}");
}

#[test]
fn error_is_proportional_to_tolerance() {
    let t_end = 10.0 * 2.0 * PI;
    let exact = oscillator_exact(t_end);
    let mut prev: Option<f64> = None;
    for k in 4..=12 {
        let tol = 10f64.powi(-k);
        let sol = Dop853::new()
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
        assert!(e < 50.0 * tol, "tol {tol:e}: error {e:e}");
        if let Some(pe) = prev {
            let ratio = pe / e;
            assert!((2.0..100.0).contains(&ratio), "tol {tol:e}: ratio {ratio}");
        }
        prev = Some(e);
    }
}

#[test]
fn fsal_accounting() {
    let sol = Dop853::new()
        .rtol(1e-10)
        .atol(1e-10)
        .solve(oscillator, 0.0, &[1.0, 0.0], 20.0)
        .unwrap();
    let Stats {
        rhs_calls,
        accepted,
        rejected,
    } = sol.stats;
    // One initial call, one for the initial step, 12 per accepted step and
    // 11 per rejected one.
    assert_eq!(rhs_calls, 2 + 12 * accepted + 11 * rejected);
    let sol = Dop853::new()
        .h_init(Some(1e-3))
        .solve(oscillator, 0.0, &[1.0, 0.0], 20.0)
        .unwrap();
    assert_eq!(
        sol.stats.rhs_calls,
        1 + 12 * sol.stats.accepted + 11 * sol.stats.rejected
    );
    // The PI controller works too.
    let sol = Dop853::new()
        .rtol(1e-9)
        .atol(1e-9)
        .beta(0.04)
        .solve(oscillator, 0.0, &[1.0, 0.0], 20.0)
        .unwrap();
    assert!(err2(&sol.x, &oscillator_exact(20.0)) < 1e-7);
}

// ---------------------------------------------------------------------------
// Work compared with Dopri5.

#[test]
fn fewer_rhs_calls_than_dopri5_at_tight_tolerances() {
    let t_end = 4.0 * 2.0 * PI;
    let x0 = kepler_start(0.5);
    for tol in [1e-6, 1e-9, 1e-12] {
        let d5 = Dopri5::new()
            .rtol(tol)
            .atol(tol)
            .solve(kepler, 0.0, &x0, t_end)
            .unwrap();
        let d8 = Dop853::new()
            .rtol(tol)
            .atol(tol)
            .solve(kepler, 0.0, &x0, t_end)
            .unwrap();
        let (e5, e8) = (err4(&d5.x, &x0), err4(&d8.x, &x0));
        println!(
            "Kepler e = 0.5, 4 orbits, tol {tol:.0e}: Dopri5 {} rhs / {} steps ({} rejected), \
             error {e5:.2e}; Dop853 {} rhs / {} steps ({} rejected), error {e8:.2e}",
            d5.stats.rhs_calls,
            d5.stats.accepted,
            d5.stats.rejected,
            d8.stats.rhs_calls,
            d8.stats.accepted,
            d8.stats.rejected
        );
        if tol == 1e-12 {
            assert!(
                2 * d8.stats.rhs_calls < d5.stats.rhs_calls,
                "{:?} vs {:?}",
                d8.stats,
                d5.stats
            );
            assert!(e8 < 1e-8 && e5 < 1e-8, "{e8:e} {e5:e}");
        }
    }
    let t_end = 10.0 * 2.0 * PI;
    for tol in [1e-6, 1e-9, 1e-12] {
        let d5 = Dopri5::new()
            .rtol(tol)
            .atol(tol)
            .solve(oscillator, 0.0, &[1.0, 0.0], t_end)
            .unwrap();
        let d8 = Dop853::new()
            .rtol(tol)
            .atol(tol)
            .solve(oscillator, 0.0, &[1.0, 0.0], t_end)
            .unwrap();
        let exact = oscillator_exact(t_end);
        let (e5, e8) = (err2(&d5.x, &exact), err2(&d8.x, &exact));
        println!(
            "oscillator, 10 periods, tol {tol:.0e}: Dopri5 {} rhs / {} steps, error {e5:.2e}; \
             Dop853 {} rhs / {} steps, error {e8:.2e}",
            d5.stats.rhs_calls, d5.stats.accepted, d8.stats.rhs_calls, d8.stats.accepted
        );
        if tol == 1e-12 {
            assert!(2 * d8.stats.rhs_calls < d5.stats.rhs_calls);
        }
    }
}

// ---------------------------------------------------------------------------
// Dense output.

#[test]
fn dense_output_is_as_accurate_as_the_steps() {
    let tol = 1e-10;
    let solver = Dop853::new().rtol(tol).atol(tol);
    let t_end = 2.0 * 2.0 * PI;
    let x0 = kepler_start(0.6);
    // The state at the output times, from a much tighter reference run
    // stopping at each time exactly.
    let n = 500;
    let mut out: Vec<(f64, [f64; 4])> = (0..=n)
        .map(|i| (t_end * i as f64 / n as f64, [f64::NAN; 4]))
        .collect();
    let sol = solver.solve_at(kepler, 0.0, &x0, &mut out).unwrap();
    assert_eq!(sol.outputs, out.len());
    assert_eq!(sol.t, t_end);
    let end_error = err4(&sol.x, &x0);
    let reference = Dop853::new().rtol(1e-14).atol(1e-14);
    let mut dense_error: f64 = 0.0;
    let mut x_ref = x0;
    let mut t_ref = 0.0;
    for (t, x) in &out {
        x_ref = reference.solve(kepler, t_ref, &x_ref, *t).unwrap().x;
        t_ref = *t;
        dense_error = dense_error.max(err4(x, &x_ref));
    }
    println!(
        "dense output (Kepler e = 0.6): max error {dense_error:.3e}, end error {end_error:.3e}, \
         {:?}",
        sol.stats
    );
    // Many more outputs than steps: outputs are interpolated.
    assert!(sol.stats.accepted < 200, "{:?}", sol.stats);
    assert!(dense_error < 20.0 * end_error.max(tol), "{dense_error:e}");
    // The same with a callback.
    let times: Vec<f64> = out.iter().map(|o| o.0).collect();
    let mut seen = Vec::new();
    let sol2 = solver
        .solve_with(
            kepler,
            0.0,
            &x0,
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
fn dense_output_has_order_7_inside_fixed_steps() {
    // One step of size h from 0 on the oscillator: the interpolant error at
    // interior points scales like h^8 (local error of an order-7 extension).
    let dense_err = |h: f64| {
        let mut out: Vec<(f64, [f64; 2])> =
            (1..10).map(|i| (h * i as f64 / 10.0, [0.0; 2])).collect();
        out.push((h, [0.0; 2]));
        Dop853::new()
            .adaptive(false)
            .h_init(Some(h))
            .solve_at(oscillator, 0.0, &[1.0, 0.0], &mut out)
            .unwrap();
        out.iter()
            .map(|(t, x)| err2(x, &oscillator_exact(*t)))
            .fold(0.0, f64::max)
    };
    let (e1, e2) = (dense_err(1.0), dense_err(0.5));
    let p = (e1 / e2).log2();
    println!("dense output local errors {e1:.3e} {e2:.3e}: slope {p:.2}");
    assert!((p - 8.0).abs() < 0.5, "{p}");
    // And the interpolant on many fixed steps is as accurate as the steps.
    let t_end = 8.0;
    let mut out: Vec<(f64, [f64; 2])> = (0..=997)
        .map(|i| (t_end * i as f64 / 997.0, [0.0; 2]))
        .collect();
    let sol = Dop853::new()
        .adaptive(false)
        .h_init(Some(0.25))
        .solve_at(oscillator, 0.0, &[1.0, 0.0], &mut out)
        .unwrap();
    let step_error = err2(&sol.x, &oscillator_exact(t_end));
    let dense_error = out
        .iter()
        .map(|(t, x)| err2(x, &oscillator_exact(*t)))
        .fold(0.0, f64::max);
    println!("fixed h = 0.25: step error {step_error:.3e}, dense error {dense_error:.3e}");
    assert!(dense_error < 10.0 * step_error.max(1e-14));
}

// ---------------------------------------------------------------------------
// Events.

#[test]
fn event_locates_a_falling_body_hitting_the_ground() {
    let (g, h0) = (9.81, 20.0);
    let f = |_t: f64, x: &[f64; 2], dx: &mut [f64; 2]| -> Result<(), ModelError> {
        dx[0] = x[1];
        dx[1] = -g;
        Ok(())
    };
    let sol = Dop853::new()
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
fn event_on_a_kepler_orbit_and_outputs_stop_there() {
    // q2 changes sign from + to − at apocentre, t = π.
    let x0 = kepler_start(0.5);
    let times = [1.0, 2.0, 3.0, 4.0, 5.0];
    let mut seen = Vec::new();
    let mut g = |_t: f64, x: &[f64; 4]| x[1];
    // g is 0 at t0: not an event.
    let sol = Dop853::new()
        .rtol(1e-11)
        .atol(1e-11)
        .event_tol(1e-13)
        .solve_with(
            kepler,
            0.0,
            &x0,
            10.0,
            &times,
            &mut |t, _x| seen.push(t),
            Some(&mut g),
        )
        .unwrap();
    println!("Kepler apocentre: t − π = {:.2e}", sol.t - PI);
    assert!(sol.event);
    assert!((sol.t - PI).abs() < 1e-9, "{}", sol.t - PI);
    assert!((sol.x[0] + 1.5).abs() < 1e-9, "{:?}", sol.x);
    assert_eq!(seen, [1.0, 2.0, 3.0]);
    assert_eq!(sol.outputs, 3);
    // No sign change: runs to the end.
    let sol = Dop853::new()
        .solve_until(oscillator, |_t, _x: &[f64; 2]| 1.0, 0.0, &[1.0, 0.0], 1.0)
        .unwrap();
    assert!(!sol.event);
    assert_eq!(sol.t, 1.0);
}

/// x' = −x in any scalar.
fn decay<T: Copy + std::ops::Neg<Output = T>>(
    _t: T,
    x: &[T; 1],
    dx: &mut [T; 1],
) -> Result<(), ModelError> {
    dx[0] = -x[0];
    Ok(())
}

#[test]
fn backward_integration_and_other_scalars() {
    let e1 = (-1.0f64).exp();
    let mut out = [(0.5, [0.0]), (0.0, [0.0])];
    let sol = Dop853::new()
        .rtol(1e-10)
        .atol(1e-12)
        .solve_at(decay, 1.0, &[e1], &mut out)
        .unwrap();
    assert_eq!(sol.t, 0.0);
    assert!((sol.x[0] - 1.0).abs() < 1e-9);
    assert!((out[0].1[0] - (-0.5f64).exp()).abs() < 1e-9);
    // f32 state.
    let sol = Dop853::new()
        .rtol(1e-5)
        .atol(1e-6)
        .solve(decay, 0.0, &[1.0f32], 2.0)
        .unwrap();
    assert!((sol.x[0] as f64 - (-2.0f64).exp()).abs() < 1e-4);
    // Dual numbers: d x(t) / d x0 for x' = −x is exp(−t).
    let sol = Dop853::new()
        .rtol(1e-10)
        .atol(1e-12)
        .solve(decay, 0.0, &[Dual64::new(2.0, 1.0)], 2.0)
        .unwrap();
    assert!((sol.x[0].re - 2.0 * (-2.0f64).exp()).abs() < 1e-9);
    assert!((sol.x[0].eps - (-2.0f64).exp()).abs() < 1e-9);
}

// ---------------------------------------------------------------------------
// Typed errors.

#[test]
fn non_finite_states_are_typed_errors() {
    let nan = |_t: f64, _x: &[f64; 1], dx: &mut [f64; 1]| -> Result<(), ModelError> {
        dx[0] = f64::NAN;
        Ok(())
    };
    assert_eq!(
        Dop853::new().solve(nan, 0.0, &[1.0], 1.0),
        Err(IntegrateError::NonFinite { t: 0.0 })
    );
    // NaN only past t = 0.5: the step is shrunk, then the failure reported
    // at the last good time.
    let late = |t: f64, x: &[f64; 1], dx: &mut [f64; 1]| -> Result<(), ModelError> {
        dx[0] = if t > 0.5 { f64::NAN } else { -x[0] };
        Ok(())
    };
    match Dop853::new().solve(late, 0.0, &[1.0], 1.0) {
        Err(IntegrateError::NonFinite { t }) => assert!(t <= 0.5 && t > 0.49, "{t}"),
        other => panic!("{other:?}"),
    }
    // With fixed steps, reported at once.
    match Dop853::new()
        .adaptive(false)
        .h_init(Some(0.1))
        .solve(late, 0.0, &[1.0], 1.0)
    {
        Err(IntegrateError::NonFinite { t }) => assert!((t - 0.5).abs() < 1e-9, "{t}"),
        other => panic!("{other:?}"),
    }
    // A non-finite initial state.
    assert_eq!(
        Dop853::new().solve(oscillator, 0.0, &[f64::NAN, 0.0], 1.0),
        Err(IntegrateError::NonFinite { t: 0.0 })
    );
    // Blow-up in finite time (x' = x², singular at t = 1).
    let blow = |_t: f64, x: &[f64; 1], dx: &mut [f64; 1]| -> Result<(), ModelError> {
        dx[0] = x[0] * x[0];
        Ok(())
    };
    let r = Dop853::new().solve(blow, 0.0, &[1.0], 2.0);
    println!("blow-up: {r:?}");
    assert!(matches!(
        r,
        Err(IntegrateError::StepSizeTooSmall { t, .. } | IntegrateError::NonFinite { t }) if (t - 1.0).abs() < 1e-3
    ));
    // A non-finite event function.
    let r = Dop853::new().solve_until(
        oscillator,
        |t, _x: &[f64; 2]| if t > 0.5 { f64::NAN } else { 1.0 },
        0.0,
        &[1.0, 0.0],
        2.0,
    );
    assert!(matches!(r, Err(IntegrateError::NonFinite { .. })), "{r:?}");
}

#[test]
fn step_underflow_and_too_many_steps() {
    let r =
        Dop853::new()
            .rtol(1e-13)
            .atol(1e-13)
            .h_min(0.5)
            .solve(oscillator, 0.0, &[1.0, 0.0], 10.0);
    assert!(
        matches!(r, Err(IntegrateError::StepSizeTooSmall { h, .. }) if h < 0.5),
        "{r:?}"
    );
    let r = Dop853::new()
        .max_steps(10)
        .solve(oscillator, 0.0, &[1.0, 0.0], 1000.0);
    assert!(
        matches!(r, Err(IntegrateError::TooManySteps { steps: 10, t }) if t > 0.0),
        "{r:?}"
    );
}

#[test]
fn model_and_input_errors_are_typed() {
    let failing = |_t: f64, _x: &[f64; 1], _dx: &mut [f64; 1]| -> Result<(), ModelError> {
        Err(ModelError::UnknownScene { index: 3 })
    };
    assert_eq!(
        Dop853::new().solve(failing, 0.0, &[1.0], 1.0),
        Err(IntegrateError::Model(ModelError::UnknownScene { index: 3 }))
    );
    assert!(matches!(
        Dop853::new().solve_model(&PENDULUM, &[], 0.0, &[0.1, 0.0, 0.0], 1.0),
        Err(IntegrateError::Model(ModelError::Length { .. }))
    ));
    let bad = |s: Dop853| s.solve(oscillator, 0.0, &[1.0, 0.0], 1.0);
    for s in [
        Dop853::new().rtol(-1.0),
        Dop853::new().rtol(0.0).atol(0.0),
        Dop853::new().atol(f64::NAN),
        Dop853::new().h_init(Some(0.0)),
        Dop853::new().h_init(Some(f64::INFINITY)),
        Dop853::new().h_max(Some(-1.0)),
        Dop853::new().h_min(f64::NAN),
        Dop853::new().beta(0.5),
        Dop853::new().event_tol(-1.0),
        Dop853::new().adaptive(false),
    ] {
        assert!(
            matches!(bad(s), Err(IntegrateError::InvalidInput { .. })),
            "{s:?}"
        );
    }
    assert!(matches!(
        Dop853::new().solve(oscillator, 0.0, &[1.0, 0.0], f64::INFINITY),
        Err(IntegrateError::InvalidInput { .. })
    ));
    let mut out = [(1.0, [0.0; 2]), (0.5, [0.0; 2])];
    assert!(matches!(
        Dop853::new().solve_at(oscillator, 0.0, &[1.0, 0.0], &mut out),
        Err(IntegrateError::InvalidInput { .. })
    ));
    // An empty interval returns at once.
    let sol = Dop853::new()
        .solve(oscillator, 1.0, &[1.0, 0.0], 1.0)
        .unwrap();
    assert_eq!(sol.stats, Stats::default());
}

#[test]
fn model_solvers_match_the_closure_solvers() {
    let prepared = PENDULUM.prepare::<f64>();
    let x0 = [0.3, 0.0];
    let solver = Dop853::new().rtol(1e-10).atol(1e-10);
    let a = solver.solve_model(&PENDULUM, &[], 0.0, &x0, 3.0).unwrap();
    let f = |t: f64, x: &[f64; 2], dx: &mut [f64; 2]| PENDULUM.rhs(&prepared, t, x, &[], dx);
    let b = solver.solve(f, 0.0, &x0, 3.0).unwrap();
    assert_eq!(a, b);
    let mut out = [(1.0, [0.0; 2]), (3.0, [0.0; 2])];
    let c = solver
        .solve_model_at(&PENDULUM, &[], 0.0, &x0, &mut out)
        .unwrap();
    assert_eq!(c.x, a.x);
    // The pendulum passes the vertical (θ = 0) going down first.
    let d = solver
        .solve_model_until(&PENDULUM, &[], |_t, x: &[f64; 2]| x[0], 0.0, &x0, 3.0)
        .unwrap();
    assert!(d.event && d.t > 0.0 && d.t < 3.0);
    assert!(d.x[0].abs() < 1e-9);
}
