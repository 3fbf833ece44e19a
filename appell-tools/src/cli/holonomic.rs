//! The holonomic constraints of an input state: the coordinates left out
//! of `q` that the constraints fix (a bicycle's pitch) solved from the
//! others, and a warning for a `q` off the constraints. Every action that
//! reads a state (`eval`, `contacts`, `accuracy`, `animate`) goes through
//! here.

use appell_core::dynamic::DynModel;
use appell_linearize::newton_dyn;
use serde_json::{json, Map, Value};

/// How far, relative to 1 + max |q|, a holonomic residual may be from zero
/// before a warning: a thousand times what solving the constraints to
/// round-off leaves.
pub(super) const HOLONOMIC_TOLERANCE: f64 = 1e-9;

/// A second start for Newton's method, for a constraint that is flat at 0
/// in a coordinate it fixes (x² + y² = l² at y = 0).
const SECOND_GUESS: f64 = 0.3;

/// What [`fill_in`] did to `q`.
#[derive(Default)]
pub(super) struct Filled {
    /// The coordinates solved, by name, with their values.
    pub(super) solved: Vec<(&'static str, f64)>,
    /// The largest |holonomic residual| after solving (when something was).
    pub(super) residual: Option<f64>,
    /// The warning of [`warning`], when `q` is off the constraints.
    pub(super) warning: Option<Value>,
}

impl Filled {
    /// `"solved"`, `"residual"` and `"warning"`, those there are, for an
    /// answer object.
    pub(super) fn notes(&self) -> Map<String, Value> {
        let mut out = Map::new();
        if !self.solved.is_empty() {
            let solved: Map<String, Value> = self
                .solved
                .iter()
                .map(|(name, v)| (name.to_string(), json!(v)))
                .collect();
            out.insert("solved".into(), Value::Object(solved));
        }
        if let Some(r) = self.residual {
            out.insert("residual".into(), json!(r));
        }
        if let Some(w) = &self.warning {
            out.insert("warning".into(), w.clone());
        }
        out
    }

    /// The notes as lines of text (for stderr).
    pub(super) fn lines(&self) -> Vec<String> {
        let mut out = Vec::new();
        if !self.solved.is_empty() {
            let solved: Vec<String> = self
                .solved
                .iter()
                .map(|(name, v)| format!("{name} = {v}"))
                .collect();
            out.push(format!(
                "solved from the holonomic constraints: {} (largest residual {:e})",
                solved.join(", "),
                self.residual.unwrap_or(0.0)
            ));
        }
        if let Some(message) = self.warning.as_ref().and_then(|w| w["message"].as_str()) {
            out.push(format!("warning: {message}"));
        }
        out
    }
}

/// Completes `q`, whose entries at `missing` were left out (and are 0):
/// those of them that are dependent coordinates some holonomic constraint
/// of `model` involves are solved from the constraints (Newton from 0, or
/// from [`SECOND_GUESS`] when that fails). A left-out coordinate in
/// `required` (the retained ones) that is not solved this way is an error
/// naming it. Then checks `q` against the constraints.
pub(super) fn fill_in(
    model: &dyn DynModel,
    t: f64,
    q: &mut [f64],
    inputs: &[f64],
    missing: &[usize],
    required: &[usize],
) -> Result<Filled, String> {
    let info = model.dyn_info();
    let candidates: Vec<usize> = missing
        .iter()
        .copied()
        .filter(|&i| info.dependent.contains(&info.coordinates[i]))
        .collect();
    let mut second = q.to_vec();
    for &i in &candidates {
        second[i] = SECOND_GUESS;
    }
    let at_zero =
        newton_dyn::involved(model, t, q, inputs, &candidates).map_err(|e| e.to_string())?;
    let at_second =
        newton_dyn::involved(model, t, &second, inputs, &candidates).unwrap_or_default();
    let union = |a: Vec<usize>, b: Vec<usize>| {
        let mut u: Vec<usize> = a.into_iter().chain(b).collect();
        u.sort_unstable();
        u.dedup();
        u
    };
    let unknowns = union(at_zero.0, at_second.0);
    let rows = union(at_zero.1, at_second.1);
    if let Some(&i) = required
        .iter()
        .find(|i| missing.contains(i) && !unknowns.contains(i))
    {
        let why = if info.holonomic > 0 {
            " (the holonomic constraints do not fix it)"
        } else {
            ""
        };
        return Err(format!(
            "missing coordinate `{}` in `q`{why}",
            info.coordinates[i]
        ));
    }
    let mut filled = Filled::default();
    if !unknowns.is_empty() {
        let first = newton_dyn::solve(model, t, q, inputs, &unknowns, &rows);
        let residual = match first {
            Ok(r) => r,
            Err(first) => {
                q.copy_from_slice(&second);
                newton_dyn::solve(model, t, q, inputs, &unknowns, &rows).map_err(|_| {
                    let names: Vec<String> = unknowns
                        .iter()
                        .map(|&i| format!("`{}`", info.coordinates[i]))
                        .collect();
                    format!(
                        "could not solve the holonomic constraints for {} (left out of `q`): {first}; give {} in `q`",
                        names.join(", "),
                        if names.len() == 1 { "it" } else { "them" }
                    )
                })?
            }
        };
        filled.solved = unknowns
            .iter()
            .map(|&i| (info.coordinates[i], q[i]))
            .collect();
        filled.residual = Some(residual);
    }
    filled.warning = warning(model, t, q, inputs)?;
    Ok(filled)
}

/// A warning when `q` is off a holonomic constraint by more than
/// [`HOLONOMIC_TOLERANCE`] × (1 + max |q|): the answer is still computed,
/// but for a state the mechanism cannot take.
pub(super) fn warning(
    model: &dyn DynModel,
    t: f64,
    q: &[f64],
    inputs: &[f64],
) -> Result<Option<Value>, String> {
    if model.dyn_info().holonomic == 0 {
        return Ok(None);
    }
    let h = newton_dyn::residuals(model, t, q, inputs).map_err(|e| e.to_string())?;
    let scale = 1.0 + q.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let tolerance = HOLONOMIC_TOLERANCE * scale;
    let worst = h
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()));
    Ok(match worst {
        // A NaN residual warns too.
        Some((index, &residual)) if residual.is_nan() || residual.abs() > tolerance => {
            Some(json!({
                "message": format!(
                    "the coordinates violate holonomic constraint {index} by {residual:e} (tolerance {tolerance:e}): the answer is for a state the mechanism cannot take; leave a dependent coordinate out of `q` to have it solved (or solve it with appell::linearize::solve_holonomic)"
                ),
                "holonomic_residuals": h.iter().map(|x| super::output::finite_or_null(*x)).collect::<Vec<_>>(),
            }))
        }
        _ => None,
    })
}
