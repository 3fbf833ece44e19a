//! The adaptive TR-BDF2 integrator: accuracy and work on stiff problems
//! against Dormand–Prince, observed order, Jacobians by dual numbers, and
//! typed errors. The models are hand-written `impl Model`s whose only
//! meaningful methods are `info`, `prepare` and `rhs`.

use appell_core::{check_len, Model, ModelError, ModelInfo, OpCounts, Scalar};
use appell_integrate::{Dopri5, IntegrateError, ProjectionFailed, Radau5, TrBdf2, TrBdf2Stats};

fn unused() -> Result<(), ModelError> {
    Err(ModelError::NonFinite { what: "unused" })
}

const fn info(
    name: &'static str,
    retained: &'static [&'static str],
    speeds: &'static [&'static str],
    inputs: &'static [&'static str],
) -> ModelInfo {
    ModelInfo {
        name,
        parameters: &[],
        coordinates: retained,
        speeds,
        dependent: &[],
        cyclic: &[],
        ignorable: &[],
        retained,
        inputs,
        effects: &[],
        outputs: &[],
        row_sources: &[],
        contacts: &[],
        holonomic: 0,
        constraints: 0,
        bodies: &[],
        force_points: 0,
        torques: 0,
        form: "closed form",
        symbolic_elimination: true,
        rhs_ops: OpCounts {
            add: 0,
            mul: 0,
            div: 0,
            calls: 0,
            total: 0,
        },
        jacobian: None,
        equations: "",
    }
}

/// Everything of `Model` except `Prepared`, `info`, `prepare` and `rhs`.
macro_rules! rest_of_model {
    () => {
        fn parameter_values(&self, _: &mut [f64]) -> Result<(), ModelError> {
            unused()
        }
        fn set_parameter(&mut self, _: &str, _: f64) -> bool {
            false
        }
        fn mass_matrix_and_forcing<T: Scalar>(
            &self,
            _: T,
            _: &[T],
            _: &[T],
            _: &[T],
            _: &mut [T],
            _: &mut [T],
        ) -> Result<(), ModelError> {
            unused()
        }
        fn speed_transform<T: Scalar>(
            &self,
            _: T,
            _: &[T],
            _: &mut [T],
            _: &mut [T],
        ) -> Result<(), ModelError> {
            unused()
        }
        fn coordinate_rates<T: Scalar>(
            &self,
            _: T,
            _: &[T],
            _: &[T],
            _: &mut [T],
        ) -> Result<(), ModelError> {
            unused()
        }
        fn constraint_residuals<T: Scalar>(
            &self,
            _: T,
            _: &[T],
            _: &[T],
            _: &mut [T],
            _: &mut [T],
        ) -> Result<(), ModelError> {
            unused()
        }
        fn kinetic_energy<T: Scalar>(&self, _: T, _: &[T], _: &[T]) -> Result<T, ModelError> {
            unused().map(|_| T::zero())
        }
        fn mass_properties(&self, _: &mut [f64], _: &mut [[f64; 9]]) -> Result<(), ModelError> {
            unused()
        }
        fn body_poses<T: Scalar>(
            &self,
            _: T,
            _: &[T],
            _: &mut [[T; 3]],
            _: &mut [[T; 9]],
        ) -> Result<(), ModelError> {
            unused()
        }
        fn constraint_rows<T: Scalar>(
            &self,
            _: T,
            _: &[T],
            _: &mut [T],
            _: &mut [T],
        ) -> Result<(), ModelError> {
            unused()
        }
        fn load_geometry<T: Scalar>(
            &self,
            _: T,
            _: &[T],
            _: &mut [[T; 3]],
            _: &mut [[T; 9]],
        ) -> Result<(), ModelError> {
            unused()
        }
        fn load_values<T: Scalar>(
            &self,
            _: T,
            _: &[T],
            _: &[T],
            _: &[T],
            _: &mut [[T; 3]],
            _: &mut [[T; 3]],
        ) -> Result<(), ModelError> {
            unused()
        }
    };
}

// ---------------------------------------------------------------------------
// x' = −λ (x − a cos t), with the amplitude a an input.

struct StiffLinear {
    lambda: f64,
}

static STIFF_INFO: ModelInfo = info("StiffLinear", &["x"], &[], &["a"]);

impl Model for StiffLinear {
    type Prepared<T: Scalar> = T;
    fn info() -> &'static ModelInfo {
        &STIFF_INFO
    }
    fn prepare<T: Scalar>(&self) -> T {
        T::from_f64(self.lambda)
    }
    fn rhs<T: Scalar>(
        &self,
        lambda: &T,
        t: T,
        state: &[T],
        inputs: &[T],
        dstate: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("state", state, 1)?;
        check_len("inputs", inputs, 1)?;
        check_len("dstate", dstate, 1)?;
        dstate[0] = -(*lambda * (state[0] - inputs[0] * t.cos()));
        Ok(())
    }
    rest_of_model!();
}

/// The exact solution of `StiffLinear` with x(0) = 0, a = 1.
fn stiff_exact(lambda: f64, t: f64) -> f64 {
    let l2 = lambda * lambda;
    lambda * (lambda * t.cos() + t.sin()) / (l2 + 1.0) - (-lambda * t).exp() * l2 / (l2 + 1.0)
}

// ---------------------------------------------------------------------------
// Van der Pol: x'' = μ (1 − x²) x' − x.

struct VanDerPol {
    mu: f64,
}

static VDP_INFO: ModelInfo = info("VanDerPol", &["x"], &["x"], &[]);

impl Model for VanDerPol {
    type Prepared<T: Scalar> = T;
    fn info() -> &'static ModelInfo {
        &VDP_INFO
    }
    fn prepare<T: Scalar>(&self) -> T {
        T::from_f64(self.mu)
    }
    fn rhs<T: Scalar>(
        &self,
        mu: &T,
        _t: T,
        state: &[T],
        inputs: &[T],
        dstate: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("state", state, 2)?;
        check_len("inputs", inputs, 0)?;
        check_len("dstate", dstate, 2)?;
        let (x, v) = (state[0], state[1]);
        dstate[0] = v;
        dstate[1] = *mu * (T::one() - x * x) * v - x;
        Ok(())
    }
    rest_of_model!();
}

// ---------------------------------------------------------------------------
// A smooth nonlinear non-stiff problem with a closed form: the pendulum-free
// x' = y, y' = −x (harmonic oscillator) and z' = −z² (z = 1/(1 + t)).

struct Smooth;

static SMOOTH_INFO: ModelInfo = info("Smooth", &["x", "z"], &["x"], &[]);

impl Model for Smooth {
    type Prepared<T: Scalar> = ();
    fn info() -> &'static ModelInfo {
        &SMOOTH_INFO
    }
    fn prepare<T: Scalar>(&self) {}
    fn rhs<T: Scalar>(
        &self,
        _: &(),
        _t: T,
        state: &[T],
        _inputs: &[T],
        dstate: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("state", state, 3)?;
        check_len("dstate", dstate, 3)?;
        dstate[0] = state[2];
        dstate[1] = -(state[1] * state[1]);
        dstate[2] = -state[0];
        Ok(())
    }
    rest_of_model!();
}

fn smooth_exact(t: f64) -> [f64; 3] {
    [t.cos(), 1.0 / (1.0 + t), -t.sin()]
}

fn max_err(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

// ---------------------------------------------------------------------------
// Models that fail: x' = x² (blows up at t = 1 from x(0) = 1), and one whose
// rhs reports a singular configuration past x = 0.5.

struct BlowUp;

static BLOWUP_INFO: ModelInfo = info("BlowUp", &["x"], &[], &[]);

impl Model for BlowUp {
    type Prepared<T: Scalar> = ();
    fn info() -> &'static ModelInfo {
        &BLOWUP_INFO
    }
    fn prepare<T: Scalar>(&self) {}
    fn rhs<T: Scalar>(
        &self,
        _: &(),
        _t: T,
        state: &[T],
        _inputs: &[T],
        dstate: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("state", state, 1)?;
        dstate[0] = state[0] * state[0];
        Ok(())
    }
    rest_of_model!();
}

struct Singular;

static SINGULAR_INFO: ModelInfo = info("Singular", &["x"], &[], &[]);

impl Model for Singular {
    type Prepared<T: Scalar> = ();
    fn info() -> &'static ModelInfo {
        &SINGULAR_INFO
    }
    fn prepare<T: Scalar>(&self) {}
    fn rhs<T: Scalar>(
        &self,
        _: &(),
        _t: T,
        state: &[T],
        _inputs: &[T],
        dstate: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("state", state, 1)?;
        if state[0].re() > 0.5 {
            return Err(ModelError::SingularMassMatrix {
                index: 0,
                pivot: 0.0,
            });
        }
        dstate[0] = T::one();
        Ok(())
    }
    rest_of_model!();
}

// ---------------------------------------------------------------------------

const LAMBDA: f64 = 1000.0;

fn dopri5_stiff(tol: f64) -> (f64, appell_integrate::Stats) {
    let model = StiffLinear { lambda: LAMBDA };
    let sol = Dopri5::new()
        .rtol(tol)
        .atol(tol)
        .solve_model(&model, &[1.0], 0.0, &[0.0], 5.0)
        .unwrap();
    ((sol.x[0] - stiff_exact(LAMBDA, 5.0)).abs(), sol.stats)
}

fn trbdf2_stiff(tol: f64) -> (f64, TrBdf2Stats) {
    let model = StiffLinear { lambda: LAMBDA };
    let sol = TrBdf2::new()
        .rtol(tol)
        .atol(tol)
        .solve_model(&model, &[1.0], 0.0, &[0.0], 5.0)
        .unwrap();
    assert_eq!(sol.t, 5.0);
    ((sol.x[0] - stiff_exact(LAMBDA, 5.0)).abs(), sol.stats)
}

#[test]
fn stiff_linear_is_accurate_with_far_fewer_steps_than_dopri5() {
    for tol in [1e-4, 1e-6, 1e-8] {
        let (e_imp, s_imp) = trbdf2_stiff(tol);
        let (e_exp, s_exp) = dopri5_stiff(tol);
        println!(
            "tol {tol:e}: TR-BDF2 error {e_imp:.2e} {s_imp:?}\n            Dopri5  error {e_exp:.2e} {s_exp:?}"
        );
        assert!(e_imp <= 10.0 * tol, "tol {tol}: error {e_imp}");
        // Linear problem: one Jacobian for the whole run.
        assert_eq!(s_imp.jacobians, 1, "{s_imp:?}");
        assert_eq!(s_imp.jacobian_rhs_calls, 1);
        assert_eq!(s_imp.newton_failures, 0, "{s_imp:?}");
        // Dopri5 is held at its stability limit (≈ 3.3/λ) everywhere.
        assert!(s_exp.accepted > 1400, "{s_exp:?}");
        let factor = if tol >= 1e-6 { 10 } else { 3 };
        assert!(
            factor * (s_imp.accepted + s_imp.rejected) < s_exp.accepted + s_exp.rejected,
            "tol {tol}: {s_imp:?} vs {s_exp:?}"
        );
        assert!(factor * s_imp.rhs_calls < s_exp.rhs_calls);
    }
}

#[test]
fn user_jacobian_gives_the_same_trajectory_as_dual_numbers() {
    let f = |t: f64, x: &[f64], dx: &mut [f64]| -> Result<(), ModelError> {
        // The model's own cosine (`Scalar::cos`), so both runs see the
        // same bits.
        dx[0] = -(LAMBDA * (x[0] - Scalar::cos(t)));
        Ok(())
    };
    let jac = |_t: f64, _x: &[f64], j: &mut [f64]| -> Result<(), ModelError> {
        j[0] = -LAMBDA;
        Ok(())
    };
    let solver = TrBdf2::new().rtol(1e-6).atol(1e-6);
    let a = solver.solve(f, jac, 0.0, &[0.0], 5.0).unwrap();
    let b = solver
        .solve_model(&StiffLinear { lambda: LAMBDA }, &[1.0], 0.0, &[0.0], 5.0)
        .unwrap();
    assert_eq!(a.x, b.x);
    assert_eq!(a.stats.accepted, b.stats.accepted);
    assert_eq!(a.stats.jacobian_rhs_calls, 0);
    assert_eq!(b.stats.jacobian_rhs_calls, 1);
}

#[test]
fn inputs_reach_the_model() {
    // a = 2: the solution doubles.
    let sol = TrBdf2::new()
        .rtol(1e-8)
        .atol(1e-8)
        .solve_model(&StiffLinear { lambda: LAMBDA }, &[2.0], 0.0, &[0.0], 2.0)
        .unwrap();
    assert!((sol.x[0] - 2.0 * stiff_exact(LAMBDA, 2.0)).abs() < 1e-6);
}

#[test]
fn fixed_steps_converge_with_order_two() {
    let t_end = 2.0;
    let errs: Vec<f64> = [20, 40, 80, 160]
        .iter()
        .map(|&n| {
            let h = t_end / n as f64;
            let sol = TrBdf2::new()
                .rtol(1e-10)
                .atol(1e-10)
                .adaptive(false)
                .h_init(Some(h))
                .solve_model(&Smooth, &[], 0.0, &[1.0, 1.0, 0.0], t_end)
                .unwrap();
            assert_eq!(sol.stats.accepted, n, "{:?}", sol.stats);
            assert_eq!(sol.stats.rejected, 0);
            max_err(&sol.x, &smooth_exact(t_end))
        })
        .collect();
    let orders: Vec<f64> = errs.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
    println!("fixed-step errors {errs:?}, observed orders {orders:?}");
    for p in &orders {
        assert!((p - 2.0).abs() < 0.15, "order {p}");
    }
}

#[test]
fn tolerance_sweep_shows_order_two_in_steps() {
    // With local error ∝ tol, global error ∝ N^−2 for N steps.
    let runs: Vec<(f64, usize)> = [1e-5, 1e-7, 1e-9, 1e-11]
        .iter()
        .map(|&tol| {
            let sol = TrBdf2::new()
                .rtol(tol)
                .atol(tol)
                .solve_model(&Smooth, &[], 0.0, &[1.0, 1.0, 0.0], 10.0)
                .unwrap();
            (max_err(&sol.x, &smooth_exact(10.0)), sol.stats.accepted)
        })
        .collect();
    println!("tolerance sweep (error, steps): {runs:?}");
    let (e0, n0) = runs[0];
    let (e1, n1) = runs[runs.len() - 1];
    let p = (e0 / e1).ln() / (n1 as f64 / n0 as f64).ln();
    println!("observed order over the sweep: {p}");
    assert!((p - 2.0).abs() < 0.35, "order {p}");
    // The error follows the tolerance (proportionality tol^(2/3)).
    for w in runs.windows(2) {
        assert!(w[1].0 < w[0].0);
    }
}

#[test]
fn van_der_pol_mu_1000_completes_with_modest_work() {
    let model = VanDerPol { mu: 1000.0 };
    let t_end = 2000.0;
    let sol = TrBdf2::new()
        .rtol(1e-6)
        .atol(1e-6)
        .solve_model(&model, &[], 0.0, &[2.0, 0.0], t_end)
        .unwrap();
    println!(
        "van der Pol μ = 1000 to t = {t_end}: x = {:?}, {:?}",
        sol.x, sol.stats
    );
    assert_eq!(sol.t, t_end);
    let s = sol.stats;
    assert!(s.accepted + s.rejected < 5_000, "{s:?}");
    assert!(s.jacobians < s.accepted, "{s:?}");
    assert!(s.lu_factorizations <= s.accepted + s.rejected + s.jacobians);
    assert_eq!(s.jacobian_rhs_calls, 2 * s.jacobians);

    // A tight reference: the two agree on the slow branch.
    let reference = TrBdf2::new()
        .rtol(1e-9)
        .atol(1e-9)
        .solve_model(&model, &[], 0.0, &[2.0, 0.0], t_end)
        .unwrap();
    println!("reference: x = {:?}, {:?}", reference.x, reference.stats);
    assert!((sol.x[0] - reference.x[0]).abs() < 1e-2, "{:?}", sol.x);
    // Half a period is ≈ (3 − 2 ln 2) μ / 2 ≈ 807: by t = 2000 x has jumped
    // twice (near 807 and 1614) and is back on the positive branch.
    assert!(sol.x[0] > 1.0 && sol.x[0] < 2.1, "{:?}", sol.x);
    let half = TrBdf2::new()
        .rtol(1e-6)
        .atol(1e-6)
        .solve_model(&model, &[], 0.0, &[2.0, 0.0], 1000.0)
        .unwrap();
    assert!(half.x[0] < -1.0 && half.x[0] > -2.1, "{:?}", half.x);
}

#[test]
fn dopri5_cannot_do_van_der_pol_mu_1000_on_a_budget() {
    // Over only a tenth of the interval above, the default 100 000 steps of
    // Dopri5 are not enough (its step is held near 3.3 / (μ (x² − 1))).
    let model = VanDerPol { mu: 1000.0 };
    let r = Dopri5::new()
        .rtol(1e-6)
        .atol(1e-6)
        .max_steps(100_000)
        .solve_model(&model, &[], 0.0, &[2.0, 0.0], 2000.0);
    match r {
        Err(IntegrateError::TooManySteps { t, steps }) => {
            println!("Dopri5 van der Pol μ = 1000: {steps} steps reached only t = {t}");
            assert!(t < 400.0);
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn backward_integration_returns_to_the_start() {
    let fwd = TrBdf2::new()
        .rtol(1e-10)
        .atol(1e-10)
        .solve_model(&Smooth, &[], 0.0, &[1.0, 1.0, 0.0], 1.0)
        .unwrap();
    let back = TrBdf2::new()
        .rtol(1e-10)
        .atol(1e-10)
        .solve_model(&Smooth, &[], 1.0, &fwd.x, 0.0)
        .unwrap();
    assert_eq!(back.t, 0.0);
    assert!(max_err(&back.x, &[1.0, 1.0, 0.0]) < 1e-7, "{:?}", back.x);
}

#[test]
fn zero_length_interval_returns_the_initial_state() {
    let sol = TrBdf2::new()
        .solve_model(&Smooth, &[], 1.0, &[1.0, 2.0, 3.0], 1.0)
        .unwrap();
    assert_eq!(sol.x, vec![1.0, 2.0, 3.0]);
    assert_eq!(sol.stats, TrBdf2Stats::default());
}

#[test]
fn errors_are_typed() {
    let s = TrBdf2::new();
    let stiff = StiffLinear { lambda: LAMBDA };
    // Too many steps.
    assert!(matches!(
        s.max_steps(5).solve_model(&stiff, &[1.0], 0.0, &[0.0], 5.0),
        Err(IntegrateError::TooManySteps { steps: 5, t }) if t > 0.0 && t < 5.0
    ));
    // Blow-up at t = 1: the step shrinks to nothing there.
    match s.solve_model(&BlowUp, &[], 0.0, &[1.0], 2.0) {
        Err(IntegrateError::StepSizeTooSmall { t, .. } | IntegrateError::NonFinite { t }) => {
            assert!((t - 1.0).abs() < 1e-2, "{t}")
        }
        other => panic!("{other:?}"),
    }
    // A minimum step size that is too large.
    assert!(matches!(
        s.h_min(0.5).solve_model(&BlowUp, &[], 0.0, &[1.0], 2.0),
        Err(IntegrateError::StepSizeTooSmall { h, .. }) if h < 0.5
    ));
    // Model errors are passed on.
    assert_eq!(
        s.solve_model(&Singular, &[], 0.0, &[0.0], 1.0),
        Err(IntegrateError::Model(ModelError::SingularMassMatrix {
            index: 0,
            pivot: 0.0
        }))
    );
    assert!(matches!(
        s.solve_model(&stiff, &[1.0], 0.0, &[0.0, 1.0], 1.0),
        Err(IntegrateError::Model(ModelError::Length {
            argument: "state",
            expected: 1,
            found: 2
        }))
    ));
    assert!(matches!(
        s.solve_model(&stiff, &[], 0.0, &[0.0], 1.0),
        Err(IntegrateError::Model(ModelError::Length {
            argument: "inputs",
            ..
        }))
    ));
    // Non-finite initial state; a rhs that is NaN at the start.
    assert_eq!(
        s.solve_model(&stiff, &[1.0], 0.0, &[f64::NAN], 1.0),
        Err(IntegrateError::NonFinite { t: 0.0 })
    );
    assert_eq!(
        s.solve_model(&stiff, &[f64::INFINITY], 0.0, &[0.0], 1.0),
        Err(IntegrateError::NonFinite { t: 0.0 })
    );
    // A rhs that becomes NaN past x = 0.5 (the step shrinks, then fails).
    let f = |_t: f64, x: &[f64], dx: &mut [f64]| -> Result<(), ModelError> {
        dx[0] = if x[0] > 0.5 { f64::NAN } else { 1.0 };
        Ok(())
    };
    let jac = |_t: f64, _x: &[f64], j: &mut [f64]| -> Result<(), ModelError> {
        j[0] = 0.0;
        Ok(())
    };
    match s.solve(f, jac, 0.0, &[0.0], 1.0) {
        Err(IntegrateError::NonFinite { t }) => assert!((t - 0.5).abs() < 1e-3, "{t}"),
        other => panic!("{other:?}"),
    }
    // Invalid settings and arguments.
    for bad in [
        s.rtol(-1.0),
        s.atol(f64::NAN),
        s.rtol(0.0).atol(0.0),
        s.h_init(Some(0.0)),
        s.h_max(Some(-1.0)),
        s.h_min(f64::INFINITY),
        s.max_newton(0),
        s.adaptive(false),
    ] {
        assert!(
            matches!(
                bad.solve_model(&stiff, &[1.0], 0.0, &[0.0], 1.0),
                Err(IntegrateError::InvalidInput { .. })
            ),
            "{bad:?}"
        );
    }
    assert!(matches!(
        s.solve_model(&stiff, &[1.0], 0.0, &[0.0], f64::NAN),
        Err(IntegrateError::InvalidInput { .. })
    ));
}

// ---------------------------------------------------------------------------
// Dense output, output times and events.

/// The states at the ends of all accepted steps (recorded by an event
/// function that never changes sign) and the final solution.
fn step_ends<M: Model>(
    s: TrBdf2,
    model: &M,
    x0: &[f64],
    t_end: f64,
    inputs: &[f64],
) -> Vec<(f64, Vec<f64>)> {
    let mut ends = vec![(0.0, x0.to_vec())];
    let g = |t: f64, x: &[f64]| {
        ends.push((t, x.to_vec()));
        1.0
    };
    let sol = s
        .solve_model_until(model, inputs, g, 0.0, x0, t_end)
        .unwrap();
    assert!(!sol.event);
    assert_eq!(sol.t, t_end);
    // The first call of g is at t0.
    ends.remove(0);
    ends
}

/// Max error of the step ends and of the dense output at `k` times per step
/// (strictly inside each step), against `exact`.
fn dense_vs_ends<M: Model>(
    s: TrBdf2,
    model: &M,
    x0: &[f64],
    t_end: f64,
    inputs: &[f64],
    exact: impl Fn(f64) -> Vec<f64>,
    k: usize,
) -> (f64, f64, usize) {
    let ends = step_ends(s, model, x0, t_end, inputs);
    let e_ends = ends
        .iter()
        .map(|(t, x)| max_err(x, &exact(*t)))
        .fold(0.0, f64::max);
    let mut out = Vec::new();
    for w in ends.windows(2) {
        let (a, b) = (w[0].0, w[1].0);
        for j in 1..=k {
            out.push((a + (b - a) * j as f64 / (k + 1) as f64, Vec::new()));
        }
    }
    out.push((t_end, Vec::new()));
    let sol = s.solve_model_at(model, inputs, 0.0, x0, &mut out).unwrap();
    assert_eq!(sol.outputs, out.len());
    assert!(!sol.event);
    let e_dense = out
        .iter()
        .map(|(t, x)| max_err(x, &exact(*t)))
        .fold(0.0, f64::max);
    (e_ends, e_dense, ends.len() - 1)
}

#[test]
fn dense_output_is_as_accurate_as_the_step_ends_on_the_smooth_problem() {
    for tol in [1e-5, 1e-7, 1e-9] {
        let s = TrBdf2::new().rtol(tol).atol(tol);
        let (e_ends, e_dense, steps) = dense_vs_ends(
            s,
            &Smooth,
            &[1.0, 1.0, 0.0],
            5.0,
            &[],
            |t| smooth_exact(t).to_vec(),
            9,
        );
        println!(
            "smooth tol {tol:e}: {steps} steps, step-end error {e_ends:.3e}, dense error {e_dense:.3e}"
        );
        assert!(e_dense <= 2.0 * e_ends, "{e_dense} vs {e_ends}");
    }
}

#[test]
fn dense_output_is_as_accurate_as_the_step_ends_on_the_stiff_problem() {
    for tol in [1e-5, 1e-6, 1e-7, 1e-8, 1e-9] {
        let s = TrBdf2::new().rtol(tol).atol(tol);
        let (e_ends, e_dense, steps) = dense_vs_ends(
            s,
            &StiffLinear { lambda: LAMBDA },
            &[0.0],
            5.0,
            &[1.0],
            |t| vec![stiff_exact(LAMBDA, t)],
            9,
        );
        println!(
            "stiff tol {tol:e}: {steps} steps, step-end error {e_ends:.3e}, dense error {e_dense:.3e}"
        );
        // Once the steps resolve cos t (tol ≤ 1e-6) the interpolant is as
        // good as the step ends; at 1e-5 the longest steps (≈ 0.5) leave an
        // interpolation error of ≈ 8.5× the (L-stably damped) end error.
        let factor = if tol >= 1e-5 { 10.0 } else { 2.5 };
        assert!(e_dense <= factor * e_ends, "{e_dense} vs {e_ends}");
    }
}

#[test]
fn solve_at_costs_no_extra_work_and_ends_where_solve_ends() {
    let s = TrBdf2::new().rtol(1e-8).atol(1e-8);
    let stiff = StiffLinear { lambda: LAMBDA };
    let plain = s.solve_model(&stiff, &[1.0], 0.0, &[0.0], 5.0).unwrap();
    let mut out: Vec<(f64, Vec<f64>)> = (0..=500).map(|k| (0.01 * k as f64, vec![])).collect();
    let at = s
        .solve_model_at(&stiff, &[1.0], 0.0, &[0.0], &mut out)
        .unwrap();
    assert_eq!(at.t, 5.0);
    assert_eq!(at.x, plain.x);
    assert_eq!(at.stats, plain.stats);
    assert_eq!(at.outputs, 501);
    assert_eq!(out[0].1, vec![0.0]);
    assert_eq!(out[500].1, plain.x);
    // The closure form, backward, with repeated times.
    let f = |_t: f64, x: &[f64], dx: &mut [f64]| -> Result<(), ModelError> {
        dx[0] = -x[0];
        Ok(())
    };
    let jac = |_t: f64, _x: &[f64], j: &mut [f64]| -> Result<(), ModelError> {
        j[0] = -1.0;
        Ok(())
    };
    let mut out = vec![
        (1.0, vec![9.0; 4]),
        (0.5, vec![]),
        (0.5, vec![]),
        (-1.0, vec![]),
    ];
    let sol = s.solve_at(f, jac, 1.0, &[1.0], &mut out).unwrap();
    assert_eq!((sol.t, sol.outputs, sol.event), (-1.0, 4, false));
    assert_eq!(out[0].1, vec![1.0]);
    for (t, x) in &out {
        assert_eq!(x.len(), 1);
        assert!(
            (x[0] - (1.0 - t).exp()).abs() < 1e-5 * (1.0 - t).exp(),
            "{t} {x:?}"
        );
    }
    // Nothing to do.
    let sol = s.solve_at(f, jac, 1.0, &[1.0], &mut []).unwrap();
    assert_eq!((sol.t, sol.outputs), (1.0, 0));
}

#[test]
fn output_times_are_validated() {
    let s = TrBdf2::new();
    for times in [
        vec![0.5, 0.2, 1.0],      // out of order
        vec![-0.5, 1.0],          // before t0
        vec![0.5, f64::NAN, 1.0], // not finite
        vec![0.5, f64::INFINITY], // not finite end
        vec![0.5, -1.0],          // changes direction
    ] {
        let mut out: Vec<(f64, Vec<f64>)> = times.iter().map(|&t| (t, vec![])).collect();
        let r = s.solve_model_at(&Smooth, &[], 0.0, &[1.0, 1.0, 0.0], &mut out);
        assert!(
            matches!(r, Err(IntegrateError::InvalidInput { .. })),
            "{times:?}: {r:?}"
        );
        assert!(out.iter().all(|o| o.1.is_empty()), "{times:?}");
    }
    // Wrong state length is a model error.
    let mut out = vec![(1.0, vec![])];
    assert!(matches!(
        s.solve_model_at(&Smooth, &[], 0.0, &[1.0], &mut out),
        Err(IntegrateError::Model(ModelError::Length { .. }))
    ));
}

#[test]
fn event_is_located_to_tolerance() {
    // y = 1/(1 + t) reaches 1/4 at t = 3; x = cos t reaches 1/2 at π/3.
    let s = TrBdf2::new().rtol(1e-10).atol(1e-10);
    let x0 = [1.0, 1.0, 0.0];
    let sol = s
        .solve_model_until(&Smooth, &[], |_t, x: &[f64]| x[1] - 0.25, 0.0, &x0, 10.0)
        .unwrap();
    println!(
        "event y = 1/4: t = {:.15}, error {:.3e}, {} steps",
        sol.t,
        sol.t - 3.0,
        sol.stats.accepted
    );
    assert!(sol.event);
    // Located to tolerance on the dense output: g = y − 1/4 has slope
    // −1/16 there, so within event_tol = 1e-12 of the root |g| ≤ 1e-13, on
    // the far side of the crossing.
    assert!(sol.x[1] <= 0.25 && sol.x[1] > 0.25 - 1e-13, "{}", sol.x[1]);
    // The time error is that of the solution: 16 × the error of y.
    let ey = sol.x[1] - 1.0 / (1.0 + sol.t);
    assert!((sol.t - 3.0).abs() < 1e-6, "{}", sol.t);
    assert!(
        ((sol.t - 3.0) - 16.0 * ey).abs() < 1e-3 * (sol.t - 3.0).abs() + 1e-12,
        "{} {ey}",
        sol.t
    );

    let sol = s
        .solve_model_until(&Smooth, &[], |_t, x: &[f64]| x[0] - 0.5, 0.0, &x0, 10.0)
        .unwrap();
    let exact = std::f64::consts::FRAC_PI_3;
    println!(
        "event cos t = 1/2: t = {:.15}, error {:.3e}",
        sol.t,
        sol.t - exact
    );
    assert!(sol.event);
    assert!((sol.t - exact).abs() < 1e-6, "{}", sol.t);
    assert!(sol.x[0] <= 0.5 && sol.x[0] > 0.5 - 1e-12);

    // The located time is within event_tol of the root of g on the dense
    // output: with a coarse event_tol, the reported time is past the root by
    // at most event_tol.
    let coarse = s.event_tol(1e-3);
    let sol = coarse
        .solve_model_until(&Smooth, &[], |_t, x: &[f64]| x[1] - 0.25, 0.0, &x0, 10.0)
        .unwrap();
    println!("event_tol 1e-3: t = {:.15}", sol.t);
    assert!(
        sol.event && sol.t >= 3.0 - 1e-6 && sol.t <= 3.0 + 1e-3 + 1e-6,
        "{}",
        sol.t
    );

    // Backward: from t = 3 to 0, y = 1/(1 + t) reaches 1/2 at t = 1.
    let sol = s
        .solve_model_until(
            &Smooth,
            &[],
            |_t, x: &[f64]| x[1] - 0.5,
            3.0,
            &smooth_exact(3.0),
            0.0,
        )
        .unwrap();
    assert!(sol.event);
    assert!((sol.t - 1.0).abs() < 1e-6, "{}", sol.t);
    assert!(sol.x[1] >= 0.5 && sol.x[1] < 0.5 + 1e-12);

    // A zero at t0 is not an event (cos t − 1 ≤ 0 touches 0 again only at 2π).
    let sol = s
        .solve_model_until(&Smooth, &[], |_t, x: &[f64]| x[0] - 1.0, 0.0, &x0, 5.0)
        .unwrap();
    assert!(!sol.event);
    assert_eq!(sol.t, 5.0);

    // The closure form on the stiff problem: x crosses 1/2 in the layer, at
    // t ≈ ln 2 / 1000.
    let f = |t: f64, x: &[f64], dx: &mut [f64]| -> Result<(), ModelError> {
        dx[0] = -LAMBDA * (x[0] - t.cos());
        Ok(())
    };
    let jac = |_t: f64, _x: &[f64], j: &mut [f64]| -> Result<(), ModelError> {
        j[0] = -LAMBDA;
        Ok(())
    };
    let sol = TrBdf2::new()
        .rtol(1e-9)
        .atol(1e-12)
        .solve_until(f, jac, |_t, x: &[f64]| x[0] - 0.5, 0.0, &[0.0], 5.0)
        .unwrap();
    let g_exact = stiff_exact(LAMBDA, sol.t) - 0.5;
    println!(
        "stiff event: t = {:.12}, exact x − 1/2 there {g_exact:.3e}",
        sol.t
    );
    assert!(sol.event);
    assert!((sol.t - 2.0_f64.ln() / LAMBDA).abs() < 1e-5, "{}", sol.t);
    assert!(g_exact.abs() < 1e-6);
}

#[test]
fn non_finite_event_function_is_an_error() {
    let s = TrBdf2::new();
    let x0 = [1.0, 1.0, 0.0];
    assert_eq!(
        s.solve_model_until(&Smooth, &[], |_t, _x: &[f64]| f64::NAN, 0.0, &x0, 5.0),
        Err(IntegrateError::NonFinite { t: 0.0 })
    );
    match s.solve_model_until(
        &Smooth,
        &[],
        |t, _x: &[f64]| if t > 1.0 { f64::INFINITY } else { 1.0 },
        0.0,
        &x0,
        5.0,
    ) {
        Err(IntegrateError::NonFinite { t }) => assert!(t > 0.0 && t <= 1.0, "{t}"),
        other => panic!("{other:?}"),
    }
    // A bad event tolerance.
    for tol in [-1.0, f64::NAN] {
        assert!(matches!(
            s.event_tol(tol)
                .solve_model_until(&Smooth, &[], |_t, x: &[f64]| x[0], 0.0, &x0, 5.0),
            Err(IntegrateError::InvalidInput { .. })
        ));
    }
}

// ---------------------------------------------------------------------------
// Radau5 on the same models: Jacobians by dual numbers, inputs, work
// against TR-BDF2.

#[test]
fn radau5_user_jacobian_gives_the_same_trajectory_as_dual_numbers() {
    let f = |t: f64, x: &[f64], dx: &mut [f64]| -> Result<(), ModelError> {
        dx[0] = -(LAMBDA * (x[0] - Scalar::cos(t)));
        Ok(())
    };
    let jac = |_t: f64, _x: &[f64], j: &mut [f64]| -> Result<(), ModelError> {
        j[0] = -LAMBDA;
        Ok(())
    };
    let solver = Radau5::new().rtol(1e-6).atol(1e-6);
    let a = solver.solve(f, jac, 0.0, &[0.0], 5.0).unwrap();
    let model = StiffLinear { lambda: LAMBDA };
    let b = solver
        .solve_model(&model, &[1.0], 0.0, &[0.0], 5.0)
        .unwrap();
    assert_eq!(a.x, b.x);
    assert_eq!(a.stats.accepted, b.stats.accepted);
    assert_eq!(a.stats.jacobian_rhs_calls, 0);
    assert_eq!(b.stats.jacobian_rhs_calls, b.stats.jacobians);
    // Inputs reach the model: a = 2 doubles the solution.
    let c = Radau5::new()
        .rtol(1e-8)
        .atol(1e-8)
        .solve_model(&model, &[2.0], 0.0, &[0.0], 2.0)
        .unwrap();
    assert!((c.x[0] - 2.0 * stiff_exact(LAMBDA, 2.0)).abs() < 1e-6);
    // Wrong lengths are the model's typed errors.
    assert!(matches!(
        Radau5::new().solve_model(&model, &[], 0.0, &[0.0], 2.0),
        Err(IntegrateError::Model(ModelError::Length { .. }))
    ));
}

#[test]
fn radau5_does_van_der_pol_with_a_fraction_of_the_work_of_trbdf2() {
    let model = VanDerPol { mu: 1000.0 };
    let (x0, t_end) = ([2.0, 0.0], 2000.0);
    let radau = Radau5::new()
        .rtol(1e-6)
        .atol(1e-6)
        .solve_model(&model, &[], 0.0, &x0, t_end)
        .unwrap();
    let trbdf2 = TrBdf2::new()
        .rtol(1e-6)
        .atol(1e-6)
        .solve_model(&model, &[], 0.0, &x0, t_end)
        .unwrap();
    let reference = Radau5::new()
        .rtol(1e-11)
        .atol(1e-11)
        .solve_model(&model, &[], 0.0, &x0, t_end)
        .unwrap();
    let err = |x: &[f64]| (x[0] - reference.x[0]).abs();
    println!(
        "van der Pol to {t_end}: Radau5 error {:e}, {:?}; TR-BDF2 error {:e}, {:?}",
        err(&radau.x),
        radau.stats,
        err(&trbdf2.x),
        trbdf2.stats
    );
    assert!(err(&radau.x) < 1e-5, "{:?}", radau.x);
    assert!(err(&radau.x) < err(&trbdf2.x));
    let (r, t) = (radau.stats, trbdf2.stats);
    assert!(
        r.accepted + r.rejected < t.accepted + t.rejected,
        "{r:?} {t:?}"
    );
    assert_eq!(r.jacobian_rhs_calls, 2 * r.jacobians);
}

#[test]
fn projected_model_solves_keep_the_invariant() {
    // The Smooth model's x² + x'² = 1 (components 0 and 2).
    let onto_circle = |_t: f64, s: &mut [f64]| {
        let r = s[0].hypot(s[2]);
        if r == 0.0 {
            return Err(ProjectionFailed {
                reason: "zero radius",
            });
        }
        s[0] /= r;
        s[2] /= r;
        Ok(())
    };
    let x0 = smooth_exact(0.0);
    let radau = Radau5::new()
        .rtol(1e-3)
        .solve_model_projected(&Smooth, &[], onto_circle, 0.0, &x0, 20.0)
        .unwrap();
    let trbdf2 = TrBdf2::new()
        .rtol(1e-3)
        .solve_model_projected(&Smooth, &[], onto_circle, 0.0, &x0, 20.0)
        .unwrap();
    for x in [&radau.x, &trbdf2.x] {
        assert!((x[0].hypot(x[2]) - 1.0).abs() < 1e-15, "{x:?}");
    }
    // The projection does not touch z = 1/(1 + t).
    assert!((radau.x[1] - 1.0 / 21.0).abs() < 1e-5, "{:?}", radau.x);
}
