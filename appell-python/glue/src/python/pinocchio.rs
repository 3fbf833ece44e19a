//! A robot's state in Pinocchio's conventions and back, from Python:
//! `appell::pinocchio::PinocchioMap` over rows of NumPy arrays.

use appell::pinocchio::PinocchioMap;
use numpy::ndarray::IxDyn;
use numpy::{PyArray1, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use super::model_error;

/// The conversions between a model's coordinates, speeds, accelerations,
/// forces and mass matrix and Pinocchio's `q`, `v`, `a`, `tau` and `M`
/// (`module.model.pinocchio_map(...)`; wrapped by the package's
/// `appell.PinocchioMap`).
#[pyclass(frozen, module = "appell")]
pub struct NativePinocchioMap {
    pub(super) map: PinocchioMap,
    /// The model's coordinates and speeds.
    pub(super) n: usize,
    pub(super) l: usize,
}

/// A conversion: its arguments' widths and its result's, for a map of
/// `nq`, `nv` and a model of `n` coordinates and `l` speeds.
fn widths(what: &str, n: usize, l: usize, nq: usize, nv: usize) -> Option<(Vec<usize>, usize)> {
    Some(match what {
        "q_to" => (vec![n], nq),
        "q_from" => (vec![nq], n),
        "v_to" | "tau_to" => (vec![n, l], nv),
        "v_from" | "tau_from" => (vec![n, nv], l),
        "a_to" => (vec![n, l, l], nv),
        "a_from" => (vec![n, nv, nv], l),
        "mass_to" => (vec![n, l * l], nv * nv),
        _ => return None,
    })
}

impl NativePinocchioMap {
    /// One row of `what` from `args` into `out`.
    fn row(&self, what: &str, args: &[&[f64]], out: &mut [f64]) -> Result<(), appell::ModelError> {
        let m = &self.map;
        match (what, args) {
            ("q_to", [q]) => m.q_to_pinocchio(q, out),
            ("q_from", [q]) => m.q_from_pinocchio(q, out),
            ("v_to", [q, u]) => m.v_to_pinocchio(q, u, out),
            ("v_from", [q, v]) => m.v_from_pinocchio(q, v, out),
            ("tau_to", [q, tau]) => m.tau_to_pinocchio(q, tau, out),
            ("tau_from", [q, tau]) => m.tau_from_pinocchio(q, tau, out),
            ("a_to", [q, u, u_dot]) => m.a_to_pinocchio(q, u, u_dot, out),
            ("a_from", [q, v, a]) => m.a_from_pinocchio(q, v, a, out),
            ("mass_to", [q, mass]) => m.mass_to_pinocchio(q, mass, out),
            _ => unreachable!("`widths` admits only these"),
        }
    }
}

#[pymethods]
impl NativePinocchioMap {
    /// The length of Pinocchio's `q`.
    #[getter]
    fn nq(&self) -> usize {
        self.map.nq()
    }

    /// The length of Pinocchio's `v`.
    #[getter]
    fn nv(&self) -> usize {
        self.map.nv()
    }

    /// `what` (`q_to`, `q_from`, `v_to`, `v_from`, `a_to`, `a_from`,
    /// `tau_to`, `tau_from`, `mass_to`) on C-contiguous float64 arrays of
    /// one row each, or of N rows each (then N result rows).
    fn convert<'py>(
        &self,
        py: Python<'py>,
        what: &str,
        args: Vec<PyReadonlyArrayDyn<'py, f64>>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (nq, nv) = (self.map.nq(), self.map.nv());
        let (inputs, width) = widths(what, self.n, self.l, nq, nv)
            .ok_or_else(|| PyValueError::new_err(format!("unknown conversion `{what}`")))?;
        if args.len() != inputs.len() {
            return Err(PyValueError::new_err(format!(
                "`{what}` takes {} arrays, not {}",
                inputs.len(),
                args.len()
            )));
        }
        let mut rows: Option<usize> = None;
        let mut slices = Vec::with_capacity(args.len());
        for (k, (a, &w)) in args.iter().zip(&inputs).enumerate() {
            let r = match a.shape() {
                [x] if *x == w => None,
                [r, x] if *x == w => Some(*r),
                shape => {
                    return Err(PyValueError::new_err(format!(
                        "argument {k} of `{what}` has shape {shape:?}; expected ({w},) or (N, {w})"
                    )))
                }
            };
            if let (Some(r), Some(first)) = (r, rows) {
                if r != first {
                    return Err(PyValueError::new_err(format!(
                        "the arguments of `{what}` have {first} and {r} rows"
                    )));
                }
            }
            rows = rows.or(r);
            let slice = a
                .as_slice()
                .map_err(|_| PyValueError::new_err("arrays must be C-contiguous"))?;
            if let Some(bad) = slice.iter().position(|v| !v.is_finite()) {
                return Err(model_error(
                    py,
                    format!("argument {k} of `{what}` has a non-finite entry at {bad}"),
                ));
            }
            slices.push((slice, w, r.is_some()));
        }
        let n = rows.unwrap_or(1);
        let mut out = vec![0.0; n * width];
        for (i, chunk) in out.chunks_exact_mut(width.max(1)).enumerate() {
            let row: Vec<&[f64]> = slices
                .iter()
                .map(|&(s, w, batched)| if batched { &s[i * w..(i + 1) * w] } else { s })
                .collect();
            self.row(what, &row, chunk).map_err(|e| {
                let at = if rows.is_some() {
                    format!(" at row {i}")
                } else {
                    String::new()
                };
                model_error(py, format!("{what}{at}: {e}"))
            })?;
        }
        let shape: Vec<usize> = match rows {
            Some(n) => vec![n, width],
            None => vec![width],
        };
        PyArray1::from_vec(py, out).reshape(IxDyn(&shape))
    }
}
