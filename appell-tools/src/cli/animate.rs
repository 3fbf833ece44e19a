//! The `animate` subcommand: a simulation of one state, drawn as an
//! animated SVG ([`crate::animate`]).

use super::eval::EvalState;
use super::input::number;
use super::json::parse_object;
use super::progress::Bar;
use crate::animate::{simulate_with_progress, steps_needed, svg, SvgOptions, View, MAX_STEP};
use appell_core::dynamic::DynModel;
use serde_json::{Map, Value};
use std::io::Write;

/// The RK4 steps an `animate` problem may take unless its `max_steps`
/// says otherwise: 2000 s of motion at the 1 ms step, seconds to a few
/// minutes of computing for the models of the examples.
pub(super) const DEFAULT_MAX_STEPS: u64 = 2_000_000;

/// Runs of at least this many steps show a progress bar (on a terminal).
const PROGRESS_STEPS: f64 = 100_000.0;

/// The fields an `animate` problem may add to an `eval` state.
const FIELDS: [&str; 13] = [
    "t_end",
    "max_steps",
    "frames",
    "playback",
    "width",
    "height",
    "title",
    "view",
    "up",
    "follow",
    "connectors",
    "traces",
    "dots",
];

/// A picture, and what `animate` did to the state it was given (the
/// coordinates it solved, a warning), as lines for stderr.
pub(super) struct Animated {
    pub(super) svg: String,
    pub(super) notes: Vec<String>,
}

/// Parses one problem (an `eval` state plus `t_end` and the picture's
/// options, see the module documentation), simulates it and returns the
/// SVG, or why it could not. A run of many steps draws a progress bar on
/// `terminal` when there is one.
pub(super) fn animate_dyn(
    model: &mut dyn DynModel,
    text: &str,
    terminal: Option<&mut dyn Write>,
) -> Result<Animated, String> {
    let obj = parse_object(text)?;
    let evaluator = EvalState::new(model).map_err(|e| e.to_string())?;
    let point = evaluator.parse_point(model, &obj, &FIELDS)?;
    let t_end = match obj.get("t_end") {
        Some(v) => number(v, "`t_end`")?,
        None => return Err("missing field `t_end` (when the motion ends)".to_string()),
    };
    if t_end <= point.t {
        return Err(format!("`t_end` ({t_end}) must be after `t` ({})", point.t));
    }
    let frames = count(&obj, "frames", 200, 10_000)?;
    let steps = steps_needed(point.t, t_end, frames);
    check_budget(&obj, point.t, t_end, steps)?;
    let options = options(model, &obj)?;
    let mut bar = terminal
        .filter(|_| steps >= PROGRESS_STEPS)
        .map(|out| Bar::new(out, "animate", frames));
    let motion = simulate_with_progress(
        &*model,
        point.t,
        &point.q,
        &point.u,
        &point.inputs,
        t_end,
        frames,
        &mut |done, _| {
            if let Some(bar) = bar.as_mut() {
                bar.set(done);
            }
        },
    )
    .map_err(|e| format!("the simulation stopped: {e}"))?;
    let notes = point.filled.lines();
    let mut picture = svg(&*model, &motion, &options).map_err(|e| e.to_string())?;
    // The notes go into the picture too, so that a saved SVG records the
    // state it started from; `--` may not appear in an XML comment.
    if let Some(end) = picture.find('>').filter(|_| !notes.is_empty()) {
        let comment = format!("\n<!-- {} -->", notes.join("; ").replace("--", "- -"));
        picture.insert_str(end + 1, &comment);
    }
    Ok(Animated {
        svg: picture,
        notes,
    })
}

/// The step budget: `max_steps` (an integer of at least 1) or
/// [`DEFAULT_MAX_STEPS`]; a run that needs more is an error saying how
/// many steps it needs and what to change.
fn check_budget(obj: &Map<String, Value>, t: f64, t_end: f64, steps: f64) -> Result<(), String> {
    let (budget, whose) = match obj.get("max_steps") {
        None => (DEFAULT_MAX_STEPS, "the default"),
        Some(v) => match v.as_u64() {
            Some(n) if n >= 1 => (n, "`max_steps`"),
            _ => return Err(format!("`max_steps` must be a positive integer, found {v}")),
        },
    };
    if steps <= budget as f64 {
        return Ok(());
    }
    Err(format!(
        "the motion from t = {t} to t_end = {t_end} needs {steps:.0} RK4 steps (at most {MAX_STEP} s each), more than the budget of {budget} ({whose}): shorten `t_end` (about {:.0} s of motion fit) or raise `max_steps` to at least {steps:.0} if the wait is worth it",
        budget as f64 * MAX_STEP
    ))
}

/// An integer field from 1 to `max`, `default` when absent.
fn count(obj: &Map<String, Value>, key: &str, default: usize, max: usize) -> Result<usize, String> {
    match obj.get(key) {
        None => Ok(default),
        Some(v) => match v.as_u64() {
            Some(n) if (1..=max as u64).contains(&n) => Ok(n as usize),
            _ => Err(format!(
                "`{key}` must be an integer from 1 to {max}, found {v}"
            )),
        },
    }
}

/// The picture's options; bodies are named as in `info`'s `bodies`.
fn options(model: &dyn DynModel, obj: &Map<String, Value>) -> Result<SvgOptions, String> {
    let info = model.dyn_info();
    let mut o = SvgOptions {
        title: info.name.to_string(),
        ..SvgOptions::default()
    };
    o.width = count(obj, "width", 640, 4096)? as u32;
    o.height = count(obj, "height", 480, 4096)? as u32;
    if let Some(v) = obj.get("playback") {
        o.playback = number(v, "`playback`")?;
        if o.playback <= 0.0 {
            return Err("`playback` (seconds of motion per second) must be positive".into());
        }
    }
    if let Some(v) = obj.get("title") {
        o.title = v.as_str().ok_or("`title` must be a string")?.to_string();
    }
    if let Some(v) = obj.get("view") {
        o.view = match v.as_str() {
            Some("auto") => View::Auto,
            Some("oblique") => View::Oblique,
            Some("x") => View::Along(0),
            Some("y") => View::Along(1),
            Some("z") => View::Along(2),
            _ => {
                return Err(format!(
                    "`view` must be \"auto\", \"oblique\", \"x\", \"y\" or \"z\", found {v}"
                ))
            }
        };
    }
    if let Some(v) = obj.get("up") {
        let up: Vec<f64> = match v.as_array() {
            Some(a) if a.len() == 3 => a
                .iter()
                .map(|x| number(x, "an entry of `up`"))
                .collect::<Result<_, _>>()?,
            _ => return Err(format!("`up` must be three numbers, found {v}")),
        };
        o.up = [up[0], up[1], up[2]];
    }
    if let Some(v) = obj.get("follow") {
        o.follow = v.as_bool().ok_or("`follow` must be true or false")?;
    }
    let body = |v: &Value, field: &str| -> Result<Option<usize>, String> {
        let name = v
            .as_str()
            .ok_or_else(|| format!("`{field}` names bodies (strings), found {v}"))?;
        if name == "O" {
            return Ok(None);
        }
        info.bodies
            .iter()
            .position(|b| b.name == name)
            .map(Some)
            .ok_or_else(|| {
                let names: Vec<&str> = info.bodies.iter().map(|b| b.name).collect();
                format!(
                    "unknown body `{name}` in `{field}` (bodies: {}; O: the origin)",
                    names.join(", ")
                )
            })
    };
    let list = |field: &str| -> Result<Vec<&Value>, String> {
        match obj.get(field) {
            None => Ok(Vec::new()),
            Some(Value::Array(a)) => Ok(a.iter().collect()),
            Some(v) => Err(format!("`{field}` must be a list, found {v}")),
        }
    };
    for pair in list("connectors")? {
        match pair.as_array().map(Vec::as_slice) {
            Some([a, b]) => o
                .connectors
                .push((body(a, "connectors")?, body(b, "connectors")?)),
            _ => {
                return Err(format!(
                    "each of `connectors` is a pair of body names, found {pair}"
                ))
            }
        }
    }
    for (field, out) in [("traces", &mut o.traces), ("dots", &mut o.dots)] {
        for v in list(field)? {
            out.push(body(v, field)?.ok_or_else(|| format!("`{field}` names bodies, not O"))?);
        }
    }
    Ok(o)
}
