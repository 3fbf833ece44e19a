//! The `bench` subcommand: timing the generated rhs against the oracle.

use super::error::CliError;
use super::output::finite_or_null;
use appell_core::dynamic::DynModel;
use appell_core::Model;
use serde_json::{json, Value};
use std::hint::black_box;
use std::time::{Duration, Instant};

/// The result of [`bench()`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BenchReport {
    /// Median nanoseconds per call of the generated [`Model::rhs`].
    pub rhs_ns: f64,
    /// Median nanoseconds per call of [`appell_dynamics::oracle::reduced_rhs`].
    pub oracle_ns: f64,
    /// [`OpCounts::total`](appell_core::OpCounts::total) of the generated rhs.
    pub ops: usize,
    /// Number of states timed (those where both succeeded).
    pub states: usize,
}

impl BenchReport {
    /// `{"rhs_ns": .., "oracle_ns": .., "ops": .., "states": ..}`.
    ///
    /// ```
    /// use appell_tools::cli::BenchReport;
    /// let r = BenchReport { rhs_ns: 12.5, oracle_ns: 4000.0, ops: 40, states: 256 };
    /// assert_eq!(r.to_json()["oracle_ns"], 4000.0);
    /// ```
    pub fn to_json(&self) -> Value {
        json!({
            "rhs_ns": finite_or_null(self.rhs_ns),
            "oracle_ns": finite_or_null(self.oracle_ns),
            "ops": self.ops,
            "states": self.states,
        })
    }
}

/// Number of benchmark states.
pub const BENCH_STATES: usize = 256;

/// Number of timed batches (the median is reported).
pub const BENCH_BATCHES: usize = 15;

/// Seed of the benchmark states.
pub const BENCH_SEED: u64 = 0x00A9_9E11_5EED_2003;

/// The shortest duration of one timed batch.
const MIN_BATCH: Duration = Duration::from_millis(2);

/// SplitMix64: a small deterministic generator.
struct SplitMix(u64);

impl SplitMix {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [-1, 1).
    fn symmetric(&mut self) -> f64 {
        let unit = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        2.0 * unit - 1.0
    }
}

struct BenchState {
    q_full: Vec<f64>,
    state: Vec<f64>,
    u: Vec<f64>,
    inputs: Vec<f64>,
}

/// Median nanoseconds per call of `pass` (which makes `calls` calls), after
/// one warm-up pass, over [`BENCH_BATCHES`] batches of at least 2 ms each.
fn time_per_call(calls: usize, mut pass: impl FnMut()) -> f64 {
    let start = Instant::now();
    pass();
    let once = start.elapsed().max(Duration::from_nanos(1));
    let reps = (MIN_BATCH.as_nanos() / once.as_nanos()).max(1) as usize + 1;
    let mut samples: Vec<f64> = (0..BENCH_BATCHES)
        .map(|_| {
            let start = Instant::now();
            for _ in 0..reps {
                pass();
            }
            start.elapsed().as_nanos() as f64 / (reps * calls) as f64
        })
        .collect();
    samples.sort_by(f64::total_cmp);
    samples[samples.len() / 2]
}

/// Times the generated [`Model::rhs`] (with [`Model::prepare`] done once)
/// and the oracle's [`reduced_rhs`](appell_dynamics::oracle::reduced_rhs) over
/// [`BENCH_STATES`] pseudo-random states from [`BENCH_SEED`]: every
/// coordinate (ignorable ones included, for the oracle), every privileged
/// speed and every input uniform in [-1, 1], t = 0. States where either
/// fails are skipped; [`CliError::Bench`] when all fail.
///
/// The reported times are medians over [`BENCH_BATCHES`] batches, each
/// repeating the whole set of states for at least 2 ms, after a warm-up.
/// This takes a noticeable time (about 16 passes of the oracle over the
/// states at least); a runnable example would be slow, so see the module
/// documentation and the crate's tests.
pub fn bench<M: Model>(model: &M) -> Result<BenchReport, CliError> {
    bench_dyn(model)
}

/// [`bench()`] of any [`DynModel`], compiled once.
pub(super) fn bench_dyn(model: &dyn DynModel) -> Result<BenchReport, CliError> {
    let info = model.dyn_info();
    let n = info.coordinates.len();
    let mut retained = Vec::with_capacity(info.retained.len());
    for r in info.retained {
        retained.push(
            info.coordinate_index(r)
                .ok_or_else(|| CliError::Bench(format!("retained `{r}` is not a coordinate")))?,
        );
    }
    let prepared = model.dyn_prepare();
    let mut rng = SplitMix(BENCH_SEED);
    let mut states = Vec::with_capacity(BENCH_STATES);
    let mut dstate = vec![0.0; info.state_len()];
    let mut last_error = String::from("no states");
    for _ in 0..BENCH_STATES {
        let q_full: Vec<f64> = (0..n).map(|_| rng.symmetric()).collect();
        let u: Vec<f64> = info.speeds.iter().map(|_| rng.symmetric()).collect();
        let inputs: Vec<f64> = info.inputs.iter().map(|_| rng.symmetric()).collect();
        let mut state: Vec<f64> = retained.iter().map(|&i| q_full[i]).collect();
        state.extend_from_slice(&u);
        let rhs = prepared.rhs(0.0, &state, &inputs, &mut dstate);
        let oracle = appell_dynamics::oracle::reduced_rhs_dyn(model, 0.0, &q_full, &u, &inputs);
        match (rhs, oracle) {
            (Ok(()), Ok(_)) if dstate.iter().all(|x| x.is_finite()) => states.push(BenchState {
                q_full,
                state,
                u,
                inputs,
            }),
            (Err(e), _) => last_error = format!("rhs: {e}"),
            (_, Err(e)) => last_error = format!("oracle: {e}"),
            (Ok(()), Ok(_)) => last_error = "rhs: the result is not finite".to_string(),
        }
    }
    if states.is_empty() {
        return Err(CliError::Bench(format!(
            "no state where both the rhs and the oracle succeed (last error: {last_error})"
        )));
    }

    let cases: Vec<(&[f64], &[f64])> = states
        .iter()
        .map(|s| (s.state.as_slice(), s.inputs.as_slice()))
        .collect();
    let rhs_ns = time_per_call(states.len(), || {
        prepared.rhs_pass(0.0, &cases, &mut dstate);
    });
    let oracle_ns = time_per_call(states.len(), || {
        for s in &states {
            let r = appell_dynamics::oracle::reduced_rhs_dyn(
                model,
                black_box(0.0),
                black_box(&s.q_full),
                black_box(&s.u),
                black_box(&s.inputs),
            );
            let _ = black_box(r);
        }
    });
    Ok(BenchReport {
        rhs_ns,
        oracle_ns,
        ops: info.rhs_ops.total,
        states: states.len(),
    })
}
