//! The public `solve*` methods of [`TrBdf2`], for a right-hand side with
//! its Jacobian or for a [`Model`] (Jacobian by dual numbers).

use super::dense::EventG;
use super::dual_jacobian;
use super::settings::TrBdf2;
use super::shared::ProjectG;
use super::stats::TrBdf2Solution;
use crate::solution::{IntegrateError, ProjectionFailed};
use crate::watch::watched_slices;
use appell_core::dynamic::{DynRhs, Prepared};
use appell_core::{check_len, Model, ModelError};

// Items the documentation links to.
#[cfg(doc)]
use super::TrBdf2Stats;
#[cfg(doc)]
use num_dual::Dual64;

impl TrBdf2 {
    /// Integrates `dx/dt = f(t, x)` from `(t0, x0)` to `t_end` (which may be
    /// before `t0`). `f(t, x, dx)` writes the derivative into `dx`;
    /// `jac(t, x, j)` writes `∂f/∂x` into `j` (n×n, row-major). Both are
    /// called with slices of the length of `x0`.
    ///
    /// See [`TrBdf2`] for an example; [`TrBdf2::solve_model`] computes the
    /// Jacobian of a model by dual numbers.
    pub fn solve<F, J>(
        &self,
        f: F,
        jac: J,
        t0: f64,
        x0: &[f64],
        t_end: f64,
    ) -> Result<TrBdf2Solution, IntegrateError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
        J: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
    {
        self.run(f, jac, t0, x0, t_end, &mut [], None, None)
    }

    /// Integrates from `(t0, x0)` to the last time of `out` and writes the
    /// state at each `out[i].0` (set by the caller) into `out[i].1` (the
    /// vector is cleared and refilled with the `x0.len()` components), from
    /// the dense output ([`TrBdf2`]). The times must be finite and ordered in
    /// the direction of integration (which is that from `t0` to the last
    /// time; equal times are allowed), else [`IntegrateError::InvalidInput`].
    /// An empty `out` integrates nothing. [`TrBdf2Solution::outputs`] counts
    /// the written entries; the solution holds the state at the last time.
    ///
    /// ```
    /// use appell_integrate::TrBdf2;
    /// use appell_core::ModelError;
    ///
    /// let f = |_t: f64, x: &[f64], dx: &mut [f64]| -> Result<(), ModelError> {
    ///     dx[0] = -x[0];
    ///     Ok(())
    /// };
    /// let jac = |_t: f64, _x: &[f64], j: &mut [f64]| -> Result<(), ModelError> {
    ///     j[0] = -1.0;
    ///     Ok(())
    /// };
    /// let mut out = vec![(0.5, vec![]), (1.0, vec![]), (2.0, vec![])];
    /// let sol = TrBdf2::new()
    ///     .rtol(1e-8)
    ///     .atol(1e-10)
    ///     .solve_at(f, jac, 0.0, &[1.0], &mut out)
    ///     .unwrap();
    /// assert_eq!((sol.t, sol.outputs), (2.0, 3));
    /// for (t, x) in &out {
    ///     assert!((x[0] - (-t).exp()).abs() < 1e-5);
    /// }
    /// ```
    pub fn solve_at<F, J>(
        &self,
        f: F,
        jac: J,
        t0: f64,
        x0: &[f64],
        out: &mut [(f64, Vec<f64>)],
    ) -> Result<TrBdf2Solution, IntegrateError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
        J: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
    {
        let t_end = out.last().map_or(t0, |o| o.0);
        self.run(f, jac, t0, x0, t_end, out, None, None)
    }

    /// As [`TrBdf2::solve`], stopping at the first sign change of the event
    /// function `g(t, x)` (see [`TrBdf2`]); [`TrBdf2Solution::event`] tells
    /// whether it happened. A zero of `g` at `t0` is not an event; a
    /// non-finite value of `g` is [`IntegrateError::NonFinite`].
    ///
    /// The reported time is the end of the final bracket on the far side of
    /// the crossing (where `g` has its new sign or is zero), within
    /// [`TrBdf2::event_tol`] of the root of `g` on the dense output; the
    /// state there comes from the dense output.
    ///
    /// ```
    /// use appell_integrate::TrBdf2;
    /// use appell_core::ModelError;
    ///
    /// // x' = −x from 1: x = 1/2 at t = ln 2.
    /// let f = |_t: f64, x: &[f64], dx: &mut [f64]| -> Result<(), ModelError> {
    ///     dx[0] = -x[0];
    ///     Ok(())
    /// };
    /// let jac = |_t: f64, _x: &[f64], j: &mut [f64]| -> Result<(), ModelError> {
    ///     j[0] = -1.0;
    ///     Ok(())
    /// };
    /// let g = |_t: f64, x: &[f64]| x[0] - 0.5;
    /// let sol = TrBdf2::new()
    ///     .rtol(1e-9)
    ///     .atol(1e-12)
    ///     .solve_until(f, jac, g, 0.0, &[1.0], 5.0)
    ///     .unwrap();
    /// assert!(sol.event);
    /// assert!((sol.t - 2.0_f64.ln()).abs() < 1e-5);
    /// assert!(sol.x[0] <= 0.5);
    /// ```
    pub fn solve_until<F, J, G>(
        &self,
        f: F,
        jac: J,
        mut g: G,
        t0: f64,
        x0: &[f64],
        t_end: f64,
    ) -> Result<TrBdf2Solution, IntegrateError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
        J: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
        G: FnMut(f64, &[f64]) -> f64,
    {
        self.run(f, jac, t0, x0, t_end, &mut [], Some(&mut g), None)
    }

    /// As [`TrBdf2::solve`], with `project(t, x)` applied to the state after
    /// every accepted step: it moves `x` (in place) back onto a constraint
    /// manifold (a holonomic constraint the integration drifts from, an
    /// invariant), or returns a [`ProjectionFailed`] whose reason stops the
    /// integration as [`IntegrateError::Projection`] (so does a non-finite
    /// projected state). When it moves the state, the next step starts from
    /// the projected state with its own derivative (one more rhs call,
    /// counted). The step's error control and dense output are those of the
    /// unprojected step.
    ///
    /// ```
    /// use appell_integrate::{ProjectionFailed, TrBdf2};
    /// use appell_core::ModelError;
    ///
    /// // The harmonic oscillator keeps x² + v² = 1; TR-BDF2 damps it
    /// // slightly, projecting onto the circle removes that drift.
    /// let f = |_t: f64, x: &[f64], dx: &mut [f64]| -> Result<(), ModelError> {
    ///     dx[0] = x[1];
    ///     dx[1] = -x[0];
    ///     Ok(())
    /// };
    /// let jac = |_t: f64, _x: &[f64], j: &mut [f64]| -> Result<(), ModelError> {
    ///     j.copy_from_slice(&[0.0, 1.0, -1.0, 0.0]);
    ///     Ok(())
    /// };
    /// let onto_circle = |_t: f64, x: &mut [f64]| {
    ///     let r = x[0].hypot(x[1]);
    ///     if r == 0.0 {
    ///         return Err(ProjectionFailed { reason: "the origin has no direction" });
    ///     }
    ///     x[0] /= r;
    ///     x[1] /= r;
    ///     Ok(())
    /// };
    /// let solver = TrBdf2::new().rtol(1e-4).atol(1e-6);
    /// let free = solver.solve(f, jac, 0.0, &[1.0, 0.0], 100.0).unwrap();
    /// let kept = solver.solve_projected(f, jac, onto_circle, 0.0, &[1.0, 0.0], 100.0).unwrap();
    /// let radius = |x: &[f64]| x[0].hypot(x[1]);
    /// assert!((radius(&kept.x) - 1.0).abs() < 1e-15);
    /// assert!((radius(&free.x) - 1.0).abs() > 1e-6);
    /// // A failing projection stops the integration with its reason.
    /// let err = solver
    ///     .solve_projected(f, jac, onto_circle, 0.0, &[0.0, 0.0], 1.0)
    ///     .unwrap_err();
    /// assert!(err.to_string().contains("the origin has no direction"));
    /// ```
    pub fn solve_projected<F, J, P>(
        &self,
        f: F,
        jac: J,
        mut project: P,
        t0: f64,
        x0: &[f64],
        t_end: f64,
    ) -> Result<TrBdf2Solution, IntegrateError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
        J: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
        P: FnMut(f64, &mut [f64]) -> Result<(), ProjectionFailed>,
    {
        self.run(f, jac, t0, x0, t_end, &mut [], None, Some(&mut project))
    }

    /// Integrates a model's reduced equations ([`Model::rhs`]) from
    /// `(t0, x0)` to `t_end` with `inputs` held constant. The Jacobian is
    /// the model's generated [`Model::rhs_jacobian`] where it has one, else
    /// computed exactly by forward-mode dual numbers: one [`Dual64`]
    /// evaluation of the generated rhs per state component (counted in
    /// [`TrBdf2Stats::jacobian_rhs_calls`]; see [`TrBdf2::jacobian_by_duals`]).
    ///
    /// Errors: [`ModelError::Length`] (as [`IntegrateError::Model`]) when
    /// `x0` is not [`ModelInfo::state_len`](appell_core::ModelInfo::state_len)
    /// long, any error of [`Model::rhs`], and the integration errors of
    /// [`TrBdf2`].
    pub fn solve_model<M: Model>(
        &self,
        model: &M,
        inputs: &[f64],
        t0: f64,
        x0: &[f64],
        t_end: f64,
    ) -> Result<TrBdf2Solution, IntegrateError> {
        self.run_model(model, t0, x0, t_end, inputs, &mut [], None, None)
    }

    /// [`TrBdf2::solve_at`] of a model's reduced equations, as
    /// [`TrBdf2::solve_model`].
    ///
    /// ```
    /// use appell_integrate::TrBdf2;
    /// # use appell_core::__doc_model::Oscillator;
    ///
    /// // x'' = −w² x, x(0) = 1, x'(0) = 0: x(t) = cos(w t).
    /// let model = Oscillator { w: 2.0 };
    /// let mut out: Vec<(f64, Vec<f64>)> = (1..=10).map(|k| (0.1 * k as f64, vec![])).collect();
    /// let sol = TrBdf2::new()
    ///     .rtol(1e-9)
    ///     .atol(1e-12)
    ///     .solve_model_at(&model, &[], 0.0, &[1.0, 0.0], &mut out)
    ///     .unwrap();
    /// assert_eq!(sol.outputs, 10);
    /// for (t, x) in &out {
    ///     assert!((x[0] - (2.0 * t).cos()).abs() < 1e-6);
    /// }
    /// // Output times out of order are invalid input.
    /// let mut bad = vec![(0.5, vec![]), (0.2, vec![])];
    /// assert!(TrBdf2::new().solve_model_at(&model, &[], 0.0, &[1.0, 0.0], &mut bad).is_err());
    /// ```
    pub fn solve_model_at<M: Model>(
        &self,
        model: &M,
        inputs: &[f64],
        t0: f64,
        x0: &[f64],
        out: &mut [(f64, Vec<f64>)],
    ) -> Result<TrBdf2Solution, IntegrateError> {
        let t_end = out.last().map_or(t0, |o| o.0);
        self.run_model(model, t0, x0, t_end, inputs, out, None, None)
    }

    /// [`TrBdf2::solve_until`] of a model's reduced equations, as
    /// [`TrBdf2::solve_model`].
    ///
    /// ```
    /// use appell_integrate::TrBdf2;
    /// # use appell_core::__doc_model::Oscillator;
    ///
    /// // x = cos(2t) first reaches 0 at t = π/4.
    /// let model = Oscillator { w: 2.0 };
    /// let sol = TrBdf2::new()
    ///     .rtol(1e-10)
    ///     .atol(1e-12)
    ///     .solve_model_until(&model, &[], |_t, x: &[f64]| x[0], 0.0, &[1.0, 0.0], 10.0)
    ///     .unwrap();
    /// assert!(sol.event);
    /// assert!((sol.t - core::f64::consts::FRAC_PI_4).abs() < 1e-6);
    /// ```
    pub fn solve_model_until<M: Model, G>(
        &self,
        model: &M,
        inputs: &[f64],
        mut g: G,
        t0: f64,
        x0: &[f64],
        t_end: f64,
    ) -> Result<TrBdf2Solution, IntegrateError>
    where
        G: FnMut(f64, &[f64]) -> f64,
    {
        self.run_model(model, t0, x0, t_end, inputs, &mut [], Some(&mut g), None)
    }

    /// [`TrBdf2::solve_projected`] of a model's reduced equations, as
    /// [`TrBdf2::solve_model`]; the arguments in the order of the explicit
    /// integrators' [`solve_model_projected`](crate::Dopri5::solve_model_projected)
    /// (model, inputs, projection, then the interval).
    ///
    /// ```
    /// use appell_integrate::{ProjectionFailed, TrBdf2};
    /// # use appell_core::__doc_model::Oscillator;
    ///
    /// // x'' = −x keeps x² + x'² = 1 from (1, 0).
    /// let model = Oscillator { w: 1.0 };
    /// let onto_circle = |_t: f64, x: &mut [f64]| {
    ///     let r = x[0].hypot(x[1]);
    ///     x[0] /= r;
    ///     x[1] /= r;
    ///     Ok::<(), ProjectionFailed>(())
    /// };
    /// let sol = TrBdf2::new()
    ///     .rtol(1e-4)
    ///     .solve_model_projected(&model, &[], onto_circle, 0.0, &[1.0, 0.0], 50.0)
    ///     .unwrap();
    /// assert!((sol.x[0].hypot(sol.x[1]) - 1.0).abs() < 1e-15);
    /// ```
    pub fn solve_model_projected<M: Model, P>(
        &self,
        model: &M,
        inputs: &[f64],
        mut project: P,
        t0: f64,
        x0: &[f64],
        t_end: f64,
    ) -> Result<TrBdf2Solution, IntegrateError>
    where
        P: FnMut(f64, &mut [f64]) -> Result<(), ProjectionFailed>,
    {
        let project: &mut ProjectG<'_> = &mut project;
        self.run_model(model, t0, x0, t_end, inputs, &mut [], None, Some(project))
    }

    // one body for the four solve_model* forms, each passing `&mut []` or None for what it lacks;
    // watched_slices may put the contact watch in as the event or after the projection
    #[allow(clippy::too_many_arguments)]
    fn run_model<M: Model>(
        &self,
        model: &M,
        t0: f64,
        x0: &[f64],
        t_end: f64,
        inputs: &[f64],
        out: &mut [(f64, Vec<f64>)],
        event: Option<&mut EventG<'_>>,
        project: Option<&mut ProjectG<'_>>,
    ) -> Result<TrBdf2Solution, IntegrateError> {
        check_len("state", x0, M::info().state_len())?;
        model.validate()?;
        let rhs = Prepared::new(model);
        let on = self.contact_watch;
        watched_slices(
            model,
            inputs,
            on,
            t0,
            x0,
            event,
            project,
            |event, project| self.run_prepared(&rhs, t0, x0, t_end, inputs, out, event, project),
        )
    }

    /// [`TrBdf2::solve_model_at`] of a prepared rhs (compiled once for
    /// `dyn DynRhs`).
    // Shared with the accuracy sweep; not part of the API.
    #[doc(hidden)]
    pub fn solve_prepared_at<R: DynRhs + ?Sized>(
        &self,
        rhs: &R,
        inputs: &[f64],
        t0: f64,
        x0: &[f64],
        out: &mut [(f64, Vec<f64>)],
    ) -> Result<TrBdf2Solution, IntegrateError> {
        let t_end = out.last().map_or(t0, |o| o.0);
        self.run_prepared(rhs, t0, x0, t_end, inputs, out, None, None)
    }

    // run's arguments with the prepared rhs and its inputs in place of f and jac_fn, which it
    // builds from them; called by run_model and solve_prepared_at
    #[allow(clippy::too_many_arguments)]
    fn run_prepared<R: DynRhs + ?Sized>(
        &self,
        rhs: &R,
        t0: f64,
        x0: &[f64],
        t_end: f64,
        inputs: &[f64],
        out: &mut [(f64, Vec<f64>)],
        event: Option<&mut EventG<'_>>,
        project: Option<&mut ProjectG<'_>>,
    ) -> Result<TrBdf2Solution, IntegrateError> {
        let n = rhs.state_len();
        check_len("state", x0, n)?;
        let f = |t: f64, x: &[f64], dx: &mut [f64]| rhs.rhs(t, x, inputs, dx);
        let by_duals = self.jacobian_by_duals || !rhs.has_generated_jacobian();
        let jac = dual_jacobian(rhs, inputs, by_duals);
        let mut sol = self.run(f, jac, t0, x0, t_end, out, event, project)?;
        sol.stats.jacobian_rhs_calls = if by_duals { sol.stats.jacobians * n } else { 0 };
        Ok(sol)
    }
}
