//! Writing JSON output: numbers that may not be finite, and the constraint
//! forces `contacts` answers.

use appell_core::dynamic::DynModel;
use appell_core::RowSource;
use appell_dynamics::constraint_forces::{contact_forces_dyn, Friction, Normal, NormalSource};
use serde_json::{json, Value};

/// A JSON number, or `null` for a value JSON cannot hold.
pub(super) fn finite_or_null(x: f64) -> Value {
    serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number)
}

/// A finite result as a JSON number.
pub(super) fn result_number(x: f64, name: &str) -> Result<Value, String> {
    serde_json::Number::from_f64(x)
        .map(Value::Number)
        .ok_or_else(|| format!("the result for `{name}` is not finite"))
}

/// `{"multipliers": [..], "rows": [{"source", "multiplier"}], "contacts":
/// [{"point", "body", "position", "force", "normal", "friction"}], "feet":
/// [{"link", "position", "force", "moment", "friction"}]}` (a point foot's
/// moment is `null`).
pub(super) fn contact_forces_json(
    model: &dyn DynModel,
    t: f64,
    q: &[f64],
    u: &[f64],
    inputs: &[f64],
) -> Result<Value, String> {
    let info = model.dyn_info();
    let info_links = model.dyn_contact_links();
    let f = contact_forces_dyn(model, t, q, u, inputs).map_err(|e| e.to_string())?;
    let v3 = |v: [f64; 3]| {
        json!([
            finite_or_null(v[0]),
            finite_or_null(v[1]),
            finite_or_null(v[2])
        ])
    };
    let rows: Vec<Value> = f
        .rows
        .iter()
        .map(|r| {
            let source = match r.source {
                RowSource::Holonomic { index } => format!("holonomic {index}"),
                RowSource::Nonholonomic { index } => format!("nonholonomic {index}"),
                RowSource::Driven { constraint, .. } => format!("driven, {constraint}"),
                RowSource::Contact { contact, axis } => {
                    let link = info_links.get(contact).copied().unwrap_or("?");
                    let what = ["x", "y", "z"][axis % 3];
                    if axis < 3 {
                        format!("contact of {link}, force along N.{what}")
                    } else {
                        format!("contact of {link}, moment about N.{what}")
                    }
                }
                RowSource::Rolling { contact, direction } => {
                    let point = info.contacts.get(contact).map_or("?", |c| c.point);
                    match info.contacts.get(contact) {
                        Some(c) if !c.along => {
                            format!("rolls at {point}, N.{}", ["x", "y", "z"][direction.min(2)])
                        }
                        _ => format!("rolls at {point}, along {direction}"),
                    }
                }
            };
            json!({ "source": source, "multiplier": finite_or_null(r.multiplier) })
        })
        .collect();
    let contacts: Vec<Value> = f
        .contacts
        .iter()
        .map(|c| {
            let normal = match c.normal {
                Normal::Available {
                    direction,
                    force,
                    source,
                } => json!({
                    "force": finite_or_null(force),
                    "direction": v3(direction),
                    "source": match source {
                        NormalSource::HolonomicRow { index } => format!("holonomic {index}"),
                        NormalSource::MomentumBalance => "momentum balance".to_string(),
                    },
                }),
                Normal::Unavailable(why) => json!({ "unavailable": format!("{why:?}") }),
            };
            let friction = friction_json(c.friction());
            json!({
                "point": c.point,
                "body": info.bodies.get(c.body).map(|b| b.name),
                "position": v3(c.position),
                "force": v3(c.force),
                "normal": normal,
                "friction": friction,
            })
        })
        .collect();
    let feet: Vec<Value> = f
        .feet
        .iter()
        .map(|foot| {
            json!({
                "link": foot.link,
                "position": v3(foot.position),
                "force": v3(foot.force),
                "moment": foot.moment.map(v3),
                "friction": friction_json(foot.friction()),
            })
        })
        .collect();
    Ok(json!({
        "multipliers": f.multipliers.iter().map(|x| finite_or_null(*x)).collect::<Vec<_>>(),
        "rows": rows,
        "contacts": contacts,
        "feet": feet,
    }))
}

/// `{"mu"}`, `{"lift_off": normal}` or `{"unavailable": why}`.
fn friction_json(friction: Friction) -> Value {
    match friction {
        Friction::Required { mu, .. } => json!({ "mu": finite_or_null(mu) }),
        Friction::LiftOff { normal } => json!({ "lift_off": finite_or_null(normal) }),
        Friction::NormalUnavailable(why) => json!({ "unavailable": format!("{why:?}") }),
    }
}
