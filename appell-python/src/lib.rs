//! `appell._native`: the source of the appell crates this package compiles
//! models with, embedded when the package was built (see `build.rs`).

use pyo3::prelude::*;
use pyo3::types::PyBytes;

mod carried {
    include!(concat!(env!("OUT_DIR"), "/sources.rs"));
}

/// Every carried file as (path relative to the source tree, contents).
#[pyfunction]
fn sources(py: Python<'_>) -> Vec<(&'static str, Bound<'_, PyBytes>)> {
    carried::SOURCES
        .iter()
        .map(|(path, bytes)| (*path, PyBytes::new(py, bytes)))
        .collect()
}

/// The extension module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(sources, m)?)?;
    m.add("APPELL_HASH", carried::APPELL_HASH)?;
    m.add("GLUE_HASH", carried::GLUE_HASH)?;
    m.add(
        "SOURCE_HASH",
        format!("{}-{}", carried::APPELL_HASH, carried::GLUE_HASH),
    )?;
    m.add("VERSION", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
