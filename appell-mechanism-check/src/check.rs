//! The checks each random mechanism (and each of its scenes) goes
//! through, at random states:
//!
//! - the generated rhs against the multiplier oracle's
//!   ([`appell::oracle::reduced_rhs`]);
//! - the generated inverse dynamics at the oracle's accelerations against
//!   the inputs' generalized forces f(q, u, inputs) − f(q, u, 0);
//! - the constraint forces ([`appell::constraint_forces::contact_forces`]):
//!   the reactions do no work along the generated speed transform's
//!   columns (Cᵀ Dᵀ λ = 0), and the oracle's q̈ behind them equals the
//!   generated accelerations of the privileged coordinates;
//! - where the loads are conservative (gravity) or inputs, the energy
//!   balance d(T + V)/dt = input power ([`appell::energy::energies`]);
//! - the generated `rhs_jacobian` (symbolic or by the derive's dual
//!   numbers) against num-dual's dual numbers through the rhs
//!   ([`appell::linearize::dual_linearize`]), and the generated
//!   `inverse_dynamics_derivatives` against num-dual through
//!   `inverse_dynamics`.
//!
//! A state where both the generated code and the oracle refuse (a
//! singular configuration) is counted and skipped; one where only one of
//! them refuses is a failure.

use appell::{Model, ModelError};

/// States drawn per model and per scene.
pub const STATES: usize = 12;

/// xorshift64*, seeded: the states are reproducible.
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

/// The largest relative differences found, and what was checked.
#[derive(Clone, Copy, Debug, Default)]
pub struct Report {
    /// Models and scenes checked.
    pub variants: usize,
    /// States where both sides evaluated.
    pub states: usize,
    /// States both refused.
    pub singular: usize,
    pub rhs: f64,
    pub inverse_dynamics: f64,
    pub reactions: f64,
    pub energy: f64,
    /// The generated Jacobian against dual numbers.
    pub jacobian: f64,
    /// States whose energy balance was checked.
    pub energy_states: usize,
}

impl Report {
    /// This report and `other` together.
    pub fn merge(&mut self, other: Report) {
        self.variants += other.variants;
        self.states += other.states;
        self.singular += other.singular;
        self.energy_states += other.energy_states;
        self.rhs = self.rhs.max(other.rhs);
        self.inverse_dynamics = self.inverse_dynamics.max(other.inverse_dynamics);
        self.reactions = self.reactions.max(other.reactions);
        self.energy = self.energy.max(other.energy);
        self.jacobian = self.jacobian.max(other.jacobian);
    }

    /// The largest of the differences.
    pub fn worst(&self) -> f64 {
        self.rhs
            .max(self.inverse_dynamics)
            .max(self.reactions)
            .max(self.energy)
            .max(self.jacobian)
    }
}

/// |a − b| relative to `1 + scale`.
fn relative(a: f64, b: f64, scale: f64) -> f64 {
    (a - b).abs() / (1.0 + scale)
}

fn worst_of(a: &[f64], b: &[f64]) -> f64 {
    let scale = a.iter().chain(b).fold(0.0f64, |m, x| m.max(x.abs()));
    a.iter()
        .zip(b)
        .map(|(x, y)| relative(*x, *y, scale))
        .fold(0.0, f64::max)
}

/// A random state: coordinates in [−1.2, 1.2] (each quaternion's four
/// normalized), speeds and inputs in [−1, 1].
fn random_state<M: Model>(rng: &mut Rng) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let info = M::info();
    let mut q: Vec<f64> = (0..info.coordinates.len())
        .map(|_| rng.uniform(-1.2, 1.2))
        .collect();
    for (k, name) in info.coordinates.iter().enumerate() {
        let stem = if *name == "qw" {
            Some("")
        } else {
            name.strip_suffix("_qw")
        };
        if let Some(stem) = stem {
            let sep = if stem.is_empty() { "" } else { "_" };
            let group: Vec<usize> = ["qw", "qx", "qy", "qz"]
                .iter()
                .filter_map(|s| info.coordinate_index(&format!("{stem}{sep}{s}")))
                .collect();
            let norm = group.iter().map(|&i| q[i] * q[i]).sum::<f64>().sqrt();
            debug_assert_eq!(group[0], k);
            for &i in &group {
                q[i] /= norm;
            }
        }
    }
    let u = (0..info.speeds.len())
        .map(|_| rng.uniform(-1.0, 1.0))
        .collect();
    let inputs = (0..info.inputs.len())
        .map(|_| rng.uniform(-1.0, 1.0))
        .collect();
    (q, u, inputs)
}

/// Checks `model` at [`STATES`] random states; `energy` when its loads
/// are conservative or inputs (and no drive does work).
pub fn model<M: Model>(model: &M, rng: &mut Rng, energy: bool) -> Result<Report, String> {
    let info = M::info();
    let prepared = model.prepare::<f64>();
    let mut report = Report {
        variants: 1,
        ..Report::default()
    };
    for _ in 0..STATES {
        let (q, u, inputs) = random_state::<M>(rng);
        let mut state: Vec<f64> = info
            .retained
            .iter()
            .map(|c| q[info.coordinate_index(c).expect("a coordinate")])
            .collect();
        let kept = state.len();
        state.extend(&u);
        let mut rates = vec![0.0; state.len()];
        let generated = model.rhs(&prepared, 0.0, &state, &inputs, &mut rates);
        let oracle = appell::oracle::reduced_rhs(model, 0.0, &q, &u, &inputs);
        let oracle = match (generated, oracle) {
            (Ok(()), Ok(o)) => o,
            (Err(_), Err(_)) => {
                report.singular += 1;
                continue;
            }
            (g, o) => {
                return Err(format!(
                    "{}: at q = {q:?}, u = {u:?}, inputs = {inputs:?} the rhs gives {g:?} and the oracle {:?}",
                    info.name,
                    o.map(|_| ())
                ))
            }
        };
        report.states += 1;
        report.rhs = report.rhs.max(worst_of(&rates, &oracle));
        let udot = &oracle[kept..];
        report.inverse_dynamics = report
            .inverse_dynamics
            .max(inverse_dynamics(model, &q, &u, &inputs, udot)?);
        report.reactions = report
            .reactions
            .max(reactions(model, &q, &u, &inputs, &rates[kept..])?);
        report.jacobian = report
            .jacobian
            .max(jacobian(model, &state, &inputs)?)
            .max(inverse_derivatives(model, &q, &u, udot)?);
        if energy {
            let e = appell::energy::energies(model, 0.0, &q, &u, &inputs)
                .map_err(|e| format!("{}: energies: {e}", info.name))?;
            let scale = e.kinetic.abs() + e.potential.abs() + e.input_power.abs();
            report.energy = report.energy.max(relative(e.rate, e.input_power, scale));
            report.energy_states += 1;
        }
    }
    Ok(report)
}

/// The generated Jacobian against dual numbers through the rhs, each
/// matrix relative to its largest entry.
fn jacobian<M: Model>(model: &M, state: &[f64], inputs: &[f64]) -> Result<f64, String> {
    let info = M::info();
    let (s, ni) = (state.len(), inputs.len());
    let (mut v, mut a, mut b) = (vec![0.0; s], vec![0.0; s * s], vec![0.0; s * ni]);
    let generated = model.rhs_jacobian(0.0, state, inputs, &mut v, &mut a, &mut b);
    let dual = appell::linearize::dual_linearize(model, 0.0, state, inputs);
    match (generated, dual) {
        (Ok(()), Ok(d)) => {
            // nalgebra stores by columns; the generated matrices by rows.
            let (da, db) = (d.a.transpose(), d.b.transpose());
            Ok(worst_of(&a, da.as_slice()).max(worst_of(&b, db.as_slice())))
        }
        (Err(ModelError::NotGenerated { .. }), _) if info.jacobian.is_none() => Ok(0.0),
        (g, d) => Err(format!(
            "{}: at state {state:?}, inputs {inputs:?} the generated Jacobian gives {g:?} and the dual numbers {:?}",
            info.name,
            d.map(|_| ())
        )),
    }
}

/// The generated `inverse_dynamics_derivatives` (∂Q/∂q, ∂Q/∂u) against
/// num-dual's dual numbers through `inverse_dynamics`, one column at a
/// time (0 where the model has neither).
fn inverse_derivatives<M: Model>(
    model: &M,
    q: &[f64],
    u: &[f64],
    udot: &[f64],
) -> Result<f64, String> {
    use appell::num_dual::Dual64;
    let name = M::info().name;
    let (n, l) = (q.len(), u.len());
    let (mut f, mut dq, mut du, mut m) = (
        vec![0.0; l],
        vec![0.0; l * n],
        vec![0.0; l * l],
        vec![0.0; l * l],
    );
    match model.inverse_dynamics_derivatives(0.0, q, u, udot, &mut f, &mut dq, &mut du, &mut m) {
        Ok(()) => {}
        Err(ModelError::NeedsInputs { .. } | ModelError::NotGenerated { .. }) => return Ok(0.0),
        Err(e) => return Err(format!("{name}: inverse dynamics derivatives: {e}")),
    }
    let mut worst = 0.0f64;
    for c in 0..n + l {
        let seed = |values: &[f64], at: Option<usize>| -> Vec<Dual64> {
            let mut d: Vec<Dual64> = values.iter().map(|&v| Dual64::from_re(v)).collect();
            if let Some(k) = at {
                d[k].eps = 1.0;
            }
            d
        };
        let (qd, ud) = if c < n {
            (seed(q, Some(c)), seed(u, None))
        } else {
            (seed(q, None), seed(u, Some(c - n)))
        };
        let mut out = vec![Dual64::from_re(0.0); l];
        model
            .inverse_dynamics(Dual64::from_re(0.0), &qd, &ud, &seed(udot, None), &mut out)
            .map_err(|e| format!("{name}: inverse dynamics in dual numbers: {e}"))?;
        let column: Vec<f64> = (0..l)
            .map(|i| {
                if c < n {
                    dq[i * n + c]
                } else {
                    du[i * l + c - n]
                }
            })
            .collect();
        let dual: Vec<f64> = out.iter().map(|d| d.eps).collect();
        worst = worst.max(worst_of(&column, &dual));
    }
    Ok(worst)
}

/// The inverse dynamics at the oracle's accelerations against the
/// inputs' generalized forces (0 where the model has none to compare).
fn inverse_dynamics<M: Model>(
    model: &M,
    q: &[f64],
    u: &[f64],
    inputs: &[f64],
    udot: &[f64],
) -> Result<f64, String> {
    let l = u.len();
    let mut forces = vec![0.0; l];
    match model.inverse_dynamics(0.0, q, u, udot, &mut forces) {
        Ok(()) => {}
        Err(ModelError::NeedsInputs { .. } | ModelError::NotGenerated { .. }) => return Ok(0.0),
        Err(e) => return Err(format!("{}: inverse dynamics: {e}", M::info().name)),
    }
    let (mut m, mut f, mut f0) = (vec![0.0; l * l], vec![0.0; l], vec![0.0; l]);
    let zero = vec![0.0; inputs.len()];
    let name = M::info().name;
    model
        .mass_matrix_and_forcing(0.0, q, u, inputs, &mut m, &mut f)
        .map_err(|e| format!("{name}: M and f: {e}"))?;
    model
        .mass_matrix_and_forcing(0.0, q, u, &zero, &mut m, &mut f0)
        .map_err(|e| format!("{name}: M and f: {e}"))?;
    let applied: Vec<f64> = f.iter().zip(&f0).map(|(a, b)| a - b).collect();
    let scale = f.iter().chain(&f0).fold(0.0f64, |s, x| s.max(x.abs()));
    Ok(forces
        .iter()
        .zip(&applied)
        .map(|(a, b)| relative(*a, *b, scale))
        .fold(0.0, f64::max))
}

/// The constraint forces: Cᵀ Dᵀ λ = 0, and the oracle's q̈ behind them
/// against the generated accelerations `udot` of the speeds that are
/// coordinate rates.
fn reactions<M: Model>(
    model: &M,
    q: &[f64],
    u: &[f64],
    inputs: &[f64],
    udot: &[f64],
) -> Result<f64, String> {
    let info = M::info();
    if info.row_sources.is_empty() {
        return Ok(0.0);
    }
    let forces = appell::constraint_forces::contact_forces(model, 0.0, q, u, inputs)
        .map_err(|e| format!("{}: constraint forces: {e}", info.name))?;
    let (n, l) = (q.len(), u.len());
    let (mut c, mut c0) = (vec![0.0; n * l], vec![0.0; n]);
    model
        .driven_speed_transform(0.0, q, inputs, &mut c, &mut c0)
        .map_err(|e| format!("{}: speed transform: {e}", info.name))?;
    let mut worst: f64 = 0.0;
    for k in 0..l {
        let terms: Vec<f64> = forces
            .rows
            .iter()
            .flat_map(|row| (0..n).map(move |r| (r, row.generalized[r])))
            .map(|(r, g)| g * c[r * l + k])
            .collect();
        let scale = terms.iter().fold(0.0f64, |s, x| s.max(x.abs()));
        worst = worst.max(relative(terms.iter().sum::<f64>(), 0.0, scale));
    }
    for (k, speed) in info.speeds.iter().enumerate() {
        if let Some(r) = info.coordinate_index(speed) {
            let scale = udot[k].abs().max(forces.qddot[r].abs());
            worst = worst.max(relative(udot[k], forces.qddot[r], scale));
        }
    }
    Ok(worst)
}
