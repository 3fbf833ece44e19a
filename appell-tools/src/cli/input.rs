//! Reading the JSON input: an evaluation point and its named numbers.

use super::holonomic::Filled;
use serde_json::Value;

/// A parsed `eval` object.
pub(super) struct Point {
    pub(super) t: f64,
    pub(super) q: Vec<f64>,
    pub(super) u: Vec<f64>,
    pub(super) inputs: Vec<f64>,
    pub(super) state: Vec<f64>,
    /// The coordinates solved from the holonomic constraints, and the
    /// warning when `q` is off them.
    pub(super) filled: Filled,
}

/// A finite JSON number from a value.
pub(super) fn number(v: &Value, what: &str) -> Result<f64, String> {
    match v.as_f64() {
        Some(x) if x.is_finite() => Ok(x),
        Some(_) => Err(format!("{what} is not a finite number")),
        None => Err(format!("{what} must be a number, found {v}")),
    }
}

/// Parses an optional object of named numbers; entry `i` of the result is the
/// value given for `names[i]`.
pub(super) fn named(
    v: Option<&Value>,
    field: &str,
    kind: &str,
    names: &[&str],
) -> Result<Vec<Option<f64>>, String> {
    let mut out = vec![None; names.len()];
    let Some(v) = v else { return Ok(out) };
    let Value::Object(obj) = v else {
        return Err(format!("`{field}` must be an object of {kind} values"));
    };
    for (key, value) in obj {
        let i = names
            .iter()
            .position(|n| n == key)
            .ok_or_else(|| match names.is_empty() {
                // A scene whose effects read no input takes none.
                true => format!("unknown {kind} `{key}` in `{field}`: there are no {field} here"),
                false => format!("unknown {kind} `{key}` in `{field}`"),
            })?;
        out[i] = Some(number(value, &format!("`{field}.{key}`"))?);
    }
    Ok(out)
}
