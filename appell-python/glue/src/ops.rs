//! The model's functions on rows of `f64`: [`Op`] names them and gives
//! their layouts, [`Evaluate`] is the object-safe interface the Python class
//! holds, and [`Compiled`] implements it for any [`Model`].

use std::sync::Arc;

use appell::linearize::{step_jacobian, FixedStep};
use appell::{DynModel, Model, ModelInfo, SceneVisitor};

use crate::simulate::{simulate_dyn, SimJob};

/// One function of the model, as the Python package calls it.
///
/// Sizes: s = the reduced state's length, n coordinates, l speeds, i
/// inputs, m velocity constraint rows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    /// `rhs(x[s], u[i]) -> xdot[s]`.
    Rhs,
    /// The generated Jacobian: `(x[s], u[i]) -> xdot[s], A[s×s], B[s×i]`
    /// (row-major, concatenated).
    RhsJacobian,
    /// `appell::linearize::linearize`: `(x, u) -> A[s×s], B[s×i]`, from the
    /// generated Jacobian or, where there is none, by dual numbers.
    Linearize,
    /// `(q[n], v[l], u[i]) -> qdot[n]` (the dependent and the ignorable
    /// coordinates' rates too).
    CoordinateRates,
    /// `q[n] -> M[l×l]`.
    MassMatrix,
    /// `(q, v, u) -> M[l×l], f[l]` (Appell's equations M ÿ = f).
    MassMatrixAndForcing,
    /// `(q, v, a[l]) -> Q[l]` (recursive Newton–Euler on trees).
    InverseDynamics,
    /// `(q, v, a) -> Q[l], ∂Q/∂q[l×n], ∂Q/∂v[l×l], M[l×l]` (Pinocchio's
    /// `computeRNEADerivatives`).
    InverseDynamicsDerivatives,
    /// `(q, v, u) -> ÿ[l], ∂ÿ/∂q[l×n], ∂ÿ/∂v[l×l], ∂ÿ/∂u[l×i]` (Pinocchio's
    /// `computeABADerivatives`).
    ForwardDynamicsDerivatives,
    /// `q -> g[l]`, the forces that hold the mechanism still.
    GravityForces,
    /// `(q, v) -> h[l]`, velocity products and loads at zero inputs.
    BiasForces,
    /// `(q, v, u) -> [kinetic, potential, d(kinetic + potential)/dt, input power]`.
    Energies,
    /// `(q, v, u) -> multipliers[m], qddot[n]` (the constraint forces'
    /// multipliers from the independent KKT solve).
    ConstraintForces,
    /// One fixed step of the classical Runge–Kutta method and its
    /// Jacobians (`appell::linearize::step_jacobian`): `(x[s], u[i], h[1])
    /// -> x⁺[s], ∂x⁺/∂x[s×s], ∂x⁺/∂u[s×i]`.
    StepJacobianRk4,
    /// The same for one semi-implicit Euler step.
    StepJacobianSemiImplicitEuler,
    /// `(q, v, u) -> [position[3], force[3], moment[3]]` for each foot of
    /// [`held_feet`] (`appell::constraint_forces::FootForce`; a point
    /// foot's moment zero).
    FootForces,
}

/// The feet a model or scene holds (`contact(link, point | flat)` rows in
/// its `row_sources`): each one's index into `Model::contact_links` and
/// whether it is flat (holds the link's rotation too), in that order.
pub fn held_feet(info: &ModelInfo) -> Vec<(usize, bool)> {
    let mut feet: Vec<(usize, bool)> = Vec::new();
    for src in info.row_sources {
        if let appell::RowSource::Contact { contact, axis } = *src {
            match feet.iter_mut().find(|(c, _)| *c == contact) {
                Some((_, flat)) => *flat |= axis >= 3,
                None => feet.push((contact, axis >= 3)),
            }
        }
    }
    feet.sort_by_key(|(c, _)| *c);
    feet
}

impl Op {
    /// Every operation, for the Python package's table.
    pub const ALL: [Op; 16] = [
        Op::Rhs,
        Op::RhsJacobian,
        Op::Linearize,
        Op::CoordinateRates,
        Op::MassMatrix,
        Op::MassMatrixAndForcing,
        Op::InverseDynamics,
        Op::InverseDynamicsDerivatives,
        Op::ForwardDynamicsDerivatives,
        Op::GravityForces,
        Op::BiasForces,
        Op::Energies,
        Op::ConstraintForces,
        Op::FootForces,
        Op::StepJacobianRk4,
        Op::StepJacobianSemiImplicitEuler,
    ];

    /// The name the Python package uses.
    pub fn name(self) -> &'static str {
        match self {
            Op::Rhs => "rhs",
            Op::RhsJacobian => "rhs_jacobian",
            Op::Linearize => "linearize",
            Op::CoordinateRates => "coordinate_rates",
            Op::MassMatrix => "mass_matrix",
            Op::MassMatrixAndForcing => "mass_matrix_and_forcing",
            Op::InverseDynamics => "inverse_dynamics",
            Op::InverseDynamicsDerivatives => "inverse_dynamics_derivatives",
            Op::ForwardDynamicsDerivatives => "forward_dynamics_derivatives",
            Op::GravityForces => "gravity_forces",
            Op::BiasForces => "bias_forces",
            Op::Energies => "energies",
            Op::ConstraintForces => "constraint_forces",
            Op::FootForces => "foot_forces",
            Op::StepJacobianRk4 => "step_jacobian_rk4",
            Op::StepJacobianSemiImplicitEuler => "step_jacobian_semi_implicit_euler",
        }
    }

    /// The operation called `name`.
    pub fn from_name(name: &str) -> Option<Op> {
        Op::ALL.into_iter().find(|op| op.name() == name)
    }

    /// The arguments' names and lengths.
    pub fn args(self, info: &ModelInfo) -> Vec<(&'static str, usize)> {
        let (s, n, l, i) = (
            info.state_len(),
            info.coordinates.len(),
            info.speeds.len(),
            info.inputs.len(),
        );
        match self {
            Op::Rhs | Op::RhsJacobian | Op::Linearize => vec![("x", s), ("u", i)],
            Op::CoordinateRates
            | Op::MassMatrixAndForcing
            | Op::ForwardDynamicsDerivatives
            | Op::Energies
            | Op::ConstraintForces
            | Op::FootForces => vec![("q", n), ("v", l), ("u", i)],
            Op::MassMatrix | Op::GravityForces => vec![("q", n)],
            Op::InverseDynamics | Op::InverseDynamicsDerivatives => {
                vec![("q", n), ("v", l), ("a", l)]
            }
            Op::BiasForces => vec![("q", n), ("v", l)],
            Op::StepJacobianRk4 | Op::StepJacobianSemiImplicitEuler => {
                vec![("x", s), ("u", i), ("h", 1)]
            }
        }
    }

    /// The length of one row of the result.
    pub fn out_len(self, info: &ModelInfo) -> usize {
        let (s, n, l, i, m) = (
            info.state_len(),
            info.coordinates.len(),
            info.speeds.len(),
            info.inputs.len(),
            info.constraints,
        );
        match self {
            Op::Rhs => s,
            Op::RhsJacobian | Op::StepJacobianRk4 | Op::StepJacobianSemiImplicitEuler => {
                s + s * s + s * i
            }
            Op::Linearize => s * s + s * i,
            Op::CoordinateRates => n,
            Op::MassMatrix => l * l,
            Op::MassMatrixAndForcing => l * l + l,
            Op::InverseDynamics | Op::GravityForces | Op::BiasForces => l,
            Op::InverseDynamicsDerivatives => l + l * n + 2 * l * l,
            Op::ForwardDynamicsDerivatives => l + l * n + l * l + l * i,
            Op::Energies => 4,
            Op::ConstraintForces => m + n,
            Op::FootForces => 9 * held_feet(info).len(),
        }
    }
}

/// An argument of a call: one row (`batched == false`, the same for every
/// row of a batch) or `rows × len` values.
#[derive(Clone, Copy, Debug)]
pub struct Arg<'a> {
    /// The values, row-major.
    pub data: &'a [f64],
    /// The length of one row.
    pub len: usize,
    /// Whether `data` holds one row per row of the batch.
    pub batched: bool,
}

impl<'a> Arg<'a> {
    /// Row `r` of the argument.
    pub fn row(&self, r: usize) -> &'a [f64] {
        if self.batched {
            &self.data[r * self.len..(r + 1) * self.len]
        } else {
            self.data
        }
    }
}

/// A failed call: the row of the batch and the model's message.
#[derive(Clone, Debug, PartialEq)]
pub struct Failure {
    /// The row of the batch (0 for a single call).
    pub row: usize,
    /// What went wrong, as the runtime's error says it.
    pub message: String,
}

/// A model behind an object-safe interface in `f64`, with its parameters.
pub trait Evaluate: Send + Sync {
    /// The model's `ModelInfo`, or scene `scene`'s.
    fn info(&self, scene: Option<usize>) -> &'static ModelInfo;
    /// The scenes' `ModelInfo`s.
    fn scene_infos(&self) -> &'static [&'static ModelInfo];
    /// The links of the model's `contact(link, ...)` declarations.
    fn contact_links(&self) -> &'static [&'static str];
    /// The parameter values, in `ModelInfo::parameters` order.
    fn parameter_values(&self) -> Vec<f64>;
    /// A copy with the parameters `values` (in `ModelInfo::parameters`
    /// order), checked by `Model::validate` and prepared.
    fn with_parameters(&self, values: &[f64]) -> Result<Arc<dyn Evaluate>, String>;
    /// Evaluates `op` on rows `first..first + out.len() / op.out_len()` of
    /// `args` into `out`.
    fn rows(
        &self,
        scene: Option<usize>,
        op: Op,
        t: f64,
        args: &[Arg<'_>],
        out: &mut [f64],
        first: usize,
    ) -> Result<(), Failure>;
    /// Integrates the reduced equations (see [`SimJob`]).
    fn simulate(&self, scene: Option<usize>, job: &mut SimJob<'_>) -> Result<(), String>;
}

/// A model and its prepared parameter-only values: the [`Evaluate`] of
/// every [`Model`].
pub struct Compiled<M: Model> {
    model: M,
    prepared: M::Prepared<f64>,
}

impl<M: Model> Compiled<M> {
    /// `model`, prepared.
    pub fn new(model: M) -> Self {
        let prepared = model.prepare::<f64>();
        Compiled { model, prepared }
    }
}

impl<M> Evaluate for Compiled<M>
where
    M: Model + Clone + Send + Sync + 'static,
    M::Prepared<f64>: Send + Sync,
{
    fn info(&self, scene: Option<usize>) -> &'static ModelInfo {
        match scene {
            Some(k) => M::scene_infos()[k],
            None => M::info(),
        }
    }

    fn scene_infos(&self) -> &'static [&'static ModelInfo] {
        M::scene_infos()
    }

    fn contact_links(&self) -> &'static [&'static str] {
        M::contact_links()
    }

    fn parameter_values(&self) -> Vec<f64> {
        let mut values = vec![0.0; M::info().parameters.len()];
        // The length is the model's own: this cannot fail.
        let _ = self.model.parameter_values(&mut values);
        values
    }

    fn with_parameters(&self, values: &[f64]) -> Result<Arc<dyn Evaluate>, String> {
        let names = M::info().parameters;
        if values.len() != names.len() {
            return Err(format!(
                "{} parameter values for the {} parameters {:?}",
                values.len(),
                names.len(),
                names
            ));
        }
        let mut model = self.model.clone();
        for (name, &value) in names.iter().zip(values) {
            if !value.is_finite() {
                return Err(format!("parameter `{name}` is {value}"));
            }
            model.set_parameter(name, value);
        }
        model.validate().map_err(|e| e.to_string())?;
        Ok(Arc::new(Compiled::new(model)))
    }

    fn rows(
        &self,
        scene: Option<usize>,
        op: Op,
        t: f64,
        args: &[Arg<'_>],
        out: &mut [f64],
        first: usize,
    ) -> Result<(), Failure> {
        match scene {
            None => run_rows(&self.model, &self.prepared, op, t, args, out, first),
            Some(k) => self
                .model
                .visit_scene(
                    k,
                    RowsVisit {
                        op,
                        t,
                        args,
                        out,
                        first,
                    },
                )
                .map_err(|e| Failure {
                    row: first,
                    message: e.to_string(),
                })?,
        }
    }

    fn simulate(&self, scene: Option<usize>, job: &mut SimJob<'_>) -> Result<(), String> {
        match scene {
            None => simulate_model(&self.model, job),
            Some(k) => self
                .model
                .visit_scene(k, SimulateVisit { job })
                .map_err(|e| e.to_string())?,
        }
    }
}

struct RowsVisit<'a, 'b> {
    op: Op,
    t: f64,
    args: &'a [Arg<'b>],
    out: &'a mut [f64],
    first: usize,
}

impl SceneVisitor for RowsVisit<'_, '_> {
    type Output = Result<(), Failure>;
    fn visit<S: Model>(self, scene: &S) -> Self::Output {
        let prepared = scene.prepare::<f64>();
        run_rows(
            scene, &prepared, self.op, self.t, self.args, self.out, self.first,
        )
    }
}

struct SimulateVisit<'a, 'b> {
    job: &'a mut SimJob<'b>,
}

impl SceneVisitor for SimulateVisit<'_, '_> {
    type Output = Result<(), String>;
    fn visit<S: Model>(self, scene: &S) -> Self::Output {
        simulate_model(scene, self.job)
    }
}

fn simulate_model<M: Model>(model: &M, job: &mut SimJob<'_>) -> Result<(), String> {
    model.validate().map_err(|e| e.to_string())?;
    let rhs = model.dyn_prepare();
    simulate_dyn(&*rhs, job)
}

fn run_rows<M: Model>(
    model: &M,
    prepared: &M::Prepared<f64>,
    op: Op,
    t: f64,
    args: &[Arg<'_>],
    out: &mut [f64],
    first: usize,
) -> Result<(), Failure> {
    let info = M::info();
    let width = op.out_len(info);
    if width == 0 {
        return Ok(());
    }
    let names = op.args(info);
    let mut row_args: [&[f64]; 3] = [&[]; 3];
    for (k, chunk) in out.chunks_exact_mut(width).enumerate() {
        let row = first + k;
        for (j, (arg, (name, _))) in args.iter().zip(&names).enumerate() {
            let values = arg.row(row);
            if let Some(bad) = values.iter().position(|v| !v.is_finite()) {
                return Err(Failure {
                    row,
                    message: format!("argument `{name}` has a non-finite entry at {bad}"),
                });
            }
            row_args[j] = values;
        }
        if !t.is_finite() {
            return Err(Failure {
                row,
                message: format!("t = {t} is not finite"),
            });
        }
        eval_row(model, prepared, op, t, &row_args[..args.len()], chunk)
            .map_err(|message| Failure { row, message })?;
        if let Some(bad) = chunk.iter().position(|v| !v.is_finite()) {
            return Err(Failure {
                row,
                message: format!("{} gave a non-finite value at entry {bad}", op.name()),
            });
        }
    }
    Ok(())
}

fn row_major(m: &appell::nalgebra::DMatrix<f64>, out: &mut [f64]) {
    let cols = m.ncols();
    for i in 0..m.nrows() {
        for j in 0..cols {
            out[i * cols + j] = m[(i, j)];
        }
    }
}

fn eval_row<M: Model>(
    model: &M,
    prepared: &M::Prepared<f64>,
    op: Op,
    t: f64,
    a: &[&[f64]],
    out: &mut [f64],
) -> Result<(), String> {
    let info = M::info();
    let s = info.state_len();
    let l = info.speeds.len();
    let text = |e: appell::ModelError| e.to_string();
    match op {
        Op::Rhs => model.rhs(prepared, t, a[0], a[1], out).map_err(text),
        Op::RhsJacobian => {
            let (values, rest) = out.split_at_mut(s);
            let (da, db) = rest.split_at_mut(s * s);
            model
                .rhs_jacobian(t, a[0], a[1], values, da, db)
                .map_err(text)
        }
        Op::Linearize => {
            let lin = appell::linearize::linearize(model, t, a[0], a[1]).map_err(text)?;
            let (da, db) = out.split_at_mut(s * s);
            row_major(&lin.a, da);
            row_major(&lin.b, db);
            Ok(())
        }
        Op::CoordinateRates => model
            .driven_coordinate_rates(t, a[0], a[1], a[2], out)
            .map_err(text),
        Op::MassMatrix => model.mass_matrix(t, a[0], out).map_err(text),
        Op::MassMatrixAndForcing => {
            let (m, f) = out.split_at_mut(l * l);
            model
                .mass_matrix_and_forcing(t, a[0], a[1], a[2], m, f)
                .map_err(text)
        }
        Op::InverseDynamics => model
            .inverse_dynamics(t, a[0], a[1], a[2], out)
            .map_err(text),
        Op::InverseDynamicsDerivatives => {
            let n = info.coordinates.len();
            let (forces, rest) = out.split_at_mut(l);
            let (dq, rest) = rest.split_at_mut(l * n);
            let (du, m) = rest.split_at_mut(l * l);
            model
                .inverse_dynamics_derivatives(t, a[0], a[1], a[2], forces, dq, du, m)
                .map_err(text)
        }
        Op::ForwardDynamicsDerivatives => {
            let n = info.coordinates.len();
            let (accel, rest) = out.split_at_mut(l);
            let (dq, rest) = rest.split_at_mut(l * n);
            let (du, dinputs) = rest.split_at_mut(l * l);
            model
                .forward_dynamics_derivatives(t, a[0], a[1], a[2], accel, dq, du, dinputs)
                .map_err(text)
        }
        Op::StepJacobianRk4 | Op::StepJacobianSemiImplicitEuler => {
            let method = match op {
                Op::StepJacobianRk4 => FixedStep::Rk4,
                _ => FixedStep::SemiImplicitEuler,
            };
            let step = step_jacobian(model, method, t, a[2][0], a[0], a[1]).map_err(text)?;
            let (next, rest) = out.split_at_mut(s);
            let (da, db) = rest.split_at_mut(s * s);
            next.copy_from_slice(&step.next);
            row_major(&step.a, da);
            row_major(&step.b, db);
            Ok(())
        }
        Op::GravityForces => model.gravity_forces(t, a[0], out).map_err(text),
        Op::BiasForces => model.bias_forces(t, a[0], a[1], out).map_err(text),
        Op::Energies => {
            let e = appell::energy::energies(model, t, a[0], a[1], a[2]).map_err(text)?;
            out.copy_from_slice(&[e.kinetic, e.potential, e.rate, e.input_power]);
            Ok(())
        }
        Op::ConstraintForces => {
            let forces = appell::constraint_forces::contact_forces(model, t, a[0], a[1], a[2])
                .map_err(|e| e.to_string())?;
            let m = info.constraints;
            if forces.multipliers.len() != m || forces.qddot.len() != out.len() - m {
                return Err(format!(
                    "the constraint forces have {} multipliers and {} accelerations, not {} and {}",
                    forces.multipliers.len(),
                    forces.qddot.len(),
                    m,
                    out.len() - m
                ));
            }
            out[..m].copy_from_slice(&forces.multipliers);
            out[m..].copy_from_slice(&forces.qddot);
            Ok(())
        }
        Op::FootForces => {
            let forces = appell::constraint_forces::contact_forces(model, t, a[0], a[1], a[2])
                .map_err(|e| e.to_string())?;
            let held = held_feet(info);
            let found: Vec<usize> = forces.feet.iter().map(|f| f.contact).collect();
            if found != held.iter().map(|(c, _)| *c).collect::<Vec<_>>() {
                return Err(format!("the feet {found:?} are not the rows' {held:?}"));
            }
            for (foot, chunk) in forces.feet.iter().zip(out.chunks_exact_mut(9)) {
                chunk[..3].copy_from_slice(&foot.position);
                chunk[3..6].copy_from_slice(&foot.force);
                chunk[6..].copy_from_slice(&foot.moment.unwrap_or([0.0; 3]));
            }
            Ok(())
        }
    }
}
