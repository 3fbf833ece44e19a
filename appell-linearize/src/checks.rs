//! Argument checks shared by the linearizations and the holonomic solves.

use super::error::LinearizeError;
use appell_core::{check_len, ModelError, ModelInfo};

pub(super) fn finite(xs: &[f64], what: &'static str) -> Result<(), ModelError> {
    if xs.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(ModelError::NonFinite { what })
    }
}

/// The index of every coordinate named in `names`.
pub(super) fn indices(
    info: &ModelInfo,
    names: &[&str],
    list: &str,
) -> Result<Vec<usize>, LinearizeError> {
    names
        .iter()
        .map(|name| {
            info.coordinate_index(name).ok_or_else(|| {
                LinearizeError::InvalidInfo(format!("`{name}` in `{list}` is not a coordinate"))
            })
        })
        .collect()
}

/// Checks `t` and a full configuration `q`.
pub(super) fn check_configuration(info: &ModelInfo, t: f64, q: &[f64]) -> Result<(), ModelError> {
    check_len("q", q, info.coordinates.len())?;
    finite(&[t], "t")?;
    finite(q, "q")
}
