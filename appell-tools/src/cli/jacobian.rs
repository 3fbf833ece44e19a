//! The `jacobian` subcommand: A = ∂ẋ/∂x and B = ∂ẋ/∂u of the reduced
//! equations at each state, or of one fixed step x⁺ of RK4 or
//! semi-implicit Euler: by the model's generated `rhs_jacobian` (chained
//! through the step's stages), or by dual numbers through the generated
//! rhs for a model without one.

use super::input::{number, Point};
use appell_core::dynamic::{DynModel, DynRhs};
use appell_core::ModelInfo;
use appell_linearize::discrete::{chained_with, step_with};
use appell_linearize::jacobian::{dual_columns, state_names};
use appell_linearize::FixedStep;
use nalgebra::DMatrix;
use num_dual::Dual64;
use serde_json::{json, Map, Value};

/// The `step` field of a `jacobian` line: `{"method": "rk4" |
/// "semi_implicit_euler", "h": number}`, or `None` without it.
pub(super) fn parse_step(obj: &Map<String, Value>) -> Result<Option<(FixedStep, f64)>, String> {
    let Some(step) = obj.get("step") else {
        return Ok(None);
    };
    let Value::Object(step) = step else {
        return Err("`step` must be an object {\"method\": .., \"h\": ..}".into());
    };
    if let Some(key) = step.keys().find(|k| !["method", "h"].contains(&k.as_str())) {
        return Err(format!(
            "unknown field `{key}` in `step` (expected method, h)"
        ));
    }
    let method = match step.get("method").and_then(Value::as_str) {
        Some("rk4") => FixedStep::Rk4,
        Some("semi_implicit_euler") => FixedStep::SemiImplicitEuler,
        _ => return Err("`step.method` must be \"rk4\" or \"semi_implicit_euler\"".into()),
    };
    let h = number(step.get("h").ok_or("missing `step.h`")?, "`step.h`")?;
    Ok(Some((method, h)))
}

/// `{"state": [..], "inputs": [..], "rates": [..] | "next": [..], "a":
/// [[..]], "b": [[..]]}` for `target` (the model or the scene that answers)
/// at `point`.
pub(super) fn jacobian_answer(
    target: &dyn DynModel,
    info: &ModelInfo,
    point: &Point,
    step: Option<(FixedStep, f64)>,
) -> Result<Map<String, Value>, String> {
    let rhs = target.dyn_prepare();
    let (values, a, b) = if info.jacobian.is_some() {
        generated(rhs.as_ref(), info, point, step)
    } else {
        dual_columns(&point.state, &point.inputs, |x, w| {
            evaluate(rhs.as_ref(), info, point.t, x, w, step)
        })
    }
    .map_err(|e| e.to_string())?;
    if !(a
        .iter()
        .chain(b.iter())
        .chain(&values)
        .all(|v| v.is_finite()))
    {
        return Err("the Jacobian is not finite at this state".into());
    }
    let rows = |m: &DMatrix<f64>| -> Vec<Vec<f64>> {
        m.row_iter().map(|r| r.iter().copied().collect()).collect()
    };
    let (a, b) = (rows(&a), rows(&b));
    let mut answer = Map::new();
    let names = state_names(info);
    answer.insert("state".into(), json!(names));
    answer.insert("inputs".into(), json!(info.inputs));
    match step {
        None => answer.insert("rates".into(), json!(values)),
        Some((method, h)) => {
            let method = match method {
                FixedStep::Rk4 => "rk4",
                FixedStep::SemiImplicitEuler => "semi_implicit_euler",
            };
            answer.insert("step".into(), json!({ "method": method, "h": h }));
            answer.insert("next".into(), json!(values))
        }
    };
    answer.insert("a".into(), json!(a));
    answer.insert("b".into(), json!(b));
    Ok(answer)
}

/// The values (rates or the next state), A and B.
type Columns = (Vec<f64>, DMatrix<f64>, DMatrix<f64>);

/// The rates (or one step) and their Jacobians by the model's generated
/// `rhs_jacobian`, chained through the step's stages.
fn generated(
    rhs: &dyn DynRhs,
    info: &ModelInfo,
    point: &Point,
    step: Option<(FixedStep, f64)>,
) -> Result<Columns, appell_core::ModelError> {
    let (x, w) = (&point.state[..], &point.inputs[..]);
    let (s, ni) = (x.len(), w.len());
    let mut jacobian = |t: f64, y: &[f64], v: &mut [f64], a: &mut [f64], b: &mut [f64]| match rhs
        .generated_jacobian(t, y, w, v, a, b)?
    {
        true => Ok(()),
        false => Err(appell_core::ModelError::NotGenerated {
            function: "rhs_jacobian",
        }),
    };
    match step {
        None => {
            let (mut v, mut a, mut b) = (vec![0.0; s], vec![0.0; s * s], vec![0.0; s * ni]);
            jacobian(point.t, x, &mut v, &mut a, &mut b)?;
            let a = DMatrix::from_row_slice(s, s, &a);
            Ok((v, a, DMatrix::from_row_slice(s, ni, &b)))
        }
        Some((method, h)) => {
            let retained = info.retained.len();
            let mut f = |t: f64, x: &[f64], dx: &mut [f64]| rhs.rhs(t, x, w, dx);
            let next = step_with(&mut f, retained, method, point.t, h, x)?;
            let (a, b) = chained_with(&mut jacobian, retained, method, point.t, h, x, ni)?;
            Ok((next, a, b))
        }
    }
}

/// The rates, or one step, in dual numbers.
fn evaluate(
    rhs: &dyn DynRhs,
    info: &ModelInfo,
    t: f64,
    x: &[Dual64],
    w: &[Dual64],
    step: Option<(FixedStep, f64)>,
) -> Result<Vec<Dual64>, appell_core::ModelError> {
    let t = Dual64::from_re(t);
    match step {
        None => {
            let mut out = vec![Dual64::from_re(0.0); x.len()];
            rhs.rhs_dual(t, x, w, &mut out)?;
            Ok(out)
        }
        Some((method, h)) => {
            let mut f = |t: Dual64, x: &[Dual64], dx: &mut [Dual64]| rhs.rhs_dual(t, x, w, dx);
            let retained = info.retained.len();
            step_with(&mut f, retained, method, t, Dual64::from_re(h), x)
        }
    }
}
