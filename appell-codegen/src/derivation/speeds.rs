//! Stage 2: the privileged speeds ẏ_k and the unknown rates.
//!
//! Each speed is defined by u = W q̇ + w: a unit row of W for a coordinate
//! rate (Method II), or the defining combination of a quasi-velocity
//! (Method III), which must be linear in q̇. The stage checks that
//! the constraint rows are independent, that l + m = n, that [D; W] is
//! invertible with quasi-velocities, and that each holonomic constraint
//! involves a dependent coordinate. The unknowns are the dependent rates ż
//! (Method II) or every rate (Method III, [D; W] q̇ = [−d; u − w]).

use appell_symbolic::{Id, SymbolKind, SymbolicError};

use super::rows::ConstraintRows;
use crate::ctxt::Ctxt;
use crate::model::{Constraint, ConstraintSet, Model, SpeedSpec};
use crate::probe::dependent_row;
use appell_core::RowSource;

/// The output of stage 2.
#[derive(Clone)]
pub struct SpeedDefinitions {
    /// W (l×n), row-major.
    pub w: Vec<Id>,
    /// w (l).
    pub w0: Vec<Id>,
    /// Whether some speed is a quasi-velocity (Method III).
    pub quasi: bool,
    /// The coordinates whose rates are unknowns: the dependent ones, or
    /// every coordinate with quasi-velocities.
    pub dependent: Vec<usize>,
}

/// What to say of a constraint row that the others already imply. Two
/// rolling contacts are the likely case: wheels on one axle each told not
/// to slip sideways give the same row twice.
fn dependent_row_message(
    model: &Model,
    set: &ConstraintSet,
    rows: &ConstraintRows,
    row: usize,
) -> String {
    let plain = "this constraint row is a linear combination of the others (the velocity constraints are linearly dependent); drop it, or give a rolling contact `along = [...]` directions";
    let RowSource::Rolling { contact, .. } = rows.sources[row] else {
        return plain.to_string();
    };
    let others = rows.sources[..row]
        .iter()
        .any(|s| matches!(s, RowSource::Rolling { contact: c, .. } if *c != contact));
    if !others {
        return plain.to_string();
    }
    let body = &model.bodies[set.rolling[contact].body].name;
    format!(
        "this row of `{body}`'s rolling contact is a linear combination of the other contacts' rows (the velocity constraints are linearly dependent): wheels on one axle share the row that keeps the axle from sliding sideways; keep it on one wheel and give this one only its rolling direction, e.g. `along = [A.x]` with A.x the direction the wheel rolls along"
    )
}

/// Stage 2. `None` when errors were recorded in `cx`.
pub fn speed_definitions(
    cx: &Ctxt,
    model: &mut Model,
    set: &ConstraintSet,
    rows: &ConstraintRows,
) -> Result<Option<SpeedDefinitions>, SymbolicError> {
    let n = model.coords.len();
    let m = rows.d0.len();
    let l = set.speed_specs.len();
    let quasi = set.speed_specs.iter().any(|s| s.definition.is_some());
    let (zero, one) = (model.g.int(0)?, model.g.int(1)?);
    let mut w = Vec::with_capacity(l * n);
    let mut w0 = Vec::with_capacity(l);
    for spec in set.speed_specs.clone() {
        match (spec.coordinate, spec.definition) {
            (Some(r), _) => {
                w.extend((0..n).map(|c| if c == r { one } else { zero }));
                w0.push(zero);
            }
            (None, Some(def)) => {
                if let Some((row, rest)) = quasi_velocity_row(cx, model, set, &spec, def) {
                    w.extend(row);
                    w0.push(rest);
                }
            }
            (None, None) => unreachable!("a speed is a coordinate or a definition"),
        }
    }
    if cx.has_errors() {
        return Ok(None);
    }
    if let Some(row) = dependent_row(&model.g, &rows.d, n, m) {
        cx.error_spanned_by(&rows.at[row], dependent_row_message(model, set, rows, row));
        return Ok(None);
    }
    if m >= n {
        cx.error_spanned_by(
            &set.speeds_at,
            format!(
                "the model has no degree of freedom: its {m} velocity constraint(s) fix all {n} coordinate(s), so no speed is independent and nothing moves; drop a constraint or add a coordinate"
            ),
        );
        return Ok(None);
    }
    if !model.speeds_declared {
        cx.error_spanned_by(
            &set.speeds_at,
            format!(
                "the model declares no `speeds(...)`: its {m} velocity constraint(s) on {n} coordinates leave {} independent speed(s); name the coordinates whose rates they are",
                n - m
            ),
        );
        return Ok(None);
    }
    if l + m != n {
        let joints = if model.joint_speeds.is_empty() {
            String::new()
        } else {
            format!(
                "; joints add the rates of {} unless written with `dependent`",
                model.joint_speeds.join(", ")
            )
        };
        cx.error_spanned_by(
            &set.speeds_at,
            format!(
                "{l} privileged speed(s) with {m} velocity constraint(s) on {n} coordinates: the constraints leave {} independent speed(s), so `speeds(...)` must name {}{joints}",
                n.saturating_sub(m),
                n.saturating_sub(m)
            ),
        );
        return Ok(None);
    }
    if quasi {
        let mut full = rows.d.clone();
        full.extend(&w);
        if let Some(row) = dependent_row(&model.g, &full, n, n) {
            let name = &set.speed_specs[row.saturating_sub(m).min(l - 1)].name;
            cx.error_spanned_by(
                &set.speeds_at,
                format!("the speeds' definitions are not invertible: with the constraints they do not determine the coordinate rates ([D; W] is singular; `{name}` depends on the others)"),
            );
            return Ok(None);
        }
    }
    let dependent: Vec<usize> = if quasi {
        (0..n).collect()
    } else {
        (0..n).filter(|i| !set.speeds.contains(i)).collect()
    };
    check_holonomic_involve_dependent(cx, model, &set.holonomic, &dependent);
    if cx.has_errors() {
        return Ok(None);
    }
    Ok(Some(SpeedDefinitions {
        w,
        w0,
        quasi,
        dependent,
    }))
}

/// A quasi-velocity's row of W and entry of w; `None` (with an error
/// recorded) when its definition is not a linear combination of q̇.
fn quasi_velocity_row(
    cx: &Ctxt,
    model: &mut Model,
    set: &ConstraintSet,
    spec: &SpeedSpec,
    def: Id,
) -> Option<(Vec<Id>, Id)> {
    let rates = model.coordinate_rates();
    let bad: Vec<String> = model
        .g
        .dependencies(def)
        .iter()
        .filter(|s| {
            matches!(
                model.g.symbol_kind(*s),
                SymbolKind::Input | SymbolKind::Acceleration(_) | SymbolKind::Auxiliary
            )
        })
        .map(|s| model.g.symbol_name(s).to_string())
        .collect();
    if !bad.is_empty() {
        cx.error_spanned_by(
            &set.speeds_at,
            format!(
                "the quasi-velocity `{}` cannot depend on {}; to prescribe a speed by an input, write it as a constraint (`nonholonomic(dt(q) == input)`) and leave that rate out of `speeds(...)`",
                spec.name,
                bad.join(", ")
            ),
        );
        return None;
    }
    match model.g.linear_coefficients(def, &rates) {
        Ok(form) => {
            if form.coefficients.iter().all(|c| model.g.is_zero(*c)) {
                cx.error_spanned_by(
                    &set.speeds_at,
                    format!(
                        "the quasi-velocity `{}` involves no coordinate rate",
                        spec.name
                    ),
                );
                return None;
            }
            Some((form.coefficients, form.remainder))
        }
        Err(SymbolicError::NonLinear { symbol, .. }) => {
            cx.error_spanned_by(
                &set.speeds_at,
                format!("the quasi-velocity `{}` must be linear in the coordinate rates (Method III), and it is not linear in `{symbol}`", spec.name),
            );
            None
        }
        Err(e) => {
            cx.error_spanned_by(&set.speeds_at, e);
            None
        }
    }
}

/// A holonomic constraint among privileged coordinates only would restrict
/// the privileged speeds, which must stay independent.
fn check_holonomic_involve_dependent(
    cx: &Ctxt,
    model: &Model,
    holonomic: &[Constraint],
    dependent: &[usize],
) {
    for c in holonomic {
        let involves_dependent = dependent
            .iter()
            .any(|&i| model.g.depends_on(c.residual, model.coords[i].1.q));
        if !involves_dependent {
            cx.error_spanned_by(
                &c.at,
                "this holonomic constraint involves no dependent coordinate: it would restrict the privileged speeds, which must stay independent; leave one of its coordinates out of `speeds(...)`",
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::rows::constraint_rows;
    use super::super::testing::{self, assert_agrees};
    use super::*;

    fn definitions(src: &str) -> (Model, Option<SpeedDefinitions>, Result<(), String>) {
        let (mut model, calculus) = testing::model_and_calculus(src);
        let cx = Ctxt::new();
        let set = model.constraints.clone();
        let rows = constraint_rows(&cx, &mut model, &set, &calculus)
            .expect("rows")
            .expect("no errors");
        let speeds = speed_definitions(&cx, &mut model, &set, &rows).expect("no engine error");
        let checked = cx.check().map_err(|e| e.to_string());
        (model, speeds, checked)
    }

    #[test]
    fn coordinate_speeds_are_unit_rows_of_w() {
        let (m, speeds, ok) = definitions(testing::SLEIGH);
        ok.expect("no errors");
        let s = speeds.expect("definitions");
        let one = |e: &Id| m.g.as_number(*e).map(|n| n.to_f64());
        let w: Vec<Option<f64>> = s.w.iter().map(one).collect();
        let (o, z) = (Some(1.0), Some(0.0));
        assert_eq!(w, vec![o, z, z, z, z, o]);
        assert!(s.w0.iter().all(|e| m.g.is_zero(*e)));
        assert!(!s.quasi);
        assert_eq!(s.dependent, vec![1]);
    }

    #[test]
    fn a_quasi_velocity_is_its_defining_row_and_every_rate_is_unknown() {
        // v = velocity(P)·B.x = ẋ cos θ + ẏ sin θ, w = θ̇ (Method III).
        let (mut m, speeds, ok) = definitions(
            r#"
            #[appell(coordinates(x, y, theta), positive(m, b))]
            #[appell(speeds(v = dot(velocity(P), B.x), w = dot(omega(B), N.z)))]
            #[appell(frame(B = N.rotate_z(theta)))]
            #[appell(point(P = O + x * N.x + y * N.y), point(C = P + b * B.x))]
            #[appell(body(sleigh, center = C, frame = B, mass = m, inertia = principal(i0, i0, i0)))]
            #[appell(nonholonomic(dt(y) * cos(theta) - dt(x) * sin(theta) == 0))]
            struct Sleigh { m: f64, b: f64, i0: f64 }
            "#,
        );
        ok.expect("no errors");
        let s = speeds.expect("definitions");
        assert!(s.quasi);
        assert_eq!(s.dependent, vec![0, 1, 2]);
        assert_agrees(&mut m.g, s.w[0], "cos(theta)");
        assert_agrees(&mut m.g, s.w[1], "sin(theta)");
        assert!(m.g.is_zero(s.w[2]));
        assert_agrees(&mut m.g, s.w[5], "1");
    }

    #[test]
    fn a_wrong_number_of_speeds_is_reported_with_the_right_count() {
        let (_, speeds, checked) =
            definitions(&testing::SLEIGH.replace("speeds(x, theta)", "speeds(x, y, theta)"));
        assert!(speeds.is_none());
        let err = checked.expect_err("an error");
        assert!(err.contains("must name 2"), "{err}");
    }
}
