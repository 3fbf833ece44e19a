//! The `accuracy` subcommand: a work-precision sweep of every integrator.

use super::eval::EvalState;
use super::input::{number, Point};
use super::json::parse_object;
use super::output::finite_or_null;
use crate::accuracy::{standard_methods, Run};
use appell_core::dynamic::{DynModel, DynRhs};
use appell_core::Model;
use serde_json::{json, Value};

/// The largest reduced state `accuracy` handles (the integrators work on
/// fixed-size arrays; the sweep is compiled for every size up to this).
pub const ACCURACY_MAX_STATE: usize = 16;

/// The `accuracy` subcommand: parses one problem (an `eval` object plus
/// `t_end`, and optionally `checkpoints` (default 10), `levels` (default 4)
/// and `repeats` (default 3)), computes the reference and runs
/// [`standard_methods`]`(100, levels)` over it ([`Problem::sweep`](crate::accuracy::Problem::sweep)). Returns
/// the report as one JSON object, or why it could not.
///
/// The report: `{"t_end", "checkpoints", "reference_error", "points": [{"method",
/// "setting", "error_final", "error_max", "seconds", "rhs_calls", "steps"}, ..]}`
/// with the fields of [`crate::accuracy::Point`]; methods that fail (a
/// step-size underflow, say) are left out. Coordinates solved from the
/// holonomic constraints add `"solved"` and `"residual"`, a start off them
/// `"warning"`, as `eval` answers (see [the module](super)).
pub fn accuracy<M: Model>(mut model: M, text: &str) -> Result<Value, String> {
    accuracy_dyn(&mut model, text)
}

/// [`accuracy()`] of any [`DynModel`], compiled once.
pub(super) fn accuracy_dyn(model: &mut dyn DynModel, text: &str) -> Result<Value, String> {
    let obj = parse_object(text)?;
    let evaluator = EvalState::new(model).map_err(|e| e.to_string())?;
    let extra = ["t_end", "checkpoints", "levels", "repeats"];
    let point = evaluator.parse_point(model, &obj, &extra)?;
    if point.t != 0.0 {
        return Err("`t` must be 0 (or omitted): a sweep starts at t = 0".to_string());
    }
    let t_end = match obj.get("t_end") {
        Some(v) => number(v, "`t_end`")?,
        None => return Err("missing field `t_end` (the horizon)".to_string()),
    };
    if t_end <= 0.0 {
        return Err(format!("`t_end` must be positive, not {t_end}"));
    }
    let count = |key: &str, default: usize, max: usize| -> Result<usize, String> {
        match obj.get(key) {
            None => Ok(default),
            Some(v) => match v.as_u64() {
                Some(n) if (1..=max as u64).contains(&n) => Ok(n as usize),
                _ => Err(format!(
                    "`{key}` must be an integer from 1 to {max}, found {v}"
                )),
            },
        }
    };
    let checkpoints = count("checkpoints", 10, 1000)?;
    let levels = count("levels", 4, 10)?;
    let repeats = count("repeats", 3, 100)?;
    let rhs = model.dyn_prepare();
    macro_rules! sizes {
        ($($n:literal)*) => {
            match point.state.len() {
                $($n => sweep_report::<$n>(&*rhs, &point, t_end, checkpoints, levels, repeats),)*
                n => Err(format!(
                    "the reduced state has {n} entries; `accuracy` handles up to {ACCURACY_MAX_STATE}"
                )),
            }
        };
    }
    let mut report = sizes!(1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16)?;
    // What was solved, and whether the start is off the constraints.
    if let Value::Object(fields) = &mut report {
        fields.extend(point.filled.notes());
    }
    Ok(report)
}

fn sweep_report<const S: usize>(
    rhs: &dyn DynRhs,
    point: &Point,
    t_end: f64,
    checkpoints: usize,
    levels: usize,
    repeats: usize,
) -> Result<Value, String> {
    let mut x0 = [0.0; S];
    x0.copy_from_slice(&point.state);
    let problem = Run {
        x0,
        t_end,
        inputs: &point.inputs,
        checkpoints,
    };
    let (reference, estimate) = problem
        .reference(rhs)
        .map_err(|e| format!("the reference integration failed: {e}"))?;
    let points = problem.sweep(
        rhs,
        &reference,
        &standard_methods(100, levels),
        repeats,
        |_, _| {},
    );
    let points: Vec<Value> = points
        .iter()
        .map(|p| {
            json!({
                "method": p.method.name(),
                "setting": p.method.setting(),
                "error_final": finite_or_null(p.error_final),
                "error_max": finite_or_null(p.error_max),
                "seconds": p.seconds,
                "rhs_calls": p.rhs_calls,
                "steps": p.steps,
            })
        })
        .collect();
    Ok(json!({
        "t_end": t_end,
        "checkpoints": checkpoints,
        "reference_error": finite_or_null(estimate),
        "points": points,
    }))
}
