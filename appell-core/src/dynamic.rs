//! [`DynModel`]: a [`Model`] behind an object-safe interface, in `f64` and
//! the dual numbers the oracle needs, so that tools written against it (the
//! command line, the oracle, the contact forces, the accuracy sweep) are
//! compiled once instead of once per model.
//!
//! [`Model`]'s methods are generic over the [`Scalar`](crate::Scalar), which
//! keeps a `Model` out of a trait object and makes every generic function
//! that takes one compile again for every model (and every scene) a program
//! uses: the command line's integrators, JSON and oracle were most of a
//! model program's build. Every `Model` is a `DynModel` (a blanket
//! implementation in which each method is one call of the model's); a tool
//! that takes `&dyn DynModel` is compiled once and only these small
//! forwarding methods are compiled per model.
//!
//! The methods are prefixed `dyn_` so that both traits can be in scope
//! together without making calls such as `model.rhs(..)` ambiguous.

use crate::{Model, ModelError, ModelInfo, SceneVisitor};
use num_dual::{Dual2_64, Dual64};
use std::hint::black_box;

mod sealed {
    /// Keeps [`DynModel`](super::DynModel) implemented only by the blanket
    /// implementation, so methods can be added to it.
    pub trait Sealed {}
    impl<M: crate::Model> Sealed for M {}
}

/// A model's reduced rhs with its parameter-only work
/// ([`Model::prepare`]) done once, in `f64` and in [`Dual64`] (for
/// Jacobians): what integrators driven through a [`DynModel`] call. Made by
/// [`DynModel::dyn_prepare`]; it borrows the model, so the parameters cannot
/// change under it.
///
/// ```
/// use appell_core::DynModel;
/// # use appell_core::__doc_model::Oscillator;
/// use num_dual::Dual64;
///
/// // x'' = −w² x as a trait object: ẋ₂ = −w² x₁.
/// let model: &dyn DynModel = &Oscillator { w: 2.0 };
/// let rhs = model.dyn_prepare();
/// assert_eq!(rhs.state_len(), 2);
/// let mut dx = [0.0; 2];
/// rhs.rhs(0.0, &[1.0, 0.5], &[], &mut dx).unwrap();
/// assert_eq!(dx, [0.5, -4.0]);
///
/// // ∂ẋ₂/∂x₁ = −w² by a dual number.
/// let mut d = [Dual64::from(0.0); 2];
/// rhs.rhs_dual(Dual64::from(0.0), &[Dual64::new(1.0, 1.0), Dual64::from(0.0)], &[], &mut d)
///     .unwrap();
/// assert_eq!(d[1].eps, -4.0);
/// ```
pub trait DynRhs {
    /// The length of the reduced state ([`ModelInfo::state_len`]).
    fn state_len(&self) -> usize;

    /// [`Model::rhs`] in `f64`.
    fn rhs(
        &self,
        t: f64,
        state: &[f64],
        inputs: &[f64],
        dstate: &mut [f64],
    ) -> Result<(), ModelError>;

    /// [`Model::rhs`] in [`Dual64`] (a column of the Jacobian per seed).
    fn rhs_dual(
        &self,
        t: Dual64,
        state: &[Dual64],
        inputs: &[Dual64],
        dstate: &mut [Dual64],
    ) -> Result<(), ModelError>;

    /// ∂rhs/∂state (row-major n×n into `a`) by the model's generated
    /// [`Model::rhs_jacobian`], `values` (n) and `b` (n × inputs) its
    /// other outputs; `Ok(false)` where it has none.
    fn generated_jacobian(
        &self,
        t: f64,
        state: &[f64],
        inputs: &[f64],
        values: &mut [f64],
        a: &mut [f64],
        b: &mut [f64],
    ) -> Result<bool, ModelError>;

    /// Whether the model has a generated [`Model::rhs_jacobian`].
    fn has_generated_jacobian(&self) -> bool;

    /// Calls [`DynRhs::rhs`] at `t` on every `(state, inputs)` of `cases`
    /// into `dstate`, every argument and result through
    /// [`black_box`], results dropped: one pass of a timing loop, whose
    /// calls stay direct calls of the generated code.
    fn rhs_pass(&self, t: f64, cases: &[(&[f64], &[f64])], dstate: &mut [f64]);
}

/// A model and its prepared values: the [`DynRhs`] of every [`Model`], for
/// tools that keep the model's type (what [`DynModel::dyn_prepare`] boxes).
///
/// ```
/// use appell_core::__doc_model::Pendulum;
/// use appell_core::dynamic::{DynRhs, Prepared};
///
/// // θ̈ = −(g/l) sin θ + τ at θ = 0, θ̇ = 1, τ = 0.5.
/// let model = Pendulum { g_over_l: 9.81 };
/// let rhs = Prepared::new(&model);
/// let mut dx = [0.0; 2];
/// rhs.rhs(0.0, &[0.0, 1.0], &[0.5], &mut dx).unwrap();
/// assert_eq!(dx, [1.0, 0.5]);
/// ```
pub struct Prepared<'a, M: Model> {
    model: &'a M,
    real: M::Prepared<f64>,
    dual: M::Prepared<Dual64>,
}

impl<'a, M: Model> Prepared<'a, M> {
    /// Prepares `model` in `f64` and [`Dual64`].
    pub fn new(model: &'a M) -> Self {
        Prepared {
            model,
            real: model.prepare::<f64>(),
            dual: model.prepare::<Dual64>(),
        }
    }
}

impl<M: Model> DynRhs for Prepared<'_, M> {
    fn state_len(&self) -> usize {
        M::info().state_len()
    }

    fn rhs(
        &self,
        t: f64,
        state: &[f64],
        inputs: &[f64],
        dstate: &mut [f64],
    ) -> Result<(), ModelError> {
        self.model.rhs(&self.real, t, state, inputs, dstate)
    }

    fn rhs_dual(
        &self,
        t: Dual64,
        state: &[Dual64],
        inputs: &[Dual64],
        dstate: &mut [Dual64],
    ) -> Result<(), ModelError> {
        self.model.rhs(&self.dual, t, state, inputs, dstate)
    }

    fn generated_jacobian(
        &self,
        t: f64,
        state: &[f64],
        inputs: &[f64],
        values: &mut [f64],
        a: &mut [f64],
        b: &mut [f64],
    ) -> Result<bool, ModelError> {
        if !self.has_generated_jacobian() {
            return Ok(false);
        }
        self.model.rhs_jacobian(t, state, inputs, values, a, b)?;
        Ok(true)
    }

    fn has_generated_jacobian(&self) -> bool {
        M::info().jacobian.is_some()
    }

    fn rhs_pass(&self, t: f64, cases: &[(&[f64], &[f64])], dstate: &mut [f64]) {
        for (state, inputs) in cases {
            let r = self.model.rhs(
                black_box(&self.real),
                black_box(t),
                black_box(state),
                black_box(inputs),
                black_box(&mut *dstate),
            );
            let _ = black_box((r, &*dstate));
        }
    }
}

/// Passes a scene to a `dyn` callback.
struct Visit<'a, 'b>(&'a mut (dyn FnMut(&dyn DynModel) + 'b));

impl SceneVisitor for Visit<'_, '_> {
    type Output = ();
    fn visit<S: Model>(self, scene: &S) {
        (self.0)(scene)
    }
}

/// Writes [`DynModel`] and its implementation for every [`Model`]: the
/// methods written out by hand, then the forwarded ones, each declared
/// with its docs and implemented as the `Model` method it names, called
/// with the same arguments (at the scalar its argument types give).
macro_rules! dyn_model {
    (
        $(#[$attr:meta])*
        declared { $($declared:tt)* }
        implemented { $($implemented:tt)* }
        forwarded {
            $(
                $(#[$doc:meta])*
                fn $dyn:ident => $name:ident($($arg:ident: $ty:ty),* $(,)?) -> $ret:ty;
            )*
        }
    ) => {
        $(#[$attr])*
        pub trait DynModel: sealed::Sealed {
            $($declared)*
            $(
                $(#[$doc])*
                fn $dyn(&self, $($arg: $ty),*) -> $ret;
            )*
        }

        impl<M: Model> DynModel for M {
            $($implemented)*
            $(
                fn $dyn(&self, $($arg: $ty),*) -> $ret {
                    self.$name($($arg),*)
                }
            )*
        }
    };
}

dyn_model! {
    /// The object-safe face of a [`Model`]: its metadata, parameters, reduced
    /// equations and kinematic description in `f64`, and the few methods the
    /// oracle evaluates in dual numbers ([`Dual64`], [`Dual2_64`]). Each method
    /// is the `Model` method of the same name without the `dyn_` prefix, at the
    /// scalar its suffix names (none: `f64`).
    ///
    /// Implemented for every [`Model`] (and only for them); a `&M` coerces to
    /// `&dyn DynModel`, so one function over `&dyn DynModel` serves every model
    /// and is compiled once. The command line is written this way.
    ///
    /// ```
    /// use appell_core::DynModel;
    /// # use appell_core::ModelError;
    /// # use appell_core::__doc_model::Oscillator;
    /// // A function compiled once, whatever the model.
    /// fn period_guess(model: &mut dyn DynModel, w: f64) -> Result<f64, ModelError> {
    ///     assert!(model.dyn_set_parameter("w", w));
    ///     let mut d = vec![0.0; model.dyn_info().state_len()];
    ///     model.dyn_rhs(0.0, &[1.0, 0.0], &[], &mut d)?;
    ///     Ok(2.0 * std::f64::consts::PI / (-d[1]).sqrt())
    /// }
    ///
    /// let mut model = Oscillator { w: 1.0 };
    /// assert!((period_guess(&mut model, 2.0).unwrap() - std::f64::consts::PI).abs() < 1e-12);
    /// assert_eq!(model.w, 2.0);
    /// ```
    declared {
        /// [`Model::info`].
        fn dyn_info(&self) -> &'static ModelInfo;

        /// [`Model::scene_infos`].
        fn dyn_scene_infos(&self) -> &'static [&'static ModelInfo];

        /// [`Model::set_parameter`].
        fn dyn_set_parameter(&mut self, name: &str, value: f64) -> bool;

        /// The reduced rhs with [`Model::prepare`] done once, in `f64` and
        /// [`Dual64`].
        fn dyn_prepare(&self) -> Box<dyn DynRhs + '_>;

        /// [`Model::rhs`] after [`Model::prepare`], in `f64`.
        fn dyn_rhs(
            &self,
            t: f64,
            state: &[f64],
            inputs: &[f64],
            dstate: &mut [f64],
        ) -> Result<(), ModelError>;

        /// Calls `visit` with scene `scene` as a `DynModel` ([`Model::visit_scene`]).
        fn dyn_visit_scene(
            &self,
            scene: usize,
            visit: &mut dyn FnMut(&dyn DynModel),
        ) -> Result<(), ModelError>;

        /// [`Model::contact_links`].
        fn dyn_contact_links(&self) -> &'static [&'static str];

        /// [`Model::joint_limits`].
        fn dyn_joint_limits(&self) -> &'static [crate::JointLimit];
    }

    implemented {
        fn dyn_info(&self) -> &'static ModelInfo {
            M::info()
        }

        fn dyn_scene_infos(&self) -> &'static [&'static ModelInfo] {
            M::scene_infos()
        }

        fn dyn_set_parameter(&mut self, name: &str, value: f64) -> bool {
            self.set_parameter(name, value)
        }

        fn dyn_prepare(&self) -> Box<dyn DynRhs + '_> {
            Box::new(Prepared::new(self))
        }

        fn dyn_rhs(
            &self,
            t: f64,
            state: &[f64],
            inputs: &[f64],
            dstate: &mut [f64],
        ) -> Result<(), ModelError> {
            self.rhs(&self.prepare::<f64>(), t, state, inputs, dstate)
        }

        fn dyn_visit_scene(
            &self,
            scene: usize,
            visit: &mut dyn FnMut(&dyn DynModel),
        ) -> Result<(), ModelError> {
            self.visit_scene(scene, Visit(visit))
        }

        fn dyn_contact_links(&self) -> &'static [&'static str] {
            M::contact_links()
        }

        fn dyn_joint_limits(&self) -> &'static [crate::JointLimit] {
            M::joint_limits()
        }
    }

    forwarded {
        /// [`Model::parameter_values`].
        fn dyn_parameter_values => parameter_values(out: &mut [f64]) -> Result<(), ModelError>;

        /// [`Model::validate`].
        fn dyn_validate => validate() -> Result<(), ModelError>;

        /// [`Model::scene_rhs`].
        fn dyn_scene_rhs => scene_rhs(
            scene: usize,
            t: f64,
            state: &[f64],
            inputs: &[f64],
            dstate: &mut [f64],
        ) -> Result<(), ModelError>;

        /// [`Model::coordinate_rates`].
        fn dyn_coordinate_rates => coordinate_rates(t: f64, q: &[f64], u: &[f64], qdot: &mut [f64])
            -> Result<(), ModelError>;

        /// [`Model::constraint_residuals`].
        fn dyn_constraint_residuals => constraint_residuals(
            t: f64,
            q: &[f64],
            qdot: &[f64],
            holonomic: &mut [f64],
            velocity: &mut [f64],
        ) -> Result<(), ModelError>;

        /// [`Model::speed_definitions`].
        fn dyn_speed_definitions => speed_definitions(
            t: f64,
            q: &[f64],
            w: &mut [f64],
            w0: &mut [f64],
        ) -> Result<(), ModelError>;

        /// [`Model::mass_matrix_and_forcing`].
        fn dyn_mass_matrix_and_forcing => mass_matrix_and_forcing(
            t: f64,
            q: &[f64],
            u: &[f64],
            inputs: &[f64],
            m: &mut [f64],
            f: &mut [f64],
        ) -> Result<(), ModelError>;

        /// [`Model::speed_definitions`] in [`Dual64`].
        fn dyn_speed_definitions_dual => speed_definitions(
            t: Dual64,
            q: &[Dual64],
            w: &mut [Dual64],
            w0: &mut [Dual64],
        ) -> Result<(), ModelError>;

        /// [`Model::kinetic_energy`] in [`Dual64`].
        fn dyn_kinetic_energy_dual => kinetic_energy(t: Dual64, q: &[Dual64], u: &[Dual64])
            -> Result<Dual64, ModelError>;

        /// [`Model::potential_energy`] in [`Dual64`].
        fn dyn_potential_energy_dual => potential_energy(t: Dual64, q: &[Dual64])
            -> Result<Dual64, ModelError>;

        /// [`Model::input_power`].
        fn dyn_input_power => input_power(t: f64, q: &[f64], u: &[f64], inputs: &[f64])
            -> Result<f64, ModelError>;

        /// [`Model::mass_properties`].
        fn dyn_mass_properties => mass_properties(masses: &mut [f64], inertias: &mut [[f64; 9]])
            -> Result<(), ModelError>;

        /// [`Model::body_poses`].
        fn dyn_body_poses => body_poses(
            t: f64,
            q: &[f64],
            positions: &mut [[f64; 3]],
            rotations: &mut [[f64; 9]],
        ) -> Result<(), ModelError>;

        /// [`Model::body_poses`] in [`Dual64`].
        fn dyn_body_poses_dual => body_poses(
            t: Dual64,
            q: &[Dual64],
            positions: &mut [[Dual64; 3]],
            rotations: &mut [[Dual64; 9]],
        ) -> Result<(), ModelError>;

        /// [`Model::body_poses`] in [`Dual2_64`].
        fn dyn_body_poses_dual2 => body_poses(
            t: Dual2_64,
            q: &[Dual2_64],
            positions: &mut [[Dual2_64; 3]],
            rotations: &mut [[Dual2_64; 9]],
        ) -> Result<(), ModelError>;

        /// [`Model::constraint_rows`].
        fn dyn_constraint_rows => constraint_rows(t: f64, q: &[f64], d: &mut [f64], d0: &mut [f64])
            -> Result<(), ModelError>;

        /// [`Model::driven_constraint_rows`].
        fn dyn_driven_constraint_rows => driven_constraint_rows(
            t: f64,
            q: &[f64],
            inputs: &[f64],
            d: &mut [f64],
            d0: &mut [f64],
        ) -> Result<(), ModelError>;

        /// [`Model::dependent_block_margin`].
        fn dyn_dependent_block_margin => dependent_block_margin(t: f64, q: &[f64], inputs: &[f64])
            -> Result<f64, ModelError>;

        /// [`Model::driven_constraint_rows`] in [`Dual64`].
        fn dyn_driven_constraint_rows_dual => driven_constraint_rows(
            t: Dual64,
            q: &[Dual64],
            inputs: &[Dual64],
            d: &mut [Dual64],
            d0: &mut [Dual64],
        ) -> Result<(), ModelError>;

        /// [`Model::driven_coordinate_rates`].
        fn dyn_driven_coordinate_rates => driven_coordinate_rates(
            t: f64,
            q: &[f64],
            u: &[f64],
            inputs: &[f64],
            qdot: &mut [f64],
        ) -> Result<(), ModelError>;

        /// [`Model::driven_coordinate_rates`] in [`Dual64`].
        fn dyn_driven_coordinate_rates_dual => driven_coordinate_rates(
            t: Dual64,
            q: &[Dual64],
            u: &[Dual64],
            inputs: &[Dual64],
            qdot: &mut [Dual64],
        ) -> Result<(), ModelError>;

        /// [`Model::driven_speed_transform`].
        fn dyn_driven_speed_transform => driven_speed_transform(
            t: f64,
            q: &[f64],
            inputs: &[f64],
            c: &mut [f64],
            c0: &mut [f64],
        ) -> Result<(), ModelError>;

        /// [`Model::driven_constraint_residuals`].
        fn dyn_driven_constraint_residuals => driven_constraint_residuals(
            t: f64,
            q: &[f64],
            qdot: &[f64],
            inputs: &[f64],
            holonomic: &mut [f64],
            velocity: &mut [f64],
        ) -> Result<(), ModelError>;

        /// [`Model::driven_kinetic_energy`].
        fn dyn_driven_kinetic_energy => driven_kinetic_energy(
            t: f64,
            q: &[f64],
            u: &[f64],
            inputs: &[f64],
        ) -> Result<f64, ModelError>;

        /// [`Model::driven_kinetic_energy`] in [`Dual64`].
        fn dyn_driven_kinetic_energy_dual => driven_kinetic_energy(
            t: Dual64,
            q: &[Dual64],
            u: &[Dual64],
            inputs: &[Dual64],
        ) -> Result<Dual64, ModelError>;

        /// [`Model::constraint_rows`] in [`Dual64`].
        fn dyn_constraint_rows_dual => constraint_rows(
            t: Dual64,
            q: &[Dual64],
            d: &mut [Dual64],
            d0: &mut [Dual64],
        ) -> Result<(), ModelError>;

        /// [`Model::load_geometry`].
        fn dyn_load_geometry => load_geometry(
            t: f64,
            q: &[f64],
            points: &mut [[f64; 3]],
            frames: &mut [[f64; 9]],
        ) -> Result<(), ModelError>;

        /// [`Model::load_geometry`] in [`Dual64`].
        fn dyn_load_geometry_dual => load_geometry(
            t: Dual64,
            q: &[Dual64],
            points: &mut [[Dual64; 3]],
            frames: &mut [[Dual64; 9]],
        ) -> Result<(), ModelError>;

        /// [`Model::contact_geometry`].
        fn dyn_contact_geometry => contact_geometry(
            t: f64,
            q: &[f64],
            points: &mut [[f64; 3]],
            directions: &mut [[f64; 3]],
        ) -> Result<(), ModelError>;

        /// [`Model::contact_points`].
        fn dyn_contact_points => contact_points(t: f64, q: &[f64], points: &mut [[f64; 3]])
            -> Result<(), ModelError>;

        /// [`Model::load_values`].
        fn dyn_load_values => load_values(
            t: f64,
            q: &[f64],
            qdot: &[f64],
            inputs: &[f64],
            forces: &mut [[f64; 3]],
            torques: &mut [[f64; 3]],
        ) -> Result<(), ModelError>;
    }
}
