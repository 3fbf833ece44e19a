//! Helpers shared by the integration tests.

#![allow(dead_code)] // each test file uses a subset

use appell::Model;

/// A small deterministic generator (xorshift64*), so failures reproduce.
pub struct Rng(pub u64);

impl Rng {
    /// Uniform in `[lo, hi)`.
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let x = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11;
        lo + (hi - lo) * x as f64 / (1u64 << 53) as f64
    }
}

/// The plain xorshift64 generator (shifts 13, 7, 17), uniform in
/// `[lo, hi)`: the sequence some tests' recorded figures were drawn from.
pub struct XorShift(pub u64);

impl XorShift {
    /// Uniform in `[lo, hi)`.
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        lo + (hi - lo) * ((self.0 >> 11) as f64 / (1u64 << 53) as f64)
    }
}

/// A wheel-axle (the `WheelAxle` in scope) with random geometry, mass and
/// slope, drawn from the `Rng` named `rng` in a fixed order.
#[allow(unused_macros)] // each test file uses a subset
macro_rules! random_wheel_axle {
    ($rng:ident) => {
        WheelAxle {
            a: $rng.uniform(0.1, 1.0),
            l: $rng.uniform(0.2, 2.0),
            mass: $rng.uniform(0.5, 5.0),
            rim: $rng.uniform(0.1, 2.0),
            g: 9.81,
            alpha: $rng.uniform(-0.5, 0.5),
        }
    };
}
#[allow(unused_imports)] // each test file uses a subset
pub(crate) use random_wheel_axle;

/// Relative closeness with an absolute floor of `rel`.
pub fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * (1.0 + a.abs().max(b.abs()))
}

/// The textbook accelerations of a planar double pendulum (point masses,
/// absolute angles from the downward vertical): state (θ1, θ2, ω1, ω2).
pub fn double_pendulum_accelerations(
    m1: f64,
    m2: f64,
    l1: f64,
    l2: f64,
    g: f64,
    s: [f64; 4],
) -> (f64, f64) {
    let (t1, t2, w1, w2) = (s[0], s[1], s[2], s[3]);
    let den = 2.0 * m1 + m2 - m2 * (2.0 * t1 - 2.0 * t2).cos();
    let a1 = (-g * (2.0 * m1 + m2) * t1.sin()
        - m2 * g * (t1 - 2.0 * t2).sin()
        - 2.0 * (t1 - t2).sin() * m2 * (w2 * w2 * l2 + w1 * w1 * l1 * (t1 - t2).cos()))
        / (l1 * den);
    let a2 = 2.0
        * (t1 - t2).sin()
        * (w1 * w1 * l1 * (m1 + m2)
            + g * (m1 + m2) * t1.cos()
            + w2 * w2 * l2 * m2 * (t1 - t2).cos())
        / (l2 * den);
    (a1, a2)
}

/// Compares generated and oracle reduced rhs at `count` random states;
/// returns the largest relative difference seen.
pub fn agree<M: Model>(model: &M, rng: &mut Rng, count: usize, q_range: f64) -> f64 {
    agree_with_inputs(model, rng, count, q_range, 1.0)
}

/// [`agree`] with inputs drawn from [−input_range, input_range].
pub fn agree_with_inputs<M: Model>(
    model: &M,
    rng: &mut Rng,
    count: usize,
    q_range: f64,
    input_range: f64,
) -> f64 {
    let info = M::info();
    let prepared = model.prepare::<f64>();
    let n = info.coordinates.len();
    let l = info.speeds.len();
    let mut worst: f64 = 0.0;
    for _ in 0..count {
        let q: Vec<f64> = (0..n).map(|_| rng.uniform(-q_range, q_range)).collect();
        let u: Vec<f64> = (0..l).map(|_| rng.uniform(-2.0, 2.0)).collect();
        let inputs: Vec<f64> = info
            .inputs
            .iter()
            .map(|_| rng.uniform(-input_range, input_range))
            .collect();
        let mut state: Vec<f64> = info
            .retained
            .iter()
            .map(|c| q[info.coordinate_index(c).unwrap()])
            .collect();
        state.extend(&u);
        let mut d = vec![0.0; state.len()];
        model.rhs(&prepared, 0.0, &state, &inputs, &mut d).unwrap();
        let o = appell::oracle::reduced_rhs(model, 0.0, &q, &u, &inputs).unwrap();
        for (a, b) in d.iter().zip(&o) {
            let rel = (a - b).abs() / (1.0 + a.abs().max(b.abs()));
            worst = worst.max(rel);
        }
    }
    println!(
        "{}: largest relative difference over {count} states: {worst:.2e}",
        info.name
    );
    worst
}

/// The controller functions against `mass_matrix_and_forcing` and the rhs
/// at `count` random states: inverse dynamics of the rhs's ÿ gives the
/// inputs' generalized forces f(q, u, inputs) − f(q, u, 0), M alone is
/// M, the bias is −f(q, u, 0) and the gravity term −f(q, 0, 0). Returns
/// the largest relative difference.
pub fn controller_agrees<M: Model>(model: &M, rng: &mut Rng, count: usize, q_range: f64) -> f64 {
    let info = M::info();
    let prepared = model.prepare::<f64>();
    let (n, l) = (info.coordinates.len(), info.speeds.len());
    let mut worst: f64 = 0.0;
    let mut compare = |a: &[f64], b: &[f64]| {
        for (a, b) in a.iter().zip(b) {
            worst = worst.max((a - b).abs() / (1.0 + a.abs().max(b.abs())));
        }
    };
    for _ in 0..count {
        let q: Vec<f64> = (0..n).map(|_| rng.uniform(-q_range, q_range)).collect();
        let u: Vec<f64> = (0..l).map(|_| rng.uniform(-2.0, 2.0)).collect();
        let inputs: Vec<f64> = info.inputs.iter().map(|_| rng.uniform(-1.0, 1.0)).collect();
        let zero_inputs = vec![0.0; inputs.len()];
        let mut state: Vec<f64> = info
            .retained
            .iter()
            .map(|c| q[info.coordinate_index(c).unwrap()])
            .collect();
        let kept = state.len();
        state.extend(&u);
        let mut d = vec![0.0; state.len()];
        model.rhs(&prepared, 0.0, &state, &inputs, &mut d).unwrap();
        let (mut m, mut f, mut f0, mut fg) =
            (vec![0.0; l * l], vec![0.0; l], vec![0.0; l], vec![0.0; l]);
        model
            .mass_matrix_and_forcing(0.0, &q, &u, &inputs, &mut m, &mut f)
            .unwrap();
        model
            .mass_matrix_and_forcing(0.0, &q, &u, &zero_inputs, &mut m, &mut f0)
            .unwrap();
        model
            .mass_matrix_and_forcing(0.0, &q, &vec![0.0; l], &zero_inputs, &mut m, &mut fg)
            .unwrap();
        let mut out = vec![0.0; l];
        model
            .inverse_dynamics(0.0, &q, &u, &d[kept..], &mut out)
            .unwrap();
        let applied: Vec<f64> = f.iter().zip(&f0).map(|(a, b)| a - b).collect();
        compare(&out, &applied);
        let mut mm = vec![0.0; l * l];
        model.mass_matrix(0.0, &q, &mut mm).unwrap();
        compare(&mm, &m);
        model.bias_forces(0.0, &q, &u, &mut out).unwrap();
        compare(&out, &f0.iter().map(|x| -x).collect::<Vec<_>>());
        model.gravity_forces(0.0, &q, &mut out).unwrap();
        compare(&out, &fg.iter().map(|x| -x).collect::<Vec<_>>());
    }
    println!(
        "{}: controller functions, largest relative difference over {count} states: {worst:.2e}",
        info.name
    );
    worst
}
