//! Contacts (`contact(link, point | flat)`): their rows, held only in the
//! scenes that name their effects, and the privileged speeds such a scene
//! takes when it names none: each contact makes the joints nearest its link
//! dependent, as many as it has rows (a leg's joints under a stance foot),
//! so the base and the free legs keep theirs.

use appell_symbolic::{Graph, Symbol, Tape};

use super::bodies::Side;
use super::builder::{hint, Builder};
use super::{Constraint, SpeedSpec, Vec3};
use crate::ast::JointKind;
use crate::ast::*;
use crate::probe::{pseudo_value, Basis};

/// A resolved contact.
#[derive(Clone)]
pub struct Contact {
    /// The frame in contact.
    pub link: syn::Ident,
    /// The effect whose scenes hold it.
    pub effect: String,
    /// Whether its frame's turning is held too.
    pub flat: bool,
    /// Its rows: the origin's velocity along N's axes (identically zero
    /// components dropped), then for a flat contact the frame's angular
    /// velocity, each with its axis.
    pub rows: Vec<Constraint>,
    /// The link's origin (N components).
    pub origin: Vec3,
}

impl Builder<'_> {
    /// The model's contacts; a link that no joint made is reported.
    pub(super) fn contacts(&mut self, ast: &ModelAst) -> Vec<Contact> {
        let mut out = Vec::new();
        for c in &ast.contacts {
            let Some((_, origin)) = ast.origins.iter().find(|(f, _)| *f == c.link) else {
                let h = hint(
                    &c.link.to_string(),
                    ast.origins.iter().map(|(f, _)| f.to_string()),
                );
                self.cx.error_spanned_by(
                    &c.link,
                    format!("`contact` names a frame a joint made (a URDF link), and `{}` is not one{h}", c.link),
                );
                continue;
            };
            if out.iter().any(|o: &Contact| o.link == c.link) {
                self.cx
                    .error_spanned_by(&c.link, format!("`{}` has a contact already", c.link));
                continue;
            }
            let Some(position) = self.points.iter().find(|p| *origin == p.name) else {
                continue;
            };
            let position = position.pos;
            let index = out.len();
            let mut rows = Vec::new();
            for (k, def) in contact_rows(c, origin).iter().enumerate() {
                rows.extend(self.contact_row(def, (index, 3 * k)));
            }
            out.push(Contact {
                link: c.link.clone(),
                effect: c.effect.to_string(),
                flat: c.flat,
                rows,
                origin: position,
            });
        }
        out
    }
}

impl Builder<'_> {
    /// The N components of a contact's vector equation, identically zero
    /// ones dropped, each tagged with its contact and axis (`first` the
    /// axis of its x component).
    fn contact_row(
        &mut self,
        def: &ConstraintDef,
        (contact, first): (usize, usize),
    ) -> Vec<Constraint> {
        self.context = "a contact".to_string();
        let Some(Side::Vector(l, r)) = self.constraint_sides(def) else {
            return Vec::new();
        };
        let mut rows = Vec::new();
        for axis in 0..3 {
            match self.g.sub(l[axis], r[axis]) {
                Ok(residual) if self.g.is_zero(residual) => {}
                Ok(residual) => rows.push(Constraint {
                    residual,
                    at: def.at.clone(),
                    effect: def.effect.as_ref().map(|e| e.to_string()),
                    contact: Some((contact, first + axis)),
                }),
                Err(e) => self.cx.error_spanned_by(&def.at, e),
            }
        }
        rows
    }
}

/// `velocity(origin) == 0`, and for a flat contact `omega(link) == 0`.
fn contact_rows(c: &ContactDef, origin: &syn::Ident) -> Vec<ConstraintDef> {
    let span = c.link.span();
    let call = |f: &str, arg: &syn::Ident| {
        Expr::Call(
            syn::Ident::new(f, span),
            vec![Expr::Name(arg.clone())],
            span,
        )
    };
    let row = |lhs: Expr| ConstraintDef {
        lhs,
        rhs: Expr::Int(0, span),
        along: None,
        effect: Some(c.effect.clone()),
        at: c.at.clone(),
    };
    let mut rows = vec![row(call("velocity", origin))];
    if c.flat {
        rows.push(row(call("omega", &c.link)));
    }
    rows
}

/// The privileged speeds of a scene that holds `held` (contacts) and names
/// no speeds: `speeds` less, for each contact in turn, joints above its
/// link (nearest first, not taken already) whose columns in the contact's
/// rows are independent (numerically, at pseudo-random configurations),
/// as many as its rows: an ankle whose axis passes through the foot's
/// origin moves no point contact and is passed over. An error names the
/// contact whose leg has too few.
pub(super) fn scene_speeds(
    g: &mut Graph,
    ast: &ModelAst,
    rates: &[(String, Symbol)],
    held: &[&Contact],
    speeds: &[SpeedSpec],
) -> Result<Vec<SpeedSpec>, String> {
    let mut dependent: Vec<String> = Vec::new();
    for c in held {
        let path = one_axis_joints_above(ast, &c.link);
        let free: Vec<&String> = path
            .iter()
            .filter(|q| !dependent.contains(q) && speeds.iter().any(|s| s.name == **q))
            .collect();
        let rows = c.rows.len();
        let chosen = independent_columns(g, c, rates, &free, rows).map_err(|e| e.to_string())?;
        if chosen.len() < rows {
            let names: Vec<String> = free.iter().map(|q| format!("`{q}`")).collect();
            let above = match names.len() {
                0 => "no revolute or prismatic joint above it is free to give way".to_string(),
                k => format!(
                    "the {k} revolute or prismatic joint{} above it free to give way ({}) move{} it along {} of them",
                    if k == 1 { "" } else { "s" },
                    names.join(", "),
                    if k == 1 { "s" } else { "" },
                    chosen.len()
                ),
            };
            return Err(format!(
                "the contact of `{}` holds {rows} rows, and {above}: name the scene's privileged speeds with `speeds(...)`",
                c.link
            ));
        }
        dependent.extend(chosen);
    }
    Ok(speeds
        .iter()
        .filter(|s| !dependent.contains(&s.name))
        .cloned()
        .collect())
}

/// Of `candidates` (joint coordinates, in order), the first ones whose
/// columns ∂(row)/∂q̇ in `c`'s rows are independent of those chosen before
/// them, up to `rows`: the most found at any of three pseudo-random
/// configurations.
fn independent_columns(
    g: &mut Graph,
    c: &Contact,
    rates: &[(String, Symbol)],
    candidates: &[&String],
    rows: usize,
) -> Result<Vec<String>, appell_symbolic::SymbolicError> {
    let mut columns = Vec::with_capacity(candidates.len() * rows);
    for q in candidates {
        let rate = rates.iter().find(|(name, _)| name == *q).map(|(_, r)| *r);
        for row in &c.rows {
            columns.push(match rate {
                Some(r) => g.diff(row.residual, r)?,
                None => g.int(0)?,
            });
        }
    }
    let tape = Tape::new(g, &columns);
    let mut best: Vec<String> = Vec::new();
    for trial in 0..3u64 {
        let value = |s: Symbol| Some(pseudo_value(g, s, trial));
        let Ok(values) = tape.eval(&value) else {
            continue;
        };
        let mut basis = Basis::default();
        let mut chosen = Vec::new();
        for (k, q) in candidates.iter().enumerate() {
            if chosen.len() == rows {
                break;
            }
            if basis.extends(&values[k * rows..(k + 1) * rows]) {
                chosen.push((*q).clone());
            }
        }
        if chosen.len() > best.len() {
            best = chosen;
        }
    }
    Ok(best)
}

/// The coordinates of the revolute and prismatic joints from `link` up to
/// the ground, nearest first (mimic and other dependent joints left out).
fn one_axis_joints_above(ast: &ModelAst, link: &syn::Ident) -> Vec<String> {
    let mut out = Vec::new();
    let mut frame = link.clone();
    while let Some(j) = ast.joints.iter().find(|j| j.child == frame) {
        if matches!(j.kind, JointKind::Revolute(_) | JointKind::Prismatic(_)) && !j.dependent {
            out.push(j.name.to_string());
        }
        frame = j.parent.clone();
    }
    out
}

#[cfg(test)]
mod tests {
    use crate::ctxt::Ctxt;
    use crate::{model, parse};

    /// A body on a leg of `joints` revolute joints (a hip roll about x,
    /// then pitches about y), a foot at its end.
    fn leg(joints: usize, scene: &str) -> String {
        let mut src = String::from("#[appell(joint(base, free, parent = N, child = B))]\n");
        src += "#[appell(body(B, frame = B, center = origin(B), mass = 1.0, inertia = principal(0.1, 0.1, 0.1)))]\n";
        let mut parent = "B".to_string();
        for k in 0..joints {
            let axis = if k == 0 { "x" } else { "y" };
            src += &format!("#[appell(joint(j{k}, revolute({axis}), parent = {parent}, child = L{k}, xyz = [0.0, 0.0, -0.2]))]\n");
            src += &format!("#[appell(body(L{k}, frame = L{k}, center = origin(L{k}), mass = 0.1, inertia = principal(0.01, 0.01, 0.01)))]\n");
            parent = format!("L{k}");
        }
        src += &format!(
            "#[appell(joint(ankle, weld, parent = {parent}, child = F, xyz = [0.0, 0.0, -0.2]))]\n"
        );
        src += "#[appell(contact(F, point, effect = down), gravity(-9.81 * N.z))]\n";
        src + scene + "\nstruct Leg;"
    }

    fn build(src: &str) -> (Ctxt, Option<model::Kinematics>) {
        let cx = Ctxt::new();
        let input: syn::DeriveInput = syn::parse_str(src).unwrap();
        let ast = parse::parse(&cx, &input);
        let k = model::build(&cx, &ast);
        (cx, k)
    }

    #[test]
    fn a_held_foot_takes_the_speeds_of_the_nearest_joints_that_move_it_apart() {
        let (cx, k) = build(&leg(
            4,
            "#[appell(scene(standing, effects(gravity, down)))]",
        ));
        cx.check().expect("no errors");
        let model = k.expect("a model").model;
        // The rows are the foot's velocity along N's axes; the model
        // itself holds none of them.
        assert_eq!(model.contacts[0].rows.len(), 3);
        assert!(model.constraints.nonholonomic.is_empty());
        // j3, j2 and j1 pitch about parallel axes: the foot's sideways
        // row needs the roll j0, and j1 keeps its speed.
        let (speeds, _) = model.scenes[0].speeds.clone().expect("speeds");
        let names: Vec<&str> = speeds.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(
            names,
            ["base_wx", "base_wy", "base_wz", "base_x", "base_y", "base_z", "j1"]
        );
    }

    #[test]
    fn a_leg_too_short_for_its_foot_is_an_error_naming_its_joints() {
        let (cx, _) = build(&leg(
            2,
            "#[appell(scene(standing, effects(gravity, down)))]",
        ));
        let errors = cx.check().expect_err("an error").to_string();
        assert!(
            errors.contains("holds 3 rows, and the 2 revolute or prismatic joints above it free to give way (`j1`, `j0`) move it along 2 of them"),
            "{errors}"
        );
    }
}
