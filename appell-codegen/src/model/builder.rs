//! The builder: declares the symbols, then resolves frames, points,
//! bodies, constraints, loads, rolling contacts, speeds and scenes in that
//! order, each step reading the names the earlier ones declared.

use syn::Ident;

use appell_symbolic::{Coordinate, Graph, Id, RateRules, Symbol, SymbolKind, SymbolicError};

use super::{ConstraintSet, Cut, Frame, Mat3, Model, Param, Point, SpeedSpec, Vec3};
use crate::ast::*;
use crate::ctxt::{did_you_mean, Ctxt};

/// Resolves one model: the names declared so far and the graph they live in.
pub(super) struct Builder<'a> {
    pub(super) cx: &'a Ctxt,
    pub(super) g: Graph,
    pub(super) params: Vec<Param>,
    pub(super) coords: Vec<(Ident, Coordinate)>,
    pub(super) inputs: Vec<(Ident, Symbol)>,
    pub(super) time: Symbol,
    pub(super) frames: Vec<Frame>,
    pub(super) points: Vec<Point>,
    /// Frames and points whose definition failed: references to them are
    /// not reported again.
    pub(super) poisoned: Vec<String>,
    /// The definition being evaluated (for `norms`).
    pub(super) context: String,
    pub(super) norms: Vec<(Id, String)>,
    /// Divisors made of parameters alone, with where they occur.
    pub(super) divisors: Vec<(Id, String)>,
    /// Quaternion frames' coordinates (see `Model::quaternions`).
    pub(super) quaternions: Vec<[usize; 4]>,
    /// When building the twin: the model's frame matrices, whose entries
    /// become symbols.
    pub(super) cut_from: Option<Vec<Mat3>>,
    pub(super) cuts: Vec<Cut>,
    pub(super) rules: RateRules,
    /// Every declared frame and point, built or not yet: a name used
    /// before its declaration is reported as such.
    pub(super) declared: Vec<Ident>,
    /// Frames made by joints (and URDF roots) with their origin points,
    /// for `origin(F)`.
    pub(super) origins: Vec<(Ident, Ident)>,
}

pub(super) fn engine_error(cx: &Ctxt, span: proc_macro2::Span, e: SymbolicError) {
    cx.error_at(span, e);
}

/// One build of the model from `ast` in `g`; with `cut_from` (the model's
/// frame matrices), the twin's build, whose direction cosines become
/// symbols. Returns the model and the direction-cosine symbols made.
pub(super) fn build_in(
    cx: &Ctxt,
    ast: &ModelAst,
    g: Graph,
    cut_from: Option<Vec<Mat3>>,
) -> Option<(Model, Vec<Cut>)> {
    let mut b = Builder::new(cx, ast, g, cut_from);
    b.declare_symbols(ast);
    if b.cut_from.is_none() {
        duplicate_bodies(cx, ast);
    }
    b.frames_and_points(ast)?;
    let bodies: Vec<super::Body> = ast
        .bodies
        .iter()
        .filter_map(|d| b.add_body(d, !ast.unchecked_inertia.contains(&d.name.to_string())))
        .collect();
    let holonomic: Vec<_> = ast.holonomic.iter().flat_map(|c| b.constraint(c)).collect();
    let nonholonomic: Vec<_> = ast
        .nonholonomic
        .iter()
        .flat_map(|c| b.constraint(c))
        .collect();
    let input_rates = b.driving_inputs(&holonomic, &nonholonomic);
    let loads = b.loads(ast, &bodies)?;
    let rolling = b.rolling_contacts(ast, &bodies);
    let contacts = b.contacts(ast);
    let (speed_specs, speeds_at) = b.speeds(ast);
    let speeds: Vec<usize> = speed_specs.iter().filter_map(|s| s.coordinate).collect();
    let named = holonomic
        .iter()
        .chain(&nonholonomic)
        .map(|c| &c.effect)
        .chain(rolling.iter().map(|r| &r.effect));
    let (effects, constraint_effects) = effects(&loads.effects, named.flatten(), &contacts);
    let scenes = b.scenes(ast, &effects, &constraint_effects, &speed_specs, &contacts);
    if bodies.is_empty() && !cx.has_errors() {
        cx.error_at(
            ast.name.span(),
            "the model has no `body(...)` or `particle(...)`: there is nothing to move",
        );
    }
    if cx.has_errors() {
        return None;
    }
    // The tree's numbers in the graph last, after everything the model
    // itself makes; the twin (built again in the same graph) keeps none.
    let tree = match b.cut_from {
        Some(_) => Err("the twin keeps no tree".to_string()),
        None => lowered_tree(cx, ast, &mut b.g),
    };
    let model = Model {
        g: b.g,
        name: ast.name.clone(),
        params: b.params,
        coords: b.coords,
        constraints: ConstraintSet {
            holonomic,
            nonholonomic,
            rolling,
            speeds,
            speed_specs,
            speeds_at,
        },
        speeds_declared: ast.speeds.is_some(),
        inputs: b.inputs,
        input_rates,
        time: b.time,
        frames: b.frames,
        points: b.points,
        bodies,
        contacts,
        joint_limits: ast.joint_limits.clone(),
        forces: loads.forces,
        torques: loads.torques,
        effects,
        scenes,
        gravity: loads.gravity,
        jacobian: ast.jacobian,
        norms: b.norms,
        divisors: b.divisors,
        quaternions: b.quaternions,
        joint_speeds: ast.joint_speeds.iter().map(|q| q.to_string()).collect(),
        files: ast.files.clone(),
        tree,
    };
    Some((model, b.cuts))
}

/// The tree of joints with its numbers in `g`, or why the model is not one.
/// A number that cannot be lowered (every name in it was resolved with the
/// model, so this is not the model's fault) is an error, not a quiet
/// fallback to the closed form.
fn lowered_tree(cx: &Ctxt, ast: &ModelAst, g: &mut Graph) -> Result<super::tree::TreeSpec, String> {
    let spec = super::tree::tree_spec(ast)?;
    spec.lower(g).map_err(|e| {
        let why = format!("lowering the joint tree's numbers failed: {e}");
        cx.error_at(ast.name.span(), why.clone());
        why
    })
}

/// Every effect (the loads', then those only constraints name, then the
/// contacts'), and those the constraints name. A contact's effect adds its
/// rows where named: leaving it out is the model as declared.
fn effects<'a>(
    loads: &[String],
    constraints: impl Iterator<Item = &'a String>,
    contacts: &[super::Contact],
) -> (Vec<String>, Vec<String>) {
    let mut effects = loads.to_vec();
    let mut constraint_effects: Vec<String> = Vec::new();
    for e in constraints {
        if !constraint_effects.contains(e) {
            constraint_effects.push(e.clone());
        }
        if !effects.contains(e) {
            effects.push(e.clone());
        }
    }
    for c in contacts {
        if !effects.contains(&c.effect) {
            effects.push(c.effect.clone());
        }
    }
    (effects, constraint_effects)
}

impl<'a> Builder<'a> {
    /// A builder of `ast` in the fresh graph `g` (see [`build_in`]).
    fn new(cx: &'a Ctxt, ast: &ModelAst, mut g: Graph, cut_from: Option<Vec<Mat3>>) -> Builder<'a> {
        let time = g.time().expect("fresh graph");
        Builder {
            cx,
            g,
            params: Vec::new(),
            coords: Vec::new(),
            inputs: Vec::new(),
            time,
            frames: Vec::new(),
            points: Vec::new(),
            poisoned: Vec::new(),
            context: String::new(),
            norms: Vec::new(),
            divisors: Vec::new(),
            quaternions: Vec::new(),
            cut_from,
            cuts: Vec::new(),
            rules: RateRules::coordinates(),
            declared: ast
                .frames
                .iter()
                .map(|f| f.name.clone())
                .chain(ast.points.iter().map(|p| p.name.clone()))
                .collect(),
            origins: ast.origins.clone(),
        }
    }
}

/// Names every model has: the inertial frame, its origin, time.
const RESERVED: &[&str] = &["N", "O", "t"];

impl Builder<'_> {
    /// The inertial frame N and its origin O, then the model's frames and
    /// points in order; a definition that fails poisons its name, so that
    /// later references to it are not reported again.
    pub(super) fn frames_and_points(&mut self, ast: &ModelAst) -> Option<()> {
        let (zero, one) = match (self.g.int(0), self.g.int(1)) {
            (Ok(zero), Ok(one)) => (zero, one),
            (Err(e), _) | (_, Err(e)) => {
                engine_error(self.cx, ast.name.span(), e);
                return None;
            }
        };
        self.frames.push(Frame {
            name: "N".into(),
            rot: [[one, zero, zero], [zero, one, zero], [zero, zero, one]],
            omega: [zero; 3],
        });
        self.points.push(Point {
            name: "O".into(),
            pos: [zero; 3],
        });
        for f in &ast.frames {
            let before = self.frames.len();
            self.add_frame(f);
            if self.frames.len() == before {
                self.poisoned.push(f.name.to_string());
            }
        }
        for p in &ast.points {
            let before = self.points.len();
            self.add_point(p);
            if self.points.len() == before {
                self.poisoned.push(p.name.to_string());
            }
        }
        Some(())
    }

    pub(super) fn declare_symbols(&mut self, ast: &ModelAst) {
        let mut seen: Vec<(String, &'static str)> = Vec::new();
        let mut check = |cx: &Ctxt, ident: &Ident, what: &'static str| -> bool {
            let name = ident.to_string();
            // Reported, but still declared: references to it resolve and
            // raise nothing more.
            not_raw(cx, ident, what);
            if RESERVED.contains(&name.as_str()) {
                cx.error_spanned_by(
                    ident,
                    format!(
                        "`{name}` is reserved (N is the Newtonian frame, O its origin, t time)"
                    ),
                );
                return false;
            }
            if name.ends_with("_dot") || name.ends_with("_ddot") {
                cx.error_spanned_by(
                    ident,
                    format!("`{name}`: names ending in `_dot` or `_ddot` are reserved for rates"),
                );
                return false;
            }
            if let Some((_, other)) = seen.iter().find(|(n, _)| *n == name) {
                let note = urdf_note(ast, &name);
                if *other == what {
                    cx.error_spanned_by(ident, format!("duplicate {what} `{name}`{note}"));
                } else {
                    cx.error_spanned_by(ident, format!("`{name}` is already a {other}{note}"));
                }
                return false;
            }
            seen.push((name, what));
            true
        };
        for f in &ast.fields {
            if check(self.cx, &f.name, "parameter") {
                let s = self.g.parameter(&f.name.to_string()).expect("fresh name");
                let positive = ast.positive.iter().any(|p| *p == f.name || *p == f.field);
                self.params.push(Param {
                    ident: f.name.clone(),
                    symbol: s,
                    positive,
                    field: f.field.clone(),
                    index: f.index,
                });
            }
        }
        for p in &ast.positive {
            if !ast.fields.iter().any(|f| f.name == *p || f.field == *p) {
                let hint = hint(
                    &p.to_string(),
                    ast.fields.iter().map(|f| f.name.to_string()),
                );
                self.cx.error_spanned_by(
                    p,
                    format!("`positive` names a parameter, and `{p}` is not one{hint}"),
                );
            }
        }
        if ast.coordinates.is_empty() {
            // A URDF of one rigid body (a quadrotor) held by a fixed base.
            let urdf = if ast.files.is_empty() {
                ""
            } else {
                "; the URDF's joints are all fixed, so its robot moves only on a base of its own: `urdf(\"...\", base = free)`"
            };
            self.cx
                .error_at(ast.name.span(), format!("the model declares no coordinates, so nothing in it moves: declare `coordinates(...)` (or a joint that is not welded), then name their independent rates in `speeds(...)`{urdf}"));
        }
        for c in &ast.coordinates {
            if check(self.cx, c, "coordinate") {
                let coord = self.g.coordinate(&c.to_string()).expect("fresh name");
                self.coords.push((c.clone(), coord));
            }
        }
        for i in &ast.inputs {
            if check(self.cx, i, "input") {
                let s = self.g.input(&i.to_string()).expect("fresh name");
                self.inputs.push((i.clone(), s));
            }
        }
        for f in &ast.frames {
            if check(self.cx, &f.name, "frame") {}
        }
        for p in &ast.points {
            if check(self.cx, &p.name, "point") {}
        }
    }

    pub(super) fn speeds(&mut self, ast: &ModelAst) -> (Vec<SpeedSpec>, proc_macro2::TokenStream) {
        let Some((list, at)) = &ast.speeds else {
            // The speeds stage says how many to name once the constraints
            // are counted (no coordinates at all is reported above).
            let name = &ast.name;
            return (Vec::new(), quote::quote!(#name));
        };
        let mut out: Vec<SpeedSpec> = Vec::new();
        for s in list {
            let name = s.name.to_string();
            if out.iter().any(|o| o.name == name) {
                self.cx
                    .error_spanned_by(&s.name, format!("duplicate speed `{name}`"));
                continue;
            }
            match &s.definition {
                None => match self.coords.iter().position(|(c, _)| *c == s.name) {
                    Some(i) => {
                        let c = self.coords[i].1;
                        out.push(SpeedSpec {
                            name,
                            symbol: c.rate,
                            accel: c.accel,
                            coordinate: Some(i),
                            definition: None,
                        });
                    }
                    None => {
                        let h = hint(&name, self.coords.iter().map(|(c, _)| c.to_string()));
                        self.cx.error_spanned_by(
                            &s.name,
                            format!("`{name}` is not a coordinate; a speed is a coordinate's name, or `name = expression` for a quasi-velocity{h}"),
                        );
                    }
                },
                Some(def) => {
                    if !not_raw(self.cx, &s.name, "quasi-velocity") {
                        continue;
                    }
                    if self.all_names().contains(&name) {
                        self.cx.error_spanned_by(&s.name, format!("the quasi-velocity `{name}` needs a new name; `{name}` is already used"));
                        continue;
                    }
                    let Some(e) = self.scalar(def) else { continue };
                    let (Ok(symbol), Ok(accel)) = (
                        self.g.declare(&name, SymbolKind::Auxiliary),
                        self.g
                            .declare(&format!("{name}_dot"), SymbolKind::Auxiliary),
                    ) else {
                        self.cx.error_spanned_by(
                            &s.name,
                            format!("the quasi-velocity `{name}` clashes with another name"),
                        );
                        continue;
                    };
                    out.push(SpeedSpec {
                        name,
                        symbol,
                        accel,
                        coordinate: None,
                        definition: Some(e),
                    });
                }
            }
        }
        (out, at.clone())
    }

    /// Driven coordinates: every declared input a constraint reads gets a
    /// companion input `{input}_rate` (its time derivative), and one read
    /// by a holonomic constraint also `{input}_accel` (the second
    /// derivative, the rate of `{input}_rate`), appended to the inputs in
    /// that order, input by input. Returns each (symbol, its rate's
    /// symbol) pair, for the derivation's rate rules.
    pub(super) fn driving_inputs(
        &mut self,
        holonomic: &[super::Constraint],
        nonholonomic: &[super::Constraint],
    ) -> Vec<(Symbol, Symbol)> {
        let reads = |g: &Graph, cs: &[super::Constraint], s: Symbol| {
            cs.iter().any(|c| g.depends_on(c.residual, s))
        };
        let mut rates = Vec::new();
        let declared = self.inputs.clone();
        for (ident, s) in declared {
            let in_h = reads(&self.g, holonomic, s);
            if !in_h && !reads(&self.g, nonholonomic, s) {
                continue;
            }
            let mut names = vec![format!("{ident}_rate")];
            if in_h {
                names.push(format!("{ident}_accel"));
            }
            let mut of = s;
            for name in names {
                // The twin's build finds the first build's companion in the
                // graph, an input.
                let clash = self.all_names().contains(&name)
                    || self
                        .g
                        .symbol_named(&name)
                        .is_some_and(|x| self.g.symbol_kind(x) != SymbolKind::Input);
                let Some(rate) = (!clash).then(|| self.g.input(&name).ok()).flatten() else {
                    self.cx.error_spanned_by(
                        &ident,
                        format!("`{ident}` drives a constraint, so the input `{name}` stands for its time derivative; `{name}` is already used"),
                    );
                    break;
                };
                self.inputs.push((Ident::new(&name, ident.span()), rate));
                rates.push((of, rate));
                of = rate;
            }
        }
        rates
    }

    pub(super) fn all_names(&self) -> Vec<String> {
        let mut v: Vec<String> = self.params.iter().map(|p| p.ident.to_string()).collect();
        v.extend(self.coords.iter().map(|(c, _)| c.to_string()));
        v.extend(self.inputs.iter().map(|(c, _)| c.to_string()));
        v.extend(self.points.iter().map(|p| p.name.clone()));
        v.push("t".into());
        v
    }

    /// Whether `ident` names a frame or point declared but not built yet:
    /// one declared below its use (frames and points are built in
    /// declaration order). Reports it at the use and at the declaration.
    pub(super) fn declared_below(&self, ident: &Ident) -> bool {
        let Some(decl) = self.declared.iter().find(|d| *d == ident) else {
            return false;
        };
        self.cx.error_spanned_by(
            ident,
            format!("`{ident}` is used before its declaration: frames and points are built in order, so declare it above its first use"),
        );
        self.cx.error_spanned_by(
            decl,
            format!("`{ident}` is declared here, below its first use"),
        );
        true
    }

    pub(super) fn frame_named(&self, ident: &Ident) -> Option<usize> {
        let name = ident.to_string();
        if let Some(i) = self.frames.iter().position(|f| f.name == name) {
            return Some(i);
        }
        if self.poisoned.contains(&name) || self.declared_below(ident) {
            return None;
        }
        let h = hint(&name, self.frames.iter().map(|f| f.name.clone()));
        self.cx
            .error_spanned_by(ident, format!("unknown frame `{name}`{h}"));
        None
    }

    pub(super) fn point_named(&self, ident: &Ident) -> Option<Vec3> {
        let name = ident.to_string();
        if let Some(p) = self.points.iter().find(|p| p.name == name) {
            return Some(p.pos);
        }
        if self.poisoned.contains(&name) || self.declared_below(ident) {
            return None;
        }
        let h = hint(&name, self.points.iter().map(|p| p.name.clone()));
        self.cx
            .error_spanned_by(ident, format!("unknown point `{name}`{h}"));
        None
    }
}

/// Whether `ident` is not a raw identifier (`r#type`); reports it when it
/// is. The generated code builds other names from a model's names (`q_dot`,
/// a scene's type name), which a raw identifier cannot form.
pub(super) fn not_raw(cx: &Ctxt, ident: &Ident, what: &str) -> bool {
    let name = ident.to_string();
    let Some(bare) = name.strip_prefix("r#") else {
        return true;
    };
    cx.error_spanned_by(
        ident,
        format!("a raw identifier cannot name a {what}, since the generated code builds other names from it; rename `{bare}`"),
    );
    false
}

/// " (made by the URDF's link `x`)" when a URDF made the name: a clash
/// with a name the model declares says where the other one comes from.
pub(super) fn urdf_note(ast: &ModelAst, name: &str) -> String {
    ast.urdf_names
        .iter()
        .find(|(n, _)| n == name)
        .map(|(_, what)| format!(" (one of them made by {what}; rename the model's own)"))
        .unwrap_or_default()
}

/// An error for each body named like one before it.
pub(super) fn duplicate_bodies(cx: &Ctxt, ast: &ModelAst) {
    for (k, b) in ast.bodies.iter().enumerate() {
        if ast.bodies[..k].iter().any(|o| o.name == b.name) {
            let note = urdf_note(ast, &b.name.to_string());
            cx.error_spanned_by(&b.name, format!("duplicate body `{}`{note}", b.name));
        }
    }
}

/// "; did you mean `x`?" when `name` is close to a candidate.
pub(super) fn hint(name: &str, candidates: impl IntoIterator<Item = String>) -> String {
    let c: Vec<String> = candidates.into_iter().collect();
    did_you_mean(name, c.iter().map(|s| s.as_str()))
        .map(|s| format!("; did you mean `{s}`?"))
        .unwrap_or_default()
}
