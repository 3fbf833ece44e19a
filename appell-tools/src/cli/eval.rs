//! The `eval`, `contacts` and `jacobian` subcommands: answering JSON
//! states line by line with rates, a scene's outputs, the constraint
//! forces or the Jacobians.

use super::error::CliError;
use super::holonomic::fill_in;
use super::input::{named, number, Point};
use super::jacobian::{jacobian_answer, parse_step};
use super::json::parse_object;
use super::output::{contact_forces_json, finite_or_null, result_number};
use appell_core::dynamic::DynModel;
use appell_core::{Model, ModelError, ModelInfo};
use serde_json::{json, Map, Value};
use std::io::{BufRead, Write};

// Items the documentation links to.
#[cfg(doc)]
use super::run_with;

/// Answers every non-empty line of `stdin` on `stdout`.
pub(super) fn eval_stream(
    evaluator: &EvalState,
    model: &mut dyn DynModel,
    stdin: &mut dyn BufRead,
    stdout: &mut dyn Write,
) -> Result<(), CliError> {
    let mut buf = Vec::new();
    loop {
        buf.clear();
        if stdin.read_until(b'\n', &mut buf)? == 0 {
            break;
        }
        let answer = match std::str::from_utf8(&buf) {
            Ok(line) if line.trim().is_empty() => continue,
            Ok(line) => evaluator.eval_line(model, line),
            Err(_) => json!({ "error": "the line is not valid UTF-8" }),
        };
        writeln!(stdout, "{answer}")?;
        stdout.flush()?;
    }
    Ok(())
}

/// Evaluates `eval` lines against a model (the state of the `eval`
/// subcommand, usable on its own).
///
/// Every line starts from the parameter values the model had when the
/// evaluator was created. The accepted format is described in the module
/// documentation; see [`run_with`] for an example through the command line.
pub struct Evaluator<M: Model> {
    model: M,
    state: EvalState,
}

impl<M: Model> Evaluator<M> {
    /// Takes the model and records its current parameter values.
    pub fn new(model: M) -> Result<Self, ModelError> {
        let state = EvalState::new(&model)?;
        Ok(Evaluator { model, state })
    }

    /// An evaluator of the scene named `name` (as in `info`'s `scenes`: the
    /// part after `::`, or the whole name).
    pub fn with_scene(model: M, name: &str) -> Result<Self, CliError> {
        let state = EvalState::with_scene(&model, name)?;
        Ok(Evaluator { model, state })
    }

    /// The model (with the parameters of the last evaluated line).
    pub fn model(&self) -> &M {
        &self.model
    }

    /// Answers one line: `{"qdot": {..}, "udot": {..}}` or
    /// `{"error": ".."}`.
    pub fn eval_line(&mut self, line: &str) -> Value {
        self.state.eval_line(&mut self.model, line)
    }
}

/// What an [`Evaluator`] keeps besides its model; its methods take the
/// model as a `&dyn DynModel`, so they are compiled once.
pub(super) struct EvalState {
    defaults: Vec<f64>,
    scene: Option<usize>,
    /// What a line is answered with.
    pub(super) answer: Answer,
}

/// What a state line is answered with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Answer {
    /// The rates (`eval`).
    Rates,
    /// The constraint forces (`contacts`).
    Contacts,
    /// A = ∂ẋ/∂x and B = ∂ẋ/∂u, or those of one step (`jacobian`).
    Jacobian,
}

impl Answer {
    /// The answer of subcommand `command`, if it answers state lines.
    pub(super) fn of_command(command: &str) -> Option<Answer> {
        match command {
            "eval" => Some(Answer::Rates),
            "contacts" => Some(Answer::Contacts),
            "jacobian" => Some(Answer::Jacobian),
            _ => None,
        }
    }
}

impl EvalState {
    /// Records the model's current parameter values.
    pub(super) fn new(model: &dyn DynModel) -> Result<Self, ModelError> {
        let mut defaults = vec![0.0; model.dyn_info().parameters.len()];
        model.dyn_parameter_values(&mut defaults)?;
        Ok(EvalState {
            defaults,
            scene: None,
            answer: Answer::Rates,
        })
    }

    /// The error for `eval --scene` (or `contacts --scene`) without a name.
    pub(super) fn scene_name_missing(model: &dyn DynModel, command: &str) -> CliError {
        CliError::Usage(format!(
            "`{command} --scene` needs the name of a scene after it (`{command} --scene NAME`); the model's scenes: {}\n",
            scene_names(model)
        ))
    }

    /// The state of an evaluator of the scene named `name`.
    pub(super) fn with_scene(model: &dyn DynModel, name: &str) -> Result<Self, CliError> {
        let scenes = model.dyn_scene_infos();
        let index = scenes
            .iter()
            .position(|s| s.name == name || s.name.rsplit("::").next() == Some(name))
            .ok_or_else(|| {
                CliError::Usage(format!(
                    "unknown scene `{name}`; the model's scenes: {}\n",
                    scene_names(model)
                ))
            })?;
        let mut e = EvalState::new(model)?;
        e.scene = Some(index);
        Ok(e)
    }

    /// Answers one line: `{"qdot": {..}, "udot": {..}}` or
    /// `{"error": ".."}`.
    pub(super) fn eval_line(&self, model: &mut dyn DynModel, line: &str) -> Value {
        match self.try_eval(model, line) {
            Ok(v) => v,
            Err(message) => json!({ "error": message }),
        }
    }

    /// The info of the model or of the selected scene (a scene has the
    /// model's coordinates and parameters, its own reduced state, and its
    /// own speeds where it names them).
    fn info(&self, model: &dyn DynModel) -> &'static ModelInfo {
        match self.scene {
            Some(i) => model.dyn_scene_infos()[i],
            None => model.dyn_info(),
        }
    }

    fn try_eval(&self, model: &mut dyn DynModel, line: &str) -> Result<Value, String> {
        let info = self.info(model);
        let obj = parse_object(line)?;
        let extra: &[&str] = match self.answer {
            Answer::Jacobian => &["step"],
            _ => &[],
        };
        let point = self.parse_point(model, &obj, extra)?;
        let model: &dyn DynModel = model;
        let notes = point.filled.notes();
        if self.answer == Answer::Jacobian {
            let step = parse_step(&obj)?;
            let mut answer =
                self.on_target(model, |target| jacobian_answer(target, info, &point, step))?;
            answer.extend(notes);
            return Ok(Value::Object(answer));
        }
        let (t, q, u, inputs, state) = (point.t, point.q, point.u, point.inputs, point.state);
        let outputs = |energies: bool, contacts: bool| {
            let outputs = Outputs {
                t,
                q: &q,
                u: &u,
                inputs: &inputs,
                energies,
                contacts,
            };
            self.on_target(model, |target| outputs.of(target))
        };
        if self.answer == Answer::Contacts {
            let mut out = outputs(false, true)?;
            let mut forces = out.remove("contact_forces").unwrap_or(Value::Null);
            if let Value::Object(forces) = &mut forces {
                forces.extend(notes);
            }
            return Ok(forces);
        }
        let mut dstate = vec![0.0; info.state_len()];
        match self.scene {
            Some(i) => model.dyn_scene_rhs(i, t, &state, &inputs, &mut dstate),
            None => model.dyn_rhs(t, &state, &inputs, &mut dstate),
        }
        .map_err(|e| e.to_string())?;
        // q̇ is the scene's own: a scene may have other speeds than the model.
        let mut qdot = vec![0.0; info.coordinates.len()];
        self.on_target(model, |target| {
            target
                .dyn_driven_coordinate_rates(t, &q, &u, &inputs, &mut qdot)
                .map_err(|e| e.to_string())
        })?;

        let mut qdot_out = Map::new();
        for (name, v) in info.coordinates.iter().zip(&qdot) {
            qdot_out.insert(name.to_string(), result_number(*v, name)?);
        }
        let mut udot_out = Map::new();
        let udot = dstate.get(info.retained.len()..).unwrap_or(&[]);
        for (name, v) in info.speeds.iter().zip(udot) {
            udot_out.insert(name.to_string(), result_number(*v, name)?);
        }
        let mut answer = Map::new();
        answer.insert("qdot".into(), Value::Object(qdot_out));
        answer.insert("udot".into(), Value::Object(udot_out));
        answer.extend(notes);
        let (energies, contacts) = (
            info.has_output("energies"),
            info.has_output("contact_forces"),
        );
        if energies || contacts {
            answer.extend(outputs(energies, contacts)?);
        }
        Ok(Value::Object(answer))
    }

    /// Reads `t`, `params`, `q`, `u` and `inputs` of a JSON object (fields
    /// in `extra` are allowed and left to the caller), sets the parameters
    /// and assembles the reduced state.
    pub(super) fn parse_point(
        &self,
        model: &mut dyn DynModel,
        obj: &Map<String, Value>,
        extra: &[&str],
    ) -> Result<Point, String> {
        let info = self.info(model);
        for key in obj.keys() {
            if !["t", "params", "q", "u", "inputs"].contains(&key.as_str())
                && !extra.contains(&key.as_str())
            {
                let mut expected = String::from("t, params, q, u, inputs");
                for e in extra {
                    expected += ", ";
                    expected += e;
                }
                return Err(format!("unknown field `{key}` (expected {expected})"));
            }
        }
        let t = match obj.get("t") {
            None => 0.0,
            Some(v) => number(v, "`t`")?,
        };
        let params = named(obj.get("params"), "params", "parameter", info.parameters)?;
        let q_given = named(obj.get("q"), "q", "coordinate", info.coordinates)?;
        let u_given = named(obj.get("u"), "u", "privileged speed", info.speeds)?;
        let inputs_given = named(obj.get("inputs"), "inputs", "input", info.inputs)?;

        for (i, name) in info.parameters.iter().enumerate() {
            let value = params[i].unwrap_or(self.defaults[i]);
            if !model.dyn_set_parameter(name, value) {
                return Err(format!("the model does not accept parameter `{name}`"));
            }
        }
        model.dyn_validate().map_err(|e| e.to_string())?;
        if let Some(k) = u_given.iter().position(Option::is_none) {
            return Err(format!(
                "missing privileged speed `{}` in `u`",
                info.speeds[k]
            ));
        }
        let mut q: Vec<f64> = q_given.iter().map(|v| v.unwrap_or(0.0)).collect();
        let u: Vec<f64> = u_given.iter().map(|v| v.unwrap_or(0.0)).collect();
        let inputs: Vec<f64> = inputs_given.iter().map(|v| v.unwrap_or(0.0)).collect();
        let missing: Vec<usize> = (0..q.len()).filter(|&i| q_given[i].is_none()).collect();
        let retained: Vec<usize> = info
            .retained
            .iter()
            .map(|r| {
                info.coordinate_index(r)
                    .ok_or_else(|| format!("retained `{r}` is not a coordinate"))
            })
            .collect::<Result<_, _>>()?;
        let filled = self.on_target(model, |target| {
            fill_in(target, t, &mut q, &inputs, &missing, &retained)
        })?;

        let mut state = Vec::with_capacity(info.state_len());
        state.extend(retained.iter().map(|&i| q[i]));
        state.extend_from_slice(&u);
        Ok(Point {
            t,
            q,
            u,
            inputs,
            state,
            filled,
        })
    }

    /// Calls `f` with the model whose equations answer: the selected
    /// scene (whose constraints and speeds may differ from the model's), or
    /// the model itself.
    fn on_target<R>(
        &self,
        model: &dyn DynModel,
        f: impl FnOnce(&dyn DynModel) -> Result<R, String>,
    ) -> Result<R, String> {
        let Some(i) = self.scene else {
            return f(model);
        };
        let (mut f, mut result) = (Some(f), None);
        model
            .dyn_visit_scene(i, &mut |scene| result = f.take().map(|f| f(scene)))
            .map_err(|e| e.to_string())?;
        result.unwrap_or_else(|| Err(ModelError::UnknownScene { index: i }.to_string()))
    }
}

/// The outputs a scene asks for (or the `contacts` answer), computed on
/// the scene's own model.
struct Outputs<'a> {
    t: f64,
    q: &'a [f64],
    u: &'a [f64],
    inputs: &'a [f64],
    energies: bool,
    contacts: bool,
}

impl Outputs<'_> {
    fn of(&self, model: &dyn DynModel) -> Result<Map<String, Value>, String> {
        let mut out = Map::new();
        if self.energies {
            let e =
                appell_dynamics::energy::energies_dyn(model, self.t, self.q, self.u, self.inputs)
                    .map_err(|e| e.to_string())?;
            out.insert(
                "energies".into(),
                json!({
                    "kinetic": finite_or_null(e.kinetic),
                    "potential": finite_or_null(e.potential),
                    "rate": finite_or_null(e.rate),
                    "input_power": finite_or_null(e.input_power),
                }),
            );
        }
        if self.contacts {
            out.insert(
                "contact_forces".into(),
                contact_forces_json(model, self.t, self.q, self.u, self.inputs)?,
            );
        }
        Ok(out)
    }
}

/// The model's scenes' names, comma-separated ("none" when it has none).
fn scene_names(model: &dyn DynModel) -> String {
    let names: Vec<&str> = model.dyn_scene_infos().iter().map(|s| s.name).collect();
    if names.is_empty() {
        "none".to_string()
    } else {
        names.join(", ")
    }
}
