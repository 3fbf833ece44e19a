//! The builder setters and the public `solve*` methods every explicit
//! integrator shares, as a macro.

/// The builder setters common to both integrators and the public `solve*`
/// methods of the integrator `$ty` (a struct with `set: Settings`) whose
/// method is `$pair<T, S>`.
macro_rules! explicit_api {
    ($ty:ident, $pair:ident) => {
        /// Error control on (default `true`). With `false`, every step has the
        #[doc = concat!("size [`", stringify!($ty), "::h_init`] (required; the last step is cut to end at")]
        #[doc = concat!("`t_end`, and [`", stringify!($ty), "::h_max`] is ignored) and is accepted without an")]
        /// error estimate (a fixed-step method with dense output, for
        /// convergence studies); a non-finite state is reported at once.
        pub const fn adaptive(mut self, adaptive: bool) -> Self {
            self.set.adaptive = adaptive;
            self
        }

        /// Relative tolerance (default `1e-6`; must be ≥ 0).
        pub const fn rtol(mut self, rtol: f64) -> Self {
            self.set.rtol = rtol;
            self
        }

        /// Absolute tolerance (default `1e-9`; must be ≥ 0, and `rtol` and
        /// `atol` not both 0).
        pub const fn atol(mut self, atol: f64) -> Self {
            self.set.atol = atol;
            self
        }

        /// Maximum number of steps, accepted and rejected (default `100_000`).
        pub const fn max_steps(mut self, max_steps: usize) -> Self {
            self.set.max_steps = max_steps;
            self
        }

        /// Minimum step size (default `0`: only the floor of 16 ulp of `t`); a
        /// smaller proposed step is [`IntegrateError::StepSizeTooSmall`]. The
        /// last step, cut to end exactly at `t_end`, may be smaller.
        pub const fn h_min(mut self, h_min: f64) -> Self {
            self.set.h_min = h_min;
            self
        }

        /// Maximum step size, or `None` (default) for the interval length.
        pub const fn h_max(mut self, h_max: Option<f64>) -> Self {
            self.set.h_max = h_max;
            self
        }

        /// Absolute time tolerance of event location (default `1e-12`, never
        /// below 4 ulp of the event time).
        pub const fn event_tol(mut self, event_tol: f64) -> Self {
            self.set.event_tol = event_tol;
            self
        }

        /// Whether the `solve_model*` methods watch a model's one-sided
        /// contacts (default `true`; with `std`): for a model with `rolls`
        /// contacts they check the initial state with a stopping
        /// [`ContactWatch`](crate::contact_watch::ContactWatch), locate where a
        /// normal force turns negative or the body leaves the region where the
        /// model holds as an event (or, for `solve_model_until`, check the end
        /// of each accepted step) and end there with
        /// [`IntegrateError::Contact`]. With
        /// `false` nothing is checked (give a warning watch as the projection
        /// of `solve_model_projected` to warn instead).
        pub const fn contact_watch(mut self, on: bool) -> Self {
            self.set.contact_watch = on;
            self
        }

        /// Integrates `dx/dt = f(t, x)` from `(t0, x0)` to `t_end` (which may
        /// be before `t0`). `f(t, x, dx)` writes the derivative into `dx`.
        ///
        #[doc = concat!("See [`", stringify!($ty), "`] for an example.")]
        pub fn solve<T, F, const S: usize>(
            &self,
            f: F,
            t0: f64,
            x0: &[T; S],
            t_end: f64,
        ) -> Result<Solution<T, S>, IntegrateError>
        where
            T: Scalar,
            F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
        {
            let mut sink = CallbackSink {
                times: &[],
                cb: &mut |_, _| {},
            };
            explicit::run::<$pair<T, S>, _, _, _, S>(&self.set, f, t0, x0, t_end, &mut sink, None, None)
        }

        #[doc = concat!("As [`", stringify!($ty), "::solve`], stopping at the first sign change of the event")]
        #[doc = concat!("function `g(t, x)` (see [`", stringify!($ty), "`]); [`Solution::event`] tells")]
        /// whether it happened. A zero of `g` at `t0` is not an event.
        ///
        /// The reported time is the end of the final bracket on the far side of
        /// the crossing (where `g` has its new sign or is zero), within
        #[doc = concat!("[`", stringify!($ty), "::event_tol`] of the root of `g` on the dense output; the")]
        /// state there comes from the dense output.
        pub fn solve_until<T, F, G, const S: usize>(
            &self,
            f: F,
            mut g: G,
            t0: f64,
            x0: &[T; S],
            t_end: f64,
        ) -> Result<Solution<T, S>, IntegrateError>
        where
            T: Scalar,
            F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
            G: FnMut(f64, &[T; S]) -> f64,
        {
            let mut sink = CallbackSink {
                times: &[],
                cb: &mut |_, _| {},
            };
            explicit::run::<$pair<T, S>, _, _, _, S>(
                &self.set,
                f,
                t0,
                x0,
                t_end,
                &mut sink,
                Some(&mut g),
                None,
            )
        }

        /// Integrates from `(t0, x0)` to the last time of `out` and writes the
        /// state at each `out[i].0` (set by the caller, ordered in the
        /// direction of integration) into `out[i].1`, from the dense output.
        ///
        /// ```
        #[doc = concat!("use appell_integrate::", stringify!($ty), ";")]
        /// use appell_core::ModelError;
        ///
        /// let f = |_t: f64, x: &[f64; 1], dx: &mut [f64; 1]| -> Result<(), ModelError> {
        ///     dx[0] = -x[0];
        ///     Ok(())
        /// };
        /// let mut out = [(0.5, [0.0]), (1.0, [0.0]), (2.0, [0.0])];
        #[doc = concat!("let sol = ", stringify!($ty), "::new().rtol(1e-9).atol(1e-12).solve_at(f, 0.0, &[1.0], &mut out).unwrap();")]
        /// assert_eq!(sol.outputs, 3);
        /// for (t, x) in out {
        ///     assert!((x[0] - (-t).exp()).abs() < 1e-8);
        /// }
        /// ```
        pub fn solve_at<T, F, const S: usize>(
            &self,
            f: F,
            t0: f64,
            x0: &[T; S],
            out: &mut [(f64, [T; S])],
        ) -> Result<Solution<T, S>, IntegrateError>
        where
            T: Scalar,
            F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
        {
            let t_end = out.last().map_or(t0, |o| o.0);
            explicit::run::<$pair<T, S>, _, _, _, S>(
                &self.set,
                f,
                t0,
                x0,
                t_end,
                &mut SliceSink(out),
                None,
                None,
            )
        }

        /// The general form: integrates from `(t0, x0)` to `t_end`, calls
        /// `on_output(t, x)` at each of `times` (ordered in the direction of
        /// integration and within the interval), and stops at an event of `g`
        #[doc = concat!("when one is given (as [`", stringify!($ty), "::solve_until`]); output times past the")]
        /// event are not reached.
        // the public general form: solve's problem plus the output times, an output callback and an
        // optional event, each the caller's own; times and on_output become run's CallbackSink
        #[allow(clippy::too_many_arguments)]
        pub fn solve_with<T, F, const S: usize>(
            &self,
            f: F,
            t0: f64,
            x0: &[T; S],
            t_end: f64,
            times: &[f64],
            on_output: &mut dyn FnMut(f64, &[T; S]),
            event: Option<&mut EventFn<'_, T, S>>,
        ) -> Result<Solution<T, S>, IntegrateError>
        where
            T: Scalar,
            F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
        {
            let mut sink = CallbackSink {
                times,
                cb: on_output,
            };
            explicit::run::<$pair<T, S>, _, _, _, S>(&self.set, f, t0, x0, t_end, &mut sink, event, None)
        }

        #[doc = concat!("As [`", stringify!($ty), "::solve`], with `project(t, x)` applied to the state")]
        /// after every accepted step: it moves `x` back onto a constraint
        /// manifold (a holonomic constraint the integration drifts from, an
        /// invariant) and returns a [`ProjectionFailed`](crate::ProjectionFailed)
        /// saying why if it cannot (the integration then stops with
        /// [`IntegrateError::Projection`], which carries the reason). When it moves the state, the next
        /// step starts afresh from the projected state (one more rhs call,
        /// counted). The step's error control and dense output are those of the
        /// unprojected step.
        ///
        /// ```
        #[doc = concat!("use appell_integrate::{", stringify!($ty), ", ProjectionFailed};")]
        /// // The harmonic oscillator keeps x² + v² = 1; projecting onto that
        /// // circle removes the slow drift of a loose tolerance.
        /// let f = |_t: f64, x: &[f64; 2], dx: &mut [f64; 2]| {
        ///     dx[0] = x[1];
        ///     dx[1] = -x[0];
        ///     Ok(())
        /// };
        /// let mut onto_circle = |_t: f64, x: &mut [f64; 2]| {
        ///     let r = (x[0] * x[0] + x[1] * x[1]).sqrt();
        ///     if r == 0.0 {
        ///         return Err(ProjectionFailed { reason: "the origin has no nearest point on the circle" });
        ///     }
        ///     x[0] /= r;
        ///     x[1] /= r;
        ///     Ok(())
        /// };
        #[doc = concat!("let solver = ", stringify!($ty), "::new().rtol(1e-4).atol(1e-6);")]
        /// let free = solver.solve(f, 0.0, &[1.0, 0.0], 100.0).unwrap();
        /// let kept = solver.solve_projected(f, &mut onto_circle, 0.0, &[1.0, 0.0], 100.0).unwrap();
        /// let radius = |x: [f64; 2]| (x[0] * x[0] + x[1] * x[1]).sqrt();
        /// assert!((radius(kept.x) - 1.0).abs() < 1e-15);
        /// assert!((radius(free.x) - 1.0).abs() > (radius(kept.x) - 1.0).abs());
        /// ```
        pub fn solve_projected<T, F, const S: usize>(
            &self,
            f: F,
            project: &mut ProjectFn<'_, T, S>,
            t0: f64,
            x0: &[T; S],
            t_end: f64,
        ) -> Result<Solution<T, S>, IntegrateError>
        where
            T: Scalar,
            F: FnMut(T, &[T; S], &mut [T; S]) -> Result<(), ModelError>,
        {
            let mut sink = CallbackSink {
                times: &[],
                cb: &mut |_, _| {},
            };
            explicit::run::<$pair<T, S>, _, _, _, S>(
                &self.set,
                f,
                t0,
                x0,
                t_end,
                &mut sink,
                None,
                Some(project),
            )
        }

        #[doc = concat!("[`", stringify!($ty), "::solve_projected`] of a model's reduced equations, as")]
        #[doc = concat!("[`", stringify!($ty), "::solve_model`]; with")]
        /// `appell::linearize::project_holonomic` as the
        /// projection it keeps a model on its holonomic constraints.
        pub fn solve_model_projected<M: Model, T: Scalar, const S: usize>(
            &self,
            model: &M,
            inputs: &[T],
            project: &mut ProjectFn<'_, T, S>,
            t0: f64,
            x0: &[T; S],
            t_end: f64,
        ) -> Result<Solution<T, S>, IntegrateError> {
            let mut sink = CallbackSink {
                times: &[],
                cb: &mut |_, _| {},
            };
            self.run_model(model, inputs, t0, x0, t_end, &mut sink, None, Some(project))
        }

        #[doc = concat!("[`", stringify!($ty), "::solve`] of a model's reduced equations ([`Model::rhs`],")]
        /// after one [`Model::prepare`]) with `inputs` held constant. The array
        /// length `S` must be the reduced state length.
        pub fn solve_model<M: Model, T: Scalar, const S: usize>(
            &self,
            model: &M,
            inputs: &[T],
            t0: f64,
            x0: &[T; S],
            t_end: f64,
        ) -> Result<Solution<T, S>, IntegrateError> {
            let mut sink = CallbackSink {
                times: &[],
                cb: &mut |_, _| {},
            };
            self.run_model(model, inputs, t0, x0, t_end, &mut sink, None, None)
        }

        #[doc = concat!("[`", stringify!($ty), "::solve_at`] of a model's reduced equations, as")]
        #[doc = concat!("[`", stringify!($ty), "::solve_model`].")]
        pub fn solve_model_at<M: Model, T: Scalar, const S: usize>(
            &self,
            model: &M,
            inputs: &[T],
            t0: f64,
            x0: &[T; S],
            out: &mut [(f64, [T; S])],
        ) -> Result<Solution<T, S>, IntegrateError> {
            let t_end = out.last().map_or(t0, |o| o.0);
            self.run_model(model, inputs, t0, x0, t_end, &mut SliceSink(out), None, None)
        }

        #[doc = concat!("[`", stringify!($ty), "::solve_until`] of a model's reduced equations, as")]
        #[doc = concat!("[`", stringify!($ty), "::solve_model`].")]
        pub fn solve_model_until<M: Model, T: Scalar, G, const S: usize>(
            &self,
            model: &M,
            inputs: &[T],
            mut g: G,
            t0: f64,
            x0: &[T; S],
            t_end: f64,
        ) -> Result<Solution<T, S>, IntegrateError>
        where
            G: FnMut(f64, &[T; S]) -> f64,
        {
            let mut sink = CallbackSink {
                times: &[],
                cb: &mut |_, _| {},
            };
            self.run_model(model, inputs, t0, x0, t_end, &mut sink, Some(&mut g), None)
        }

        /// The model methods' common run: the model's reduced equations after
        /// one [`Model::prepare`], the caller's projection (if any) and then
        /// the contact watch (see [`watched`](crate::watch)).
        #[allow(clippy::too_many_arguments)] // the problem, the outputs and two optional hooks
        fn run_model<M: Model, T: Scalar, K: Sink<T, S>, const S: usize>(
            &self,
            model: &M,
            inputs: &[T],
            t0: f64,
            x0: &[T; S],
            t_end: f64,
            sink: &mut K,
            event: Option<&mut EventFn<'_, T, S>>,
            project: Option<&mut ProjectFn<'_, T, S>>,
        ) -> Result<Solution<T, S>, IntegrateError> {
            check_model(model, S)?;
            let p = model.prepare::<T>();
            let f = |t: T, x: &[T; S], dx: &mut [T; S]| model.rhs(&p, t, x, inputs, dx);
            use crate::watch::{watched, Hook};
            let (on, has_event) = (self.set.contact_watch, event.is_some());
            watched(model, inputs, on, t0, x0, has_event, |hook| match hook {
                Hook::None => explicit::run::<$pair<T, S>, _, _, _, S>(&self.set, f, t0, x0, t_end, sink, event, project),
                Hook::Event(margin) => {
                    // The watch's margin as the event: the run stops where a
                    // contact is lost, located on the dense output.
                    let mut g = |t: f64, x: &[T; S]| -> f64 {
                        let real: [f64; S] = core::array::from_fn(|i| x[i].re());
                        margin(t, &real)
                    };
                    explicit::run::<$pair<T, S>, _, _, _, S>(&self.set, f, t0, x0, t_end, sink, Some(&mut g), project)
                }
                Hook::Project(watch) => {
                    // The caller has its own event: the watch checks the
                    // end of each step, after the caller's projection.
                    let mut project = project;
                    let mut both = |t: f64, x: &mut [T; S]| -> Result<(), crate::ProjectionFailed> {
                        if let Some(p) = project.as_mut() {
                            p(t, x)?;
                        }
                        let real: [f64; S] = core::array::from_fn(|i| x[i].re());
                        watch(t, &real)
                    };
                    explicit::run::<$pair<T, S>, _, _, _, S>(&self.set, f, t0, x0, t_end, sink, event, Some(&mut both))
                }
            })
        }
    };
}
pub(crate) use explicit_api;
