//! Round-off of the generated code (issue item 7) and chaos in the double
//! pendulum (item 8), both against the same generated code evaluated in
//! double-double ([`appell::precision::DoubleDouble`], 106-bit significand).

// The shared model files carry items (other sizes, scenes, root finding)
// these cases do not use, hence `dead_code`. `cases.rs` loads some of the
// same files as private modules; a second copy here keeps the two files
// independent at the cost of compiling those derives twice, hence
// `duplicate_mod`.
#[allow(dead_code, clippy::duplicate_mod)]
#[path = "../../examples/models/chaplygin_sleigh.rs"]
mod chaplygin_sleigh;
#[allow(clippy::duplicate_mod)]
#[path = "../common/mod.rs"]
mod common;
use common::XorShift;
#[allow(dead_code, clippy::duplicate_mod)]
#[path = "../../examples/models/double_pendulum.rs"]
mod double_pendulum;
#[allow(dead_code, clippy::duplicate_mod)]
#[path = "../../examples/models/n_link_pendulum.rs"]
mod n_link_pendulum;
#[allow(dead_code, clippy::duplicate_mod)]
#[path = "../../examples/models/rolling_disc.rs"]
mod rolling_disc;
#[allow(dead_code, clippy::duplicate_mod)]
#[path = "../../examples/models/wheel_axle.rs"]
mod wheel_axle;
#[allow(dead_code, clippy::duplicate_mod)]
#[path = "../../examples/models/whipple_bicycle.rs"]
mod whipple_bicycle;

use appell::integrate::rk4_step;
use appell::precision::DoubleDouble;
use appell::{Model, Scalar};
use num_dual::Dual64;

use crate::cases::CaseResult;

fn result(case: &str, criterion: &str, measured: String, pass: bool) -> CaseResult {
    CaseResult {
        case: case.to_string(),
        criterion: criterion.to_string(),
        measured,
        pass,
    }
}

/// A random reduced state and inputs: retained coordinates in [−1, 1],
/// speeds in [−2, 2], inputs in [−1, 1] (as `tests/oracle_agreement.rs`
/// draws them), except where a model needs its own ranges.
fn draw<M: Model>(rng: &mut XorShift) -> (Vec<f64>, Vec<f64>) {
    let info = M::info();
    let mut state: Vec<f64> = info
        .retained
        .iter()
        .map(|_| rng.uniform(-1.0, 1.0))
        .collect();
    state.extend(info.speeds.iter().map(|_| rng.uniform(-2.0, 2.0)));
    let inputs = info.inputs.iter().map(|_| rng.uniform(-1.0, 1.0)).collect();
    if info.name == "WhippleBicycle" {
        // (roll, pitch, steer, roll rate, rear wheel rate, steer rate) as
        // `tests/whipple.rs` draws them: the pitch near the steer-axis
        // tilt, so the holonomic constraint has its upright root nearby.
        state = vec![
            rng.uniform(-0.6, 0.6),
            std::f64::consts::PI / 10.0 + rng.uniform(-0.2, 0.2),
            rng.uniform(-0.8, 0.8),
            rng.uniform(-2.0, 2.0),
            rng.uniform(-20.0, 0.0),
            rng.uniform(-2.0, 2.0),
        ];
        return (state, vec![rng.uniform(-5.0, 5.0)]);
    }
    (state, inputs)
}

/// The largest of the errors `diff` in units of `unit · scale`, where the
/// scale is the largest `reference` magnitude within the component's block
/// (the rates of the retained coordinates, or the rates of the speeds):
/// components of one block share units, and a component that nearly
/// cancels to zero is measured against the size of its neighbours, not
/// against itself.
fn block_ulps(diff: &[f64], reference: &[f64], retained: usize, unit: f64) -> f64 {
    let mut worst: f64 = 0.0;
    for block in [0..retained, retained..reference.len()] {
        let scale = reference[block.clone()]
            .iter()
            .fold(0.0f64, |m, x| m.max(x.abs()));
        for i in block {
            if diff[i] != 0.0 {
                worst = worst.max(diff[i].abs() / (unit * scale.max(f64::MIN_POSITIVE)));
            }
        }
    }
    worst
}

/// The block scale of each component of `reference` (see [`block_ulps`]).
fn block_scales(reference: &[f64], retained: usize) -> Vec<f64> {
    let mut scales = vec![0.0; reference.len()];
    for block in [0..retained, retained..reference.len()] {
        let scale = reference[block.clone()]
            .iter()
            .fold(0.0f64, |m, x| m.max(x.abs()));
        for i in block {
            scales[i] = scale.max(f64::MIN_POSITIVE);
        }
    }
    scales
}

/// The componentwise condition number of the rhs itself at one point, in
/// block units: max over outputs of Σ_x |∂ẋ_i/∂x| |x| / (block scale of i),
/// x running over the state, the inputs and the parameters. It is what a
/// relative change of one unit in every datum can move an output by, so
/// any way of computing the rhs, however good, may show that much more
/// round-off at this point than at a well-conditioned one. Forward
/// differences with relative steps of 1e-8, evaluated in double-double so
/// the differences do not cancel.
fn data_condition<M: Model + Clone>(model: &M, state: &[f64], inputs: &[f64]) -> f64 {
    let info = M::info();
    let retained = info.retained.len();
    let run = |m: &M, s: &[f64], u: &[f64]| -> Vec<f64> {
        let p = m.prepare::<DoubleDouble>();
        let sd: Vec<DoubleDouble> = s.iter().map(|&x| DoubleDouble::from(x)).collect();
        let ud: Vec<DoubleDouble> = u.iter().map(|&x| DoubleDouble::from(x)).collect();
        let mut out = vec![DoubleDouble::default(); s.len()];
        m.rhs(&p, DoubleDouble::zero(), &sd, &ud, &mut out)
            .expect("the rhs near a drawn state");
        out.iter().map(|x| x.to_f64()).collect()
    };
    let base = run(model, state, inputs);
    let scales = block_scales(&base, retained);
    let mut sums = vec![0.0f64; base.len()];
    let mut add = |moved: Vec<f64>, x: f64, dx: f64| {
        for i in 0..base.len() {
            sums[i] += ((moved[i] - base[i]) / dx * x).abs();
        }
    };
    let step = |x: f64| {
        let moved = x * (1.0 + 1e-8);
        (moved, moved - x)
    };
    for k in 0..state.len() {
        if state[k] != 0.0 {
            let (moved, dx) = step(state[k]);
            let mut s = state.to_vec();
            s[k] = moved;
            add(run(model, &s, inputs), state[k], dx);
        }
    }
    for k in 0..inputs.len() {
        if inputs[k] != 0.0 {
            let (moved, dx) = step(inputs[k]);
            let mut u = inputs.to_vec();
            u[k] = moved;
            add(run(model, state, &u), inputs[k], dx);
        }
    }
    let mut values = vec![0.0; info.parameters.len()];
    model.parameter_values(&mut values).expect("parameters");
    for (name, &v) in info.parameters.iter().zip(&values) {
        if v != 0.0 {
            let (moved, dx) = step(v);
            let mut m = model.clone();
            assert!(m.set_parameter(name, moved), "{name}");
            add(run(&m, state, inputs), v, dx);
        }
    }
    sums.iter()
        .zip(&scales)
        .fold(0.0f64, |k, (s, scale)| k.max(s / scale))
}

/// What one model's round-off sweep measured.
pub struct RoundOff {
    /// The model's name.
    pub model: &'static str,
    /// Operations in its rhs (with CSE).
    pub ops: usize,
    /// Largest f64 error against double-double, in f64 ulps (2⁻⁵² times the
    /// block scale, see [`block_ulps`]).
    pub f64_max: f64,
    /// The mean of the per-state largest f64 error, same units.
    pub f64_mean: f64,
    /// Largest f32 error against f64 at the same f32-rounded parameters and
    /// state, in f32 ulps (2⁻²³ times the block scale).
    pub f32_max: f64,
    /// The mean of the per-state largest f32 error, same units.
    pub f32_mean: f64,
    /// The largest f64 error divided by the rhs's own condition number
    /// there (at least 1, see [`data_condition`]), same units.
    pub f64_conditioned: f64,
    /// The same for f32.
    pub f32_conditioned: f64,
    /// The condition number at the state of the largest f32 error (1 where
    /// it was not needed).
    pub worst_condition: f64,
}

/// Round-off of one model's generated rhs over `count` random states.
///
/// The f64 rhs is compared with the same generated function evaluated in
/// double-double at the same (f64) parameters and state, so the difference
/// is the f64 round-off alone. For f32, parameters and state are first
/// rounded to f32 (through `set_parameter`), and the f32 rhs is compared
/// with the f64 rhs at those rounded values, so again only the arithmetic
/// differs (the f64 reference's own error is 2⁻²⁹ of an f32 ulp).
pub fn round_off<M: Model + Clone>(model: &M, count: usize, seed: u64) -> RoundOff {
    let info = M::info();
    let n = info.state_len();
    let retained = info.retained.len();
    let p64 = model.prepare::<f64>();
    let pdd = model.prepare::<DoubleDouble>();
    let mut model32 = model.clone();
    let mut values = vec![0.0; info.parameters.len()];
    model.parameter_values(&mut values).expect("parameters");
    for (name, v) in info.parameters.iter().zip(&values) {
        assert!(model32.set_parameter(name, *v as f32 as f64), "{name}");
    }
    let p32 = model32.prepare::<f32>();
    let p32_64 = model32.prepare::<f64>();
    let mut rng = XorShift(seed);
    let (mut d64, mut d32, mut d32_64) = (vec![0.0; n], vec![0.0f32; n], vec![0.0; n]);
    let mut ddd = vec![DoubleDouble::default(); n];
    let (mut f64_max, mut f64_sum, mut f32_max, mut f32_sum) = (0.0f64, 0.0, 0.0f64, 0.0);
    // Errors above the plain bound are divided by the rhs's condition
    // number at their state (computed only there: it costs an evaluation
    // per datum).
    let plain = round_off_bound(info.rhs_ops.total);
    let (mut f64_conditioned, mut f32_conditioned, mut worst_condition) = (0.0f64, 0.0f64, 1.0);
    for _ in 0..count {
        let (state, inputs) = draw::<M>(&mut rng);
        model.rhs(&p64, 0.0, &state, &inputs, &mut d64).unwrap();
        let sdd: Vec<DoubleDouble> = state.iter().map(|&x| DoubleDouble::from(x)).collect();
        let idd: Vec<DoubleDouble> = inputs.iter().map(|&x| DoubleDouble::from(x)).collect();
        model
            .rhs(&pdd, DoubleDouble::zero(), &sdd, &idd, &mut ddd)
            .unwrap();
        let reference: Vec<f64> = ddd.iter().map(|x| x.to_f64()).collect();
        // The f64 result against the double-double one, its difference
        // formed in double-double.
        let diff: Vec<f64> = d64
            .iter()
            .zip(&ddd)
            .map(|(&a, &b)| (DoubleDouble::from(a) - b).to_f64())
            .collect();
        let e64 = block_ulps(&diff, &reference, retained, f64::EPSILON);
        let c64 = if e64 > plain {
            e64 / data_condition(model, &state, &inputs).max(1.0)
        } else {
            e64
        };
        f64_conditioned = f64_conditioned.max(c64);
        f64_max = f64_max.max(e64);
        f64_sum += e64;

        let s32: Vec<f32> = state.iter().map(|&x| x as f32).collect();
        let i32_: Vec<f32> = inputs.iter().map(|&x| x as f32).collect();
        model32.rhs(&p32, 0.0, &s32, &i32_, &mut d32).unwrap();
        let s32_64: Vec<f64> = s32.iter().map(|&x| x as f64).collect();
        let i32_64: Vec<f64> = i32_.iter().map(|&x| x as f64).collect();
        model32
            .rhs(&p32_64, 0.0, &s32_64, &i32_64, &mut d32_64)
            .unwrap();
        let diff: Vec<f64> = d32
            .iter()
            .zip(&d32_64)
            .map(|(&a, &b)| a as f64 - b)
            .collect();
        let e32 = block_ulps(&diff, &d32_64, retained, f32::EPSILON as f64);
        let c32 = if e32 > plain {
            let kappa = data_condition(&model32, &s32_64, &i32_64).max(1.0);
            if e32 > f32_max {
                worst_condition = kappa;
            }
            e32 / kappa
        } else {
            e32
        };
        f32_conditioned = f32_conditioned.max(c32);
        f32_max = f32_max.max(e32);
        f32_sum += e32;
    }
    RoundOff {
        model: info.name,
        ops: info.rhs_ops.total,
        f64_max,
        f64_mean: f64_sum / count as f64,
        f32_max,
        f32_mean: f32_sum / count as f64,
        f64_conditioned,
        f32_conditioned,
        worst_condition,
    }
}

/// 4 √n ulps for n operations, at least 16 (see [`round_off_all`]).
fn round_off_bound(ops: usize) -> f64 {
    (4.0 * (ops as f64).sqrt()).max(16.0)
}

/// Item 7 over `count` random states per example model: the f64 rhs
/// against double-double and the f32 rhs against f64, the error in ulps of
/// the block scale (the largest magnitude among the rates of the retained
/// coordinates, or among the rates of the speeds, in the reference).
///
/// The bound: a straight-line program of n operations, each rounding with
/// relative error at most u, has a forward error of at most about
/// n · u · κ relative to the scale (Higham's γₙ), κ the amplification of
/// the data (here chiefly the condition of the mass-matrix solve). That
/// worst case needs every rounding to push the same way; independent
/// roundings add like a random walk, which gives λ √n · u · κ with λ a
/// small constant with overwhelming probability (Higham & Mary's
/// probabilistic bound). The measured maxima over 10,000 states sit at
/// 0.5 to 3 √n ulps for all six models, so κ stays of order one at most
/// states. The criterion is 4 √n ulps, at least 16 (a handful of roundings
/// reach the output of the smallest programs), times the rhs's own
/// condition number at the state where it is above 1: an error above
/// 4 √n ulps is divided by that number ([`data_condition`]: what relative
/// changes of one unit in the state, inputs and parameters can do to the
/// exact rhs there), because no way of computing the rhs avoids it. The
/// bicycle has such states (large steer and lean, where the steer
/// acceleration is a small difference of large terms); the other models do
/// not. A regression that loses bits systematically (a cancelling form,
/// an unpivoted or badly scaled solve) grows like n, or like an
/// amplification the exact rhs does not have, and fails it; f32 gets the
/// same bound in f32 ulps.
pub fn round_off_all(count: usize) -> Vec<CaseResult> {
    let sweeps = [
        round_off(&wheel_axle::WheelAxle::default(), count, 1),
        round_off(&double_pendulum::DoublePendulum::default(), count, 2),
        round_off(&rolling_disc::RollingDisc::default(), count, 3),
        round_off(&chaplygin_sleigh::ChaplyginSleigh::default(), count, 4),
        round_off(&n_link_pendulum::Pendulum8::default(), count, 5),
        round_off(&whipple_bicycle::WhippleBicycle::default(), count, 6),
    ];
    let mut rows = Vec::new();
    for s in sweeps {
        let bound = round_off_bound(s.ops);
        rows.push(result(
            &format!("round-off, {}", s.model),
            &format!(
                "f64 rhs vs double-double over {count} states: ≤ {bound:.0} ulps of the block scale (4 √n, n = {} ops) times the rhs's condition number where above 1",
                s.ops
            ),
            format!(
                "max {:.1} ulps ({:.2} √n), {:.1} divided by the condition number, mean of per-state max {:.2}",
                s.f64_max,
                s.f64_max / (s.ops as f64).sqrt(),
                s.f64_conditioned,
                s.f64_mean
            ),
            s.f64_conditioned <= bound,
        ));
        rows.push(result(
            &format!("round-off, {}", s.model),
            &format!(
                "f32 rhs vs f64 over {count} states: ≤ {bound:.0} f32 ulps of the block scale, times the condition number"
            ),
            format!(
                "max {:.1} ulps ({:.2} √n; condition number {:.1} there), {:.1} divided by the condition number, mean of per-state max {:.2}",
                s.f32_max,
                s.f32_max / (s.ops as f64).sqrt(),
                s.worst_condition,
                s.f32_conditioned,
                s.f32_mean
            ),
            s.f32_conditioned <= bound,
        ));
    }
    rows
}

/// The double pendulum's chaotic start: both links at 2 rad from the
/// downward vertical (well above the horizontal), at rest.
const CHAOTIC_START: [f64; 4] = [2.0, 2.0, 0.0, 0.0];
/// The RK4 step of both the Lyapunov estimate and the two-precision runs.
const CHAOS_STEP: f64 = 1e-3;

/// The largest Lyapunov exponent [1/s] of the double pendulum from `x0`,
/// over `steps` RK4 steps of `h`: the tangent dynamics of the RK4 map come
/// out of the same generated rhs run on `Dual64` (the state's dual parts
/// carry a tangent vector v, so one step maps v to J v exactly); v is
/// renormalised after every step and the exponent is the mean of ln ‖J v‖
/// per unit time. A first tenth of the steps aligns v and is not counted.
pub fn lyapunov_exponent(x0: [f64; 4], h: f64, steps: usize) -> f64 {
    let model = double_pendulum::DoublePendulum::default();
    let prepared = model.prepare::<Dual64>();
    let mut x = x0;
    let mut v = [0.5; 4];
    let warm_up = steps / 10;
    let mut sum_ln = 0.0;
    for k in 0..warm_up + steps {
        let xs: [Dual64; 4] = std::array::from_fn(|i| Dual64::new(x[i], v[i]));
        let t = Dual64::from_f64(k as f64 * h);
        let next = rk4_step(&model, &prepared, t, Dual64::from_f64(h), &xs, &[]).unwrap();
        x = std::array::from_fn(|i| next[i].re);
        let norm = next.iter().map(|d| d.eps * d.eps).sum::<f64>().sqrt();
        v = std::array::from_fn(|i| next[i].eps / norm);
        if k >= warm_up {
            sum_ln += norm.ln();
        }
    }
    sum_ln / (steps as f64 * h)
}

/// Item 8: chaos in the double pendulum. An f64 RK4 run from
/// [`CHAOTIC_START`] and a double-double run with the same steps (so the
/// integrator's truncation error is the same in both and only round-off
/// differs) must agree to `tol` until about the time the largest Lyapunov
/// exponent λ predicts for an initial difference of one ulp to grow to
/// `tol`: t* = ln(tol / δ₀) / λ, δ₀ = 2⁻⁵² · max |x₀|. Criterion: they
/// separate no earlier than t* / 2 (finite-time exponents fluctuate about λ,
/// and round-off keeps entering after t = 0, so agreement to a factor of 2
/// in time is what the prediction can promise). The exponent is estimated
/// over `lyapunov_time` seconds and must be positive (the motion is chaotic,
/// or the case proves nothing).
pub fn double_pendulum_chaos(lyapunov_time: f64) -> Vec<CaseResult> {
    let h = CHAOS_STEP;
    let lambda = lyapunov_exponent(CHAOTIC_START, h, (lyapunov_time / h) as usize);
    let tol = 1e-6;
    let delta0 = f64::EPSILON * CHAOTIC_START.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let t_pred = (tol / delta0).ln() / lambda;

    let model = double_pendulum::DoublePendulum::default();
    let p64 = model.prepare::<f64>();
    let pdd = model.prepare::<DoubleDouble>();
    let mut x64 = CHAOTIC_START;
    let mut xdd = CHAOTIC_START.map(DoubleDouble::from);
    let max_steps = (4.0 * t_pred / h) as usize;
    let mut t_sep = f64::INFINITY;
    for k in 0..max_steps {
        let t = k as f64 * h;
        x64 = rk4_step(&model, &p64, t, h, &x64, &[]).unwrap();
        xdd = rk4_step(
            &model,
            &pdd,
            DoubleDouble::from(t),
            DoubleDouble::from(h),
            &xdd,
            &[],
        )
        .unwrap();
        let gap = (0..4)
            .map(|i| (DoubleDouble::from(x64[i]) - xdd[i]).abs().to_f64())
            .fold(0.0f64, f64::max);
        if gap > tol {
            t_sep = (k + 1) as f64 * h;
            break;
        }
    }
    vec![
        result(
            "chaos, double pendulum",
            &format!(
                "largest Lyapunov exponent > 0 (RK4 tangent map by Dual64 over {lyapunov_time} s, from q = (2, 2) rad at rest)"
            ),
            format!("λ = {lambda:.3} /s"),
            lambda > 0.0,
        ),
        result(
            "chaos, double pendulum",
            &format!(
                "f64 and double-double RK4 (h = {h} s) agree to {tol:e} until ≥ t*/2, t* = ln(tol/δ₀)/λ, δ₀ = 1 ulp = {delta0:.1e}"
            ),
            format!(
                "t* = {t_pred:.1} s, separated at {t_sep:.2} s ({:.2} t*)",
                t_sep / t_pred
            ),
            t_sep >= 0.5 * t_pred,
        ),
    ]
}
