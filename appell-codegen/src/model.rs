//! Stage 2: resolve names and build the kinematics in the symbolic engine.
//!
//! Frames carry their rotation matrix (columns are the frame's unit vectors
//! in N components) and angular velocity in N; points carry their position
//! in N. Everything is an expression in the coordinates, parameters, inputs
//! and time of one [`Graph`].

use proc_macro2::Span;
use syn::Ident;

use appell_symbolic::{
    Coordinate, Graph, Id, Number, RateRules, Symbol, SymbolKind, SymbolicError,
};

use crate::algebra::{cross, dot, mat_mul, mat_t_vec};
use crate::ast::*;
use crate::ctxt::{did_you_mean, Ctxt};

pub use crate::algebra::{Mat3, Vec3};

/// A parameter (struct field).
#[derive(Clone)]
pub struct Param {
    /// The field.
    pub ident: Ident,
    /// Its symbol.
    pub symbol: Symbol,
    /// Declared positive.
    pub positive: bool,
}

/// A frame: rotation (columns = unit vectors in N) and angular velocity in N.
#[derive(Clone)]
pub struct Frame {
    /// Its name.
    pub name: String,
    /// Rotation matrix.
    pub rot: Mat3,
    /// Angular velocity, as an expression in the coordinate rates.
    pub omega: Vec3,
}

/// A named point and its position in N.
#[derive(Clone)]
pub struct Point {
    /// Its name.
    pub name: String,
    /// Position.
    pub pos: Vec3,
}

/// A body or particle.
#[derive(Clone)]
pub struct Body {
    /// Its name.
    pub name: String,
    /// Mass-centre position.
    pub center: Vec3,
    /// Index of its frame (None for a particle).
    pub frame: Option<usize>,
    /// Mass.
    pub mass: Id,
    /// Central inertia in the body frame (zero for a particle).
    pub inertia: Mat3,
}

/// A force at a point or a torque on a frame.
#[derive(Clone)]
pub struct Load {
    /// Application point's position (forces).
    pub point: Vec3,
    /// The frame (torques).
    pub frame: usize,
    /// The vector in N.
    pub vector: Vec3,
    /// Effect name.
    pub effect: String,
    /// For a body's weight (`gravity(...)`): the body's index.
    pub weight_of: Option<usize>,
}

/// `rolls(...)`: the material point of a body at a contact point has zero
/// velocity.
#[derive(Clone)]
pub struct Rolling {
    /// Index of the body in [`Model::bodies`].
    pub body: usize,
    /// Position of the contact point.
    pub contact: Vec3,
    /// Directions constrained (None: N.x, N.y, N.z, zero rows dropped).
    pub along: Option<Vec<Vec3>>,
    /// The contact point's name.
    pub point: String,
    /// The item's tokens, for errors.
    pub at: proc_macro2::TokenStream,
}

/// `scene(name, effects(...), outputs(...))`: a specialised rhs with the
/// chosen effects' loads only, and the requested outputs.
#[derive(Clone)]
pub struct Scene {
    /// The scene's name.
    pub name: Ident,
    /// The effects it keeps.
    pub effects: Vec<String>,
    /// Coordinates integrated by quadrature beside the reduced state
    /// (`outputs(quadrature(x1, y1))`).
    pub quadrature: Vec<usize>,
    /// The outputs asked for, by kind (`quadrature`, `energies`,
    /// `contact_forces`), in declaration order.
    pub outputs: Vec<String>,
}

/// One privileged speed ẏ_k.
#[derive(Clone)]
pub struct SpeedSpec {
    /// Its name (the coordinate's for a coordinate rate).
    pub name: String,
    /// The symbol standing for ẏ_k.
    pub symbol: Symbol,
    /// The symbol standing for ÿ_k.
    pub accel: Symbol,
    /// The coordinate whose rate it is (Method II).
    pub coordinate: Option<usize>,
    /// Its definition, linear in the rates (Method III).
    pub definition: Option<Id>,
}

/// A constraint residual with its source span.
#[derive(Clone)]
pub struct Constraint {
    /// `lhs - rhs`.
    pub residual: Id,
    /// Its tokens, for errors.
    pub at: proc_macro2::TokenStream,
}

/// The resolved model.
#[derive(Clone)]
pub struct Model {
    /// The expression graph everything lives in.
    pub g: Graph,
    /// The struct's name.
    pub name: Ident,
    /// Parameters in field order.
    pub params: Vec<Param>,
    /// Coordinates in declaration order.
    pub coords: Vec<(Ident, Coordinate)>,
    /// Indices (into `coords`) of the coordinates whose rates are privileged
    /// speeds (Method II).
    pub speeds: Vec<usize>,
    /// All privileged speeds, in order.
    pub speed_specs: Vec<SpeedSpec>,
    /// The tokens of `speeds(...)`, for errors.
    pub speeds_at: proc_macro2::TokenStream,
    /// Inputs.
    pub inputs: Vec<(Ident, Symbol)>,
    /// Time.
    pub time: Symbol,
    /// Frames; index 0 is N.
    pub frames: Vec<Frame>,
    /// Points; index 0 is O.
    pub points: Vec<Point>,
    /// Bodies and particles.
    pub bodies: Vec<Body>,
    /// Holonomic constraints f(q, t) = 0.
    pub holonomic: Vec<Constraint>,
    /// Nonholonomic constraints, linear in the rates.
    pub nonholonomic: Vec<Constraint>,
    /// Rolling contacts.
    pub rolling: Vec<Rolling>,
    /// Forces.
    pub forces: Vec<Load>,
    /// Torques.
    pub torques: Vec<Load>,
    /// Effect names in order of first use.
    pub effects: Vec<String>,
    /// Declared scenes.
    pub scenes: Vec<Scene>,
    /// Coordinates forced into the reduced state (a scene's quadrature
    /// outputs); empty for the full model.
    pub quadrature: Vec<usize>,
    /// A scene's outputs (see [`Scene::outputs`]); empty for the full model.
    pub outputs: Vec<String>,
    /// The name the generated `ModelInfo` carries.
    pub info_name: String,
    /// The `gravity(...)` acceleration (N components), if declared.
    pub gravity: Option<Vec3>,
    /// The squared length of every `norm(...)` and `unit(...)` argument, with
    /// where it occurs, so that the generated code can name a zero-length
    /// one at run time.
    pub norms: Vec<(Id, String)>,
    /// The same kinematics with each frame's direction cosines standing as
    /// symbols (see [`Cut`]), in the same graph; `None` inside the twin.
    pub twin: Option<Box<Model>>,
    /// The twin's direction-cosine symbols (empty in the model itself).
    pub cuts: Vec<Cut>,
}

/// A direction cosine standing as a symbol in the twin model: its rate is a
/// component of ω × column, so a derivative through nested rotations stays
/// a few cross products instead of the product rule over every factor of
/// every direction cosine. [`Model::uncut_substitution`] puts the values
/// (the model's own direction cosines) back.
#[derive(Clone, Copy)]
pub struct Cut {
    /// The symbol.
    pub symbol: Symbol,
    /// Its value: the model's entry of the frame's matrix.
    pub value: Id,
    /// Its rate, linear in the coordinate rates.
    pub rate: Id,
}

impl Model {
    /// Rate rules for the coordinates and the direction-cosine symbols.
    pub fn rate_rules(&self) -> RateRules {
        let mut r = RateRules::coordinates();
        for c in &self.cuts {
            r = r.with(c.symbol, c.rate);
        }
        r
    }

    /// The substitution of every direction-cosine symbol by its value.
    pub fn uncut_substitution(&self) -> appell_symbolic::Substitution {
        let mut s = appell_symbolic::Substitution::new();
        for c in &self.cuts {
            s.insert(c.symbol, c.value);
        }
        s
    }
}

#[derive(Clone, Copy)]
enum Val {
    Scalar(Id),
    Vector(Vec3),
    Point(Vec3),
}

struct Builder<'a> {
    cx: &'a Ctxt,
    g: Graph,
    params: Vec<Param>,
    coords: Vec<(Ident, Coordinate)>,
    inputs: Vec<(Ident, Symbol)>,
    time: Symbol,
    frames: Vec<Frame>,
    points: Vec<Point>,
    /// Frames and points whose definition failed: references to them are
    /// not reported again.
    poisoned: Vec<String>,
    /// The definition being evaluated (for `norms`).
    context: String,
    norms: Vec<(Id, String)>,
    /// When building the twin: the model's frame matrices, whose entries
    /// become symbols.
    cut_from: Option<Vec<Mat3>>,
    cuts: Vec<Cut>,
    rules: RateRules,
}

fn engine_error(cx: &Ctxt, span: Span, e: SymbolicError) {
    cx.error_at(span, e);
}

/// Resolves names and builds kinematics; `None` when errors were recorded.
pub fn build(cx: &Ctxt, ast: &ModelAst) -> Option<Model> {
    let mut model = build_in(cx, ast, Graph::new(), None)?;
    // The twin, built again in the same graph with direction cosines as
    // symbols; the first build found every error there is.
    let scratch = Ctxt::new();
    let frames: Vec<Mat3> = model.frames.iter().map(|f| f.rot).collect();
    let twin = build_in(&scratch, ast, model.g.clone(), Some(frames));
    if scratch.check().is_ok() {
        if let Some(mut twin) = twin {
            model.g = std::mem::replace(&mut twin.g, Graph::new());
            model.twin = Some(Box::new(twin));
        }
    }
    Some(model)
}

fn build_in(cx: &Ctxt, ast: &ModelAst, mut g: Graph, cut_from: Option<Vec<Mat3>>) -> Option<Model> {
    let time = g.time().expect("fresh graph");
    let mut b = Builder {
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
        cut_from,
        cuts: Vec::new(),
        rules: RateRules::coordinates(),
    };
    b.declare_symbols(ast);
    let zero = b.g.int(0).ok()?;
    let one = b.g.int(1).ok()?;
    b.frames.push(Frame {
        name: "N".into(),
        rot: [[one, zero, zero], [zero, one, zero], [zero, zero, one]],
        omega: [zero; 3],
    });
    b.points.push(Point {
        name: "O".into(),
        pos: [zero; 3],
    });
    for f in &ast.frames {
        let before = b.frames.len();
        b.add_frame(f);
        if b.frames.len() == before {
            b.poisoned.push(f.name.to_string());
        }
    }
    for p in &ast.points {
        let before = b.points.len();
        b.add_point(p);
        if b.points.len() == before {
            b.poisoned.push(p.name.to_string());
        }
    }
    let bodies: Vec<Body> = ast.bodies.iter().filter_map(|d| b.add_body(d)).collect();
    let holonomic = ast
        .holonomic
        .iter()
        .filter_map(|c| b.constraint(c))
        .collect();
    let nonholonomic = ast
        .nonholonomic
        .iter()
        .filter_map(|c| b.constraint(c))
        .collect();
    let mut effects = Vec::new();
    let mut forces = Vec::new();
    let mut torques = Vec::new();
    let mut gravity = None;
    if let Some(gvec) = &ast.gravity {
        if let Some(v) = b.vector(gvec) {
            gravity = Some(v);
            for (index, body) in bodies.iter().enumerate() {
                let f = b.scale3(v, body.mass);
                if let Some(f) = f {
                    forces.push(Load {
                        point: body.center,
                        frame: 0,
                        vector: f,
                        effect: "gravity".into(),
                        weight_of: Some(index),
                    });
                }
            }
            effects.push("gravity".to_string());
        }
    }
    for l in &ast.forces {
        let Some(p) = b.point_named(&l.target) else {
            continue;
        };
        let Some(v) = b.vector(&l.vector) else {
            continue;
        };
        let effect = l.effect.to_string();
        if !effects.contains(&effect) {
            effects.push(effect.clone());
        }
        forces.push(Load {
            point: p,
            frame: 0,
            vector: v,
            effect,
            weight_of: None,
        });
    }
    for l in &ast.torques {
        let Some(fi) = b.frame_named(&l.target) else {
            continue;
        };
        let Some(v) = b.vector(&l.vector) else {
            continue;
        };
        let effect = l.effect.to_string();
        if !effects.contains(&effect) {
            effects.push(effect.clone());
        }
        torques.push(Load {
            point: [zero; 3],
            frame: fi,
            vector: v,
            effect,
            weight_of: None,
        });
    }
    let mut rolling = Vec::new();
    for r in &ast.rolls {
        let name = r.body.to_string();
        let Some(bi) = bodies.iter().position(|x| x.name == name) else {
            let h = hint(&name, bodies.iter().map(|x| x.name.clone()));
            cx.error_spanned_by(&r.body, format!("unknown body `{name}`{h}"));
            continue;
        };
        if bodies[bi].frame.is_none() {
            cx.error_spanned_by(
                &r.body,
                format!("`{name}` is a particle; only a rigid body rolls"),
            );
            continue;
        }
        let Some(contact) = b.point_named(&r.contact) else {
            continue;
        };
        let along = match &r.along {
            Some(list) => {
                let dirs: Vec<Vec3> = list.iter().filter_map(|e| b.vector(e)).collect();
                if dirs.len() != list.len() {
                    continue;
                }
                if dirs.is_empty() {
                    cx.error_spanned_by(&r.at, "`along` needs at least one direction");
                    continue;
                }
                Some(dirs)
            }
            None => None,
        };
        rolling.push(Rolling {
            body: bi,
            contact,
            along,
            point: r.contact.to_string(),
            at: r.at.clone(),
        });
    }
    let (speed_specs, speeds_at) = b.speeds(ast);
    let speeds: Vec<usize> = speed_specs.iter().filter_map(|s| s.coordinate).collect();
    let mut scenes = Vec::new();
    for sc in &ast.scenes {
        let mut ok = true;
        for e in &sc.effects {
            if !effects.contains(&e.to_string()) {
                let h = hint(&e.to_string(), effects.iter().cloned());
                cx.error_spanned_by(
                    e,
                    format!(
                        "scene `{}` names the effect `{e}`, which no load declares{h}",
                        sc.name
                    ),
                );
                ok = false;
            }
        }
        let mut quadrature = Vec::new();
        let mut outputs: Vec<String> = Vec::new();
        for (kind, args) in &sc.outputs {
            let k = kind.to_string();
            if outputs.contains(&k) {
                cx.error_spanned_by(kind, format!("scene output `{k}` is listed twice"));
                ok = false;
                continue;
            }
            outputs.push(k.clone());
            if k == "energies" || k == "contact_forces" {
                if let Some(a) = args.first() {
                    cx.error_spanned_by(a, format!("`{k}` takes no arguments"));
                    ok = false;
                }
                if k == "contact_forces"
                    && ast.holonomic.is_empty()
                    && ast.nonholonomic.is_empty()
                    && ast.rolls.is_empty()
                {
                    cx.error_spanned_by(
                        kind,
                        "`contact_forces` needs constraints (`rolls`, `holonomic` or `nonholonomic`), and the model has none",
                    );
                    ok = false;
                }
            } else if k == "quadrature" {
                if args.is_empty() {
                    cx.error_spanned_by(kind, "`quadrature(...)` needs the coordinates to keep");
                    ok = false;
                }
                for a in args {
                    match b.coords.iter().position(|(c, _)| c == a) {
                        Some(i) => quadrature.push(i),
                        None => {
                            let h =
                                hint(&a.to_string(), b.coords.iter().map(|(c, _)| c.to_string()));
                            cx.error_spanned_by(
                                a,
                                format!("`quadrature` takes coordinates, and `{a}` is not one{h}"),
                            );
                            ok = false;
                        }
                    }
                }
            } else {
                let h = hint(
                    &k,
                    ["quadrature", "energies", "contact_forces"].map(String::from),
                );
                cx.error_spanned_by(
                    kind,
                    format!("unknown scene output `{kind}`; available: quadrature(coordinates...), energies, contact_forces{h}"),
                );
                ok = false;
            }
        }
        if scenes.iter().any(|s: &Scene| s.name == sc.name) {
            cx.error_spanned_by(&sc.name, format!("duplicate scene `{}`", sc.name));
            ok = false;
        }
        if ok {
            scenes.push(Scene {
                name: sc.name.clone(),
                effects: sc.effects.iter().map(|e| e.to_string()).collect(),
                quadrature,
                outputs,
            });
        }
    }
    if bodies.is_empty() && !cx.has_errors() {
        cx.error_at(
            ast.name.span(),
            "the model has no `body(...)` or `particle(...)`: there is nothing to move",
        );
    }
    if cx.has_errors() {
        return None;
    }
    Some(Model {
        g: b.g,
        name: ast.name.clone(),
        params: b.params,
        coords: b.coords,
        speeds,
        speed_specs,
        speeds_at,
        inputs: b.inputs,
        time: b.time,
        frames: b.frames,
        points: b.points,
        bodies,
        holonomic,
        nonholonomic,
        rolling,
        forces,
        torques,
        effects,
        scenes,
        quadrature: Vec::new(),
        outputs: Vec::new(),
        info_name: ast.name.to_string(),
        gravity,
        norms: b.norms,
        twin: None,
        cuts: b.cuts,
    })
}

/// The model of one scene: loads of the scene's effects only, its
/// quadrature coordinates kept in the state.
pub fn scene_model(full: &Model, scene: &Scene) -> Model {
    let mut m = full.clone();
    m.forces.retain(|f| scene.effects.contains(&f.effect));
    m.torques.retain(|t| scene.effects.contains(&t.effect));
    m.effects.retain(|e| scene.effects.contains(e));
    m.quadrature = scene.quadrature.clone();
    m.outputs = scene.outputs.clone();
    m.info_name = format!("{}::{}", full.name, scene.name);
    m.scenes = Vec::new();
    m
}

const RESERVED: &[&str] = &["N", "O", "t"];

impl Builder<'_> {
    fn declare_symbols(&mut self, ast: &ModelAst) {
        let mut seen: Vec<(String, &'static str)> = Vec::new();
        let mut check = |cx: &Ctxt, ident: &Ident, what: &'static str| -> bool {
            let name = ident.to_string();
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
                if *other == what {
                    cx.error_spanned_by(ident, format!("duplicate {what} `{name}`"));
                } else {
                    cx.error_spanned_by(ident, format!("`{name}` is already a {other}"));
                }
                return false;
            }
            seen.push((name, what));
            true
        };
        for (f, _) in &ast.fields {
            if check(self.cx, f, "parameter") {
                let s = self.g.parameter(&f.to_string()).expect("fresh name");
                let positive = ast.positive.iter().any(|p| p == f);
                self.params.push(Param {
                    ident: f.clone(),
                    symbol: s,
                    positive,
                });
            }
        }
        for p in &ast.positive {
            if !ast.fields.iter().any(|(f, _)| f == p) {
                let hint = hint(
                    &p.to_string(),
                    ast.fields.iter().map(|(f, _)| f.to_string()),
                );
                self.cx.error_spanned_by(
                    p,
                    format!("`positive` names a parameter, and `{p}` is not one{hint}"),
                );
            }
        }
        if ast.coordinates.is_empty() {
            self.cx
                .error_at(ast.name.span(), "the model declares no `coordinates(...)`");
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

    fn speeds(&mut self, ast: &ModelAst) -> (Vec<SpeedSpec>, proc_macro2::TokenStream) {
        let Some((list, at)) = &ast.speeds else {
            self.cx.error_at(ast.name.span(), "the model declares no `speeds(...)`: name the coordinates whose rates are independent");
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

    fn all_names(&self) -> Vec<String> {
        let mut v: Vec<String> = self.params.iter().map(|p| p.ident.to_string()).collect();
        v.extend(self.coords.iter().map(|(c, _)| c.to_string()));
        v.extend(self.inputs.iter().map(|(c, _)| c.to_string()));
        v.extend(self.points.iter().map(|p| p.name.clone()));
        v.push("t".into());
        v
    }

    fn frame_named(&self, ident: &Ident) -> Option<usize> {
        let name = ident.to_string();
        if let Some(i) = self.frames.iter().position(|f| f.name == name) {
            return Some(i);
        }
        if self.poisoned.contains(&name) {
            return None;
        }
        let h = hint(&name, self.frames.iter().map(|f| f.name.clone()));
        self.cx
            .error_spanned_by(ident, format!("unknown frame `{name}`{h}"));
        None
    }

    fn point_named(&self, ident: &Ident) -> Option<Vec3> {
        let name = ident.to_string();
        if let Some(p) = self.points.iter().find(|p| p.name == name) {
            return Some(p.pos);
        }
        if self.poisoned.contains(&name) {
            return None;
        }
        let h = hint(&name, self.points.iter().map(|p| p.name.clone()));
        self.cx
            .error_spanned_by(ident, format!("unknown point `{name}`{h}"));
        None
    }

    fn add_frame(&mut self, f: &FrameDef) {
        self.context = format!("frame `{}`", f.name);
        let Some(pi) = self.frame_named(&f.parent) else {
            return;
        };
        let mut rot = self.frames[pi].rot;
        let mut omega = self.frames[pi].omega;
        // Each rotation is about an axis of the frame the previous one made.
        for (axis, angle_expr) in &f.rotations {
            let Some(angle) = self.scalar(angle_expr) else {
                return;
            };
            let result = match axis {
                RotationAxis::Parent(k) => self.parent_axis_rotation(*k, angle, rot, omega),
                RotationAxis::Vector(v) => {
                    let Some(u) = self.vector(v) else { return };
                    // The twin's matrices are symbols; the model's build
                    // has checked the axis.
                    let checked = if self.cut_from.is_some() {
                        Ok(true)
                    } else {
                        self.fixed_in(u, &rot)
                    };
                    match checked {
                        Ok(true) => {}
                        Ok(false) => {
                            self.cx.error_at(
                                v.span(),
                                "the axis of `rotate(axis, angle)` must be fixed in the frame it rotates from (write it with that frame's unit vectors and constants); this one turns relative to it as the coordinates change",
                            );
                            return;
                        }
                        Err(e) => {
                            engine_error(self.cx, v.span(), e);
                            return;
                        }
                    }
                    self.axis_rotation(u, angle, rot, omega)
                }
            };
            match result {
                Ok((r, w)) => {
                    rot = r;
                    omega = w;
                }
                Err(e) => {
                    engine_error(self.cx, angle_expr.span(), e);
                    return;
                }
            }
        }
        if let Some(values) = &self.cut_from {
            let index = self.frames.len();
            let values = values[index];
            match self.cut_rotation(index, rot, omega, values) {
                Ok(r) => rot = r,
                Err(e) => {
                    engine_error(self.cx, f.name.span(), e);
                    return;
                }
            }
        }
        self.frames.push(Frame {
            name: f.name.to_string(),
            rot,
            omega,
        });
    }

    /// In the twin: replaces the entries of a frame's matrix that depend on
    /// the coordinates by symbols (see [`Cut`]) whose values are the
    /// model's entries.
    fn cut_rotation(
        &mut self,
        index: usize,
        rot: Mat3,
        omega: Vec3,
        values: Mat3,
    ) -> Result<Mat3, SymbolicError> {
        let g = &mut self.g;
        let mut out = rot;
        let mut symbols = [[None; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                if g.is_parameter_only(rot[i][j]) {
                    continue;
                }
                let s = g.declare(&format!("__r{index}_{i}{j}"), SymbolKind::Auxiliary)?;
                symbols[i][j] = Some(s);
                out[i][j] = g.sym(s)?;
            }
        }
        for j in 0..3 {
            let column = [out[0][j], out[1][j], out[2][j]];
            let rate = cross(g, omega, column)?;
            for i in 0..3 {
                if let Some(s) = symbols[i][j] {
                    self.rules = std::mem::take(&mut self.rules).with(s, rate[i]);
                    self.cuts.push(Cut {
                        symbol: s,
                        value: values[i][j],
                        rate: rate[i],
                    });
                }
            }
        }
        Ok(out)
    }

    /// Whether the vector `u` (N components) is fixed in the frame with
    /// rotation `rot`: its components there do not change with time, checked
    /// at three pseudo-random configurations and rates (any failure to
    /// evaluate counts as not fixed).
    fn fixed_in(&mut self, u: Vec3, rot: &Mat3) -> Result<bool, SymbolicError> {
        let g = &mut self.g;
        let local = mat_t_vec(g, rot, u)?;
        let rules = RateRules::coordinates();
        let rates = [
            g.time_derivative(local[0], &rules)?,
            g.time_derivative(local[1], &rules)?,
            g.time_derivative(local[2], &rules)?,
        ];
        if rates.iter().all(|&r| g.is_zero(r)) {
            return Ok(true);
        }
        let mut roots = rates.to_vec();
        roots.extend(local);
        let tape = appell_symbolic::Tape::new(g, &roots);
        for trial in 0..3u64 {
            let env = |s: Symbol| Some(crate::derivation::pseudo_value(g, s, trial));
            let Ok(v) = tape.eval(&env) else {
                return Ok(false);
            };
            let scale = 1.0 + v[3..].iter().fold(0.0f64, |a, x| a.max(x.abs()));
            if v[..3].iter().any(|r| r.is_nan() || r.abs() > 1e-9 * scale) {
                return Ok(false);
            }
        }
        Ok(true)
    }

    /// Rotation about the parent's axis `k`: R = R_parent Rk(θ),
    /// ω = ω_parent + θ̇ (parent axis k).
    fn parent_axis_rotation(
        &mut self,
        k: usize,
        angle: Id,
        parent_rot: Mat3,
        parent_omega: Vec3,
    ) -> Result<(Mat3, Vec3), SymbolicError> {
        let g = &mut self.g;
        let rate = g.time_derivative(angle, &RateRules::coordinates())?;
        let c = g.cos(angle)?;
        let s = g.sin(angle)?;
        let local = simple_rotation(g, k, c, s)?;
        let rot = mat_mul(g, &parent_rot, &local)?;
        let mut omega = parent_omega;
        for i in 0..3 {
            let t = g.mul(rate, parent_rot[i][k])?;
            omega[i] = g.add(omega[i], t)?;
        }
        Ok((rot, omega))
    }

    /// Rotation by `angle` about the unit vector of `u` (N components, fixed
    /// in the parent): R = Rot(û, θ) R_parent (Rodrigues), ω = ω_parent + θ̇ û.
    fn axis_rotation(
        &mut self,
        u: Vec3,
        angle: Id,
        parent_rot: Mat3,
        parent_omega: Vec3,
    ) -> Result<(Mat3, Vec3), SymbolicError> {
        let g = &mut self.g;
        let n2 = dot(g, u, u)?;
        if g.is_zero(n2) {
            return Err(SymbolicError::DivisionByZero {
                expr: "a zero-length rotation axis".into(),
            });
        }
        let n = g.sqrt(n2)?;
        let mut uh = [u[0]; 3];
        for i in 0..3 {
            uh[i] = g.div(u[i], n)?;
        }
        let c = g.cos(angle)?;
        let s = g.sin(angle)?;
        let one = g.int(1)?;
        let omc = g.sub(one, c)?;
        let mut r = [[one; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                let uu = g.mul(uh[i], uh[j])?;
                let mut e = g.mul(omc, uu)?;
                if i == j {
                    e = g.add(e, c)?;
                }
                // [û]× entries: (i, j) = −ε_ijk û_k
                if i != j {
                    let k = 3 - i - j;
                    let sign = if (i + 1) % 3 == j { -1 } else { 1 };
                    let t = g.mul(s, uh[k])?;
                    let t = g.scale(t, Number::int(sign))?;
                    e = g.add(e, t)?;
                }
                r[i][j] = e;
            }
        }
        let rot = mat_mul(g, &r, &parent_rot)?;
        let rate = g.time_derivative(angle, &RateRules::coordinates())?;
        let mut omega = parent_omega;
        for i in 0..3 {
            let t = g.mul(rate, uh[i])?;
            omega[i] = g.add(omega[i], t)?;
        }
        Ok((rot, omega))
    }

    fn add_point(&mut self, p: &PointDef) {
        self.context = format!("point `{}`", p.name);
        match self.eval(&p.location) {
            Some(Val::Point(pos)) => self.points.push(Point {
                name: p.name.to_string(),
                pos,
            }),
            Some(_) => self.cx.error_at(
                p.location.span(),
                "a point is located from another point: `P = O + vector` or `P = Q + vector`",
            ),
            None => {}
        }
    }

    fn add_body(&mut self, d: &BodyDef) -> Option<Body> {
        let center = self.point_named(&d.center);
        let frame = match &d.frame {
            Some(f) => Some(self.frame_named(f)?),
            None => None,
        };
        let mass = self.scalar(&d.mass);
        if let Some(m) = mass {
            if self.g.is_zero(m) {
                self.cx
                    .error_at(d.mass.span(), format!("`{}` has zero mass", d.name));
            }
        }
        let zero = self.g.int(0).ok()?;
        let mut inertia = [[zero; 3]; 3];
        match &d.inertia {
            Some(Inertia::Principal(m)) => {
                for (i, e) in m.iter().enumerate() {
                    inertia[i][i] = self.scalar(e)?;
                }
            }
            Some(Inertia::Matrix(m)) => {
                let v: Vec<Id> = m.iter().map(|e| self.scalar(e)).collect::<Option<_>>()?;
                inertia = [[v[0], v[3], v[5]], [v[3], v[1], v[4]], [v[5], v[4], v[2]]];
            }
            None => {}
        }
        Some(Body {
            name: d.name.to_string(),
            center: center?,
            frame,
            mass: mass?,
            inertia,
        })
    }

    fn constraint(&mut self, c: &ConstraintDef) -> Option<Constraint> {
        self.context = "a constraint".to_string();
        let l = self.scalar(&c.lhs)?;
        let r = self.scalar(&c.rhs)?;
        match self.g.sub(l, r) {
            Ok(residual) => Some(Constraint {
                residual,
                at: c.at.clone(),
            }),
            Err(e) => {
                self.cx.error_spanned_by(&c.at, e);
                None
            }
        }
    }

    fn scalar(&mut self, e: &Expr) -> Option<Id> {
        match self.eval(e)? {
            Val::Scalar(s) => Some(s),
            Val::Vector(_) => {
                self.cx
                    .error_at(e.span(), "expected a scalar, found a vector");
                None
            }
            Val::Point(_) => {
                self.cx
                    .error_at(e.span(), "expected a scalar, found a point");
                None
            }
        }
    }

    fn vector(&mut self, e: &Expr) -> Option<Vec3> {
        match self.eval(e)? {
            Val::Vector(v) => Some(v),
            Val::Scalar(_) => {
                self.cx.error_at(
                    e.span(),
                    "expected a vector (e.g. `m * g * N.x`), found a scalar",
                );
                None
            }
            Val::Point(_) => {
                self.cx.error_at(
                    e.span(),
                    "expected a vector, found a point (subtract another point to get a vector)",
                );
                None
            }
        }
    }

    fn scale3(&mut self, v: Vec3, k: Id) -> Option<Vec3> {
        let mut out = v;
        for i in 0..3 {
            out[i] = self.g.mul(v[i], k).ok()?;
        }
        Some(out)
    }

    fn eval(&mut self, e: &Expr) -> Option<Val> {
        let span = e.span();
        let r: Result<Option<Val>, SymbolicError> = (|| {
            Ok(Some(match e {
                Expr::Int(n, _) => Val::Scalar(self.g.int(*n)?),
                Expr::Float(x, _) => Val::Scalar(self.g.float(*x)?),
                Expr::Name(ident) => return Ok(self.name(ident)),
                Expr::Axis(frame, k, _) => {
                    let Some(fi) = self.frame_named(frame) else {
                        return Ok(None);
                    };
                    let r = self.frames[fi].rot;
                    Val::Vector([r[0][*k], r[1][*k], r[2][*k]])
                }
                Expr::Neg(a, _) => match self.eval(a) {
                    Some(Val::Scalar(s)) => Val::Scalar(self.g.neg(s)?),
                    Some(Val::Vector(v)) => {
                        let mut out = v;
                        for i in 0..3 {
                            out[i] = self.g.neg(v[i])?;
                        }
                        Val::Vector(out)
                    }
                    Some(Val::Point(_)) => {
                        self.cx.error_at(span, "a point cannot be negated");
                        return Ok(None);
                    }
                    None => return Ok(None),
                },
                Expr::Binary(op, a, b, _) => {
                    let (Some(x), Some(y)) = (self.eval(a), self.eval(b)) else {
                        return Ok(None);
                    };
                    return self.binary(*op, x, y, span);
                }
                Expr::Call(f, args, _) => return self.call(f, args, span),
            }))
        })();
        match r {
            Ok(v) => v,
            Err(err) => {
                engine_error(self.cx, span, err);
                None
            }
        }
    }

    /// |v|² of a vector expression by the identities of its construction,
    /// so that `norm` and `unit` of vectors made of frame axes stay small
    /// (differentiated twice, they reach the accelerations): |e|² = 1 for a
    /// frame's axis and for `unit(v)`, |k v|² = k²|v|²,
    /// |a ± b|² = |a|² ± 2 a·b + |b|², and Lagrange's identity |a × b|² = |a|²|b|² − (a·b)². `None`
    /// where no identity applies (the caller takes v·v).
    fn norm_sq(&mut self, e: &Expr) -> Result<Option<Id>, SymbolicError> {
        Ok(match e {
            Expr::Axis(..) => Some(self.g.int(1)?),
            Expr::Neg(a, _) => self.norm_sq(a)?,
            Expr::Call(f, args, _) if f == "unit" && args.len() == 1 => Some(self.g.int(1)?),
            Expr::Call(f, args, _) if f == "cross" && args.len() == 2 => {
                let (Some(na), Some(nb)) = (
                    self.norm_sq_or_dot(&args[0])?,
                    self.norm_sq_or_dot(&args[1])?,
                ) else {
                    return Ok(None);
                };
                let Some(ab) = self.dot_exprs(&args[0], &args[1])? else {
                    return Ok(None);
                };
                let g = &mut self.g;
                let nn = g.mul(na, nb)?;
                let ab2 = g.mul(ab, ab)?;
                Some(g.sub(nn, ab2)?)
            }
            Expr::Binary(op @ (BinOp::Add | BinOp::Sub), a, b, _) => {
                let (Some(na), Some(nb)) = (self.norm_sq_or_dot(a)?, self.norm_sq_or_dot(b)?)
                else {
                    return Ok(None);
                };
                let Some(ab) = self.dot_exprs(a, b)? else {
                    return Ok(None);
                };
                let g = &mut self.g;
                let two_ab = g.scale(ab, Number::int(2))?;
                let cross_term = if *op == BinOp::Add {
                    two_ab
                } else {
                    g.neg(two_ab)?
                };
                Some(g.sum(&[na, nb, cross_term])?)
            }
            Expr::Binary(op @ (BinOp::Mul | BinOp::Div), a, b, _) => {
                let (k, v) = match (self.eval(a), self.eval(b)) {
                    (Some(Val::Scalar(_)), Some(Val::Vector(_))) if *op == BinOp::Mul => (a, b),
                    (Some(Val::Vector(_)), Some(Val::Scalar(_))) => (b, a),
                    _ => return Ok(None),
                };
                let (Some(Val::Scalar(k)), Some(nv)) = (self.eval(k), self.norm_sq_or_dot(v)?)
                else {
                    return Ok(None);
                };
                let g = &mut self.g;
                let k2 = g.mul(k, k)?;
                Some(if *op == BinOp::Mul {
                    g.mul(k2, nv)?
                } else {
                    g.div(nv, k2)?
                })
            }
            _ => None,
        })
    }

    /// A double cross product by the vector triple product identity,
    /// (x × y) × c = y (x·c) − x (y·c) and a × (x × y) = x (a·y) − y (a·x),
    /// with the dot products by [`Self::dot_exprs`] (so (e × f) × e = f − (e·f) e
    /// for a unit e). `None` when neither argument is a cross product.
    fn double_cross(&mut self, a: &Expr, b: &Expr) -> Result<Option<Vec3>, SymbolicError> {
        let as_cross = |e: &Expr| match e {
            Expr::Call(f, args, _) if f == "cross" && args.len() == 2 => {
                Some((args[0].clone(), args[1].clone()))
            }
            _ => None,
        };
        // (p, q, r): the result is p (q·r)... written as y (x·c) − x (y·c).
        let (x, y, c, sign) = if let Some((x, y)) = as_cross(a) {
            (x, y, b.clone(), false)
        } else if let Some((x, y)) = as_cross(b) {
            // a × (x × y) = −(x × y) × a
            (x, y, a.clone(), true)
        } else {
            return Ok(None);
        };
        let (Some(xc), Some(yc)) = (self.dot_exprs(&x, &c)?, self.dot_exprs(&y, &c)?) else {
            return Ok(None);
        };
        let (Some(Val::Vector(vx)), Some(Val::Vector(vy))) = (self.eval(&x), self.eval(&y)) else {
            return Ok(None);
        };
        let g = &mut self.g;
        let mut out = [vx[0]; 3];
        for i in 0..3 {
            let p = g.mul(vy[i], xc)?;
            let q = g.mul(vx[i], yc)?;
            out[i] = if sign { g.sub(q, p)? } else { g.sub(p, q)? };
        }
        Ok(Some(out))
    }

    /// [`Self::norm_sq`], or v·v by components.
    fn norm_sq_or_dot(&mut self, e: &Expr) -> Result<Option<Id>, SymbolicError> {
        if let Some(n) = self.norm_sq(e)? {
            return Ok(Some(n));
        }
        let Some(Val::Vector(v)) = self.eval(e) else {
            return Ok(None);
        };
        Ok(Some(dot(&mut self.g, v, v)?))
    }

    /// a·b of two vector expressions; a triple product with a repeated
    /// vector, (x × y)·x or (x × y)·y, is zero.
    fn dot_exprs(&mut self, a: &Expr, b: &Expr) -> Result<Option<Id>, SymbolicError> {
        let (Some(Val::Vector(va)), Some(Val::Vector(vb))) = (self.eval(a), self.eval(b)) else {
            return Ok(None);
        };
        if va == vb {
            return self.norm_sq_or_dot(a);
        }
        for (c, other) in [(a, vb), (b, va)] {
            if let Expr::Call(f, args, _) = c {
                if f == "cross" && args.len() == 2 {
                    for x in args {
                        if let Some(Val::Vector(vx)) = self.eval(x) {
                            if vx == other {
                                return Ok(Some(self.g.int(0)?));
                            }
                        }
                    }
                }
            }
        }
        Ok(Some(dot(&mut self.g, va, vb)?))
    }

    fn name(&mut self, ident: &Ident) -> Option<Val> {
        let name = ident.to_string();
        let g = &mut self.g;
        if name == "t" {
            return g.sym(self.time).ok().map(Val::Scalar);
        }
        if let Some(p) = self.params.iter().find(|p| p.ident == name) {
            return g.sym(p.symbol).ok().map(Val::Scalar);
        }
        if let Some((_, c)) = self.coords.iter().find(|(c, _)| c == &name) {
            return g.sym(c.q).ok().map(Val::Scalar);
        }
        if let Some((_, s)) = self.inputs.iter().find(|(c, _)| c == &name) {
            return g.sym(*s).ok().map(Val::Scalar);
        }
        if let Some(p) = self.points.iter().find(|p| p.name == name) {
            return Some(Val::Point(p.pos));
        }
        if self.poisoned.contains(&name) {
            return None;
        }
        if self.frames.iter().any(|f| f.name == name) {
            self.cx.error_spanned_by(
                ident,
                format!(
                    "`{name}` is a frame; its unit vectors are `{name}.x`, `{name}.y`, `{name}.z`"
                ),
            );
            return None;
        }
        let h = hint(&name, self.all_names());
        self.cx
            .error_spanned_by(ident, format!("unknown name `{name}`{h}"));
        None
    }

    fn binary(
        &mut self,
        op: BinOp,
        x: Val,
        y: Val,
        span: Span,
    ) -> Result<Option<Val>, SymbolicError> {
        use Val::*;
        let g = &mut self.g;
        let each = |g: &mut Graph,
                    a: Vec3,
                    b: Vec3,
                    f: fn(&mut Graph, Id, Id) -> Result<Id, SymbolicError>|
         -> Result<Vec3, SymbolicError> {
            Ok([f(g, a[0], b[0])?, f(g, a[1], b[1])?, f(g, a[2], b[2])?])
        };
        let scaled = |g: &mut Graph, v: Vec3, k: Id| -> Result<Vec3, SymbolicError> {
            Ok([g.mul(v[0], k)?, g.mul(v[1], k)?, g.mul(v[2], k)?])
        };
        Ok(Some(match (op, x, y) {
            (BinOp::Add, Scalar(a), Scalar(b)) => Scalar(g.add(a, b)?),
            (BinOp::Sub, Scalar(a), Scalar(b)) => Scalar(g.sub(a, b)?),
            (BinOp::Mul, Scalar(a), Scalar(b)) => Scalar(g.mul(a, b)?),
            (BinOp::Div, Scalar(a), Scalar(b)) => Scalar(g.div(a, b)?),
            (BinOp::Add, Vector(a), Vector(b)) => Vector(each(g, a, b, Graph::add)?),
            (BinOp::Sub, Vector(a), Vector(b)) => Vector(each(g, a, b, Graph::sub)?),
            (BinOp::Add, Point(a), Vector(b)) | (BinOp::Add, Vector(b), Point(a)) => {
                Point(each(g, a, b, Graph::add)?)
            }
            (BinOp::Sub, Point(a), Vector(b)) => Point(each(g, a, b, Graph::sub)?),
            (BinOp::Sub, Point(a), Point(b)) => Vector(each(g, a, b, Graph::sub)?),
            (BinOp::Mul, Scalar(k), Vector(v)) | (BinOp::Mul, Vector(v), Scalar(k)) => {
                Vector(scaled(g, v, k)?)
            }
            (BinOp::Div, Vector(v), Scalar(k)) => {
                let inv = g.recip(k).map_err(|_| SymbolicError::DivisionByZero {
                    expr: "a vector".into(),
                })?;
                Vector(scaled(g, v, inv)?)
            }
            _ => {
                let kind = |v: &Val| match v {
                    Scalar(_) => "a scalar",
                    Vector(_) => "a vector",
                    Point(_) => "a point",
                };
                let sym = match op {
                    BinOp::Add => "+",
                    BinOp::Sub => "-",
                    BinOp::Mul => "*",
                    BinOp::Div => "/",
                };
                self.cx.error_at(
                    span,
                    format!("cannot apply `{sym}` to {} and {}", kind(&x), kind(&y)),
                );
                return Ok(None);
            }
        }))
    }

    fn call(&mut self, f: &Ident, args: &[Expr], span: Span) -> Result<Option<Val>, SymbolicError> {
        let name = f.to_string();
        let arity = |n: usize| -> bool { args.len() == n };
        let wrong = |cx: &Ctxt, n: usize| {
            cx.error_spanned_by(
                f,
                format!("`{name}` takes {n} argument(s), found {}", args.len()),
            );
        };
        let unary = |g: &mut Graph, x: Id| -> Result<Id, SymbolicError> {
            match name.as_str() {
                "sin" => g.sin(x),
                "cos" => g.cos(x),
                "tan" => g.tan(x),
                "exp" => g.exp(x),
                "ln" => g.ln(x),
                "sqrt" => g.sqrt(x),
                _ => g.abs(x),
            }
        };
        match name.as_str() {
            "dt" => {
                if !arity(1) {
                    wrong(self.cx, 1);
                    return Ok(None);
                }
                if let Expr::Name(i) = &args[0] {
                    if let Some((_, c)) = self.coords.iter().find(|(c, _)| c == i) {
                        return Ok(Some(Val::Scalar(self.g.sym(c.rate)?)));
                    }
                }
                let Some(x) = self.scalar(&args[0]) else {
                    return Ok(None);
                };
                let d = self.g.time_derivative(x, &self.rules)?;
                Ok(Some(Val::Scalar(d)))
            }
            "sin" | "cos" | "tan" | "exp" | "ln" | "sqrt" | "abs" => {
                if !arity(1) {
                    wrong(self.cx, 1);
                    return Ok(None);
                }
                let Some(x) = self.scalar(&args[0]) else {
                    return Ok(None);
                };
                Ok(Some(Val::Scalar(unary(&mut self.g, x)?)))
            }
            "atan2" => {
                if !arity(2) {
                    wrong(self.cx, 2);
                    return Ok(None);
                }
                let (Some(y), Some(x)) = (self.scalar(&args[0]), self.scalar(&args[1])) else {
                    return Ok(None);
                };
                Ok(Some(Val::Scalar(self.g.atan2(y, x)?)))
            }
            "powi" => {
                if !arity(2) {
                    wrong(self.cx, 2);
                    return Ok(None);
                }
                let Some(x) = self.scalar(&args[0]) else {
                    return Ok(None);
                };
                let n = match &args[1] {
                    Expr::Int(n, _) => *n,
                    Expr::Neg(inner, _) => match **inner {
                        Expr::Int(n, _) => -n,
                        _ => {
                            self.cx.error_at(
                                args[1].span(),
                                "the exponent of `powi` is an integer literal",
                            );
                            return Ok(None);
                        }
                    },
                    other => {
                        self.cx
                            .error_at(other.span(), "the exponent of `powi` is an integer literal");
                        return Ok(None);
                    }
                };
                Ok(Some(Val::Scalar(self.g.powi(x, n)?)))
            }
            "omega" | "velocity" => {
                if !arity(1) {
                    wrong(self.cx, 1);
                    return Ok(None);
                }
                let Expr::Name(target) = &args[0] else {
                    let what = if name == "omega" {
                        "a frame"
                    } else {
                        "a point"
                    };
                    self.cx
                        .error_at(args[0].span(), format!("`{name}` takes the name of {what}"));
                    return Ok(None);
                };
                if name == "omega" {
                    let Some(fi) = self.frame_named(target) else {
                        return Ok(None);
                    };
                    Ok(Some(Val::Vector(self.frames[fi].omega)))
                } else {
                    let Some(p) = self.point_named(target) else {
                        return Ok(None);
                    };
                    let v = [
                        self.g.time_derivative(p[0], &self.rules)?,
                        self.g.time_derivative(p[1], &self.rules)?,
                        self.g.time_derivative(p[2], &self.rules)?,
                    ];
                    Ok(Some(Val::Vector(v)))
                }
            }
            "dot" | "cross" => {
                if !arity(2) {
                    wrong(self.cx, 2);
                    return Ok(None);
                }
                let (Some(a), Some(b)) = (self.vector(&args[0]), self.vector(&args[1])) else {
                    return Ok(None);
                };
                if name == "dot" {
                    Ok(Some(Val::Scalar(dot(&mut self.g, a, b)?)))
                } else if let Some(v) = self.double_cross(&args[0], &args[1])? {
                    Ok(Some(Val::Vector(v)))
                } else {
                    Ok(Some(Val::Vector(cross(&mut self.g, a, b)?)))
                }
            }
            "norm" | "unit" => {
                if !arity(1) {
                    wrong(self.cx, 1);
                    return Ok(None);
                }
                let Some(v) = self.vector(&args[0]) else {
                    return Ok(None);
                };
                let n2 = match self.norm_sq(&args[0])? {
                    Some(n2) => n2,
                    None => dot(&mut self.g, v, v)?,
                };
                if self.g.is_zero(n2) {
                    self.cx.error_at(
                        span,
                        format!("`{name}` of a vector that is identically zero"),
                    );
                    return Ok(None);
                }
                self.norms.push((
                    n2,
                    format!("the argument of `{name}(...)` in {}", self.context),
                ));
                let n = self.g.sqrt(n2)?;
                if name == "norm" {
                    Ok(Some(Val::Scalar(n)))
                } else {
                    let inv = self.g.recip(n)?;
                    Ok(Some(Val::Vector([
                        self.g.mul(v[0], inv)?,
                        self.g.mul(v[1], inv)?,
                        self.g.mul(v[2], inv)?,
                    ])))
                }
            }
            _ => {
                const FUNCS: &[&str] = &[
                    "dt", "sin", "cos", "tan", "exp", "ln", "sqrt", "abs", "atan2", "powi", "dot",
                    "cross", "norm", "unit", "omega", "velocity",
                ];
                let h = hint(&name, FUNCS.iter().map(|s| s.to_string()));
                self.cx
                    .error_spanned_by(f, format!("unknown function `{name}`{h}"));
                Ok(None)
            }
        }
    }
}

fn hint(name: &str, candidates: impl IntoIterator<Item = String>) -> String {
    let c: Vec<String> = candidates.into_iter().collect();
    did_you_mean(name, c.iter().map(|s| s.as_str()))
        .map(|s| format!("; did you mean `{s}`?"))
        .unwrap_or_default()
}

/// Rotation about local axis `k` by an angle with cosine `c` and sine `s`.
fn simple_rotation(g: &mut Graph, k: usize, c: Id, s: Id) -> Result<Mat3, SymbolicError> {
    let zero = g.int(0)?;
    let one = g.int(1)?;
    let ms = g.neg(s)?;
    Ok(match k {
        0 => [[one, zero, zero], [zero, c, ms], [zero, s, c]],
        1 => [[c, zero, s], [zero, one, zero], [ms, zero, c]],
        _ => [[c, ms, zero], [s, c, zero], [zero, zero, one]],
    })
}

/// Whether a symbol is of a kind that may appear in a parameter-only value.
pub fn is_parameter(g: &Graph, s: Symbol) -> bool {
    g.symbol_kind(s) == SymbolKind::Parameter
}
