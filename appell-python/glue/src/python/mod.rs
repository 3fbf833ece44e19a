//! The Python class of a compiled model: NumPy arrays in, NumPy arrays out,
//! batches split over threads with the GIL released.

use std::sync::{Arc, RwLock};

use appell::pinocchio::PinocchioMap;
use appell::{Model, ModelInfo};
use numpy::ndarray::IxDyn;
use numpy::{PyArray1, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::ops::{held_feet, Arg, Compiled, Evaluate, Failure, Op};
use crate::simulate::Method;

mod pinocchio;
mod simulate;
use pinocchio::NativePinocchioMap;
use simulate::{simulate_event, simulate_rows, Settings, States};

/// The model a compiled module exports (`module.model`), wrapped by the
/// Python package's `appell.Model`, which checks shapes and names.
#[pyclass(frozen, module = "appell")]
pub struct NativeModel {
    current: RwLock<Arc<dyn Evaluate>>,
}

/// Adds `model` (a [`NativeModel`] of `M::default()`) and `abi` to a
/// compiled model's module.
pub fn register<M>(module: &Bound<'_, PyModule>) -> PyResult<()>
where
    M: Model + Default + Clone + Send + Sync + 'static,
    M::Prepared<f64>: Send + Sync,
{
    let native = NativeModel {
        current: RwLock::new(Arc::new(Compiled::new(M::default()))),
    };
    module.add("model", native)?;
    module.add("abi", crate::ABI_VERSION)?;
    Ok(())
}

/// `appell.errors.ModelError(message)`: the package's exception for a
/// model that cannot be evaluated where it was asked to be.
pub(crate) fn model_error(py: Python<'_>, message: String) -> PyErr {
    match py
        .import("appell.errors")
        .and_then(|m| m.getattr("ModelError"))
        .and_then(|cls| cls.call1((message.clone(),)))
    {
        Ok(value) => PyErr::from_value(value),
        Err(_) => PyRuntimeError::new_err(message),
    }
}

fn failure(py: Python<'_>, f: Failure, batched: bool, op: Op) -> PyErr {
    let message = if batched {
        format!("{} at row {}: {}", op.name(), f.row, f.message)
    } else {
        format!("{}: {}", op.name(), f.message)
    };
    model_error(py, message)
}

/// The model's rhs at one state `xs` (of the reduced state's length) and
/// inputs `us` (of the inputs' number), as `rhs1` and `rhs_fast` call it.
fn one_rhs(
    py: Python<'_>,
    model: &dyn Evaluate,
    t: f64,
    xs: &[f64],
    us: &[f64],
) -> PyResult<Vec<f64>> {
    let mut out = vec![0.0; xs.len()];
    let args = [
        Arg {
            data: xs,
            len: xs.len(),
            batched: false,
        },
        Arg {
            data: us,
            len: us.len(),
            batched: false,
        },
    ];
    model
        .rows(None, Op::Rhs, t, &args, &mut out, 0)
        .map_err(|f| failure(py, f, false, Op::Rhs))?;
    Ok(out)
}

/// Splits `rows` rows of `width` results over up to `threads` threads
/// (one row per thread at least `min_rows` rows), the first failure by row
/// returned.
pub(crate) fn split_rows<F>(
    rows: usize,
    width: usize,
    threads: usize,
    min_rows: usize,
    out: &mut [f64],
    f: F,
) -> Result<(), Failure>
where
    F: Fn(usize, &mut [f64]) -> Result<(), Failure> + Sync,
{
    let threads = threads.max(1).min(rows / min_rows.max(1)).max(1);
    if threads == 1 || width == 0 {
        return f(0, out);
    }
    let per = rows.div_ceil(threads);
    std::thread::scope(|scope| {
        let f = &f;
        let handles: Vec<_> = out
            .chunks_mut(per * width)
            .enumerate()
            .map(|(k, chunk)| scope.spawn(move || f(k * per, chunk)))
            .collect();
        let mut first: Option<Failure> = None;
        for (k, handle) in handles.into_iter().enumerate() {
            let result = handle.join().unwrap_or_else(|_| {
                Err(Failure {
                    row: k * per,
                    message: "internal error: a thread panicked".into(),
                })
            });
            if let Err(e) = result {
                if first.as_ref().is_none_or(|f| e.row < f.row) {
                    first = Some(e);
                }
            }
        }
        first.map_or(Ok(()), Err)
    })
}

fn names(py: Python<'_>, list: &[&str]) -> PyResult<Py<PyList>> {
    Ok(PyList::new(py, list)?.unbind())
}

fn info_dict<'py>(py: Python<'py>, info: &ModelInfo) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("name", info.name)?;
    d.set_item("parameters", names(py, info.parameters)?)?;
    d.set_item("coordinates", names(py, info.coordinates)?)?;
    d.set_item("speeds", names(py, info.speeds)?)?;
    d.set_item("dependent", names(py, info.dependent)?)?;
    d.set_item("cyclic", names(py, info.cyclic)?)?;
    d.set_item("ignorable", names(py, info.ignorable)?)?;
    d.set_item("retained", names(py, info.retained)?)?;
    let state: Vec<String> = info.state_names().map(|n| n.to_string()).collect();
    d.set_item("state", state)?;
    d.set_item("state_len", info.state_len())?;
    d.set_item("inputs", names(py, info.inputs)?)?;
    d.set_item("effects", names(py, info.effects)?)?;
    d.set_item("outputs", names(py, info.outputs)?)?;
    d.set_item("holonomic", info.holonomic)?;
    d.set_item("constraints", info.constraints)?;
    let bodies: Vec<&str> = info.bodies.iter().map(|b| b.name).collect();
    d.set_item("bodies", bodies)?;
    d.set_item("form", info.form)?;
    d.set_item("symbolic_elimination", info.symbolic_elimination)?;
    let ops = |o: appell::OpCounts| -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("add", o.add)?;
        d.set_item("mul", o.mul)?;
        d.set_item("div", o.div)?;
        d.set_item("calls", o.calls)?;
        d.set_item("total", o.total)?;
        Ok(d)
    };
    d.set_item("rhs_ops", ops(info.rhs_ops)?)?;
    match info.jacobian {
        Some(j) => {
            let jd = PyDict::new(py);
            jd.set_item("form", j.form)?;
            jd.set_item("ops", ops(j.ops)?)?;
            d.set_item("jacobian", jd)?;
        }
        None => d.set_item("jacobian", py.None())?,
    }
    d.set_item("equations", info.equations)?;
    Ok(d)
}

impl NativeModel {
    fn current(&self) -> Arc<dyn Evaluate> {
        self.current
            .read()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
            .clone()
    }

    fn with(&self, params: Option<Vec<f64>>) -> Result<Arc<dyn Evaluate>, String> {
        let current = self.current();
        match params {
            Some(values) => current.with_parameters(&values),
            None => Ok(current),
        }
    }

    fn check_scene(&self, scene: Option<usize>) -> PyResult<()> {
        let count = self.current().scene_infos().len();
        match scene {
            Some(k) if k >= count => Err(PyValueError::new_err(format!(
                "scene {k} out of range: the model has {count} scenes"
            ))),
            _ => Ok(()),
        }
    }
}

#[pymethods]
impl NativeModel {
    /// The model's information as a dict, or scene `scene`'s.
    #[pyo3(signature = (scene=None))]
    fn info<'py>(&self, py: Python<'py>, scene: Option<usize>) -> PyResult<Bound<'py, PyDict>> {
        self.check_scene(scene)?;
        let model = self.current();
        let d = info_dict(py, model.info(scene))?;
        let links = model.contact_links();
        let feet = PyList::empty(py);
        for (c, flat) in held_feet(model.info(scene)) {
            let foot = PyDict::new(py);
            let link = links.get(c).ok_or_else(|| {
                PyRuntimeError::new_err(format!("contact {c} of {} links", links.len()))
            })?;
            foot.set_item("link", *link)?;
            foot.set_item("flat", flat)?;
            feet.append(foot)?;
        }
        d.set_item("feet", feet)?;
        Ok(d)
    }

    /// A new object with the same model and parameters, whose parameters
    /// change apart from this one's (each `appell.Model` holds its own).
    fn copy(&self) -> NativeModel {
        NativeModel {
            current: RwLock::new(self.current()),
        }
    }

    /// The scenes' struct names, in declaration order.
    fn scene_names(&self) -> Vec<&'static str> {
        self.current()
            .scene_infos()
            .iter()
            .map(|i| i.name)
            .collect()
    }

    /// The parameter values, in the model's order.
    fn parameter_values(&self) -> Vec<f64> {
        self.current().parameter_values()
    }

    /// Sets every parameter (in the model's order), checked as
    /// `Model::validate` checks them.
    fn set_parameters(&self, py: Python<'_>, values: Vec<f64>) -> PyResult<()> {
        let next = self
            .current()
            .with_parameters(&values)
            .map_err(|m| model_error(py, m))?;
        *self
            .current
            .write()
            .unwrap_or_else(|poisoned| poisoned.into_inner()) = next;
        Ok(())
    }

    /// The conversions to and from Pinocchio's conventions for this
    /// model's coordinates and speeds: a base `kind` (`"free"`, `"planar"`
    /// or `"fixed"`) on the joint named `base`, then the moving `joints` in
    /// Pinocchio's order.
    fn pinocchio_map(
        &self,
        py: Python<'_>,
        kind: &str,
        base: &str,
        joints: Vec<String>,
    ) -> PyResult<NativePinocchioMap> {
        let info = self.current().info(None);
        let (c, s) = (info.coordinates, info.speeds);
        let joints: Vec<&str> = joints.iter().map(String::as_str).collect();
        let map = match kind {
            "free" => PinocchioMap::free(base, c, s, &joints),
            "planar" => PinocchioMap::planar(base, c, s, &joints),
            "fixed" => PinocchioMap::fixed(c, s, &joints),
            _ => {
                return Err(PyValueError::new_err(format!(
                    "unknown base `{kind}`: use \"free\", \"planar\" or \"fixed\""
                )))
            }
        };
        let map =
            map.map_err(|e| model_error(py, format!("no map to Pinocchio's conventions: {e}")))?;
        Ok(NativePinocchioMap {
            map,
            n: c.len(),
            l: s.len(),
        })
    }

    /// The names of the operations `call` takes.
    #[staticmethod]
    fn operations() -> Vec<&'static str> {
        Op::ALL.iter().map(|op| op.name()).collect()
    }

    /// The reduced rhs at one state: `x` and `u` are 1-D C-contiguous
    /// float64 arrays of the right lengths (the Python wrapper makes sure).
    fn rhs1<'py>(
        &self,
        py: Python<'py>,
        x: PyReadonlyArrayDyn<'py, f64>,
        u: PyReadonlyArrayDyn<'py, f64>,
        t: f64,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let model = self.current();
        let info = model.info(None);
        let s = info.state_len();
        let (Ok(xs), Ok(us)) = (x.as_slice(), u.as_slice()) else {
            return Err(PyValueError::new_err("rhs1 needs contiguous arrays"));
        };
        if xs.len() != s || us.len() != info.inputs.len() {
            return Err(PyValueError::new_err(format!(
                "rhs1: x has {} entries (expected {s}), u {} (expected {})",
                xs.len(),
                us.len(),
                info.inputs.len()
            )));
        }
        Ok(PyArray1::from_vec(py, one_rhs(py, &*model, t, xs, us)?))
    }

    /// The reduced rhs of the model (not a scene) at one state, when `x`
    /// and `u` (None: no inputs) are 1-D C-contiguous float64 arrays of
    /// the right lengths; `None` otherwise, and the caller takes the
    /// general path. The fast path of `Model.rhs`: no conversion, no
    /// borrow bookkeeping.
    #[pyo3(signature = (x, u, t))]
    fn rhs_fast<'py>(
        &self,
        py: Python<'py>,
        x: &Bound<'py, PyAny>,
        u: Option<&Bound<'py, PyAny>>,
        t: f64,
    ) -> PyResult<Option<Bound<'py, PyArray1<f64>>>> {
        let model = self.current();
        let info = model.info(None);
        let s = info.state_len();
        let Ok(x) = x.downcast::<PyArray1<f64>>() else {
            return Ok(None);
        };
        // SAFETY: the GIL is held from here to the end of the call and no
        // Python code runs meanwhile, so nothing can write to or free the
        // arrays while their slices are read.
        let Ok(xs) = (unsafe { x.as_slice() }) else {
            return Ok(None);
        };
        let us: &[f64] = match u {
            None if info.inputs.is_empty() => &[],
            None => return Ok(None),
            Some(u) => {
                let Ok(u) = u.downcast::<PyArray1<f64>>() else {
                    return Ok(None);
                };
                // SAFETY: as for `x`.
                match unsafe { u.as_slice() } {
                    Ok(us) => us,
                    Err(_) => return Ok(None),
                }
            }
        };
        if xs.len() != s || us.len() != info.inputs.len() {
            return Ok(None);
        }
        Ok(Some(PyArray1::from_vec(
            py,
            one_rhs(py, &*model, t, xs, us)?,
        )))
    }

    /// Evaluates operation `op` (see `operations()`) on `args`, each a
    /// C-contiguous float64 array of one row (1-D) or of N rows (2-D, the
    /// same N for all); returns (N, width) or (width,). `params`: values
    /// for this call only. Batches run with the GIL released, split over
    /// up to `threads` threads of at least `min_rows` rows each.
    #[pyo3(signature = (op, args, t=0.0, scene=None, params=None, threads=1, min_rows=64))]
    // one Rust parameter per Python argument of the #[pyo3(signature)] above, which holds the
    // keyword defaults
    #[allow(clippy::too_many_arguments)]
    fn call<'py>(
        &self,
        py: Python<'py>,
        op: &str,
        args: Vec<PyReadonlyArrayDyn<'py, f64>>,
        t: f64,
        scene: Option<usize>,
        params: Option<Vec<f64>>,
        threads: usize,
        min_rows: usize,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let op = Op::from_name(op)
            .ok_or_else(|| PyValueError::new_err(format!("unknown operation `{op}`")))?;
        self.check_scene(scene)?;
        let model = self.with(params).map_err(|m| model_error(py, m))?;
        let info = model.info(scene);
        let expected = op.args(info);
        if args.len() != expected.len() {
            return Err(PyValueError::new_err(format!(
                "{} takes {} arguments, got {}",
                op.name(),
                expected.len(),
                args.len()
            )));
        }
        let mut rows: Option<usize> = None;
        let mut slices = Vec::with_capacity(args.len());
        for (arg, (name, len)) in args.iter().zip(&expected) {
            let data = arg
                .as_slice()
                .map_err(|_| PyValueError::new_err(format!("`{name}` must be C-contiguous")))?;
            let shape = arg.shape();
            let batched = match shape.len() {
                1 => false,
                2 => true,
                d => {
                    return Err(PyValueError::new_err(format!(
                        "`{name}` has {d} dimensions; expected 1 (one row) or 2 (a batch)"
                    )))
                }
            };
            let width = shape[shape.len() - 1];
            if width != *len {
                return Err(PyValueError::new_err(format!(
                    "`{name}` has rows of {width} entries; {} expects {len}",
                    op.name()
                )));
            }
            if batched {
                match rows {
                    Some(r) if r != shape[0] => {
                        return Err(PyValueError::new_err(format!(
                            "`{name}` has {} rows, another argument {r}",
                            shape[0]
                        )))
                    }
                    _ => rows = Some(shape[0]),
                }
            }
            slices.push(Arg {
                data,
                len: *len,
                batched,
            });
        }
        let width = op.out_len(info);
        let n = rows.unwrap_or(1);
        let mut out = vec![0.0; n * width];
        let result = if rows.is_some() && n > 1 {
            py.allow_threads(|| {
                split_rows(n, width, threads, min_rows, &mut out, |first, chunk| {
                    model.rows(scene, op, t, &slices, chunk, first)
                })
            })
        } else {
            model.rows(scene, op, t, &slices, &mut out, 0)
        };
        result.map_err(|f| failure(py, f, rows.is_some(), op))?;
        let shape: Vec<usize> = match rows {
            Some(n) => vec![n, width],
            None => vec![width],
        };
        PyArray1::from_vec(py, out).reshape(IxDyn(&shape))
    }

    /// Integrates from `x0` (1-D, or 2-D for a batch of initial states) at
    /// `t0` and returns the states at `t_eval`: (len(t_eval), s) or
    /// (N, len(t_eval), s). With `event` (one initial state, DOP853), a
    /// callable g(t, x) -> float: the run stops where g changes sign and
    /// the result is (times reached, states, (t_event, x_event) or None).
    /// With `feedback`, a callable u(t, x) -> float64 array of the inputs
    /// called at every evaluation of the rhs (`u` then only gives their
    /// number): rows run one after another, holding the GIL.
    #[pyo3(signature = (x0, u, t0, t_eval, method="dop853", rtol=1e-8, atol=1e-10, h_max=None, max_steps=1_000_000, scene=None, params=None, threads=1, event=None, feedback=None))]
    // one Rust parameter per Python argument of the #[pyo3(signature)] above; they are gathered
    // into Settings and States just below
    #[allow(clippy::too_many_arguments)]
    fn simulate<'py>(
        &self,
        py: Python<'py>,
        x0: PyReadonlyArrayDyn<'py, f64>,
        u: PyReadonlyArrayDyn<'py, f64>,
        t0: f64,
        t_eval: PyReadonlyArrayDyn<'py, f64>,
        method: &str,
        rtol: f64,
        atol: f64,
        h_max: Option<f64>,
        max_steps: usize,
        scene: Option<usize>,
        params: Option<Vec<f64>>,
        threads: usize,
        event: Option<Bound<'py, PyAny>>,
        feedback: Option<Bound<'py, PyAny>>,
    ) -> PyResult<PyObject> {
        let method = Method::from_name(method).ok_or_else(|| {
            PyValueError::new_err(format!(
                "unknown method `{method}`: use \"dop853\", \"radau5\" or \"rk4\""
            ))
        })?;
        self.check_scene(scene)?;
        let model = self.with(params).map_err(|m| model_error(py, m))?;
        let info = model.info(scene);
        let s = info.state_len();
        let contiguous =
            |name: &str| PyValueError::new_err(format!("`{name}` must be C-contiguous"));
        let xs = x0.as_slice().map_err(|_| contiguous("x0"))?;
        let us = u.as_slice().map_err(|_| contiguous("u"))?;
        let times = t_eval.as_slice().map_err(|_| contiguous("t_eval"))?;
        if us.len() != info.inputs.len() {
            return Err(PyValueError::new_err(format!(
                "u has {} entries; the model has {} inputs {:?}",
                us.len(),
                info.inputs.len(),
                info.inputs
            )));
        }
        let batch = match x0.shape() {
            [n] if *n == s => None,
            [rows, n] if *n == s => Some(*rows),
            shape => {
                return Err(PyValueError::new_err(format!(
                    "x0 has shape {shape:?}; the reduced state has {s} entries"
                )))
            }
        };
        let settings = Settings {
            method,
            inputs: us,
            t0,
            t_eval: times,
            rtol,
            atol,
            h_max,
            max_steps,
        };
        let states = States { x0: xs, s, batch };
        match event {
            Some(g) => simulate_event(py, &*model, scene, &settings, &states, g, feedback),
            None => simulate_rows(py, &*model, scene, &settings, &states, threads, feedback),
        }
    }
}
