//! The public `solve*` methods of [`Radau5`], for a right-hand side with
//! its Jacobian or for a [`Model`] (Jacobian by dual numbers).

use super::control::REUSE_DUAL;
use super::settings::Radau5;
use super::stats::Radau5Solution;
use crate::implicit::{dual_jacobian, EventG, ProjectG};
use crate::solution::{IntegrateError, ProjectionFailed};
use crate::watch::watched_slices;
use appell_core::dynamic::{DynRhs, Prepared};
use appell_core::{check_len, Model, ModelError};

// Items the documentation links to.
#[cfg(doc)]
use super::Radau5Stats;
#[cfg(doc)]
use num_dual::Dual64;

impl Radau5 {
    /// Integrates `dx/dt = f(t, x)` from `(t0, x0)` to `t_end` (which may be
    /// before `t0`). `f(t, x, dx)` writes the derivative into `dx`;
    /// `jac(t, x, j)` writes `∂f/∂x` into `j` (n×n, row-major). Both are
    /// called with slices of the length of `x0`; their errors are passed on
    /// as [`IntegrateError::Model`].
    ///
    /// See [`Radau5`] for an example on a stiff problem;
    /// [`Radau5::solve_model`] computes the Jacobian of a model by dual
    /// numbers.
    ///
    /// ```
    /// use appell_integrate::{IntegrateError, Radau5};
    /// use appell_core::ModelError;
    ///
    /// // A rhs that fails past t = 1 stops the integration with its error.
    /// let f = |t: f64, x: &[f64], dx: &mut [f64]| -> Result<(), ModelError> {
    ///     if t > 1.0 {
    ///         return Err(ModelError::NonFinite { what: "rate" });
    ///     }
    ///     dx[0] = -x[0];
    ///     Ok(())
    /// };
    /// let jac = |_t: f64, _x: &[f64], j: &mut [f64]| -> Result<(), ModelError> {
    ///     j[0] = -1.0;
    ///     Ok(())
    /// };
    /// assert!(Radau5::new().solve(f, jac, 0.0, &[1.0], 1.0).is_ok());
    /// assert_eq!(
    ///     Radau5::new().solve(f, jac, 0.0, &[1.0], 2.0),
    ///     Err(IntegrateError::Model(ModelError::NonFinite { what: "rate" }))
    /// );
    /// ```
    pub fn solve<F, J>(
        &self,
        f: F,
        jac: J,
        t0: f64,
        x0: &[f64],
        t_end: f64,
    ) -> Result<Radau5Solution, IntegrateError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
        J: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
    {
        self.run(f, jac, t0, x0, t_end, &mut [], None, None)
    }

    /// Integrates from `(t0, x0)` to the last time of `out` and writes the
    /// state at each `out[i].0` (set by the caller) into `out[i].1` (the
    /// vector is cleared and refilled with the `x0.len()` components), from
    /// the collocation polynomial of the step ([`Radau5`]). The times must
    /// be finite and ordered in the direction of integration (which is
    /// that from `t0` to the last time; equal times are allowed), else
    /// [`IntegrateError::InvalidInput`]. An empty `out` integrates
    /// nothing. [`Radau5Solution::outputs`] counts the written entries; the
    /// solution holds the state at the last time.
    ///
    /// ```
    /// use appell_integrate::Radau5;
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
    /// let sol = Radau5::new()
    ///     .rtol(1e-8)
    ///     .atol(1e-10)
    ///     .solve_at(f, jac, 0.0, &[1.0], &mut out)
    ///     .unwrap();
    /// assert_eq!((sol.t, sol.outputs), (2.0, 3));
    /// for (t, x) in &out {
    ///     assert!((x[0] - (-t).exp()).abs() < 1e-7);
    /// }
    /// ```
    pub fn solve_at<F, J>(
        &self,
        f: F,
        jac: J,
        t0: f64,
        x0: &[f64],
        out: &mut [(f64, Vec<f64>)],
    ) -> Result<Radau5Solution, IntegrateError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
        J: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
    {
        let t_end = out.last().map_or(t0, |o| o.0);
        self.run(f, jac, t0, x0, t_end, out, None, None)
    }

    /// As [`Radau5::solve`], stopping at the first sign change of the event
    /// function `g(t, x)` (see [`Radau5`]); [`Radau5Solution::event`] tells
    /// whether it happened. A zero of `g` at `t0` is not an event; a
    /// non-finite value of `g` is [`IntegrateError::NonFinite`].
    ///
    /// The reported time is the end of the final bracket on the far side of
    /// the crossing (where `g` has its new sign or is zero), within
    /// [`Radau5::event_tol`] of the root of `g` on the dense output; the
    /// state there comes from the dense output.
    ///
    /// ```
    /// use appell_integrate::Radau5;
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
    /// let sol = Radau5::new()
    ///     .rtol(1e-9)
    ///     .atol(1e-12)
    ///     .solve_until(f, jac, g, 0.0, &[1.0], 5.0)
    ///     .unwrap();
    /// assert!(sol.event);
    /// assert!((sol.t - 2.0_f64.ln()).abs() < 1e-7);
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
    ) -> Result<Radau5Solution, IntegrateError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
        J: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
        G: FnMut(f64, &[f64]) -> f64,
    {
        self.run(f, jac, t0, x0, t_end, &mut [], Some(&mut g), None)
    }

    /// As [`Radau5::solve`], with `project(t, x)` applied to the state after
    /// every accepted step: it moves `x` (in place) back onto a constraint
    /// manifold (a holonomic constraint the integration drifts from, an
    /// invariant), or returns a [`ProjectionFailed`] whose reason stops the
    /// integration as [`IntegrateError::Projection`] (so does a non-finite
    /// projected state). The next step starts from the projected state (its
    /// derivative is evaluated there in any case); the step's error control
    /// and dense output are those of the unprojected step.
    ///
    /// ```
    /// use appell_integrate::{IntegrateError, ProjectionFailed, Radau5};
    /// use appell_core::ModelError;
    ///
    /// // A pendulum of unit length in Cartesian coordinates (x, y, vx, vy):
    /// // the rod force keeps x² + y² = 1 only up to the integration error.
    /// let f = |_t: f64, s: &[f64], ds: &mut [f64]| -> Result<(), ModelError> {
    ///     let (x, y, vx, vy) = (s[0], s[1], s[2], s[3]);
    ///     let lambda = (vx * vx + vy * vy - y) / (x * x + y * y); // g = 1
    ///     ds.copy_from_slice(&[vx, vy, -lambda * x, -lambda * y - 1.0]);
    ///     Ok(())
    /// };
    /// let jac = |t: f64, s: &[f64], j: &mut [f64]| -> Result<(), ModelError> {
    ///     // By central differences (a user Jacobian need not be exact).
    ///     let (mut a, mut b) = ([0.0; 4], [0.0; 4]);
    ///     for c in 0..4 {
    ///         let (mut sp, mut sm) = ([s[0], s[1], s[2], s[3]], [s[0], s[1], s[2], s[3]]);
    ///         sp[c] += 1e-7;
    ///         sm[c] -= 1e-7;
    ///         f(t, &sp, &mut a)?;
    ///         f(t, &sm, &mut b)?;
    ///         for r in 0..4 {
    ///             j[r * 4 + c] = (a[r] - b[r]) / 2e-7;
    ///         }
    ///     }
    ///     Ok(())
    /// };
    /// let onto_circle = |_t: f64, s: &mut [f64]| {
    ///     let r = s[0].hypot(s[1]);
    ///     if !(r > 0.0) {
    ///         return Err(ProjectionFailed { reason: "no direction" });
    ///     }
    ///     s[0] /= r;
    ///     s[1] /= r;
    ///     // The velocity tangent to the circle.
    ///     let radial = s[0] * s[2] + s[1] * s[3];
    ///     s[2] -= radial * s[0];
    ///     s[3] -= radial * s[1];
    ///     Ok(())
    /// };
    /// let x0 = [1.0, 0.0, 0.0, 0.0];
    /// let solver = Radau5::new().rtol(1e-4).atol(1e-6);
    /// let sol = solver.solve_projected(f, jac, onto_circle, 0.0, &x0, 20.0).unwrap();
    /// assert!((sol.x[0].hypot(sol.x[1]) - 1.0).abs() < 1e-15);
    /// let fails = |_t: f64, _s: &mut [f64]| Err(ProjectionFailed { reason: "no manifold" });
    /// let err = solver.solve_projected(f, jac, fails, 0.0, &x0, 1.0).unwrap_err();
    /// assert!(matches!(err, IntegrateError::Projection { reason: "no manifold", .. }));
    /// ```
    pub fn solve_projected<F, J, P>(
        &self,
        f: F,
        jac: J,
        mut project: P,
        t0: f64,
        x0: &[f64],
        t_end: f64,
    ) -> Result<Radau5Solution, IntegrateError>
    where
        F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
        J: FnMut(f64, &[f64], &mut [f64]) -> Result<(), ModelError>,
        P: FnMut(f64, &mut [f64]) -> Result<(), ProjectionFailed>,
    {
        self.run(f, jac, t0, x0, t_end, &mut [], None, Some(&mut project))
    }

    /// Integrates a model's reduced equations ([`Model::rhs`]) with `inputs`
    /// held constant from `(t0, x0)` to `t_end` (the argument order of the
    /// explicit integrators' `solve_model`). The Jacobian is the model's
    /// generated [`Model::rhs_jacobian`] where it has one, else computed
    /// exactly by forward-mode dual numbers: one [`Dual64`] evaluation of
    /// the generated rhs per state component (counted in
    /// [`Radau5Stats::jacobian_rhs_calls`]; see [`Radau5::jacobian_by_duals`]).
    ///
    /// Errors: [`ModelError::Length`] (as [`IntegrateError::Model`]) when
    /// `x0` is not [`ModelInfo::state_len`](appell_core::ModelInfo::state_len)
    /// long, any error of [`Model::rhs`], and the integration errors of
    /// [`Radau5`].
    ///
    /// ```
    /// use appell_integrate::{IntegrateError, Radau5};
    /// use appell_core::ModelError;
    /// # use appell_core::__doc_model::Oscillator;
    ///
    /// // x'' = −w² x, x(0) = 1, x'(0) = 0: x(t) = cos(w t).
    /// let model = Oscillator { w: 2.0 };
    /// let sol = Radau5::new()
    ///     .rtol(1e-10)
    ///     .atol(1e-12)
    ///     .solve_model(&model, &[], 0.0, &[1.0, 0.0], 3.0)
    ///     .unwrap();
    /// assert!((sol.x[0] - 6.0_f64.cos()).abs() < 1e-9);
    /// // A linear model: one Jacobian, two dual evaluations.
    /// assert_eq!(sol.stats.jacobians, 1);
    /// assert_eq!(sol.stats.jacobian_rhs_calls, 2);
    /// // The state must have the model's length.
    /// assert!(matches!(
    ///     Radau5::new().solve_model(&model, &[], 0.0, &[1.0], 1.0),
    ///     Err(IntegrateError::Model(ModelError::Length { .. }))
    /// ));
    /// ```
    pub fn solve_model<M: Model>(
        &self,
        model: &M,
        inputs: &[f64],
        t0: f64,
        x0: &[f64],
        t_end: f64,
    ) -> Result<Radau5Solution, IntegrateError> {
        self.run_model(model, inputs, t0, x0, t_end, &mut [], None, None)
    }

    /// [`Radau5::solve_at`] of a model's reduced equations, as
    /// [`Radau5::solve_model`].
    ///
    /// ```
    /// use appell_integrate::Radau5;
    /// # use appell_core::__doc_model::Oscillator;
    ///
    /// let model = Oscillator { w: 2.0 };
    /// let mut out: Vec<(f64, Vec<f64>)> = (1..=10).map(|k| (0.1 * k as f64, vec![])).collect();
    /// let sol = Radau5::new()
    ///     .rtol(1e-9)
    ///     .atol(1e-12)
    ///     .solve_model_at(&model, &[], 0.0, &[1.0, 0.0], &mut out)
    ///     .unwrap();
    /// assert_eq!(sol.outputs, 10);
    /// for (t, x) in &out {
    ///     assert!((x[0] - (2.0 * t).cos()).abs() < 1e-8);
    /// }
    /// // Output times out of order are invalid input.
    /// let mut bad = vec![(0.5, vec![]), (0.2, vec![])];
    /// assert!(Radau5::new().solve_model_at(&model, &[], 0.0, &[1.0, 0.0], &mut bad).is_err());
    /// ```
    pub fn solve_model_at<M: Model>(
        &self,
        model: &M,
        inputs: &[f64],
        t0: f64,
        x0: &[f64],
        out: &mut [(f64, Vec<f64>)],
    ) -> Result<Radau5Solution, IntegrateError> {
        let t_end = out.last().map_or(t0, |o| o.0);
        self.run_model(model, inputs, t0, x0, t_end, out, None, None)
    }

    /// [`Radau5::solve_until`] of a model's reduced equations, as
    /// [`Radau5::solve_model`].
    ///
    /// ```
    /// use appell_integrate::Radau5;
    /// # use appell_core::__doc_model::Oscillator;
    ///
    /// // x = cos(2t) first reaches 0 at t = π/4.
    /// let model = Oscillator { w: 2.0 };
    /// let sol = Radau5::new()
    ///     .rtol(1e-10)
    ///     .atol(1e-12)
    ///     .solve_model_until(&model, &[], |_t, x: &[f64]| x[0], 0.0, &[1.0, 0.0], 10.0)
    ///     .unwrap();
    /// assert!(sol.event);
    /// assert!((sol.t - core::f64::consts::FRAC_PI_4).abs() < 1e-9);
    /// ```
    pub fn solve_model_until<M: Model, G>(
        &self,
        model: &M,
        inputs: &[f64],
        mut g: G,
        t0: f64,
        x0: &[f64],
        t_end: f64,
    ) -> Result<Radau5Solution, IntegrateError>
    where
        G: FnMut(f64, &[f64]) -> f64,
    {
        self.run_model(model, inputs, t0, x0, t_end, &mut [], Some(&mut g), None)
    }

    /// [`Radau5::solve_projected`] of a model's reduced equations, as
    /// [`Radau5::solve_model`]; with a closure around
    /// `appell::linearize::project_holonomic` as the
    /// projection it keeps a model on its holonomic constraints.
    ///
    /// ```
    /// use appell_integrate::{ProjectionFailed, Radau5};
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
    /// let sol = Radau5::new()
    ///     .rtol(1e-3)
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
    ) -> Result<Radau5Solution, IntegrateError>
    where
        P: FnMut(f64, &mut [f64]) -> Result<(), ProjectionFailed>,
    {
        let project: &mut ProjectG<'_> = &mut project;
        self.run_model(model, inputs, t0, x0, t_end, &mut [], None, Some(project))
    }

    // one body for the four solve_model* forms, each passing `&mut []` or None for what it lacks;
    // watched_slices may put the contact watch in as the event or after the projection
    #[allow(clippy::too_many_arguments)]
    fn run_model<M: Model>(
        &self,
        model: &M,
        inputs: &[f64],
        t0: f64,
        x0: &[f64],
        t_end: f64,
        out: &mut [(f64, Vec<f64>)],
        event: Option<&mut EventG<'_>>,
        project: Option<&mut ProjectG<'_>>,
    ) -> Result<Radau5Solution, IntegrateError> {
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
            |event, project| self.run_prepared(&rhs, inputs, t0, x0, t_end, out, event, project),
        )
    }

    /// [`Radau5::solve_model_at`] of a prepared rhs (the accuracy sweep's,
    /// compiled once for `dyn DynRhs`).
    // Shared with the accuracy sweep; not part of the API.
    #[doc(hidden)]
    pub fn solve_prepared_at<R: DynRhs + ?Sized>(
        &self,
        rhs: &R,
        inputs: &[f64],
        t0: f64,
        x0: &[f64],
        out: &mut [(f64, Vec<f64>)],
    ) -> Result<Radau5Solution, IntegrateError> {
        let t_end = out.last().map_or(t0, |o| o.0);
        self.run_prepared(rhs, inputs, t0, x0, t_end, out, None, None)
    }

    /// The integration of a prepared rhs (compiled once for `dyn DynRhs`),
    /// its Jacobian by dual numbers.
    // run's arguments with the prepared rhs and its inputs in place of f and jac_fn, which it
    // builds from them; called by run_model and solve_prepared_at
    #[allow(clippy::too_many_arguments)]
    fn run_prepared<R: DynRhs + ?Sized>(
        &self,
        rhs: &R,
        inputs: &[f64],
        t0: f64,
        x0: &[f64],
        t_end: f64,
        out: &mut [(f64, Vec<f64>)],
        event: Option<&mut EventG<'_>>,
        project: Option<&mut ProjectG<'_>>,
    ) -> Result<Radau5Solution, IntegrateError> {
        let n = rhs.state_len();
        check_len("state", x0, n)?;
        let f = |t: f64, x: &[f64], dx: &mut [f64]| rhs.rhs(t, x, inputs, dx);
        let by_duals = self.jacobian_by_duals || !rhs.has_generated_jacobian();
        let jac = dual_jacobian(rhs, inputs, by_duals);
        let settings = Radau5 {
            jacobian_reuse: Some(self.jacobian_reuse.unwrap_or(REUSE_DUAL)),
            ..*self
        };
        let mut sol = settings.run(f, jac, t0, x0, t_end, out, event, project)?;
        sol.stats.jacobian_rhs_calls = if by_duals { sol.stats.jacobians * n } else { 0 };
        Ok(sol)
    }
}
