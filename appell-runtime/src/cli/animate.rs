//! The `animate` subcommand: a simulation of one state, drawn as an
//! animated SVG ([`crate::animate`]).

use super::eval::EvalState;
use super::input::number;
use super::json::parse_object;
use crate::animate::{simulate, svg, SvgOptions, View};
use crate::dynamic::DynModel;
use serde_json::{Map, Value};

/// The fields an `animate` problem may add to an `eval` state.
const FIELDS: [&str; 12] = [
    "t_end",
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
/// SVG, or why it could not.
pub(super) fn animate_dyn(model: &mut dyn DynModel, text: &str) -> Result<Animated, String> {
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
    let options = options(model, &obj)?;
    let motion = simulate(
        &*model,
        point.t,
        &point.q,
        &point.u,
        &point.inputs,
        t_end,
        frames,
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
