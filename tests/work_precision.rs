//! The work–precision sweep in a reduced form: the error falls as the step
//! shrinks or the tolerance tightens, at the expected orders.

#[path = "../examples/models/wheel_axle.rs"]
mod wheel_axle;

use appell::accuracy::{Method, Problem};

#[test]
fn error_falls_with_step_and_tolerance() {
    let model = wheel_axle::WheelAxle::default();
    let pb = Problem {
        model: &model,
        x0: [0.3, 0.2, 1.0],
        t_end: 2.0,
        inputs: &[0.4],
        checkpoints: 4,
    };
    let (reference, estimate) = pb.reference().unwrap();
    assert!(estimate < 1e-12, "reference error estimate {estimate:e}");
    let methods = [
        Method::Rk4(20),
        Method::Rk4(40),
        Method::Rk4(80),
        Method::Heun(40),
        Method::Heun(80),
        Method::Dopri5(1e-4),
        Method::Dopri5(1e-6),
        Method::Dopri5(1e-8),
        Method::TrBdf2(1e-4),
        Method::TrBdf2(1e-6),
        Method::TrBdf2(1e-8),
        Method::Dop853(1e-6),
        Method::Dop853(1e-9),
        Method::Dop853(1e-12),
    ];
    let points = pb.sweep(&reference, &methods, 1, |_, _| {});
    assert_eq!(points.len(), methods.len());
    for p in &points {
        println!(
            "{:?}: error {:.2e}, {} rhs calls",
            p.method, p.error_max, p.rhs_calls
        );
    }
    let e = |i: usize| points[i].error_max;
    // RK4: halving h divides the error by about 16; Heun by about 4.
    assert!(e(0) > e(1) && e(1) > e(2));
    let rk4_order = (e(1) / e(2)).log2();
    assert!((rk4_order - 4.0).abs() < 0.5, "RK4 order {rk4_order}");
    let heun_order = (e(3) / e(4)).log2();
    assert!((heun_order - 2.0).abs() < 0.5, "Heun order {heun_order}");
    // Dormand–Prince: tighter tolerance, smaller error, more work.
    assert!(e(5) > e(6) && e(6) > e(7));
    assert!(points[5].rhs_calls < points[7].rhs_calls);
    // TR-BDF2 (order 2, error per step controlled): the global error falls
    // about as tol^(2/3), 1e-4 → 1e-8 divides it by roughly 2e-3 · 2.
    assert!(e(8) > e(9) && e(9) > e(10));
    assert!(points[8].rhs_calls < points[10].rhs_calls);
    let slope = (e(8) / e(10)).log10() / 4.0;
    assert!((0.5..0.85).contains(&slope), "TR-BDF2 error slope {slope}");
    // DOP853: the error follows the tolerance down to 1e-12, where it is a
    // thousand times below Dormand–Prince 5(4) at 1e-8 for less than three times
    // the rhs calls (measured: 7.7e-13 with 154 calls against 8.6e-8 with 74).
    assert!(e(11) > e(12) && e(12) > e(13));
    assert!(e(13) < 1e-11, "DOP853 at 1e-12: {:e}", e(13));
    assert!(e(13) < e(7) * 1e-3);
    assert!(points[13].rhs_calls < 3 * points[7].rhs_calls);
    let svg = appell::accuracy::svg_chart("wheel-axle", &points);
    assert!(svg.starts_with("<svg") && svg.contains("dopri5") && svg.contains("polyline"));
    assert_eq!(
        appell::accuracy::csv(&points).lines().count(),
        methods.len() + 1
    );
}
