//! Accuracy, stability, work and failure modes of [`Radau5`] on classical
//! test problems with known solutions or tight references.

use super::{Radau5, Radau5Solution};
use crate::{IntegrateError, ProjectionFailed, TrBdf2};
use appell_core::ModelError;

type R = Result<(), ModelError>;

/// x' = −2 t x², x(0) = 1: x = 1/(1 + t²) (nonlinear, non-autonomous).
fn bump(t: f64, x: &[f64], dx: &mut [f64]) -> R {
    dx[0] = -2.0 * t * x[0] * x[0];
    Ok(())
}

fn bump_jac(t: f64, x: &[f64], j: &mut [f64]) -> R {
    j[0] = -4.0 * t * x[0];
    Ok(())
}

/// x'' = −x + cos 2t from rest: x = (cos t − cos 2t)/3 (linear, forced).
fn forced(t: f64, x: &[f64], dx: &mut [f64]) -> R {
    dx[0] = x[1];
    dx[1] = -x[0] + (2.0 * t).cos();
    Ok(())
}

fn forced_jac(_t: f64, _x: &[f64], j: &mut [f64]) -> R {
    j.copy_from_slice(&[0.0, 1.0, -1.0, 0.0]);
    Ok(())
}

fn forced_exact(t: f64) -> [f64; 2] {
    [
        (t.cos() - (2.0 * t).cos()) / 3.0,
        (-t.sin() + 2.0 * (2.0 * t).sin()) / 3.0,
    ]
}

/// Van der Pol, μ = 1000: x'' = μ (1 − x²) x' − x.
const MU: f64 = 1000.0;

fn vdp(_t: f64, x: &[f64], dx: &mut [f64]) -> R {
    dx[0] = x[1];
    dx[1] = MU * (1.0 - x[0] * x[0]) * x[1] - x[0];
    Ok(())
}

fn vdp_jac(_t: f64, x: &[f64], j: &mut [f64]) -> R {
    j.copy_from_slice(&[
        0.0,
        1.0,
        -2.0 * MU * x[0] * x[1] - 1.0,
        MU * (1.0 - x[0] * x[0]),
    ]);
    Ok(())
}

/// Robertson's chemical kinetics.
fn robertson(_t: f64, y: &[f64], dy: &mut [f64]) -> R {
    let (a, b, c) = (0.04 * y[0], 1e4 * y[1] * y[2], 3e7 * y[1] * y[1]);
    dy[0] = -a + b;
    dy[1] = a - b - c;
    dy[2] = c;
    Ok(())
}

fn robertson_jac(_t: f64, y: &[f64], j: &mut [f64]) -> R {
    j.copy_from_slice(&[
        -0.04,
        1e4 * y[2],
        1e4 * y[1],
        0.04,
        -1e4 * y[2] - 6e7 * y[1],
        -1e4 * y[1],
        0.0,
        6e7 * y[1],
        0.0,
    ]);
    Ok(())
}

/// A pendulum of unit length and gravity in Cartesian coordinates
/// `(x, y, vx, vy)`, the rod force from the constraint's second
/// derivative: it keeps x² + y² = 1 only up to the integration error.
fn pendulum(_t: f64, s: &[f64], ds: &mut [f64]) -> R {
    let (x, y, vx, vy) = (s[0], s[1], s[2], s[3]);
    let lambda = (vx * vx + vy * vy - y) / (x * x + y * y);
    ds.copy_from_slice(&[vx, vy, -lambda * x, -lambda * y - 1.0]);
    Ok(())
}

fn pendulum_jac(t: f64, s: &[f64], j: &mut [f64]) -> R {
    let (mut a, mut b) = ([0.0; 4], [0.0; 4]);
    for c in 0..4 {
        let d = 1e-7 * (1.0 + s[c].abs());
        let (mut sp, mut sm) = ([s[0], s[1], s[2], s[3]], [s[0], s[1], s[2], s[3]]);
        sp[c] += d;
        sm[c] -= d;
        pendulum(t, &sp, &mut a)?;
        pendulum(t, &sm, &mut b)?;
        for r in 0..4 {
            j[r * 4 + c] = (a[r] - b[r]) / (2.0 * d);
        }
    }
    Ok(())
}

fn onto_circle(_t: f64, s: &mut [f64]) -> Result<(), ProjectionFailed> {
    let r = s[0].hypot(s[1]);
    if r.is_nan() || r <= 0.0 {
        return Err(ProjectionFailed {
            reason: "no direction",
        });
    }
    s[0] /= r;
    s[1] /= r;
    let radial = s[0] * s[2] + s[1] * s[3];
    s[2] -= radial * s[0];
    s[3] -= radial * s[1];
    Ok(())
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(u, v)| (u - v).abs())
        .fold(0.0, f64::max)
}

/// Fixed steps of `t_end/n`: a loose tolerance (a linear problem with its
/// exact Jacobian solves Newton exactly anyway) and `h_max` the step.
fn fixed_steps(n: usize, t_end: f64) -> Radau5Solution {
    let h = t_end / n as f64;
    let sol = Radau5::new()
        .rtol(1.0)
        .atol(1.0)
        .h0(Some(h))
        .h_max(Some(h))
        .solve(forced, forced_jac, 0.0, &[0.0, 0.0], t_end)
        .unwrap();
    assert_eq!(sol.stats.accepted, n, "{:?}", sol.stats);
    sol
}

#[test]
fn fixed_steps_converge_with_order_five() {
    let t_end = 4.0;
    let errs: Vec<f64> = [8, 16, 32, 64]
        .iter()
        .map(|&n| max_diff(&fixed_steps(n, t_end).x, &forced_exact(t_end)))
        .collect();
    for w in errs.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!(
            (4.6..5.6).contains(&order),
            "{errs:?}: observed order {order}"
        );
    }
}

#[test]
fn tolerance_sweep_shows_order_five_on_a_nonlinear_problem() {
    let exact = 1.0 / (1.0 + 25.0);
    let run = |tol: f64| {
        let sol = Radau5::new()
            .rtol(tol)
            .atol(tol)
            .solve(bump, bump_jac, 0.0, &[1.0], 5.0)
            .unwrap();
        let e = (sol.x[0] - exact).abs();
        (e, sol.stats.accepted as f64)
    };
    let (e1, n1) = run(1e-5);
    let (e2, n2) = run(1e-11);
    // Achieved accuracy follows the tolerance (RADAU5's mapping)...
    assert!(e1 < 1e-4 && e2 < 1e-10, "{e1:e} {e2:e}");
    assert!(e2 < 1e-4 * e1, "{e1:e} {e2:e}");
    // ...and the error falls with the number of steps like n^(−5).
    let order = (e1 / e2).ln() / (n2 / n1).ln();
    assert!(
        (3.5..7.5).contains(&order),
        "order {order}: {n1} → {n2} steps"
    );
}

#[test]
fn stiff_decay_is_damped_at_any_step_l_stability() {
    for lambda in [1.0, 1e2, 1e4, 1e6] {
        let f = move |_t: f64, x: &[f64], dx: &mut [f64]| -> R {
            dx[0] = -lambda * x[0];
            Ok(())
        };
        let jac = move |_t: f64, _x: &[f64], j: &mut [f64]| -> R {
            j[0] = -lambda;
            Ok(())
        };
        // Ten fixed steps of 1: each multiplies x by R(−λ), |R| < 1 and
        // R(z) ~ −3/z → 0 (for λ = 1, R(−1) agrees with e^(−1) to 1e-4).
        let mut out: Vec<(f64, Vec<f64>)> = (1..=10).map(|k| (k as f64, vec![])).collect();
        let sol = Radau5::new()
            .rtol(1.0)
            .atol(1.0)
            .h0(Some(1.0))
            .h_max(Some(1.0))
            .solve_at(f, jac, 0.0, &[1.0], &mut out)
            .unwrap();
        assert_eq!(sol.stats.accepted, 10);
        // R(z) = (1 + 2z/5 + z²/20)/(1 − 3z/5 + 3z²/20 − z³/60).
        let z = -lambda;
        let r = (1.0 + 0.4 * z + z * z / 20.0) / (1.0 - 0.6 * z + 0.15 * z * z - z * z * z / 60.0);
        assert!(r.abs() < 1.0 && (lambda < 1e6 || r.abs() < 4e-6), "{r}");
        let mut prev = 1.0_f64;
        for (_t, x) in &out {
            assert!(
                (x[0] - r * prev).abs() <= 1e-8 * prev.abs(),
                "λ = {lambda}: {out:?}"
            );
            prev = x[0];
        }
        if lambda >= 1e4 {
            assert!(sol.x[0].abs() < 1e-30, "λ = {lambda}: {}", sol.x[0]);
        }
        // Adaptive: the step is not limited by stability.
        let sol = Radau5::new()
            .rtol(1e-6)
            .atol(1e-9)
            .solve(f, jac, 0.0, &[1.0], 100.0)
            .unwrap();
        assert!(sol.x[0].abs() < 1e-9, "λ = {lambda}: {}", sol.x[0]);
        assert!(sol.stats.accepted < 100, "λ = {lambda}: {:?}", sol.stats);
    }
}

#[test]
fn van_der_pol_mu_1000_matches_a_tight_reference() {
    let x0 = [2.0, 0.0];
    let t_end = 3000.0;
    let reference = Radau5::new()
        .rtol(1e-12)
        .atol(1e-12)
        .solve(vdp, vdp_jac, 0.0, &x0, t_end)
        .unwrap();
    let sol = Radau5::new()
        .rtol(1e-6)
        .atol(1e-6)
        .solve(vdp, vdp_jac, 0.0, &x0, t_end)
        .unwrap();
    let s = sol.stats;
    let rel = (sol.x[0] - reference.x[0]).abs() / reference.x[0].abs();
    println!(
        "μ = 1000 to {t_end}: x = {:?} (reference {:?}), {s:?}",
        sol.x, reference.x
    );
    println!("reference: {:?}", reference.stats);
    assert!(rel < 1e-5, "relative error {rel:e}");
    // Two relaxation jumps (near 807 and 2421) back on the negative branch.
    assert!(sol.x[0] < -1.0 && sol.x[0] > -2.1, "{:?}", sol.x);
    assert!(s.accepted + s.rejected < 2_000, "{s:?}");
    // The Jacobian is reused across steps and so are factorizations.
    assert!(s.jacobians < s.accepted, "{s:?}");
    assert!(s.lu_factorizations < s.accepted + s.rejected, "{s:?}");
}

#[test]
fn robertson_conserves_mass_and_matches_the_classical_values() {
    let mut out = vec![(40.0, vec![]), (1e5, vec![])];
    let sol = Radau5::new()
        .rtol(1e-8)
        .atol(1e-14)
        .solve_at(robertson, robertson_jac, 0.0, &[1.0, 0.0, 0.0], &mut out)
        .unwrap();
    println!("Robertson to 1e5: {:?}, {:?}", sol.x, sol.stats);
    for (t, y) in &out {
        let mass: f64 = y.iter().sum();
        assert!((mass - 1.0).abs() < 1e-10, "t = {t}: {mass}");
        assert!(y.iter().all(|&v| v >= -1e-14), "t = {t}: {y:?}");
    }
    // The classical values at t = 40.
    let y = &out[0].1;
    let expected = [0.715_827_068_7, 9.185_534_764e-6, 0.284_163_745_7];
    for (u, v) in y.iter().zip(expected) {
        assert!((u - v).abs() < 1e-7 * v, "{y:?}");
    }
    assert!(sol.stats.accepted < 500, "{:?}", sol.stats);
}

#[test]
fn dense_output_is_accurate_between_steps() {
    let mut out: Vec<(f64, Vec<f64>)> = (1..=200).map(|k| (k as f64 * 0.025, vec![])).collect();
    let sol = Radau5::new()
        .rtol(1e-8)
        .atol(1e-10)
        .solve_at(bump, bump_jac, 0.0, &[1.0], &mut out)
        .unwrap();
    assert_eq!(sol.outputs, 200);
    // Far more outputs than steps: most are interpolated.
    assert!(sol.stats.accepted < 100, "{:?}", sol.stats);
    let worst = out
        .iter()
        .map(|(t, x)| (x[0] - 1.0 / (1.0 + t * t)).abs())
        .fold(0.0, f64::max);
    let end = (sol.x[0] - 1.0 / 26.0).abs();
    println!("dense output: worst error {worst:e}, end error {end:e}");
    // The polynomial is of local order 4 (the step ends superconverge to
    // order 6): between steps the error is at the level of the tolerance.
    assert!(worst < 1e-7, "{worst:e}");
    assert!(end < 1e-9, "{end:e}");
    // The same steps as without outputs (no extra work).
    let plain = Radau5::new()
        .rtol(1e-8)
        .atol(1e-10)
        .solve(bump, bump_jac, 0.0, &[1.0], 5.0)
        .unwrap();
    assert_eq!(plain.stats, sol.stats);
    assert_eq!(plain.x, sol.x);
}

#[test]
fn events_are_located_on_the_dense_output() {
    // x = (cos t − cos 2t)/3 first returns to 0 at t = 2π/3 (cos t = cos 2t).
    let g = |_t: f64, x: &[f64]| x[0];
    let sol = Radau5::new().rtol(1e-10).atol(1e-12).solve_until(
        forced,
        forced_jac,
        g,
        0.0,
        &[0.0, 0.0],
        10.0,
    );
    // g = 0 at t0 is not an event; x > 0 at first, then crosses zero.
    let sol = sol.unwrap();
    assert!(sol.event);
    let te = 2.0 * core::f64::consts::PI / 3.0;
    assert!((sol.t - te).abs() < 1e-9, "{} vs {te}", sol.t);
    assert!(max_diff(&sol.x, &forced_exact(sol.t)) < 1e-9);
    // No crossing: the integration reaches its end.
    let g = |_t: f64, x: &[f64]| x[0] - 10.0;
    let sol = Radau5::new()
        .solve_until(forced, forced_jac, g, 0.0, &[0.0, 0.0], 10.0)
        .unwrap();
    assert!(!sol.event && sol.t == 10.0);
    // A non-finite event function is an error.
    let g = |_t: f64, _x: &[f64]| f64::NAN;
    assert!(matches!(
        Radau5::new().solve_until(forced, forced_jac, g, 0.0, &[0.0, 0.0], 1.0),
        Err(IntegrateError::NonFinite { .. })
    ));
}

#[test]
fn projection_keeps_the_pendulum_on_its_circle() {
    let x0 = [1.0, 0.0, 0.0, 0.0];
    let solver = Radau5::new().rtol(1e-5).atol(1e-7);
    let free = solver
        .solve(pendulum, pendulum_jac, 0.0, &x0, 100.0)
        .unwrap();
    let mut worst: f64 = 0.0;
    let mut checked = |t: f64, s: &mut [f64]| {
        let r = onto_circle(t, s);
        worst = worst.max((s[0] * s[0] + s[1] * s[1] - 1.0).abs());
        r
    };
    let kept = solver
        .solve_projected(pendulum, pendulum_jac, &mut checked, 0.0, &x0, 100.0)
        .unwrap();
    let drift = |s: &[f64]| (s[0] * s[0] + s[1] * s[1] - 1.0).abs();
    println!(
        "drift: free {:e}, projected {:e}",
        drift(&free.x),
        drift(&kept.x)
    );
    assert!(worst < 1e-14, "{worst:e}");
    assert!(drift(&kept.x) < 1e-14);
    assert!(drift(&free.x) > 1e-9, "{:e}", drift(&free.x));
    // The energy y + v²/2 = 0 stays close too.
    let energy = kept.x[1] + 0.5 * (kept.x[2] * kept.x[2] + kept.x[3] * kept.x[3]);
    assert!(energy.abs() < 1e-3, "{energy:e}");

    // A failing projection stops the integration with its reason.
    let fail_late = |t: f64, s: &mut [f64]| {
        if t > 1.0 {
            Err(ProjectionFailed { reason: "too late" })
        } else {
            onto_circle(t, s)
        }
    };
    match solver.solve_projected(pendulum, pendulum_jac, fail_late, 0.0, &x0, 10.0) {
        Err(IntegrateError::Projection { t, reason }) => {
            assert!(t > 1.0 && t < 10.0 && reason == "too late");
        }
        other => panic!("{other:?}"),
    }
    // So does a projection leaving a non-finite state.
    let nan = |_t: f64, s: &mut [f64]| {
        s[0] = f64::NAN;
        Ok(())
    };
    assert!(matches!(
        solver.solve_projected(pendulum, pendulum_jac, nan, 0.0, &x0, 1.0),
        Err(IntegrateError::Projection { .. })
    ));
}

#[test]
fn trbdf2_projection_keeps_the_pendulum_on_its_circle() {
    let x0 = [1.0, 0.0, 0.0, 0.0];
    let solver = TrBdf2::new().rtol(1e-5).atol(1e-7);
    let free = solver
        .solve(pendulum, pendulum_jac, 0.0, &x0, 20.0)
        .unwrap();
    let kept = solver
        .solve_projected(pendulum, pendulum_jac, onto_circle, 0.0, &x0, 20.0)
        .unwrap();
    let drift = |s: &[f64]| (s[0] * s[0] + s[1] * s[1] - 1.0).abs();
    assert!(drift(&kept.x) < 1e-14);
    assert!(drift(&free.x) > 1e-9, "{:e}", drift(&free.x));
    // A moved state costs one rhs call more per accepted step at most.
    assert!(kept.stats.rhs_calls <= free.stats.rhs_calls * 2 + kept.stats.accepted + 10);
    let fails = |_t: f64, _s: &mut [f64]| Err(ProjectionFailed { reason: "no" });
    assert!(matches!(
        solver.solve_projected(pendulum, pendulum_jac, fails, 0.0, &x0, 1.0),
        Err(IntegrateError::Projection { reason: "no", .. })
    ));
}

#[test]
fn invalid_settings_and_arguments_are_reported() {
    let bad = [
        Radau5::new().rtol(-1.0),
        Radau5::new().rtol(f64::INFINITY),
        Radau5::new().atol(f64::NAN),
        Radau5::new().rtol(0.0).atol(0.0),
        Radau5::new().h0(Some(0.0)),
        Radau5::new().h0(Some(f64::NAN)),
        Radau5::new().h_max(Some(0.0)),
        Radau5::new().h_max(Some(f64::NAN)),
        Radau5::new().max_steps(0),
        Radau5::new().newton_max_iter(0),
        Radau5::new().event_tol(f64::NAN),
        Radau5::new().event_tol(-1e-3),
    ];
    for s in bad {
        let r = s.solve(bump, bump_jac, 0.0, &[1.0], 1.0);
        assert!(
            matches!(r, Err(IntegrateError::InvalidInput { .. })),
            "{s:?}: {r:?}"
        );
    }
    let ok = Radau5::new();
    let invalid = |r: Result<Radau5Solution, IntegrateError>| {
        matches!(r, Err(IntegrateError::InvalidInput { .. }))
    };
    assert!(invalid(ok.solve(bump, bump_jac, f64::NAN, &[1.0], 1.0)));
    assert!(invalid(ok.solve(
        bump,
        bump_jac,
        0.0,
        &[1.0],
        f64::INFINITY
    )));
    let mut out = vec![(0.5, vec![]), (0.2, vec![])];
    assert!(invalid(ok.solve_at(bump, bump_jac, 0.0, &[1.0], &mut out)));
    let mut out = vec![(-0.5, vec![]), (1.0, vec![])];
    assert!(invalid(ok.solve_at(bump, bump_jac, 0.0, &[1.0], &mut out)));
    assert_eq!(
        ok.solve(bump, bump_jac, 0.0, &[f64::NAN], 1.0),
        Err(IntegrateError::NonFinite { t: 0.0 })
    );
}

#[test]
fn rhs_and_jacobian_errors_are_passed_on() {
    let error = ModelError::NonFinite { what: "test" };
    let failing = |t: f64, x: &[f64], dx: &mut [f64]| -> R {
        if t > 0.5 {
            return Err(ModelError::NonFinite { what: "test" });
        }
        bump(t, x, dx)
    };
    assert_eq!(
        Radau5::new().solve(failing, bump_jac, 0.0, &[1.0], 1.0),
        Err(IntegrateError::Model(error))
    );
    let failing_jac =
        |_t: f64, _x: &[f64], _j: &mut [f64]| -> R { Err(ModelError::NonFinite { what: "test" }) };
    assert_eq!(
        Radau5::new().solve(bump, failing_jac, 0.0, &[1.0], 1.0),
        Err(IntegrateError::Model(error))
    );
    // A rhs that turns NaN past a point: steps shrink, then NonFinite.
    let nan = |t: f64, x: &[f64], dx: &mut [f64]| -> R {
        dx[0] = if t > 0.5 { f64::NAN } else { -x[0] };
        Ok(())
    };
    let jac = |_t: f64, _x: &[f64], j: &mut [f64]| -> R {
        j[0] = -1.0;
        Ok(())
    };
    assert!(matches!(
        Radau5::new().solve(nan, jac, 0.0, &[1.0], 1.0),
        Err(IntegrateError::NonFinite { t }) if (0.4..=0.5).contains(&t)
    ));
    // A Jacobian that is NaN.
    let nan_jac = |_t: f64, _x: &[f64], j: &mut [f64]| -> R {
        j[0] = f64::NAN;
        Ok(())
    };
    assert_eq!(
        Radau5::new().solve(bump, nan_jac, 0.0, &[1.0], 1.0),
        Err(IntegrateError::NonFinite { t: 0.0 })
    );
}

#[test]
fn backward_integration_returns_to_the_start() {
    let solver = Radau5::new().rtol(1e-10).atol(1e-12);
    let fwd = solver
        .solve(forced, forced_jac, 0.0, &[0.0, 0.0], 3.0)
        .unwrap();
    let back = solver.solve(forced, forced_jac, 3.0, &fwd.x, 0.0).unwrap();
    assert_eq!(back.t, 0.0);
    assert!(max_diff(&back.x, &[0.0, 0.0]) < 1e-8, "{:?}", back.x);
    let zero = solver
        .solve(forced, forced_jac, 1.0, &[2.0, 3.0], 1.0)
        .unwrap();
    assert_eq!((zero.x, zero.stats.rhs_calls), (vec![2.0, 3.0], 0));
}

#[test]
fn jacobians_and_factorizations_are_reused() {
    // A linear problem: Newton converges at once, the Jacobian is kept
    // over all steps, accepted or rejected.
    let s = Radau5::new()
        .solve(forced, forced_jac, 0.0, &[0.0, 0.0], 20.0)
        .unwrap()
        .stats;
    assert!(s.jacobians == 1 && s.rejected > 0, "{s:?}");
    assert!(s.lu_factorizations < s.accepted / 2, "{s:?}");
    // Fixed steps: one factorization for all of them but the last.
    let s = fixed_steps(16, 4.0).stats;
    assert_eq!((s.jacobians, s.lu_factorizations), (1, 1), "{s:?}");
}

#[test]
fn a_larger_jacobian_reuse_keeps_jacobians_longer() {
    // Van der Pol, μ = 1000: about the same solution from fewer Jacobians.
    let run = |reuse| {
        Radau5::new()
            .rtol(1e-6)
            .atol(1e-6)
            .jacobian_reuse(reuse)
            .solve(vdp, vdp_jac, 0.0, &[2.0, 0.0], 3000.0)
            .unwrap()
    };
    let (fresh, kept) = (run(0.001), run(0.1));
    assert!(
        kept.stats.jacobians < fresh.stats.jacobians,
        "{:?} {:?}",
        kept.stats,
        fresh.stats
    );
    let rel = (kept.x[0] - fresh.x[0]).abs() / fresh.x[0].abs();
    assert!(rel < 1e-4, "{:?} {:?}", kept.x, fresh.x);
}
