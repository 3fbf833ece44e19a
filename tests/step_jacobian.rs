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

/// The command line's answer to one `jacobian` line.
fn jacobian_line(args: &[&str], line: &str) -> serde_json::Value {
    let args: Vec<String> = args.iter().map(|s| s.to_string()).collect();
    let mut out = Vec::new();
    appell::cli::run_with(
        WheelAxle::default(),
        &args,
        &mut line.as_bytes(),
        &mut out,
        |_| Ok(()),
    )
    .unwrap();
    serde_json::from_slice(&out).unwrap()
}

/// A JSON matrix as rows.
fn rows(v: &serde_json::Value) -> Vec<Vec<f64>> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|r| {
            r.as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect()
        })
        .collect()
}

fn matrix(m: &appell::nalgebra::DMatrix<f64>) -> Vec<Vec<f64>> {
    (0..m.nrows())
        .map(|i| (0..m.ncols()).map(|j| m[(i, j)]).collect())
        .collect()
}

/// The largest difference between two matrices of the same shape,
/// relative to 1 + |entry|.
fn worst(a: &[Vec<f64>], b: &[Vec<f64>]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .flat_map(|(x, y)| {
            assert_eq!(x.len(), y.len());
            x.iter()
                .zip(y)
                .map(|(p, q)| (p - q).abs() / (1.0 + q.abs()))
        })
        .fold(0.0, f64::max)
}

/// The command line takes its Jacobians by dual numbers (it works on any
/// `dyn` model); `linearize` and `step_jacobian` from the generated
/// Jacobian where the model has one: the same to rounding.
#[test]
fn the_command_lines_jacobian_is_the_linearization_and_the_steps() {
    let line = r#"{"q": {"phi": 0.2}, "u": {"phi": 0.1, "psi1": 2.0}, "inputs": {"tau": 0.5}}"#;
    let model = WheelAxle::default();
    let info = WheelAxle::info();
    let x: Vec<f64> = info
        .retained
        .iter()
        .map(|c| if *c == "phi" { 0.2 } else { 0.0 })
        .chain([0.1, 2.0])
        .collect();
    let v = jacobian_line(&["wheel_axle", "jacobian"], line);
    let lin = appell::linearize::linearize(&model, 0.0, &x, &[0.5]).unwrap();
    assert!(worst(&rows(&v["a"]), &matrix(&lin.a)) < 1e-14);
    assert!(worst(&rows(&v["b"]), &matrix(&lin.b)) < 1e-14);
    assert_eq!(v["state"], serde_json::json!(lin.state_names));
    assert_eq!(v["inputs"], serde_json::json!(["tau"]));
    let mut rates = vec![0.0; x.len()];
    model
        .rhs(&model.prepare::<f64>(), 0.0, &x, &[0.5], &mut rates)
        .unwrap();
    assert_eq!(v["rates"], serde_json::json!(rates));

    // One RK4 step of 10 ms, as step_jacobian takes it.
    let line_step = format!(
        "{}, \"step\": {{\"method\": \"rk4\", \"h\": 0.01}}}}",
        &line[..line.len() - 1]
    );
    let v = jacobian_line(&["wheel_axle", "jacobian"], &line_step);
    let step = step_jacobian(&model, FixedStep::Rk4, 0.0, 0.01, &x, &[0.5]).unwrap();
    assert!(worst(&rows(&v["a"]), &matrix(&step.a)) < 1e-14);
    assert!(worst(&rows(&v["b"]), &matrix(&step.b)) < 1e-14);
    assert_eq!(v["next"], serde_json::json!(step.next));
    assert_eq!(v["step"]["method"], "rk4");

    // A scene answers with its own reduced state.
    let v = jacobian_line(&["wheel_axle", "jacobian", "--scene", "driven"], line);
    assert_eq!(rows(&v["a"]).len(), 2);
    assert_eq!(v["state"], serde_json::json!(["phi_dot", "psi1_dot"]));
}

#[test]
fn a_bad_jacobian_line_is_answered_with_an_error() {
    let base = r#"{"q": {"phi": 0.2}, "u": {"phi": 0.1, "psi1": 2.0}"#;
    for (extra, expected) in [
        (
            r#", "step": {"method": "euler", "h": 0.1}}"#,
            "`step.method` must be",
        ),
        (r#", "step": {"method": "rk4"}}"#, "missing `step.h`"),
        (
            r#", "step": {"method": "rk4", "h": 0.1, "k": 2}}"#,
            "unknown field `k` in `step`",
        ),
        (r#", "step": 3}"#, "`step` must be an object"),
        (r#", "stepp": 3}"#, "unknown field `stepp`"),
    ] {
        let v = jacobian_line(&["wheel_axle", "jacobian"], &format!("{base}{extra}"));
        let message = v["error"].as_str().unwrap_or_default();
        assert!(message.contains(expected), "{extra}: {v}");
    }
}
