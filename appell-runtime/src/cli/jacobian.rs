//! The `jacobian` subcommand: A = ∂ẋ/∂x and B = ∂ẋ/∂u of the reduced
//! equations at each state, or of one fixed step x⁺ of RK4 or
//! semi-implicit Euler, by dual numbers through the generated code.

use super::input::{number, Point};
use crate::dynamic::{DynModel, DynRhs};
use crate::linearize::discrete::step_with;
use crate::linearize::FixedStep;
use crate::model::ModelInfo;
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
/// at `point`: one dual pass per state component and input.
pub(super) fn jacobian_answer(
    target: &dyn DynModel,
    info: &ModelInfo,
    point: &Point,
    step: Option<(FixedStep, f64)>,
) -> Result<Map<String, Value>, String> {
    let rhs = target.dyn_prepare();
    let (s, ni) = (point.state.len(), point.inputs.len());
    let dual = |v: &[f64]| -> Vec<Dual64> { v.iter().map(|&x| Dual64::from_re(x)).collect() };
    let (mut x, mut w) = (dual(&point.state), dual(&point.inputs));
    let mut values = Vec::new();
    // One column of (A | B) per pass; a pass without a seed when there is
    // nothing to differentiate, for the values.
    let mut columns: Vec<Vec<f64>> = Vec::with_capacity(s + ni);
    for j in 0..(s + ni).max(1) {
        set_seed(&mut x, &mut w, j, 1.0);
        let out = evaluate(rhs.as_ref(), info, point.t, &x, &w, step);
        set_seed(&mut x, &mut w, j, 0.0);
        let out = out.map_err(|e| e.to_string())?;
        values = out.iter().map(|d| d.re).collect();
        columns.push(out.iter().map(|d| d.eps).collect());
    }
    let block = |cols: std::ops::Range<usize>| -> Vec<Vec<f64>> {
        (0..s)
            .map(|i| cols.clone().map(|j| columns[j][i]).collect())
            .collect()
    };
    let (a, b) = (block(0..s), block(s..s + ni));
    let finite = |m: &[Vec<f64>]| m.iter().flatten().all(|v| v.is_finite());
    if !(finite(&a) && finite(&b) && values.iter().all(|v| v.is_finite())) {
        return Err("the Jacobian is not finite at this state".into());
    }
    let mut answer = Map::new();
    let names: Vec<String> = info
        .retained
        .iter()
        .map(|r| r.to_string())
        .chain(info.speeds.iter().map(|s| format!("{s}_dot")))
        .collect();
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

/// Seeds component `j` of (state, inputs) with `eps` (past both: nothing).
fn set_seed(x: &mut [Dual64], w: &mut [Dual64], j: usize, eps: f64) {
    if let Some(d) = x.get_mut(j) {
        d.eps = eps;
    } else if let Some(d) = w.get_mut(j - x.len()) {
        d.eps = eps;
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
) -> Result<Vec<Dual64>, crate::model::ModelError> {
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
