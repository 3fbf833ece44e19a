//! One fixed step of the integrator a controller loop runs, as a
//! discrete-time map x⁺ = Φ(t, x, u) of the reduced state, and its
//! Jacobians ∂x⁺/∂x and ∂x⁺/∂u in one call: what a discrete-time MPC or
//! DDP solver linearizes at every knot.
//!
//! The Jacobians are those of the map the controller integrates, exact to
//! rounding (no finite differences, and no continuous-time Jacobian turned
//! discrete by an approximation): where the model has a generated
//! [`Model::rhs_jacobian`], [`step_jacobian`] carries each stage's A and B
//! through the step by the chain rule; elsewhere it runs the very step
//! [`fixed_step`] takes (written once over any [`Scalar`]) in [`Dual64`],
//! one pass per state component and input.

use nalgebra::DMatrix;
use num_dual::Dual64;

use super::checks::finite;
use super::jacobian::{dual_columns, state_names};
use appell_core::Scalar;
use appell_core::{check_len, Model, ModelError};

/// A fixed-step method of a controller loop.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FixedStep {
    /// The classical fourth-order Runge–Kutta step, the inputs held over
    /// it: the same arithmetic as [`rk4_step`](appell_integrate::rk4_step).
    Rk4,
    /// Semi-implicit (symplectic) Euler: the speeds first, u⁺ = u + h u̇(t,
    /// q, u), then the retained coordinates at the new speeds, q⁺ = q + h
    /// q̇(t, q, u⁺) (both rates from [`Model::rhs`] at the step's start
    /// time).
    SemiImplicitEuler,
}

/// One step x⁺ of `method` of size `h` from time `t` and reduced `state`
/// (the retained coordinates, then the privileged speeds), the `inputs`
/// held over the step, in any scalar.
///
/// Errors: wrong lengths ([`ModelError::Length`]), any error of
/// [`Model::rhs`] on the way, and [`ModelError::NonFinite`] `{ what:
/// "state" }` when x⁺ is not finite.
///
/// ```
/// use appell_linearize::{fixed_step, FixedStep};
/// # use appell_core::{check_len, BodyInfo, Model, ModelError, ModelInfo, OpCounts, Scalar};
/// # struct Pendulum { g: f64 }
/// # static INFO: ModelInfo = ModelInfo {
/// #     name: "Pendulum", parameters: &["g"], coordinates: &["theta"],
/// #     speeds: &["theta"], dependent: &[], cyclic: &[], ignorable: &[],
/// #     retained: &["theta"], inputs: &["tau"], effects: &["gravity", "motor"], outputs: &[], row_sources: &[], contacts: &[], holonomic: 0,
/// #     constraints: 0, bodies: &[BodyInfo { name: "bob", rigid: false }],
/// #     force_points: 1, torques: 1, form: "closed form", symbolic_elimination: true,
/// #     rhs_ops: OpCounts { add: 1, mul: 1, div: 0, calls: 1, total: 3 },
/// #     jacobian: None,
/// #     equations: "theta'' = tau - g sin(theta)",
/// # };
/// # fn unused() -> Result<(), ModelError> { Err(ModelError::NonFinite { what: "unused" }) }
/// # impl Model for Pendulum {
/// #     type Prepared<T: Scalar> = ();
/// #     fn info() -> &'static ModelInfo { &INFO }
/// #     fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> {
/// #         check_len("out", out, 1)?; out[0] = self.g; Ok(())
/// #     }
/// #     fn set_parameter(&mut self, _: &str, _: f64) -> bool { false }
/// #     fn prepare<T: Scalar>(&self) {}
/// #     fn rhs<T: Scalar>(&self, _: &(), _t: T, s: &[T], i: &[T], ds: &mut [T]) -> Result<(), ModelError> {
/// #         check_len("state", s, 2)?; check_len("inputs", i, 1)?; check_len("dstate", ds, 2)?;
/// #         ds[0] = s[1]; ds[1] = i[0] - T::from_f64(self.g) * s[0].sin(); Ok(())
/// #     }
/// #     fn constraint_residuals<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn mass_matrix_and_forcing<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn speed_transform<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn coordinate_rates<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn kinetic_energy<T: Scalar>(&self, _: T, _: &[T], _: &[T]) -> Result<T, ModelError> { unused().map(|_| T::zero()) }
/// #     fn mass_properties(&self, _: &mut [f64], _: &mut [[f64; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn body_poses<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn constraint_rows<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn load_geometry<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn load_values<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [[T; 3]], _: &mut [[T; 3]]) -> Result<(), ModelError> { unused() }
/// # }
/// // θ̈ = τ − g sin θ, one semi-implicit Euler step: the speed first, then
/// // the angle at the new speed.
/// let model = Pendulum { g: 9.81 };
/// let (h, x, tau) = (0.01, [0.5, 0.2], [0.3]);
/// let next = fixed_step(&model, &(), FixedStep::SemiImplicitEuler, 0.0, h, &x, &tau).unwrap();
/// let speed = 0.2 + h * (0.3 - 9.81 * 0.5_f64.sin());
/// assert_eq!(next, [0.5 + h * speed, speed]);
/// ```
pub fn fixed_step<M: Model, T: Scalar>(
    model: &M,
    prepared: &M::Prepared<T>,
    method: FixedStep,
    t: T,
    h: T,
    state: &[T],
    inputs: &[T],
) -> Result<Vec<T>, ModelError> {
    let info = M::info();
    check_len("state", state, info.state_len())?;
    check_len("inputs", inputs, info.inputs.len())?;
    let mut f = |t: T, x: &[T], dx: &mut [T]| model.rhs(prepared, t, x, inputs, dx);
    step_with(&mut f, info.retained.len(), method, t, h, state)
}

/// One step of `method` of `dx/dt = f(t, x)` from (`t`, `x`), whose first
/// `retained` components are coordinates and the rest speeds; x⁺ checked
/// to be finite. What [`fixed_step`] takes for a model, and the command
/// line for a `dyn` one.
pub fn step_with<T: Scalar>(
    f: &mut impl FnMut(T, &[T], &mut [T]) -> Result<(), ModelError>,
    retained: usize,
    method: FixedStep,
    t: T,
    h: T,
    x: &[T],
) -> Result<Vec<T>, ModelError> {
    let next = match method {
        FixedStep::Rk4 => rk4(f, t, h, x)?,
        FixedStep::SemiImplicitEuler => semi_implicit_euler(f, retained, t, h, x)?,
    };
    if next.iter().all(|v| v.re().is_finite()) {
        Ok(next)
    } else {
        Err(ModelError::NonFinite { what: "state" })
    }
}

/// The classical RK4 step, in the order of operations of
/// [`rk4_step_fn`](appell_integrate::rk4_step_fn).
fn rk4<T: Scalar>(
    f: &mut impl FnMut(T, &[T], &mut [T]) -> Result<(), ModelError>,
    t: T,
    h: T,
    x: &[T],
) -> Result<Vec<T>, ModelError> {
    let (half, sixth, two) = (T::from_f64(0.5), T::from_f64(1.0 / 6.0), T::from_f64(2.0));
    let half_h = h * half;
    let t_mid = t + half_h;
    let s = x.len();
    let mut k = vec![T::zero(); 4 * s];
    let (k1, rest) = k.split_at_mut(s);
    let (k2, rest) = rest.split_at_mut(s);
    let (k3, k4) = rest.split_at_mut(s);
    let mut y = vec![T::zero(); s];
    f(t, x, k1)?;
    for i in 0..s {
        y[i] = x[i] + half_h * k1[i];
    }
    f(t_mid, &y, k2)?;
    for i in 0..s {
        y[i] = x[i] + half_h * k2[i];
    }
    f(t_mid, &y, k3)?;
    for i in 0..s {
        y[i] = x[i] + h * k3[i];
    }
    f(t + h, &y, k4)?;
    Ok((0..s)
        .map(|i| x[i] + h * sixth * (k1[i] + two * (k2[i] + k3[i]) + k4[i]))
        .collect())
}

/// The semi-implicit Euler step: the speeds (after the first `retained`
/// components) first, then the coordinates at the new speeds.
fn semi_implicit_euler<T: Scalar>(
    f: &mut impl FnMut(T, &[T], &mut [T]) -> Result<(), ModelError>,
    retained: usize,
    t: T,
    h: T,
    x: &[T],
) -> Result<Vec<T>, ModelError> {
    let mut rates = vec![T::zero(); x.len()];
    f(t, x, &mut rates)?;
    let mut next = x.to_vec();
    for i in retained..x.len() {
        next[i] = x[i] + h * rates[i];
    }
    let mut at_new_speeds = x.to_vec();
    at_new_speeds[retained..].copy_from_slice(&next[retained..]);
    f(t, &at_new_speeds, &mut rates)?;
    for i in 0..retained {
        next[i] = x[i] + h * rates[i];
    }
    Ok(next)
}

/// One fixed step x⁺ = Φ(t, x, u) and its Jacobians. Produced by
/// [`step_jacobian`].
#[derive(Clone, Debug, PartialEq)]
pub struct StepLinearization {
    /// x⁺, as [`fixed_step`] gives it in `f64`.
    pub next: Vec<f64>,
    /// ∂x⁺/∂x, one row per component of x⁺, one column per component of x.
    pub a: DMatrix<f64>,
    /// ∂x⁺/∂u, one row per component of x⁺, one column per input.
    pub b: DMatrix<f64>,
    /// The state components: the retained coordinates, then the privileged
    /// speeds as `"{coordinate}_dot"` (as [`Linearization`](super::Linearization)).
    pub state_names: Vec<String>,
    /// The inputs, in [`ModelInfo::inputs`](appell_core::ModelInfo::inputs) order.
    pub input_names: Vec<String>,
}

/// x⁺ of one step of `method` of size `h` from (`t`, `state`) with `inputs`
/// held over it, with A = ∂x⁺/∂x and B = ∂x⁺/∂u: the step taken again in
/// [`Dual64`] once per state component and input.
///
/// Errors: wrong lengths ([`ModelError::Length`]), a non-finite `t`, `h`,
/// state, input or derivative ([`ModelError::NonFinite`]), an invalid
/// model ([`Model::validate`]), and any error of the step.
///
/// ```
/// # use appell_core::{check_len, BodyInfo, Model, ModelError, ModelInfo, OpCounts, Scalar};
/// # struct Pendulum { g: f64 }
/// # static INFO: ModelInfo = ModelInfo {
/// #     name: "Pendulum", parameters: &["g"], coordinates: &["theta"],
/// #     speeds: &["theta"], dependent: &[], cyclic: &[], ignorable: &[],
/// #     retained: &["theta"], inputs: &["tau"], effects: &["gravity", "motor"], outputs: &[], row_sources: &[], contacts: &[], holonomic: 0,
/// #     constraints: 0, bodies: &[BodyInfo { name: "bob", rigid: false }],
/// #     force_points: 1, torques: 1, form: "closed form", symbolic_elimination: true,
/// #     rhs_ops: OpCounts { add: 1, mul: 1, div: 0, calls: 1, total: 3 },
/// #     jacobian: None,
/// #     equations: "theta'' = tau - g sin(theta)",
/// # };
/// # fn unused() -> Result<(), ModelError> { Err(ModelError::NonFinite { what: "unused" }) }
/// # impl Model for Pendulum {
/// #     type Prepared<T: Scalar> = ();
/// #     fn info() -> &'static ModelInfo { &INFO }
/// #     fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> {
/// #         check_len("out", out, 1)?; out[0] = self.g; Ok(())
/// #     }
/// #     fn set_parameter(&mut self, _: &str, _: f64) -> bool { false }
/// #     fn prepare<T: Scalar>(&self) {}
/// #     fn rhs<T: Scalar>(&self, _: &(), _t: T, s: &[T], i: &[T], ds: &mut [T]) -> Result<(), ModelError> {
/// #         check_len("state", s, 2)?; check_len("inputs", i, 1)?; check_len("dstate", ds, 2)?;
/// #         ds[0] = s[1]; ds[1] = i[0] - T::from_f64(self.g) * s[0].sin(); Ok(())
/// #     }
/// #     fn constraint_residuals<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn mass_matrix_and_forcing<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn speed_transform<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn coordinate_rates<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn kinetic_energy<T: Scalar>(&self, _: T, _: &[T], _: &[T]) -> Result<T, ModelError> { unused().map(|_| T::zero()) }
/// #     fn mass_properties(&self, _: &mut [f64], _: &mut [[f64; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn body_poses<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn constraint_rows<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn load_geometry<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn load_values<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [[T; 3]], _: &mut [[T; 3]]) -> Result<(), ModelError> { unused() }
/// # }
/// use appell_linearize::{step_jacobian, FixedStep};
///
/// // The pendulum θ̈ = τ − g sin θ, one semi-implicit Euler step:
/// // ω⁺ = ω + h (τ − g sin θ), θ⁺ = θ + h ω⁺.
/// let (g, h, theta) = (9.81, 0.01, 0.5_f64);
/// let model = Pendulum { g };
/// let step = step_jacobian(&model, FixedStep::SemiImplicitEuler, 0.0, h, &[theta, 0.2], &[0.3]).unwrap();
/// let dw_dtheta = -h * g * theta.cos();
/// assert!((step.a[(1, 0)] - dw_dtheta).abs() < 1e-15);
/// assert!((step.a[(0, 0)] - (1.0 + h * dw_dtheta)).abs() < 1e-15);
/// assert!((step.a[(0, 1)] - h).abs() < 1e-15 && (step.a[(1, 1)] - 1.0).abs() < 1e-15);
/// assert!((step.b[(1, 0)] - h).abs() < 1e-15 && (step.b[(0, 0)] - h * h).abs() < 1e-15);
///
/// // Bad input is a typed error.
/// assert!(step_jacobian(&model, FixedStep::Rk4, 0.0, f64::NAN, &[theta, 0.2], &[0.3]).is_err());
/// assert!(step_jacobian(&model, FixedStep::Rk4, 0.0, h, &[theta], &[0.3]).is_err());
/// ```
pub fn step_jacobian<M: Model>(
    model: &M,
    method: FixedStep,
    t: f64,
    h: f64,
    state: &[f64],
    inputs: &[f64],
) -> Result<StepLinearization, ModelError> {
    let info = M::info();
    let (s, ni) = (info.state_len(), info.inputs.len());
    check_len("state", state, s)?;
    check_len("inputs", inputs, ni)?;
    finite(&[t], "t")?;
    finite(&[h], "h")?;
    finite(state, "state")?;
    finite(inputs, "inputs")?;
    model.validate()?;
    let next = fixed_step(model, &model.prepare::<f64>(), method, t, h, state, inputs)?;

    if info.jacobian.is_some() {
        let (a, b) = chained(model, method, t, h, state, inputs)?;
        finite(a.as_slice(), "the state Jacobian")?;
        finite(b.as_slice(), "the input Jacobian")?;
        return Ok(StepLinearization {
            next,
            a,
            b,
            state_names: state_names(info),
            input_names: info.inputs.iter().map(|s| s.to_string()).collect(),
        });
    }
    let prepared = model.prepare::<Dual64>();
    let (td, hd) = (Dual64::from_re(t), Dual64::from_re(h));
    let (_, a, b) = dual_columns(state, inputs, |x, w| {
        fixed_step(model, &prepared, method, td, hd, x, w)
    })?;
    finite(a.as_slice(), "the state Jacobian")?;
    finite(b.as_slice(), "the input Jacobian")?;
    Ok(StepLinearization {
        next,
        a,
        b,
        state_names: state_names(info),
        input_names: info.inputs.iter().map(|s| s.to_string()).collect(),
    })
}

/// ∂x⁺/∂x and ∂x⁺/∂u of one step by the chain rule through its stages,
/// each stage's A and B from the model's generated
/// [`Model::rhs_jacobian`] (the inputs held over the step).
fn chained<M: Model>(
    model: &M,
    method: FixedStep,
    t: f64,
    h: f64,
    x: &[f64],
    w: &[f64],
) -> Result<(DMatrix<f64>, DMatrix<f64>), ModelError> {
    let mut jacobian = |t: f64, y: &[f64], v: &mut [f64], a: &mut [f64], b: &mut [f64]| {
        model.rhs_jacobian(t, y, w, v, a, b)
    };
    let retained = M::info().retained.len();
    chained_with(&mut jacobian, retained, method, t, h, x, w.len())
}

/// A generated rhs Jacobian at `(t, y)` with the inputs held: the rates,
/// A and B (row-major) into the buffers.
pub type StageJacobian<'a> =
    dyn FnMut(f64, &[f64], &mut [f64], &mut [f64], &mut [f64]) -> Result<(), ModelError> + 'a;

/// `chained` for any source of stage Jacobians (`retained` coordinates
/// lead the state, `ni` inputs): what the command line calls on a model
/// it knows as a trait object.
pub fn chained_with(
    jacobian: &mut StageJacobian<'_>,
    retained: usize,
    method: FixedStep,
    t: f64,
    h: f64,
    x: &[f64],
    ni: usize,
) -> Result<(DMatrix<f64>, DMatrix<f64>), ModelError> {
    let s = x.len();
    let mut eval = |t: f64, y: &[f64]| -> Result<Stage, ModelError> {
        let (mut v, mut a, mut b) = (vec![0.0; s], vec![0.0; s * s], vec![0.0; s * ni]);
        jacobian(t, y, &mut v, &mut a, &mut b)?;
        Ok(Stage {
            rates: v,
            a: DMatrix::from_row_slice(s, s, &a),
            b: DMatrix::from_row_slice(s, ni, &b),
        })
    };
    let id = DMatrix::<f64>::identity(s, s);
    let along = |y: &[f64], k: &[f64], c: f64| -> Vec<f64> {
        y.iter().zip(k).map(|(y, k)| y + c * k).collect()
    };
    match method {
        FixedStep::Rk4 => {
            let half = 0.5 * h;
            // Stage i: k_i = f(y_i), ∂k_i = A_i ∂y_i (+ B_i for the inputs).
            let k1 = eval(t, x)?;
            let k2 = eval(t + half, &along(x, &k1.rates, half))?;
            let (k2x, k2u) = (&k2.a * (&id + &k1.a * half), &k2.a * (&k1.b * half) + &k2.b);
            let k3 = eval(t + half, &along(x, &k2.rates, half))?;
            let (k3x, k3u) = (&k3.a * (&id + &k2x * half), &k3.a * (&k2u * half) + &k3.b);
            let k4 = eval(t + h, &along(x, &k3.rates, h))?;
            let (k4x, k4u) = (&k4.a * (&id + &k3x * h), &k4.a * (&k3u * h) + &k4.b);
            let sixth = h / 6.0;
            Ok((
                &id + (&k1.a + (k2x + k3x) * 2.0 + k4x) * sixth,
                (&k1.b + (k2u + k3u) * 2.0 + k4u) * sixth,
            ))
        }
        FixedStep::SemiImplicitEuler => {
            let r = retained;
            // The speeds first: u⁺ = u + h u̇(x); y = (q, u⁺).
            let first = eval(t, x)?;
            let mut y = x.to_vec();
            let (mut dy_x, mut dy_u) = (id.clone(), DMatrix::<f64>::zeros(s, ni));
            for i in r..s {
                y[i] = x[i] + h * first.rates[i];
                for j in 0..s {
                    dy_x[(i, j)] += h * first.a[(i, j)];
                }
                for j in 0..ni {
                    dy_u[(i, j)] = h * first.b[(i, j)];
                }
            }
            // Then the coordinates at the new speeds: q⁺ = q + h q̇(y).
            let second = eval(t, &y)?;
            let (through_x, through_u) = (&second.a * &dy_x, &second.a * &dy_u + &second.b);
            let (mut ax, mut bu) = (dy_x, dy_u);
            for i in 0..r {
                for j in 0..s {
                    ax[(i, j)] = id[(i, j)] + h * through_x[(i, j)];
                }
                for j in 0..ni {
                    bu[(i, j)] = h * through_u[(i, j)];
                }
            }
            Ok((ax, bu))
        }
    }
}

/// One stage's rates and their Jacobians.
struct Stage {
    rates: Vec<f64>,
    a: DMatrix<f64>,
    b: DMatrix<f64>,
}
