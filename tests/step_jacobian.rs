//! One fixed step of a controller loop (RK4, semi-implicit Euler) and its
//! Jacobians ∂x⁺/∂x and ∂x⁺/∂u (`appell::linearize::step_jacobian`),
//! against central differences of the step itself, on the double pendulum
//! and the wheel-axle (nonholonomic, driven by a torque).

mod common;
#[path = "../examples/models/double_pendulum.rs"]
mod double_pendulum;
#[path = "../examples/models/wheel_axle.rs"]
mod wheel_axle;

use appell::integrate::rk4_step;
use appell::linearize::{fixed_step, step_jacobian, FixedStep};
use appell::{Model, ModelError};
use common::Rng;
use double_pendulum::DoublePendulum;
use wheel_axle::WheelAxle;

const METHODS: [FixedStep; 2] = [FixedStep::Rk4, FixedStep::SemiImplicitEuler];

/// The worst difference, relative to 1 + |entry|, between the step's
/// Jacobians and central differences of `fixed_step` in f64.
fn worst_against_differences<M: Model>(model: &M, method: FixedStep, x: &[f64], u: &[f64]) -> f64 {
    let (h, t, eps) = (0.01, 0.3, 1e-6);
    let step = step_jacobian(model, method, t, h, x, u).unwrap();
    let prepared = model.prepare::<f64>();
    let at = |x: &[f64], u: &[f64]| fixed_step(model, &prepared, method, t, h, x, u).unwrap();
    assert_eq!(step.next, at(x, u));
    let mut worst = 0.0f64;
    for j in 0..x.len() + u.len() {
        let (mut xp, mut up) = (x.to_vec(), u.to_vec());
        let (mut xm, mut um) = (x.to_vec(), u.to_vec());
        if j < x.len() {
            xp[j] += eps;
            xm[j] -= eps;
        } else {
            up[j - x.len()] += eps;
            um[j - x.len()] -= eps;
        }
        let (plus, minus) = (at(&xp, &up), at(&xm, &um));
        for i in 0..x.len() {
            let fd = (plus[i] - minus[i]) / (2.0 * eps);
            let exact = if j < x.len() {
                step.a[(i, j)]
            } else {
                step.b[(i, j - x.len())]
            };
            worst = worst.max((exact - fd).abs() / (1.0 + exact.abs()));
        }
    }
    worst
}

#[test]
fn the_steps_jacobians_agree_with_central_differences() {
    let mut rng = Rng(11);
    let pendulum = DoublePendulum::default();
    let axle = WheelAxle::default();
    let n_axle = WheelAxle::info().state_len();
    for method in METHODS {
        let mut worst = 0.0f64;
        for _ in 0..10 {
            let x: Vec<f64> = (0..4).map(|_| rng.uniform(-2.0, 2.0)).collect();
            worst = worst.max(worst_against_differences(&pendulum, method, &x, &[]));
            let x: Vec<f64> = (0..n_axle).map(|_| rng.uniform(-2.0, 2.0)).collect();
            let u = [rng.uniform(-1.0, 1.0)];
            worst = worst.max(worst_against_differences(&axle, method, &x, &u));
        }
        println!("{method:?}: worst relative difference to central differences {worst:.1e}");
        assert!(worst < 1e-7, "{method:?}: {worst:.1e}");
    }
}

#[test]
fn the_rk4_step_is_the_integrators_step() {
    let model = DoublePendulum::default();
    let prepared = model.prepare::<f64>();
    let x = [0.4, -1.1, 0.7, 0.2];
    let ours = fixed_step(&model, &prepared, FixedStep::Rk4, 0.1, 0.02, &x, &[]).unwrap();
    let theirs = rk4_step(&model, &prepared, 0.1, 0.02, &x, &[]).unwrap();
    assert_eq!(ours, theirs);
}

#[test]
fn a_small_steps_jacobian_is_the_identity_plus_h_times_the_continuous_one() {
    // Φ(x) = x + h f(x) + O(h²) for either method.
    let model = WheelAxle::default();
    let n = WheelAxle::info().state_len();
    let x: Vec<f64> = (0..n).map(|k| 0.3 * k as f64 - 0.5).collect();
    let u = [0.4];
    let continuous = appell::linearize::linearize(&model, 0.0, &x, &u).unwrap();
    for method in METHODS {
        let h = 1e-5;
        let step = step_jacobian(&model, method, 0.0, h, &x, &u).unwrap();
        for i in 0..n {
            for j in 0..n {
                let expected = f64::from(u8::from(i == j)) + h * continuous.a[(i, j)];
                assert!(
                    (step.a[(i, j)] - expected).abs() < 1e-8,
                    "{method:?} A[{i},{j}]"
                );
            }
            assert!((step.b[(i, 0)] - h * continuous.b[(i, 0)]).abs() < 1e-8);
        }
        assert_eq!(step.state_names, continuous.state_names);
        assert_eq!(step.input_names, ["tau"]);
    }
}

#[test]
fn bad_arguments_are_typed_errors() {
    let model = WheelAxle::default();
    let n = WheelAxle::info().state_len();
    let x = vec![0.1; n];
    for method in METHODS {
        assert!(matches!(
            step_jacobian(&model, method, 0.0, f64::INFINITY, &x, &[0.0]),
            Err(ModelError::NonFinite { what: "h" })
        ));
        assert!(matches!(
            step_jacobian(&model, method, 0.0, 0.01, &x[1..], &[0.0]),
            Err(ModelError::Length { .. })
        ));
        assert!(matches!(
            step_jacobian(&model, method, 0.0, 0.01, &x, &[]),
            Err(ModelError::Length { .. })
        ));
        // A step so long the state overflows.
        assert!(matches!(
            step_jacobian(&model, method, 0.0, 1e300, &x, &[1e300]),
            Err(ModelError::NonFinite { .. })
        ));
    }
}
