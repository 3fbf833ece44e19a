//! Integration of the reduced equations at given output times, through
//! [`DynRhs`] so that the integrators are compiled once in this crate, not
//! once per model.

use std::cell::RefCell;

use appell::integrate::{Dop853, EventFn, Radau5};
use appell::num_dual::Dual64;
use appell::{DynRhs, ModelError};

/// The integrator of [`SimJob`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Adaptive Dormand–Prince 8(5,3) with dense output (state lengths up to
    /// [`DOP853_MAX_STATE`]).
    Dop853,
    /// The implicit Radau IIA of order 5, for stiff models (the generated
    /// Jacobian where there is one, else dual numbers).
    Radau5,
    /// Classic fourth-order Runge–Kutta with fixed steps no longer than
    /// `h_max` between the output times.
    Rk4,
}

impl Method {
    /// The method called `name` (`"dop853"`, `"radau5"`, `"rk4"`).
    pub fn from_name(name: &str) -> Option<Method> {
        match name {
            "dop853" => Some(Method::Dop853),
            "radau5" => Some(Method::Radau5),
            "rk4" => Some(Method::Rk4),
            _ => None,
        }
    }
}

/// The longest state DOP853 is compiled for here (its stages are arrays
/// of the state's length, a constant of the code).
pub const DOP853_MAX_STATE: usize = 64;

/// An event function `g(t, x)` (see [`SimJob::event`]).
pub type Event<'a> = dyn FnMut(f64, &[f64]) -> f64 + 'a;

/// A state feedback `u(t, x)` (see [`SimJob::feedback`]): writes the
/// inputs at `(t, x)` into its third argument, or says why it cannot.
pub type Feedback<'a> = dyn FnMut(f64, &[f64], &mut [f64]) -> Result<(), String> + 'a;

/// A simulation: from `x0` at `t0`, the state at each of `t_eval` (ordered
/// in the direction of integration, the first not before `t0`), written
/// row after row into `out`.
pub struct SimJob<'a> {
    /// The integrator.
    pub method: Method,
    /// The initial reduced state.
    pub x0: &'a [f64],
    /// The inputs, held constant (without [`SimJob::feedback`]).
    pub inputs: &'a [f64],
    /// The inputs as a function of the time and the state, called at every
    /// evaluation of the rhs (and of Radau5's Jacobian, at the point it is
    /// taken). Radau5's Newton iteration then uses ∂rhs/∂x
    /// with the inputs frozen at `u(t, x)` (the law's own derivative is not
    /// known), which changes its convergence, not its solution.
    pub feedback: Option<&'a mut Feedback<'a>>,
    /// The initial time.
    pub t0: f64,
    /// The output times.
    pub t_eval: &'a [f64],
    /// Relative tolerance (adaptive methods).
    pub rtol: f64,
    /// Absolute tolerance (adaptive methods).
    pub atol: f64,
    /// The longest step (required for RK4).
    pub h_max: Option<f64>,
    /// The most steps an adaptive method may take.
    pub max_steps: usize,
    /// `len(t_eval) × state length` values.
    pub out: &'a mut [f64],
    /// An event function `g(t, x)`: the simulation stops where it changes
    /// sign (DOP853 only).
    pub event: Option<&'a mut Event<'a>>,
    /// Set by the simulation: how many rows of `out` were written.
    pub written: usize,
    /// Set by the simulation: the time of the event and the state there.
    pub event_at: Option<(f64, Vec<f64>)>,
}

/// The inputs of one run: held, or a feedback law called at every
/// evaluation. A law's failure is kept, to be reported in place of the
/// error it makes the integrator stop with.
struct Law<'a> {
    held: &'a [f64],
    feedback: Option<RefCell<(&'a mut Feedback<'a>, Vec<f64>)>>,
    failure: RefCell<Option<String>>,
}

impl<'a> Law<'a> {
    fn of(job: &mut SimJob<'a>) -> Law<'a> {
        let inputs = vec![0.0; job.inputs.len()];
        Law {
            held: job.inputs,
            feedback: job.feedback.take().map(|f| RefCell::new((f, inputs))),
            failure: RefCell::new(None),
        }
    }

    /// `with` called on the inputs at `(t, x)`.
    fn with<R>(
        &self,
        t: f64,
        x: &[f64],
        with: impl FnOnce(&[f64]) -> Result<R, ModelError>,
    ) -> Result<R, ModelError> {
        let Some(cell) = &self.feedback else {
            return with(self.held);
        };
        let mut guard = cell.borrow_mut();
        let (law, inputs) = &mut *guard;
        if let Err(message) = law(t, x, inputs) {
            self.failure.borrow_mut().get_or_insert(message);
            return Err(ModelError::NonFinite {
                what: "the inputs u(t, x)",
            });
        }
        with(inputs)
    }

    fn rhs(&self, rhs: &dyn DynRhs, t: f64, x: &[f64], dx: &mut [f64]) -> Result<(), ModelError> {
        self.with(t, x, |u| rhs.rhs(t, x, u, dx))
    }

    /// The run's error message: the law's failure, if it failed.
    fn error(&self, e: impl ToString) -> String {
        match self.failure.borrow().as_ref() {
            Some(message) => message.clone(),
            None => e.to_string(),
        }
    }
}

fn check(job: &SimJob<'_>, s: usize) -> Result<(), String> {
    if job.x0.len() != s {
        return Err(format!(
            "x0 has {} entries; the reduced state has {s}",
            job.x0.len()
        ));
    }
    if job.out.len() != job.t_eval.len() * s {
        return Err("the output buffer does not match t_eval".into());
    }
    if let Some(bad) = job.x0.iter().position(|v| !v.is_finite()) {
        return Err(format!("x0 has a non-finite entry at {bad}"));
    }
    if let Some(bad) = job.inputs.iter().position(|v| !v.is_finite()) {
        return Err(format!("u has a non-finite entry at {bad}"));
    }
    if job.t_eval.is_empty() {
        return Err("t_eval is empty".into());
    }
    if !job.t0.is_finite() || job.t_eval.iter().any(|t| !t.is_finite()) {
        return Err("t0 and t_eval must be finite".into());
    }
    let last = job.t_eval[job.t_eval.len() - 1];
    let dir = if last >= job.t0 { 1.0 } else { -1.0 };
    let mut prev = job.t0;
    for &t in job.t_eval {
        if (t - prev) * dir < 0.0 {
            return Err(format!(
                "t_eval must run from t0 = {} in one direction (found {t} after {prev})",
                job.t0
            ));
        }
        prev = t;
    }
    if !(job.rtol > 0.0 && job.atol >= 0.0) {
        return Err(format!(
            "rtol must be positive and atol not negative (rtol = {}, atol = {})",
            job.rtol, job.atol
        ));
    }
    Ok(())
}

/// Runs `job` on `rhs`.
pub fn simulate_dyn(rhs: &dyn DynRhs, job: &mut SimJob<'_>) -> Result<(), String> {
    let s = rhs.state_len();
    check(job, s)?;
    if job.event.is_some() && job.method != Method::Dop853 {
        return Err("an event function needs method=\"dop853\"".into());
    }
    match job.method {
        Method::Dop853 => {
            macro_rules! sizes {
                ($($n:literal)*) => {
                    match s {
                        $($n => dop853::<$n>(rhs, job),)*
                        n => Err(format!(
                            "method=\"dop853\" handles reduced states of up to {DOP853_MAX_STATE} entries, this one has {n}; use \"radau5\" or \"rk4\""
                        )),
                    }
                };
            }
            sizes!(1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25 26 27 28
                29 30 31 32 33 34 35 36 37 38 39 40 41 42 43 44 45 46 47 48 49 50 51 52 53 54
                55 56 57 58 59 60 61 62 63 64)
        }
        Method::Radau5 => radau5(rhs, job),
        Method::Rk4 => rk4(rhs, job),
    }
}

fn dop853<const S: usize>(rhs: &dyn DynRhs, job: &mut SimJob<'_>) -> Result<(), String> {
    let mut x0 = [0.0; S];
    x0.copy_from_slice(job.x0);
    let law = Law::of(job);
    let f = |t: f64, x: &[f64; S], dx: &mut [f64; S]| law.rhs(rhs, t, x, dx);
    let solver = Dop853::new()
        .rtol(job.rtol)
        .atol(job.atol)
        .max_steps(job.max_steps)
        .h_max(job.h_max);
    let t_end = job.t_eval[job.t_eval.len() - 1];
    let mut written = 0;
    let out = &mut *job.out;
    let mut sink = |_t: f64, x: &[f64; S]| {
        if written < out.len() / S {
            out[written * S..(written + 1) * S].copy_from_slice(x);
        }
        written += 1;
    };
    let solution = match job.event.as_mut() {
        Some(g) => {
            let mut event = |t: f64, x: &[f64; S]| g(t, x);
            let event: &mut EventFn<'_, f64, S> = &mut event;
            solver.solve_with(f, job.t0, &x0, t_end, job.t_eval, &mut sink, Some(event))
        }
        None => solver.solve_with(f, job.t0, &x0, t_end, job.t_eval, &mut sink, None),
    }
    .map_err(|e| law.error(e))?;
    job.written = written.min(job.t_eval.len());
    if solution.event {
        job.event_at = Some((solution.t, solution.x.to_vec()));
    } else if job.written != job.t_eval.len() {
        return Err(format!(
            "the integrator reported {} of the {} output times",
            job.written,
            job.t_eval.len()
        ));
    }
    Ok(())
}

/// ∂rhs/∂x, row-major: the generated Jacobian, or a column per dual
/// evaluation.
fn jacobian(
    rhs: &dyn DynRhs,
    t: f64,
    x: &[f64],
    inputs: &[f64],
    j: &mut [f64],
) -> Result<(), appell::ModelError> {
    let s = x.len();
    let mut values = vec![0.0; s];
    let mut b = vec![0.0; s * inputs.len()];
    if rhs.generated_jacobian(t, x, inputs, &mut values, j, &mut b)? {
        return Ok(());
    }
    let ud: Vec<Dual64> = inputs.iter().map(|&v| Dual64::from(v)).collect();
    let mut xd: Vec<Dual64> = x.iter().map(|&v| Dual64::from(v)).collect();
    let mut dx = vec![Dual64::from(0.0); s];
    for col in 0..s {
        xd[col].eps = 1.0;
        rhs.rhs_dual(Dual64::from(t), &xd, &ud, &mut dx)?;
        xd[col].eps = 0.0;
        for row in 0..s {
            j[row * s + col] = dx[row].eps;
        }
    }
    Ok(())
}

fn radau5(rhs: &dyn DynRhs, job: &mut SimJob<'_>) -> Result<(), String> {
    let law = Law::of(job);
    let s = job.x0.len();
    let f = |t: f64, x: &[f64], dx: &mut [f64]| law.rhs(rhs, t, x, dx);
    let jac = |t: f64, x: &[f64], j: &mut [f64]| law.with(t, x, |u| jacobian(rhs, t, x, u, j));
    let mut out: Vec<(f64, Vec<f64>)> = job.t_eval.iter().map(|&t| (t, Vec::new())).collect();
    let solution = Radau5::new()
        .rtol(job.rtol)
        .atol(job.atol)
        .max_steps(job.max_steps)
        .h_max(job.h_max)
        .solve_at(f, jac, job.t0, job.x0, &mut out)
        .map_err(|e| law.error(e))?;
    if solution.outputs != out.len() {
        return Err(format!(
            "the integrator reported {} of the {} output times",
            solution.outputs,
            out.len()
        ));
    }
    for (k, (_, x)) in out.iter().enumerate() {
        job.out[k * s..(k + 1) * s].copy_from_slice(x);
    }
    job.written = out.len();
    Ok(())
}

fn rk4(rhs: &dyn DynRhs, job: &mut SimJob<'_>) -> Result<(), String> {
    let Some(h_max) = job.h_max.filter(|h| *h > 0.0 && h.is_finite()) else {
        return Err("method=\"rk4\" needs a positive step h_max".into());
    };
    let law = Law::of(job);
    let s = job.x0.len();
    let mut x = job.x0.to_vec();
    let (mut k1, mut k2, mut k3, mut k4, mut tmp) = (
        vec![0.0; s],
        vec![0.0; s],
        vec![0.0; s],
        vec![0.0; s],
        vec![0.0; s],
    );
    let mut t = job.t0;
    let err = |e: ModelError| law.error(e);
    for (k, &target) in job.t_eval.iter().enumerate() {
        let span = target - t;
        let steps = (span.abs() / h_max).ceil() as usize;
        let h = if steps == 0 { 0.0 } else { span / steps as f64 };
        for _ in 0..steps {
            law.rhs(rhs, t, &x, &mut k1).map_err(err)?;
            for i in 0..s {
                tmp[i] = x[i] + 0.5 * h * k1[i];
            }
            law.rhs(rhs, t + 0.5 * h, &tmp, &mut k2).map_err(err)?;
            for i in 0..s {
                tmp[i] = x[i] + 0.5 * h * k2[i];
            }
            law.rhs(rhs, t + 0.5 * h, &tmp, &mut k3).map_err(err)?;
            for i in 0..s {
                tmp[i] = x[i] + h * k3[i];
            }
            law.rhs(rhs, t + h, &tmp, &mut k4).map_err(err)?;
            for i in 0..s {
                x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
            t += h;
            if let Some(bad) = x.iter().position(|v| !v.is_finite()) {
                return Err(format!(
                    "the state became non-finite at t = {t} (entry {bad})"
                ));
            }
        }
        t = target;
        job.out[k * s..(k + 1) * s].copy_from_slice(&x);
    }
    job.written = job.t_eval.len();
    Ok(())
}
