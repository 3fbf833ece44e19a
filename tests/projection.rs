//! Projection onto the holonomic constraint manifold: the bicycle's pitch is
//! fixed by its lean and steer (the front wheel touches the ground); an
//! integrator lets it drift at the size of its local error, and
//! `project_holonomic` between output times puts it back without moving the
//! motion.

#[allow(dead_code)] // the model file's helpers serve other tests
#[path = "../examples/models/whipple_bicycle.rs"]
mod whipple_bicycle;

use appell::linearize::project_holonomic;
use appell::Model;
use whipple_bicycle::WhippleBicycle;

/// The norm of the holonomic residuals at a reduced bicycle state
/// (q4, q5, q7, u4, u6, u7), by the library's check with no tolerance.
fn residual(p: &WhippleBicycle, x: &[f64; 6]) -> f64 {
    appell::linearize::check_holonomic(p, 0.0, x, f64::INFINITY).unwrap()[0].abs()
}

#[test]
fn projection_removes_the_pitch_drift_and_keeps_the_motion() {
    let p = WhippleBicycle::default();
    let prepared = p.prepare::<f64>();
    // 4.6 m/s (between the weave and capsize speeds: self-stable), leaning
    // 0.1 rad and steering 0.05 rad; the pitch made consistent first.
    let mut x0 = [
        0.1,
        std::f64::consts::PI / 10.0,
        0.05,
        0.3,
        -4.6 / p.rr,
        0.0,
    ];
    let (initial, steps) = project_holonomic(&p, 0.0, &mut x0, 1e-14, 30).unwrap();
    assert!(initial > 1e-4 && steps > 0, "{initial:e} {steps}");
    assert!(residual(&p, &x0) < 1e-14);

    let (segments, per, h) = (20, 25, 0.02);
    let (mut free, mut projected) = (x0, x0);
    let mut worst_projected: f64 = 0.0;
    for k in 0..segments {
        let t = (k * per) as f64 * h;
        free = appell::integrate::rk4(&p, &prepared, t, &free, h, per, &[0.0]).unwrap();
        projected = appell::integrate::rk4(&p, &prepared, t, &projected, h, per, &[0.0]).unwrap();
        project_holonomic(&p, t, &mut projected, 1e-14, 30).unwrap();
        worst_projected = worst_projected.max(residual(&p, &projected));
    }
    let drift = residual(&p, &free);
    let gap = free
        .iter()
        .zip(&projected)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    println!(
        "after 10 s of RK4 (h = 0.02): residual {drift:.2e} free, {worst_projected:.2e} projected (worst); states differ by {gap:.2e}"
    );
    // The free run drifts off the manifold; the projected one stays on it,
    // and the motion itself is unchanged to the drift's order.
    assert!(drift > 1e3 * worst_projected.max(1e-16), "{drift:e}");
    assert!(worst_projected < 1e-14);
    assert!(gap < 1e3 * drift.max(1e-12), "{gap:e}");
    // Still leaning by a small angle: the bicycle is self-stable here.
    assert!(projected[0].abs() < 0.1);
}

#[test]
fn projection_errors_are_typed() {
    let p = WhippleBicycle::default();
    let mut short = [0.0; 5];
    assert!(project_holonomic(&p, 0.0, &mut short, 1e-14, 30).is_err());
    let mut nan = [f64::NAN, 0.3, 0.0, 0.0, 0.0, 0.0];
    assert!(project_holonomic(&p, 0.0, &mut nan, 1e-14, 30).is_err());
    // No Newton steps allowed and the constraint violated: not converged,
    // and the state is left as it was.
    let mut off = [0.1, 0.0, 0.05, 0.0, 0.0, 0.0];
    let before = off;
    assert!(matches!(
        project_holonomic(&p, 0.0, &mut off, 1e-14, 0),
        Err(appell::linearize::LinearizeError::NotConverged { .. })
    ));
    assert_eq!(off, before);
}

#[test]
fn integrators_project_after_every_step() {
    use appell::integrate::{Dop853, Dopri5};
    let p = WhippleBicycle::default();
    let mut x0 = [
        0.1,
        std::f64::consts::PI / 10.0,
        0.05,
        0.3,
        -4.6 / p.rr,
        0.0,
    ];
    project_holonomic(&p, 0.0, &mut x0, 1e-14, 30).unwrap();
    let mut failures = 0;
    let mut onto_manifold = |t: f64, x: &mut [f64; 6]| {
        let r = project_holonomic(&p, t, x, 1e-14, 30);
        failures += usize::from(r.is_err());
        r.map(|_| ()).map_err(Into::into)
    };
    // A loose tolerance, so the drift is visible.
    let dop853 = Dop853::new().rtol(1e-5).atol(1e-7);
    let free = dop853.solve_model(&p, &[0.0], 0.0, &x0, 10.0).unwrap();
    let kept = dop853
        .solve_model_projected(&p, &[0.0], &mut onto_manifold, 0.0, &x0, 10.0)
        .unwrap();
    let dopri5 = Dopri5::new().rtol(1e-5).atol(1e-7);
    let kept5 = dopri5
        .solve_model_projected(&p, &[0.0], &mut onto_manifold, 0.0, &x0, 10.0)
        .unwrap();
    let (r_free, r_kept, r_kept5) = (
        residual(&p, &free.x),
        residual(&p, &kept.x),
        residual(&p, &kept5.x),
    );
    println!(
        "DOP853 rtol 1e-5, 10 s: residual {r_free:.2e} free, {r_kept:.2e} projected \
         ({} against {} rhs calls); Dopri5 projected {r_kept5:.2e}",
        kept.stats.rhs_calls, free.stats.rhs_calls
    );
    assert_eq!(failures, 0);
    assert!(r_kept < 1e-14 && r_kept5 < 1e-14);
    assert!(r_free > 1e2 * r_kept.max(1e-16), "{r_free:e}");
    // Projection costs at most one extra rhs call per accepted step.
    assert!(kept.stats.rhs_calls <= free.stats.rhs_calls + kept.stats.accepted + 20);
    // A projection that fails is a typed error at the step it failed.
    let err = dop853
        .solve_model_projected(
            &p,
            &[0.0],
            &mut |t: f64, _: &mut [f64; 6]| {
                if t < 1.0 {
                    Ok(())
                } else {
                    Err(appell::integrate::ProjectionFailed {
                        reason: "past t = 1",
                    })
                }
            },
            0.0,
            &x0,
            10.0,
        )
        .unwrap_err();
    assert!(
        matches!(err, appell::integrate::IntegrateError::Projection { t, reason: "past t = 1" } if (1.0..2.0).contains(&t)),
        "{err:?}"
    );
}
