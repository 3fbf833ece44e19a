//! The interface `#[derive(Appell)]` implements.
//!
//! Vocabulary (Wang & Pao 2003): n generalized coordinates q_r; m velocity
//! constraints D(q,t) q̇ + d = 0 (eq. 25); l = n − m privileged speeds ẏ_k,
//! which are the rates of the coordinates named in `speeds(...)`; the
//! transformation q̇_r = Σ_k C_rk ẏ_k + c_r (eqs. 30-31); Appell's equations
//! M(q,t) ÿ = f(q, ẏ, t) (eq. 56 after splitting off the accelerations).
//!
//! The *reduced state* integrated by [`Model::rhs`] is the retained (non-
//! ignorable) coordinates followed by all privileged speeds; the ignorable
//! coordinates are recovered by quadrature of [`Model::coordinate_rates`].
//!
//! All methods take slices so they can be called generically; their lengths
//! are given by [`ModelInfo`], and a wrong length is an error, never a panic.

use crate::error::{check_len, ModelError};
#[cfg(doc)]
use crate::info::RowSource;
use crate::info::{JointLimit, ModelInfo};
use crate::scalar::Scalar;

/// A constrained multibody model whose equations of motion were derived at
/// compile time. Implemented by `#[derive(Appell)]`.
///
/// Scalars: every numeric method is generic over [`Scalar`], so the same
/// generated code runs on `f64`, `f32` and dual numbers (for Jacobians).
pub trait Model {
    /// Parameter-only subexpressions of the reduced rhs, computed once per
    /// parameter set by [`Model::prepare`].
    type Prepared<T: Scalar>: Copy;

    /// Names, sizes and the derived equations.
    fn info() -> &'static ModelInfo;

    /// The `ModelInfo` of each declared scene (`scene(...)` on the struct),
    /// whose generated types implement this trait too.
    fn scene_infos() -> &'static [&'static ModelInfo] {
        &[]
    }

    /// The reduced rhs of scene `scene` (an index into
    /// [`Model::scene_infos`]) in `f64`, for tools that pick a scene by name
    /// at run time (the command line); simulations use the scene's own type.
    fn scene_rhs(
        &self,
        scene: usize,
        t: f64,
        state: &[f64],
        inputs: &[f64],
        dstate: &mut [f64],
    ) -> Result<(), ModelError> {
        let _ = (t, state, inputs, dstate);
        Err(ModelError::UnknownScene { index: scene })
    }

    /// The parameter values, in [`ModelInfo::parameters`] order.
    fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError>;

    /// Sets a parameter by name; false when there is no such parameter.
    fn set_parameter(&mut self, name: &str, value: f64) -> bool;

    /// Checks the parameter values once, before a simulation: every
    /// parameter declared `positive` is, and every body whose mass or
    /// inertia is made of parameters can be physical (a positive mass, an
    /// inertia that is positive semidefinite and obeys the triangle
    /// inequality; see [`physical`](crate::physical)), and no divisor made
    /// of parameters is zero. Bodies written in numbers were checked when
    /// the model compiled.
    ///
    /// The integrators' `solve_model*`, `appell::linearize`,
    /// the hybrid driver and the command line call it; the generated
    /// [`Model::rhs`] checks only positivity, so a controller stepping
    /// `appell::integrate::rk4_step` in a loop should call it
    /// once when its parameters change. Errors:
    /// [`ModelError::NonPositiveParameter`] and
    /// [`ModelError::ImpossibleBody`], naming the body's parameters, and
    /// [`ModelError::ZeroDivisor`] for a divisor made of parameters that is
    /// zero (`1 / k` with k = 0), naming them. The
    /// default (a model written by hand) accepts everything.
    fn validate(&self) -> Result<(), ModelError> {
        Ok(())
    }

    /// Computes the parameter-only values of the rhs.
    fn prepare<T: Scalar>(&self) -> Self::Prepared<T>;

    /// The reduced equations of motion (eq. 42): `dstate = rhs(t, state)`,
    /// state = retained coordinates then privileged speeds.
    fn rhs<T: Scalar>(
        &self,
        prepared: &Self::Prepared<T>,
        t: T,
        state: &[T],
        inputs: &[T],
        dstate: &mut [T],
    ) -> Result<(), ModelError>;

    /// The reduced rhs and its Jacobians in one call: `dstate` as
    /// [`Model::rhs`] writes it, `a` = ∂rhs/∂state (s×s row-major, s the
    /// [state length](ModelInfo::state_len)) and `b` = ∂rhs/∂inputs (s×i
    /// row-major, i the number of [inputs](ModelInfo::inputs)). Parameters
    /// and time are held fixed.
    ///
    /// The derive generates it for every model, choosing by cost between
    /// the model's equations differentiated symbolically and the rhs run
    /// in dual numbers ([`dual::rhs_jacobian_by_duals`](crate::dual::rhs_jacobian_by_duals));
    /// [`ModelInfo::jacobian`] says which, and what it costs. It needs no
    /// [`Model::prepare`], allocates nothing and runs on any [`Scalar`].
    /// A model with `jacobian(off)`, and one written by hand that does not
    /// implement it, return [`ModelError::NotGenerated`] (this default),
    /// and `appell::linearize` then runs the rhs in dual
    /// numbers itself. Errors otherwise as [`Model::rhs`]'s, and
    /// [`ModelError::NonFinite`] naming the Jacobian when a derivative is
    /// not finite.
    fn rhs_jacobian<T: Scalar>(
        &self,
        t: T,
        state: &[T],
        inputs: &[T],
        dstate: &mut [T],
        a: &mut [T],
        b: &mut [T],
    ) -> Result<(), ModelError> {
        let _ = (t, state, inputs, dstate, a, b);
        Err(ModelError::NotGenerated {
            function: "rhs_jacobian",
        })
    }

    /// Appell's equations M ÿ = f at full coordinates `q` and privileged
    /// speeds `u`; `m` is l×l row-major.
    fn mass_matrix_and_forcing<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        u: &[T],
        inputs: &[T],
        m: &mut [T],
        f: &mut [T],
    ) -> Result<(), ModelError>;

    /// Inverse dynamics: the generalized forces Q (one per privileged
    /// speed) for which the privileged accelerations are `accel` at full
    /// coordinates `q` and speeds `u` with the inputs at zero, that is
    /// M(q) `accel` = f(q, u, 0) + Q, so Q = M `accel` + h. For a robot
    /// whose joints are `actuated` (a URDF's), Q are the joint torques in
    /// joint order (computed-torque control; Pinocchio's `rnea`). Tree
    /// models compute it by recursive Newton–Euler, others from M and f.
    fn inverse_dynamics<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        u: &[T],
        accel: &[T],
        forces: &mut [T],
    ) -> Result<(), ModelError> {
        let _ = (t, q, u, accel, forces);
        Err(ModelError::NotGenerated {
            function: "inverse_dynamics",
        })
    }

    /// The inverse dynamics and its derivatives in one call (Pinocchio's
    /// `computeRNEADerivatives`): `forces` = Q as
    /// [`Model::inverse_dynamics`] writes them, `dq` = ∂Q/∂q (l×n
    /// row-major: one column per coordinate, in [`ModelInfo::coordinates`]
    /// order; a quaternion's four components each, where Pinocchio
    /// differentiates along its tangent), `du` = ∂Q/∂u (l×l) and `m` =
    /// ∂Q/∂accel = M (l×l, both triangles). For a fixed-base robot from a
    /// URDF these are Pinocchio's `dtau_dq`, `dtau_dv` and `M`.
    ///
    /// The derive writes it for every model with its Jacobian on: a tree's
    /// recursive Newton–Euler differentiated symbolically where that costs
    /// at most 4 times its expressions (or with `jacobian(on)`), else the
    /// inverse dynamics in dual numbers
    /// ([`dual::inverse_dynamics_derivatives_by_duals`](crate::dual::inverse_dynamics_derivatives_by_duals)).
    /// This default returns [`ModelError::NotGenerated`]. Errors otherwise
    /// as [`Model::inverse_dynamics`]'s, and [`ModelError::NonFinite`]
    /// when a derivative is not finite.
    #[allow(clippy::too_many_arguments)] // Pinocchio's computeRNEADerivatives: q, u, accel in; Q and its three Jacobians out
    fn inverse_dynamics_derivatives<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        u: &[T],
        accel: &[T],
        forces: &mut [T],
        dq: &mut [T],
        du: &mut [T],
        m: &mut [T],
    ) -> Result<(), ModelError> {
        let _ = (t, q, u, accel, forces, dq, du, m);
        Err(ModelError::NotGenerated {
            function: "inverse_dynamics_derivatives",
        })
    }

    /// The forward dynamics and its derivatives in full coordinates, in
    /// one call (Pinocchio's `computeABADerivatives`): `accel` = ÿ at
    /// coordinates `q`, privileged speeds `u` and `inputs`, `dq` = ∂ÿ/∂q
    /// (l×n row-major, one column per coordinate in
    /// [`ModelInfo::coordinates`] order, zero for the coordinates the
    /// equations do not depend on), `du` = ∂ÿ/∂u (l×l) and `dinputs` =
    /// ∂ÿ/∂inputs (l×i); a quaternion's four components each, where
    /// Pinocchio differentiates along its tangent. For a fixed-base robot
    /// from a URDF these are
    /// Pinocchio's `ddq_dq`, `ddq_dv` and `ddq_dtau` (= M⁻¹ where every
    /// joint is actuated). The derive writes it from
    /// [`Model::rhs_jacobian`]'s rows for ÿ wherever it writes that; this
    /// default returns [`ModelError::NotGenerated`].
    #[allow(clippy::too_many_arguments)] // Pinocchio's computeABADerivatives: q, u, inputs in; ÿ and its three Jacobians out
    fn forward_dynamics_derivatives<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        u: &[T],
        inputs: &[T],
        accel: &mut [T],
        dq: &mut [T],
        du: &mut [T],
        dinputs: &mut [T],
    ) -> Result<(), ModelError> {
        let _ = (t, q, u, inputs, accel, dq, du, dinputs);
        Err(ModelError::NotGenerated {
            function: "forward_dynamics_derivatives",
        })
    }

    /// M(q) alone, l×l row-major (Pinocchio's `crba`, both triangles).
    fn mass_matrix<T: Scalar>(&self, t: T, q: &[T], m: &mut [T]) -> Result<(), ModelError> {
        let _ = (t, q, m);
        Err(ModelError::NotGenerated {
            function: "mass_matrix",
        })
    }

    /// The bias h(q, u) = −f(q, u, 0): velocity products and every load at
    /// zero inputs, so that M ÿ + h = Q (Pinocchio's `nonLinearEffects`).
    fn bias_forces<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        u: &[T],
        bias: &mut [T],
    ) -> Result<(), ModelError> {
        let _ = (t, q, u, bias);
        Err(ModelError::NotGenerated {
            function: "bias_forces",
        })
    }

    /// The generalized forces that hold the mechanism still, h(q, 0): with
    /// gravity the only load that acts at rest, the gravity term
    /// (Pinocchio's `computeGeneralizedGravity`).
    fn gravity_forces<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        gravity: &mut [T],
    ) -> Result<(), ModelError> {
        let _ = (t, q, gravity);
        Err(ModelError::NotGenerated {
            function: "gravity_forces",
        })
    }

    /// C_rk (n×l row-major) and c_r (n) of q̇ = C ẏ + c (eqs. 30-31).
    fn speed_transform<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        c: &mut [T],
        c0: &mut [T],
    ) -> Result<(), ModelError>;

    /// All coordinate rates from the privileged speeds: the dependent speeds
    /// and the quadrature rates of the ignorable coordinates.
    fn coordinate_rates<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        u: &[T],
        qdot: &mut [T],
    ) -> Result<(), ModelError>;

    /// Residuals of the holonomic constraints (`holonomic`, one per
    /// constraint) and of all velocity constraint rows D q̇ + d (`velocity`).
    fn constraint_residuals<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        qdot: &[T],
        holonomic: &mut [T],
        velocity: &mut [T],
    ) -> Result<(), ModelError>;

    /// The definitions of the privileged speeds, u = W(q,t) q̇ + w(q,t):
    /// `w` is W (l×n row-major), `w0` is w (l). A speed that is a
    /// coordinate's rate (Method II) has a unit row; a quasi-velocity
    /// (Method III) has its defining combination. The default serves models
    /// whose speeds are all named coordinates.
    fn speed_definitions<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        w: &mut [T],
        w0: &mut [T],
    ) -> Result<(), ModelError> {
        let _ = t;
        let info = Self::info();
        let (n, l) = (info.coordinates.len(), info.speeds.len());
        check_len("q", q, n)?;
        check_len("w", w, l * n)?;
        check_len("w0", w0, l)?;
        for (k, name) in info.speeds.iter().enumerate() {
            let r = info
                .coordinate_index(name)
                .ok_or(ModelError::UnknownSpeed { name })?;
            for c in 0..n {
                w[k * n + c] = if c == r { T::one() } else { T::zero() };
            }
            w0[k] = T::zero();
        }
        Ok(())
    }

    /// The potential energy of the `gravity` effect's loads (constant forces
    /// F at points r: V = −Σ F·r), zero for a model that has none.
    fn potential_energy<T: Scalar>(&self, t: T, q: &[T]) -> Result<T, ModelError> {
        let _ = (t, q);
        Ok(T::zero())
    }

    /// The power of the loads that depend on the inputs (Σ F·v + L·ω over
    /// them), for controllers; zero for a model without inputs.
    fn input_power<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        u: &[T],
        inputs: &[T],
    ) -> Result<T, ModelError> {
        let _ = (t, q, u, inputs);
        Ok(T::zero())
    }

    /// Kinetic energy at full coordinates and privileged speeds.
    fn kinetic_energy<T: Scalar>(&self, t: T, q: &[T], u: &[T]) -> Result<T, ModelError>;

    // ----- kinematic description, for the independent multiplier solver ---

    /// Mass and body-frame central inertia (row-major 3×3) of each body.
    fn mass_properties(
        &self,
        masses: &mut [f64],
        inertias: &mut [[f64; 9]],
    ) -> Result<(), ModelError>;

    /// Mass-centre positions (N components) and rotation matrices (columns
    /// are the body axes in N, row-major) of every body at `(q, t)`.
    fn body_poses<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        positions: &mut [[T; 3]],
        rotations: &mut [[T; 9]],
    ) -> Result<(), ModelError>;

    /// The velocity constraint rows D (m×n row-major) and d (m) at `(q, t)`.
    fn constraint_rows<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        d: &mut [T],
        d0: &mut [T],
    ) -> Result<(), ModelError>;

    /// [`Model::constraint_rows`] at `inputs` too: a model whose
    /// constraints read inputs (driven coordinates, `nonholonomic(dt(q) ==
    /// w)`) generates it, and its `constraint_rows` returns
    /// [`ModelError::NeedsInputs`]; for every other model it is
    /// `constraint_rows` and ignores `inputs`.
    fn driven_constraint_rows<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        inputs: &[T],
        d: &mut [T],
        d0: &mut [T],
    ) -> Result<(), ModelError> {
        let _ = inputs;
        self.constraint_rows(t, q, d, d0)
    }

    /// [`Model::coordinate_rates`] at `inputs` too (see
    /// [`Model::driven_constraint_rows`]).
    fn driven_coordinate_rates<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        u: &[T],
        inputs: &[T],
        qdot: &mut [T],
    ) -> Result<(), ModelError> {
        let _ = inputs;
        self.coordinate_rates(t, q, u, qdot)
    }

    /// How far the dependent block D′ (the constraint rows' columns of the
    /// [`ModelInfo::dependent`] coordinates) is from singular at `(q, t)`
    /// and `inputs` (read only by models whose constraints read inputs):
    /// [`pivot_margin`](crate::linalg::pivot_margin) of D′, the smallest
    /// LU pivot relative to the largest entry, whose reciprocal estimates
    /// κ(D′). The generated rhs reports
    /// [`ModelError::SingularConstraints`] where this falls to about
    /// 1e-12. Generated without allocation and in `no_std`; it evaluates
    /// D′ and factors it once, about the cost of an rhs call.
    /// `appell::conditioning::ConditionWatch` uses it with
    /// `ConditionWatch::from_pivots`.
    ///
    /// The default returns 1 for a model without dependent rates and
    /// [`ModelError::NotGenerated`] for any other.
    ///
    /// ```
    /// use appell_core::Model;
    /// # use appell_core::__doc_model::Oscillator;
    ///
    /// // A model without constraints is as far from singular as can be.
    /// let free = Oscillator { w: 0.0 }; // x'' = 0: a free particle
    /// assert_eq!(free.dependent_block_margin(0.0, &[0.0], &[]), Ok(1.0));
    /// ```
    fn dependent_block_margin<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        inputs: &[T],
    ) -> Result<f64, ModelError> {
        let _ = (t, inputs);
        let info = Self::info();
        check_len("q", q, info.coordinates.len())?;
        if info.dependent.is_empty() {
            Ok(1.0)
        } else {
            Err(ModelError::NotGenerated {
                function: "dependent_block_margin",
            })
        }
    }

    /// [`Model::speed_transform`] at `inputs` too: C and c of q̇ = C ẏ + c
    /// when the constraints read inputs (a driven coordinate's rate is
    /// c's entry, the commanded rate). Generated for a driven model, whose
    /// `speed_transform` returns [`ModelError::NeedsInputs`]; for every
    /// other model it is `speed_transform` and ignores `inputs` (see
    /// [`Model::driven_constraint_rows`]).
    fn driven_speed_transform<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        inputs: &[T],
        c: &mut [T],
        c0: &mut [T],
    ) -> Result<(), ModelError> {
        let _ = inputs;
        self.speed_transform(t, q, c, c0)
    }

    /// [`Model::constraint_residuals`] at `inputs` too: a driven
    /// coordinate's holonomic residual is its distance from the command
    /// (`theta − q_cmd` for `holonomic(theta == q_cmd)`) and its velocity
    /// row's residual reads the commanded rate. Generated for a driven
    /// model; for every other model it is `constraint_residuals` and
    /// ignores `inputs` (see [`Model::driven_constraint_rows`]).
    fn driven_constraint_residuals<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        qdot: &[T],
        inputs: &[T],
        holonomic: &mut [T],
        velocity: &mut [T],
    ) -> Result<(), ModelError> {
        let _ = inputs;
        self.constraint_residuals(t, q, qdot, holonomic, velocity)
    }

    /// [`Model::kinetic_energy`] at `inputs` too: the driven coordinates
    /// move at the commanded rates, which the kinetic energy reads.
    /// Generated for a driven model, whose `kinetic_energy` returns
    /// [`ModelError::NeedsInputs`]; for every other model it is
    /// `kinetic_energy` and ignores `inputs` (see
    /// [`Model::driven_constraint_rows`]).
    fn driven_kinetic_energy<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        u: &[T],
        inputs: &[T],
    ) -> Result<T, ModelError> {
        let _ = inputs;
        self.kinetic_energy(t, q, u)
    }

    /// Load geometry at `(q, t)`: the position of every force's application
    /// point and the rotation matrix of every torque's frame.
    fn load_geometry<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        points: &mut [[T; 3]],
        frames: &mut [[T; 9]],
    ) -> Result<(), ModelError>;

    /// The rolling contacts' geometry at `(q, t)`: the position (N
    /// components) of every contact point in [`ModelInfo::contacts`] order,
    /// and for every velocity constraint row the direction e (N components)
    /// whose velocity component e·v_P it constrains
    /// ([`RowSource::Rolling`]), zero for the other rows. The default serves
    /// models without rolling contacts (it writes zero directions and no
    /// points); a model that lists contacts must implement it.
    fn contact_geometry<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        points: &mut [[T; 3]],
        directions: &mut [[T; 3]],
    ) -> Result<(), ModelError> {
        let _ = t;
        let info = Self::info();
        check_len("q", q, info.coordinates.len())?;
        check_len("points", points, info.contacts.len())?;
        check_len("directions", directions, info.constraints)?;
        for d in directions.iter_mut() {
            *d = [T::zero(); 3];
        }
        Ok(())
    }

    /// The limits of the joints a URDF declares, in the model's coordinate
    /// order (its revolute and prismatic joints, continuous and mimic ones
    /// included). Empty by default (a model without a URDF).
    fn joint_limits() -> &'static [JointLimit] {
        &[]
    }

    /// The links of the model's `contact(link, point | flat)` declarations,
    /// in order: [`RowSource::Contact`] rows name them by index. Empty by
    /// default (a model without such contacts).
    fn contact_links() -> &'static [&'static str] {
        &[]
    }

    /// The origin (N components) of every link of
    /// [`Model::contact_links`] at `(q, t)`: where each foot is, for a
    /// touchdown guard. The default serves models without such contacts.
    fn contact_points<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        points: &mut [[T; 3]],
    ) -> Result<(), ModelError> {
        let _ = t;
        check_len("q", q, Self::info().coordinates.len())?;
        check_len("points", points, Self::contact_links().len())
    }

    /// Calls `visitor` with scene `scene` (an index into
    /// [`Model::scene_infos`]) as its own [`Model`] type, so tools that pick
    /// a scene by name at run time can use any generic function on it.
    fn visit_scene<V: SceneVisitor>(
        &self,
        scene: usize,
        visitor: V,
    ) -> Result<V::Output, ModelError> {
        let _ = visitor;
        Err(ModelError::UnknownScene { index: scene })
    }

    /// Load values (N components) at `(q, q̇, t)` and inputs.
    fn load_values<T: Scalar>(
        &self,
        t: T,
        q: &[T],
        qdot: &[T],
        inputs: &[T],
        forces: &mut [[T; 3]],
        torques: &mut [[T; 3]],
    ) -> Result<(), ModelError>;
}

/// A generic operation on a scene, for [`Model::visit_scene`].
pub trait SceneVisitor {
    /// What the operation returns.
    type Output;
    /// Runs the operation on the scene's model.
    fn visit<S: Model>(self, scene: &S) -> Self::Output;
}
