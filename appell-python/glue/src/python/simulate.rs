//! `simulate` from Python: a batch of runs split over threads, or runs that
//! call Python back (an event function, a feedback law) holding the GIL.

use std::cell::RefCell;

use numpy::ndarray::IxDyn;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::prelude::*;

use super::{model_error, split_rows};
use crate::ops::{Evaluate, Failure};
use crate::simulate::{Event, Feedback, Method, SimJob};

/// What every simulation of one `simulate` call shares.
pub(super) struct Settings<'a> {
    pub method: Method,
    pub inputs: &'a [f64],
    pub t0: f64,
    pub t_eval: &'a [f64],
    pub rtol: f64,
    pub atol: f64,
    pub h_max: Option<f64>,
    pub max_steps: usize,
}

impl Settings<'_> {
    /// The job that integrates from `x0` into `out`.
    fn job<'b>(
        &'b self,
        x0: &'b [f64],
        out: &'b mut [f64],
        event: Option<&'b mut Event<'b>>,
        feedback: Option<&'b mut Feedback<'b>>,
    ) -> SimJob<'b> {
        SimJob {
            method: self.method,
            x0,
            inputs: self.inputs,
            feedback,
            t0: self.t0,
            t_eval: self.t_eval,
            rtol: self.rtol,
            atol: self.atol,
            h_max: self.h_max,
            max_steps: self.max_steps,
            out,
            event,
            written: 0,
            event_at: None,
        }
    }
}

/// The initial states: one (`batch` None) or `batch` rows of `s` entries.
pub(super) struct States<'a> {
    pub x0: &'a [f64],
    pub s: usize,
    pub batch: Option<usize>,
}

/// The Python function `law(t, x)` (a float64 array of the inputs) as a
/// [`Feedback`]; an exception it raises is kept in `raised`.
fn feedback_law<'a, 'py>(
    py: Python<'py>,
    law: &'a Bound<'py, PyAny>,
    raised: &'a RefCell<Option<PyErr>>,
) -> impl FnMut(f64, &[f64], &mut [f64]) -> Result<(), String> + use<'a, 'py> {
    move |t, x, inputs| {
        let state = PyArray1::from_slice(py, x);
        let value = law
            .call1((t, state))
            .and_then(|v| v.extract::<PyReadonlyArray1<'py, f64>>());
        let value = match value {
            Ok(v) => v,
            Err(e) => {
                let message = format!("u(t, x) raised at t = {t}: {e}");
                raised.borrow_mut().get_or_insert(e);
                return Err(message);
            }
        };
        let value = value.as_slice().map_err(|e| e.to_string())?;
        if value.len() != inputs.len() {
            return Err(format!(
                "u(t, x) returned {} values at t = {t}; the model has {} inputs",
                value.len(),
                inputs.len()
            ));
        }
        if let Some(bad) = value.iter().position(|v| !v.is_finite()) {
            return Err(format!(
                "u(t, x) returned {} for input {bad} at t = {t}",
                value[bad]
            ));
        }
        inputs.copy_from_slice(value);
        Ok(())
    }
}

/// One run until the Python function `g(t, x)` changes sign: the times
/// reached, the states there, and the event's (t, x) or None.
pub(super) fn simulate_event(
    py: Python<'_>,
    model: &dyn Evaluate,
    scene: Option<usize>,
    settings: &Settings<'_>,
    states: &States<'_>,
    g: Bound<'_, PyAny>,
    feedback: Option<Bound<'_, PyAny>>,
) -> PyResult<PyObject> {
    let (s, times) = (states.s, settings.t_eval);
    if states.batch.is_some() {
        return Err(pyo3::exceptions::PyValueError::new_err(
            "an event function takes one initial state, not a batch",
        ));
    }
    let mut out = vec![0.0; times.len() * s];
    let mut raised: Option<PyErr> = None;
    let mut call = |t: f64, x: &[f64]| -> f64 {
        if raised.is_some() {
            return f64::NAN;
        }
        let state = PyArray1::from_slice(py, x);
        match g.call1((t, state)).and_then(|v| v.extract::<f64>()) {
            Ok(v) => v,
            Err(e) => {
                raised = Some(e);
                f64::NAN
            }
        }
    };
    let law_raised = RefCell::new(None);
    let mut law = feedback.as_ref().map(|f| feedback_law(py, f, &law_raised));
    let law = law.as_mut().map(|f| f as &mut Feedback<'_>);
    let mut job = settings.job(states.x0, &mut out, Some(&mut call), law);
    let result = model.simulate(scene, &mut job);
    let (written, event_at) = (job.written, job.event_at.take());
    if let Some(e) = raised.or(law_raised.borrow_mut().take()) {
        return Err(e);
    }
    result.map_err(|m| model_error(py, format!("simulate: {m}")))?;
    out.truncate(written * s);
    let reached = PyArray1::from_vec(py, out).reshape(IxDyn(&[written, s]))?;
    let at = match event_at {
        Some((t, x)) => (t, PyArray1::from_vec(py, x)).into_pyobject(py)?.into_any(),
        None => py.None().into_bound(py),
    };
    Ok((&times[..written].to_vec(), reached, at)
        .into_pyobject(py)?
        .into_any()
        .unbind())
}

/// One run per initial state: (len(t_eval), s), or (batch, len(t_eval), s).
/// A batch is split over `threads` with the GIL released; with a feedback
/// law, the rows run one after another, calling it.
pub(super) fn simulate_rows(
    py: Python<'_>,
    model: &dyn Evaluate,
    scene: Option<usize>,
    settings: &Settings<'_>,
    states: &States<'_>,
    threads: usize,
    feedback: Option<Bound<'_, PyAny>>,
) -> PyResult<PyObject> {
    let (s, times, batch) = (states.s, settings.t_eval, states.batch);
    let width = times.len() * s;
    let n = batch.unwrap_or(1);
    let mut out = vec![0.0; n * width];
    let result = match &feedback {
        Some(f) => {
            let raised = RefCell::new(None);
            let mut law = feedback_law(py, f, &raised);
            let mut result = Ok(());
            for (row, rows) in out.chunks_exact_mut(width.max(1)).enumerate() {
                let x0 = &states.x0[row * s..(row + 1) * s];
                let mut job = settings.job(x0, rows, None, Some(&mut law));
                if let Err(message) = model.simulate(scene, &mut job) {
                    result = Err(Failure { row, message });
                    break;
                }
            }
            if let Some(e) = raised.borrow_mut().take() {
                return Err(e);
            }
            result
        }
        None => {
            let run = |first: usize, chunk: &mut [f64]| -> Result<(), Failure> {
                for (k, rows) in chunk.chunks_exact_mut(width.max(1)).enumerate() {
                    let row = first + k;
                    let x0 = &states.x0[row * s..(row + 1) * s];
                    let mut job = settings.job(x0, rows, None, None);
                    model
                        .simulate(scene, &mut job)
                        .map_err(|message| Failure { row, message })?;
                }
                Ok(())
            };
            py.allow_threads(|| split_rows(n, width, threads, 1, &mut out, run))
        }
    };
    result.map_err(|f| {
        let message = match batch {
            Some(_) => format!("simulate at row {}: {}", f.row, f.message),
            None => format!("simulate: {}", f.message),
        };
        model_error(py, message)
    })?;
    let shape: Vec<usize> = match batch {
        Some(n) => vec![n, times.len(), s],
        None => vec![times.len(), s],
    };
    Ok(PyArray1::from_vec(py, out)
        .reshape(IxDyn(&shape))?
        .into_any()
        .unbind())
}
