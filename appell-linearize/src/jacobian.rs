//! A = ∂rhs/∂state and B = ∂rhs/∂inputs of the reduced equations, one
//! [`Dual64`] evaluation per column.

use super::checks::finite;
use appell_core::ModelError;
use appell_core::{check_len, Model, ModelInfo};
use nalgebra::DMatrix;
use num_dual::Dual64;

// Items the documentation links to.
#[cfg(doc)]
use super::minimal_linearization;

/// A linearization `ẋ ≈ f(x0, u0) + A (x − x0) + B (u − u0)` of a model's
/// reduced equations at an operating point `(x0, u0)`. Produced by
/// [`linearize`] and [`minimal_linearization`] (example in the module
/// documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct Linearization {
    /// ∂rhs/∂state, one row and one column per state component.
    pub a: DMatrix<f64>,
    /// ∂rhs/∂inputs, one row per state component, one column per input.
    pub b: DMatrix<f64>,
    /// The state components, in order: coordinate names, then the
    /// privileged speeds as `"{coordinate}_dot"`.
    pub state_names: Vec<String>,
    /// The inputs, in [`ModelInfo::inputs`] order.
    pub input_names: Vec<String>,
}

/// The names of the reduced state: the retained coordinates, then the
/// privileged speeds suffixed `_dot`.
pub fn state_names(info: &ModelInfo) -> Vec<String> {
    info.retained
        .iter()
        .map(|r| r.to_string())
        .chain(info.speeds.iter().map(|s| format!("{s}_dot")))
        .collect()
}

/// A = ∂rhs/∂state and B = ∂rhs/∂inputs of the reduced equations
/// ([`Model::rhs`], after [`Model::prepare`]) at time `t`, reduced `state`
/// (the [retained](ModelInfo::retained) coordinates, then the privileged
/// speeds) and `inputs`.
///
/// Where the model has a generated Jacobian ([`ModelInfo::jacobian`]) it is
/// one call of [`Model::rhs_jacobian`]; else each column is one evaluation
/// of the generated code in [`Dual64`], seeded on that state component or
/// input. Either way the derivatives are exact to rounding.
/// The operating point need not be an equilibrium (A and B are the Jacobians
/// there; the affine term is `rhs(t, state, inputs)`). The state names are
/// the retained coordinates, then the speeds' coordinates suffixed `_dot`.
///
/// Errors: wrong lengths ([`ModelError::Length`]), a non-finite argument or
/// derivative ([`ModelError::NonFinite`]), and any error of
/// [`Model::rhs`] at this point (a singular configuration). Example in the
/// module documentation.
pub fn linearize<M: Model>(
    model: &M,
    t: f64,
    state: &[f64],
    inputs: &[f64],
) -> Result<Linearization, ModelError> {
    let info = M::info();
    let (s, ni) = checked_point(model, t, state, inputs)?;
    if info.jacobian.is_none() {
        return dual_columns_of(model, t, state, inputs);
    }
    let (mut values, mut a, mut b) = (vec![0.0; s], vec![0.0; s * s], vec![0.0; s * ni]);
    model.rhs_jacobian(t, state, inputs, &mut values, &mut a, &mut b)?;
    Ok(linearization(
        info,
        DMatrix::from_row_slice(s, s, &a),
        DMatrix::from_row_slice(s, ni, &b),
    ))
}

/// [`linearize`] by dual numbers through the generated rhs whether or not
/// the model has a generated Jacobian: one [`Dual64`] evaluation of
/// [`Model::rhs`] per state component and input. A check on
/// [`Model::rhs_jacobian`], and what [`linearize`] does for a model
/// without one. Errors as [`linearize`]'s.
///
/// ```
/// use appell_linearize::{dual_linearize, linearize};
/// # use appell_core::__doc_model::Oscillator;
/// let model = Oscillator { w: 2.0 };
/// let dual = dual_linearize(&model, 0.0, &[0.1, 0.0], &[]).unwrap();
/// assert_eq!(dual.a[(1, 0)], -4.0);
/// assert_eq!(dual, linearize(&model, 0.0, &[0.1, 0.0], &[]).unwrap());
/// ```
pub fn dual_linearize<M: Model>(
    model: &M,
    t: f64,
    state: &[f64],
    inputs: &[f64],
) -> Result<Linearization, ModelError> {
    checked_point(model, t, state, inputs)?;
    dual_columns_of(model, t, state, inputs)
}

/// Checks the lengths and finiteness of a point and the model's
/// parameters; returns the state's and the inputs' lengths.
fn checked_point<M: Model>(
    model: &M,
    t: f64,
    state: &[f64],
    inputs: &[f64],
) -> Result<(usize, usize), ModelError> {
    let info = M::info();
    let (s, ni) = (info.state_len(), info.inputs.len());
    check_len("state", state, s)?;
    check_len("inputs", inputs, ni)?;
    finite(&[t], "t")?;
    finite(state, "state")?;
    finite(inputs, "inputs")?;
    model.validate()?;
    Ok((s, ni))
}

/// A and B by one [`Dual64`] evaluation of the rhs per column, at a
/// checked point.
fn dual_columns_of<M: Model>(
    model: &M,
    t: f64,
    state: &[f64],
    inputs: &[f64],
) -> Result<Linearization, ModelError> {
    let s = state.len();
    let prepared = model.prepare::<Dual64>();
    let td = Dual64::from_re(t);
    let (_, a, b) = dual_columns(state, inputs, |x, w| {
        let mut out = vec![Dual64::from_re(0.0); s];
        model.rhs(&prepared, td, x, w, &mut out).map(|()| out)
    })?;
    finite(a.as_slice(), "the state Jacobian")?;
    finite(b.as_slice(), "the input Jacobian")?;
    Ok(linearization(M::info(), a, b))
}

/// A and B with the model's state and input names.
fn linearization(info: &ModelInfo, a: DMatrix<f64>, b: DMatrix<f64>) -> Linearization {
    Linearization {
        a,
        b,
        state_names: state_names(info),
        input_names: info.inputs.iter().map(|s| s.to_string()).collect(),
    }
}

/// The values of y = f(x, u) (as many components as x) at (`state`,
/// `inputs`), with A = ∂y/∂x and B = ∂y/∂u: one [`Dual64`] evaluation of
/// `f` per column, seeded on that component of x or u (one unseeded
/// evaluation when there is none, so that its error is still reported).
/// The Jacobians of the rhs, of a step and of the command line's answers.
#[allow(clippy::type_complexity)] // (values, A, B)
pub fn dual_columns<E>(
    state: &[f64],
    inputs: &[f64],
    mut f: impl FnMut(&[Dual64], &[Dual64]) -> Result<Vec<Dual64>, E>,
) -> Result<(Vec<f64>, DMatrix<f64>, DMatrix<f64>), E> {
    let (s, ni) = (state.len(), inputs.len());
    let mut x: Vec<Dual64> = state.iter().map(|&v| Dual64::from_re(v)).collect();
    let mut w: Vec<Dual64> = inputs.iter().map(|&v| Dual64::from_re(v)).collect();
    let mut a = DMatrix::<f64>::zeros(s, s);
    let mut b = DMatrix::<f64>::zeros(s, ni);
    let mut values = Vec::new();
    for j in 0..(s + ni).max(1) {
        let seed = |x: &mut [Dual64], w: &mut [Dual64], eps: f64| {
            if j < s {
                x[j].eps = eps;
            } else if j - s < ni {
                w[j - s].eps = eps;
            }
        };
        seed(&mut x, &mut w, 1.0);
        let out = f(&x, &w);
        seed(&mut x, &mut w, 0.0);
        let out = out?;
        for (i, o) in out.iter().enumerate().take(s) {
            if j < s {
                a[(i, j)] = o.eps;
            } else if j - s < ni {
                b[(i, j - s)] = o.eps;
            }
        }
        values = out.iter().map(|o| o.re).collect();
    }
    Ok((values, a, b))
}
