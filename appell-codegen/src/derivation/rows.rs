//! Stage 1: the velocity constraints D(q,t) q̇ + d = 0 (eq. 25).
//!
//! Holonomic constraints f(q, t) = 0 enter through their time derivatives;
//! nonholonomic ones as written, and each must be linear in q̇. A rolling
//! contact contributes the components of its material point's velocity,
//! v(centre) + ω × (P − centre), along N's axes (zero rows dropped) or along
//! its `along` directions.
//!
//! Beside D and d, the stage keeps each row as the model wrote it (the
//! twin's, not multiplied out): the elimination reads S and R off those
//! forms, and the dependent accelerations differentiate them. For a rolling
//! row it also records whether the contact's whole material velocity
//! vanishes on the constrained motion ("complete"), in which case the rate
//! of v·e is (rate of v)·e.

use appell_symbolic::{Id, RateRules, SymbolKind, SymbolicError};
use proc_macro2::TokenStream;

use super::Calculus;
use crate::algebra::{cross, dot, expanded, Vec3};
use crate::ctxt::Ctxt;
use crate::model::{Constraint, ConstraintSet, Model, Rolling};
use crate::probe::same_function;

pub use appell_core::RowSource;

/// The material velocity at a rolling contact, as written (the twin's).
#[derive(Clone, Copy)]
pub struct ContactMotion {
    /// v(centre) + ω × (P − centre), N components.
    pub velocity: Vec3,
    /// Whether every component of it vanishes on the constrained motion:
    /// the rows cover N, or the component normal to the two `along`
    /// directions is identically zero, or a holonomic row equals it.
    pub complete: bool,
}

/// The output of stage 1: D and d, row by row, with what later stages need
/// of each row.
#[derive(Clone)]
pub struct ConstraintRows {
    /// The holonomic residuals f(q, t), one per `holonomic(...)`.
    pub holonomic: Vec<Id>,
    /// D (m×n), row-major.
    pub d: Vec<Id>,
    /// d (m).
    pub d0: Vec<Id>,
    /// Each row's attribute tokens, for errors.
    pub at: Vec<TokenStream>,
    /// Each row's source.
    pub sources: Vec<RowSource>,
    /// Each row, D_i q̇ + d_i, as the model wrote it (the twin's).
    pub as_written: Vec<Id>,
    /// For a rolling row (or a holonomic row equal to a contact's normal
    /// component): the contact and the row's direction (the twin's).
    pub directions: Vec<Option<(usize, Vec3)>>,
    /// Per rolling contact.
    pub contacts: Vec<ContactMotion>,
}

/// One row before it is checked and split into D and d.
struct Row {
    /// D_i q̇ + d_i, expanded.
    value: Id,
    at: TokenStream,
    holonomic: bool,
    /// The same row as written.
    as_written: Id,
    direction: Option<(usize, Vec3)>,
    source: RowSource,
}

/// Stage 1. `None` when errors were recorded in `cx`.
pub fn constraint_rows(
    cx: &Ctxt,
    model: &mut Model,
    set: &ConstraintSet,
    calculus: &Calculus,
) -> Result<Option<ConstraintRows>, SymbolicError> {
    let (holonomic, mut rows) = holonomic_rows(cx, model, &set.holonomic, calculus);
    rows.extend(nonholonomic_rows(&set.nonholonomic, calculus));
    let mut contacts = Vec::new();
    for contact in 0..set.rolling.len() {
        let (motion, rolling) = rolling_rows(cx, model, calculus, &set.rolling, contact)?;
        contacts.push(motion);
        rows.extend(rolling);
    }
    complete_contacts(model, &set.rolling, calculus, &mut rows, &mut contacts)?;
    let out = linear_rows(cx, model, rows, holonomic, contacts);
    Ok(if cx.has_errors() { None } else { Some(out) })
}

/// The time derivatives of the holonomic constraints.
fn holonomic_rows(
    cx: &Ctxt,
    model: &mut Model,
    constraints: &[Constraint],
    calculus: &Calculus,
) -> (Vec<Id>, Vec<Row>) {
    let mut holonomic = Vec::new();
    let mut rows = Vec::new();
    for (index, c) in constraints.iter().enumerate() {
        holonomic.push(c.residual);
        let bad: Vec<String> = model
            .g
            .dependencies(c.residual)
            .iter()
            .filter(|s| {
                !matches!(
                    model.g.symbol_kind(*s),
                    SymbolKind::Coordinate
                        | SymbolKind::Parameter
                        | SymbolKind::Time
                        | SymbolKind::Input
                )
            })
            .map(|s| model.g.symbol_name(s).to_string())
            .collect();
        if !bad.is_empty() {
            cx.error_spanned_by(&c.at, format!("a holonomic constraint relates coordinates, parameters, inputs and time only; it uses {}", bad.join(", ")));
            continue;
        }
        let raw = match (&calculus.twin, &calculus.twin_rules) {
            (Some(t), Some(tr)) => model.g.time_derivative(t.holonomic[index].residual, tr),
            _ => model.g.time_derivative(c.residual, &calculus.rules),
        };
        match (model.g.time_derivative(c.residual, &calculus.rules), raw) {
            (Ok(value), Ok(as_written)) => rows.push(Row {
                value,
                at: c.at.clone(),
                holonomic: true,
                as_written,
                direction: None,
                source: RowSource::Holonomic { index },
            }),
            (Err(e), _) | (_, Err(e)) => cx.error_spanned_by(&c.at, e),
        }
    }
    (holonomic, rows)
}

/// The nonholonomic constraints, as written.
fn nonholonomic_rows(constraints: &[Constraint], calculus: &Calculus) -> Vec<Row> {
    let mut rows = Vec::new();
    for (index, c) in constraints.iter().enumerate() {
        let as_written = calculus
            .twin
            .as_ref()
            .map_or(c.residual, |t| t.nonholonomic[index].residual);
        rows.push(Row {
            value: c.residual,
            at: c.at.clone(),
            holonomic: false,
            as_written,
            direction: None,
            source: match c.contact {
                Some((contact, axis)) => RowSource::Contact { contact, axis },
                None => RowSource::Nonholonomic { index },
            },
        });
    }
    rows
}

/// A rolling contact's rows: v(material point at P) = v(centre) +
/// ω × (P − centre) = 0, along N's axes or the `along` directions.
fn rolling_rows(
    cx: &Ctxt,
    model: &mut Model,
    calculus: &Calculus,
    rolling: &[Rolling],
    contact: usize,
) -> Result<(ContactMotion, Vec<Row>), SymbolicError> {
    let r = &rolling[contact];
    let body = &model.bodies[r.body];
    let omega = model.frames[body.frame.expect("rigid")].omega;
    let g = &mut model.g;
    let rules = &calculus.rules;
    let mut v = [body.center[0]; 3];
    let mut arm = [body.center[0]; 3];
    for i in 0..3 {
        v[i] = g.time_derivative(body.center[i], rules)?;
        arm[i] = g.sub(r.contact[i], body.center[i])?;
    }
    let w = cross(g, omega, arm)?;
    for i in 0..3 {
        let sum = g.add(v[i], w[i])?;
        v[i] = expanded(g, sum)?;
    }
    let components: Vec<Id> = match &r.along {
        Some(dirs) => dirs
            .iter()
            .map(|d| dot(g, v, *d).and_then(|e| expanded(g, e)))
            .collect::<Result<_, _>>()?,
        None => v.to_vec(),
    };
    // The material point's velocity as written (the twin's), and the
    // directions it is constrained along.
    let (raw_v, raw_dirs): (Vec<Id>, Vec<Vec3>) = match (&calculus.twin, &calculus.twin_rules) {
        (Some(t), Some(tr)) => {
            let tb = &t.bodies[r.body];
            let tr_roll = &t.rolling[contact];
            let v = rolling_components(
                g,
                tb.center,
                t.frames[tb.frame.expect("rigid")].omega,
                tr_roll.contact,
                None,
                tr,
            )?;
            (v, tr_roll.along.clone().unwrap_or_default())
        }
        _ => (
            rolling_components(g, body.center, omega, r.contact, None, rules)?,
            r.along.clone().unwrap_or_default(),
        ),
    };
    let raw_v = [raw_v[0], raw_v[1], raw_v[2]];
    let (zero, one) = (g.int(0)?, g.int(1)?);
    let raw_dirs: Vec<Vec3> = match r.along {
        Some(_) => raw_dirs,
        None => (0..3)
            .map(|k| {
                let mut e = [zero; 3];
                e[k] = one;
                e
            })
            .collect(),
    };
    let mut raw = Vec::with_capacity(raw_dirs.len());
    for e in &raw_dirs {
        raw.push(dot(g, raw_v, *e)?);
    }
    let complete = match r.along.as_deref() {
        None => true,
        Some([d0, d1]) => {
            let n = cross(g, *d0, *d1)?;
            let c = dot(g, v, n)?;
            let c = expanded(g, c)?;
            g.is_zero(c)
        }
        Some(_) => false,
    };
    let mut rows = Vec::new();
    for (k, (c, raw_c)) in components.into_iter().zip(raw).enumerate() {
        if g.is_zero(c) {
            if r.along.is_some() {
                cx.error_spanned_by(&r.at, format!("the velocity component along direction {} is identically zero: that direction constrains nothing", k + 1));
            }
            continue;
        }
        rows.push(Row {
            value: c,
            at: r.at.clone(),
            holonomic: false,
            as_written: raw_c,
            direction: Some((contact, raw_dirs[k])),
            source: RowSource::Rolling {
                contact,
                direction: k,
            },
        });
    }
    if rows.is_empty() && r.along.is_none() {
        cx.error_spanned_by(&r.at, "this rolling contact constrains nothing: the contact point's velocity is identically zero");
    }
    let motion = ContactMotion {
        velocity: raw_v,
        complete,
    };
    Ok((motion, rows))
}

/// A holonomic row that is, identically, a rolling contact's material
/// velocity along the normal of its two `along` directions (the bicycle's
/// pitch constraint: the front contact's height rate is the vertical
/// velocity of the wheel's material point there, since that point is the
/// lowest of the rim) completes the contact.
fn complete_contacts(
    model: &mut Model,
    rolling: &[Rolling],
    calculus: &Calculus,
    rows: &mut [Row],
    contacts: &mut [ContactMotion],
) -> Result<(), SymbolicError> {
    for row in rows.iter_mut().filter(|r| r.holonomic) {
        for (contact, r) in rolling.iter().enumerate() {
            let Some([d0, d1]) = r.along.as_deref() else {
                continue;
            };
            if contacts[contact].complete {
                continue;
            }
            let g = &mut model.g;
            let body = &model.bodies[r.body];
            let omega = model.frames[body.frame.expect("rigid")].omega;
            let normal = cross(g, *d0, *d1)?;
            let candidate = rolling_components(
                g,
                body.center,
                omega,
                r.contact,
                Some(&[normal]),
                &calculus.rules,
            )?[0];
            if same_function(g, row.value, candidate) != Some(true) {
                continue;
            }
            let normal = match &calculus.twin {
                Some(t) => match t.rolling[contact].along.as_deref() {
                    Some([e0, e1]) => cross(g, *e0, *e1)?,
                    _ => continue,
                },
                None => normal,
            };
            contacts[contact].complete = true;
            row.direction = Some((contact, normal));
            break;
        }
    }
    Ok(())
}

/// Each row split into its coefficients of q̇ (a row of D) and the rest
/// (an entry of d); rows that read inputs or accelerations, are not linear
/// in q̇ or involve no rate are reported.
fn linear_rows(
    cx: &Ctxt,
    model: &mut Model,
    rows: Vec<Row>,
    holonomic: Vec<Id>,
    contacts: Vec<ContactMotion>,
) -> ConstraintRows {
    let rates = model.coordinate_rates();
    let driving: Vec<_> = model.input_rates.iter().map(|(s, _)| *s).collect();
    let mut out = ConstraintRows {
        holonomic,
        d: Vec::new(),
        d0: Vec::new(),
        at: Vec::new(),
        sources: Vec::new(),
        as_written: Vec::new(),
        directions: Vec::new(),
        contacts,
    };
    for row in rows {
        let span = &row.at;
        let bad: Vec<String> = model
            .g
            .dependencies(row.value)
            .iter()
            .filter(|s| match model.g.symbol_kind(*s) {
                // A driving input's rate is its companion input.
                SymbolKind::Input => !driving.contains(s),
                SymbolKind::Acceleration(_) => true,
                _ => false,
            })
            .map(|s| model.g.symbol_name(s).to_string())
            .collect();
        if !bad.is_empty() {
            cx.error_spanned_by(
                span,
                format!("a velocity constraint cannot depend on {} (an input may drive a constraint as written in `holonomic(...)` or `nonholonomic(...)`, not through a point, frame or rolling contact)", bad.join(", ")),
            );
            continue;
        }
        match model.g.linear_coefficients(row.value, &rates) {
            Ok(form) => {
                if form.coefficients.iter().all(|c| model.g.is_zero(*c)) {
                    cx.error_spanned_by(
                        span,
                        "this constraint does not involve any coordinate rate",
                    );
                    continue;
                }
                out.d.extend(form.coefficients);
                out.d0.push(form.remainder);
                out.as_written.push(row.as_written);
                out.directions.push(row.direction);
                out.sources.push(row.source);
                out.at.push(row.at);
            }
            Err(SymbolicError::NonLinear { symbol, .. }) => {
                let what = if row.holonomic {
                    "the differentiated holonomic constraint"
                } else {
                    "a nonholonomic constraint"
                };
                cx.error_spanned_by(
                    span,
                    format!("{what} must be linear in the coordinate rates (eq. 25: D(q,t) q̇ + d = 0), and this one is not linear in `{symbol}`"),
                );
            }
            Err(e) => cx.error_spanned_by(span, e),
        }
    }
    out
}

/// The components of a rolling contact's velocity, (v + ω × (P − centre))
/// along each direction (or in N), as written: not multiplied out.
pub(super) fn rolling_components(
    g: &mut appell_symbolic::Graph,
    center: Vec3,
    omega: Vec3,
    contact: Vec3,
    along: Option<&[Vec3]>,
    rules: &RateRules,
) -> Result<Vec<Id>, SymbolicError> {
    let mut v = center;
    let mut arm = center;
    for i in 0..3 {
        v[i] = g.time_derivative(center[i], rules)?;
        arm[i] = g.sub(contact[i], center[i])?;
    }
    let w = cross(g, omega, arm)?;
    for i in 0..3 {
        v[i] = g.add(v[i], w[i])?;
    }
    match along {
        Some(dirs) => dirs.iter().map(|d| dot(g, v, *d)).collect(),
        None => Ok(v.to_vec()),
    }
}

#[cfg(test)]
mod tests {
    use super::super::testing::{self, assert_agrees};
    use super::*;

    fn rows_of(src: &str) -> (Model, ConstraintRows) {
        let (mut model, calculus) = testing::model_and_calculus(src);
        let cx = Ctxt::new();
        let set = model.constraints.clone();
        let rows = constraint_rows(&cx, &mut model, &set, &calculus)
            .expect("rows")
            .expect("no errors");
        cx.check().expect("no errors");
        (model, rows)
    }

    #[test]
    fn a_holonomic_constraint_enters_through_its_time_derivative() {
        // x² + y² − l² = 0 → 2x ẋ + 2y ẏ = 0.
        let (mut m, rows) = rows_of(testing::CARTESIAN);
        assert_eq!(rows.sources, vec![RowSource::Holonomic { index: 0 }]);
        assert_eq!(rows.d.len(), 2);
        assert_agrees(&mut m.g, rows.d[0], "2*x");
        assert_agrees(&mut m.g, rows.d[1], "2*y");
        assert!(m.g.is_zero(rows.d0[0]));
        assert_agrees(&mut m.g, rows.holonomic[0], "x^2 + y^2 - l^2");
        assert_agrees(&mut m.g, rows.as_written[0], "2*x*x_dot + 2*y*y_dot");
    }

    #[test]
    fn a_knife_edge_is_one_nonholonomic_row() {
        // ẏ cos θ − ẋ sin θ = 0: D = [−sin θ, cos θ, 0], d = 0.
        let (mut m, rows) = rows_of(testing::SLEIGH);
        assert_eq!(rows.sources, vec![RowSource::Nonholonomic { index: 0 }]);
        assert_agrees(&mut m.g, rows.d[0], "-sin(theta)");
        assert_agrees(&mut m.g, rows.d[1], "cos(theta)");
        assert!(m.g.is_zero(rows.d[2]));
        assert!(m.g.is_zero(rows.d0[0]));
        assert!(rows.contacts.is_empty());
    }

    #[test]
    fn a_rolling_disc_on_a_line_gives_one_row_per_nonzero_component() {
        // v(material point at P) = (ẋ + r φ̇) N.x: the N.y and N.z rows are
        // identically zero and dropped.
        let (mut m, rows) = rows_of(
            r#"
            #[appell(coordinates(x, phi), speeds(phi))]
            #[appell(frame(B = N.rotate_z(phi)))]
            #[appell(point(D = O + x * N.x + r * N.y), point(P = D - r * N.y))]
            #[appell(body(disc, center = D, frame = B, mass = m, inertia = principal(i, i, j)))]
            #[appell(rolls(disc, contact = P))]
            struct Disc { m: f64, r: f64, i: f64, j: f64 }
            "#,
        );
        assert_eq!(
            rows.sources,
            vec![RowSource::Rolling {
                contact: 0,
                direction: 0
            }]
        );
        assert_agrees(&mut m.g, rows.d[0], "1");
        assert_agrees(&mut m.g, rows.d[1], "r");
        assert!(rows.contacts[0].complete);
        assert!(rows.directions[0].is_some_and(|(c, _)| c == 0));
        assert_agrees(&mut m.g, rows.contacts[0].velocity[0], "x_dot + r*phi_dot");
    }

    #[test]
    fn a_row_with_no_rate_is_reported() {
        let (mut model, calculus) = testing::model_and_calculus(
            r#"
            #[appell(coordinates(x, y), speeds(x))]
            #[appell(point(P = O + x * N.x + y * N.y), particle(P, mass = m))]
            #[appell(nonholonomic(x == 0))]
            struct Bad { m: f64 }
            "#,
        );
        let cx = Ctxt::new();
        let set = model.constraints.clone();
        let rows = constraint_rows(&cx, &mut model, &set, &calculus).expect("no engine error");
        assert!(rows.is_none());
        let err = cx.check().expect_err("an error").to_string();
        assert!(
            err.contains("does not involve any coordinate rate"),
            "{err}"
        );
    }

    #[test]
    fn an_input_drives_a_row_through_its_companion() {
        // dt(y) == w: D = [0, 1], d = −w; and x == c: D = [1, 0], d = −c_rate.
        let (mut m, rows) = rows_of(
            r#"
            #[appell(coordinates(x, y), speeds())]
            #[appell(point(P = O + x * N.x + y * N.y), particle(P, mass = m))]
            #[appell(holonomic(x == c), nonholonomic(dt(y) == w), inputs(w, c))]
            #[appell(force(P, w * N.x, effect = push))]
            struct Driven { m: f64 }
            "#,
        );
        let names: Vec<String> = m.inputs.iter().map(|(i, _)| i.to_string()).collect();
        assert_eq!(names, ["w", "c", "w_rate", "c_rate", "c_accel"]);
        assert_eq!(m.input_rates.len(), 3);
        assert_agrees(&mut m.g, rows.d[0], "1");
        assert_agrees(&mut m.g, rows.d0[0], "-c_rate");
        assert_agrees(&mut m.g, rows.d[3], "1");
        assert_agrees(&mut m.g, rows.d0[1], "-w");
    }

    #[test]
    fn an_input_through_a_point_has_no_rate_and_is_reported() {
        let (mut model, calculus) = testing::model_and_calculus(
            r#"
            #[appell(coordinates(x, phi), speeds(phi))]
            #[appell(frame(B = N.rotate_z(phi)))]
            #[appell(point(D = O + x * N.x + (r + w) * N.y), point(P = D - (r + w) * N.y))]
            #[appell(body(disc, center = D, frame = B, mass = m, inertia = principal(i, i, j)))]
            #[appell(rolls(disc, contact = P), inputs(w))]
            struct Disc { m: f64, r: f64, i: f64, j: f64 }
            "#,
        );
        let cx = Ctxt::new();
        let set = model.constraints.clone();
        let out = constraint_rows(&cx, &mut model, &set, &calculus);
        assert!(out.is_err() || cx.has_errors());
        let _ = cx.check();
    }
}
