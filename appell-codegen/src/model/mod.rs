//! Resolve names and build the kinematics in the symbolic engine.
//!
//! Frames carry their rotation matrix (columns are the frame's unit vectors
//! in N components) and angular velocity in N; points carry their position
//! in N. Everything is an expression in the coordinates, parameters, inputs
//! and time of one [`Graph`]. [`build`] makes the [`Model`] and its
//! [`Twin`] from the syntax ([`crate::ast::ModelAst`]):
//!
//! | module | what it resolves |
//! | --- | --- |
//! | `builder` | symbols, speeds, the order of the steps, names |
//! | `frames` | frames: rotations about parent or fixed axes, the twin's direction-cosine symbols |
//! | `bodies` | points, bodies, constraints, loads, rolling contacts |
//! | `scenes` | scenes: their effects and outputs |
//! | `expr` | expressions: names, arithmetic on scalars, vectors and points |
//! | `calls` | function calls: `dt`, `dot`, `cross`, `norm`, `unit`, `omega`, `velocity`, ... |
//! | `contacts` | `contact(...)`s: a foot's rows, and the speeds of a scene that holds it |
//! | [`tree`] | a tree of joints: its links, placements and bodies, its numbers lowered into the graph |

mod bodies;
mod builder;
mod calls;
mod contacts;
mod expr;
mod frames;
mod scenes;
pub mod tree;

use syn::Ident;

use appell_symbolic::{Coordinate, Graph, Id, RateRules, Symbol};

use crate::ast::ModelAst;
use crate::ctxt::Ctxt;

pub use crate::algebra::{Mat3, Vec3};
pub use contacts::Contact;

/// A parameter (struct field).
#[derive(Clone)]
pub struct Param {
    /// Its name in the model (`m_3` for element 3 of the array field `m`),
    /// also the local that holds its value in the generated code.
    pub ident: Ident,
    /// Its symbol.
    pub symbol: Symbol,
    /// Declared positive.
    pub positive: bool,
    /// The struct field.
    pub field: Ident,
    /// The element, for an array field.
    pub index: Option<usize>,
}

impl Param {
    /// The field access after `self.`: `m` or `m[3]`.
    pub fn place(&self) -> proc_macro2::TokenStream {
        let field = &self.field;
        match self.index {
            None => quote::quote!(#field),
            Some(k) => {
                let k = proc_macro2::Literal::usize_unsuffixed(k);
                quote::quote!(#field[#k])
            }
        }
    }

    /// How error messages name it: `m` or `m[3]`.
    pub fn display(&self) -> String {
        match self.index {
            None => self.field.to_string(),
            Some(k) => format!("{}[{k}]", self.field),
        }
    }
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
    /// The effect it belongs to; None: every scene keeps it.
    pub effect: Option<String>,
}

/// `scene(name, effects(...), outputs(...), speeds(...))`: a specialised
/// rhs with the chosen effects' loads and constraints only, its own
/// privileged speeds when given, and the requested outputs.
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
    /// Its own privileged speeds (`speeds(...)`) and their tokens.
    pub speeds: Option<(Vec<SpeedSpec>, proc_macro2::TokenStream)>,
}

/// The rows of the contacts `scene` holds, in declaration order.
fn held_rows(contacts: &[Contact], scene: &Scene) -> Vec<Constraint> {
    scene
        .contacts(contacts)
        .into_iter()
        .flat_map(|c| c.rows.iter().cloned())
        .collect()
}

impl Scene {
    /// The contacts the scene holds: those whose effect it names.
    pub fn contacts<'a>(&self, contacts: &'a [Contact]) -> Vec<&'a Contact> {
        contacts
            .iter()
            .filter(|c| self.effects.contains(&c.effect))
            .collect()
    }

    /// Whether the scene keeps a constraint of `effect` (one without an
    /// effect is in every scene).
    pub fn keeps_constraint(&self, effect: &Option<String>) -> bool {
        effect.as_ref().is_none_or(|e| self.effects.contains(e))
    }
}

/// The constraints and privileged speeds a derivation takes: the model's
/// own ([`Model::constraints`]), or a scene's where they differ from the
/// model's (its constraints are those without an effect or of an effect
/// it names, its speeds its own `speeds(...)`).
#[derive(Clone)]
pub struct ConstraintSet {
    /// Holonomic constraints.
    pub holonomic: Vec<Constraint>,
    /// Nonholonomic constraints.
    pub nonholonomic: Vec<Constraint>,
    /// Rolling contacts.
    pub rolling: Vec<Rolling>,
    /// The coordinates whose rates are privileged speeds.
    pub speeds: Vec<usize>,
    /// The privileged speeds.
    pub speed_specs: Vec<SpeedSpec>,
    /// The tokens of the `speeds(...)` they come from, for errors.
    pub speeds_at: proc_macro2::TokenStream,
}

impl ConstraintSet {
    /// `scene`'s constraints and speeds, or None when they are the model's.
    pub fn of_scene(model: &Model, scene: &Scene) -> Option<ConstraintSet> {
        let keeps = |e: &Option<String>| scene.keeps_constraint(e);
        let own = &model.constraints;
        let drops = own
            .holonomic
            .iter()
            .chain(&own.nonholonomic)
            .any(|c| !keeps(&c.effect))
            || own.rolling.iter().any(|r| !keeps(&r.effect));
        if !drops && scene.speeds.is_none() && scene.contacts(&model.contacts).is_empty() {
            return None;
        }
        let (speed_specs, speeds_at) = scene
            .speeds
            .clone()
            .unwrap_or_else(|| (own.speed_specs.clone(), own.speeds_at.clone()));
        let kept = |list: &[Constraint]| -> Vec<Constraint> {
            list.iter().filter(|c| keeps(&c.effect)).cloned().collect()
        };
        Some(ConstraintSet {
            holonomic: kept(&own.holonomic),
            nonholonomic: kept(&own.nonholonomic)
                .into_iter()
                .chain(held_rows(&model.contacts, scene))
                .collect(),
            rolling: own
                .rolling
                .iter()
                .filter(|r| keeps(&r.effect))
                .cloned()
                .collect(),
            speeds: speed_specs.iter().filter_map(|s| s.coordinate).collect(),
            speed_specs,
            speeds_at,
        })
    }

    /// `twin` with `scene`'s constraints only.
    pub fn twin(&self, twin: &Twin, scene: &Scene) -> Twin {
        let keeps = |e: &Option<String>| scene.keeps_constraint(e);
        let mut t = twin.clone();
        t.holonomic.retain(|c| keeps(&c.effect));
        t.nonholonomic.retain(|c| keeps(&c.effect));
        t.nonholonomic.extend(held_rows(&t.contacts, scene));
        t.rolling.retain(|r| keeps(&r.effect));
        t
    }
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
    /// The effect it belongs to; None: every scene keeps it.
    pub effect: Option<String>,
    /// For a row of a `contact(...)`: the contact's index and the row's
    /// axis (see `appell_core::RowSource::Contact`).
    pub contact: Option<(usize, usize)>,
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
    /// The model's own constraints and privileged speeds: the set the
    /// full derivation takes, and the one a tree's recursions run in (a
    /// scene takes its own, [`ConstraintSet::of_scene`]).
    pub constraints: ConstraintSet,
    /// Whether the model names its speeds (`speeds(...)` or joints); the
    /// speeds stage says what to name when it does not.
    pub speeds_declared: bool,
    /// Inputs: the declared ones, then the companions of the inputs that
    /// drive constraints (`{input}_rate`, and `{input}_accel` for a
    /// holonomic one).
    pub inputs: Vec<(Ident, Symbol)>,
    /// The rate of each input that drives a constraint (and of its
    /// `_rate` companion in a holonomic one): (input, its rate's symbol).
    pub input_rates: Vec<(Symbol, Symbol)>,
    /// Time.
    pub time: Symbol,
    /// Frames; index 0 is N.
    pub frames: Vec<Frame>,
    /// Points; index 0 is O.
    pub points: Vec<Point>,
    /// Bodies and particles.
    pub bodies: Vec<Body>,
    /// `contact(...)`s: held only in the scenes that name their effects.
    pub contacts: Vec<Contact>,
    /// The URDF's joint limits: joint, lower, upper, velocity, effort.
    pub joint_limits: Vec<(String, [f64; 4])>,
    /// Forces.
    pub forces: Vec<Load>,
    /// Torques.
    pub torques: Vec<Load>,
    /// Effect names in order of first use.
    pub effects: Vec<String>,
    /// Declared scenes.
    pub scenes: Vec<Scene>,
    /// The `gravity(...)` acceleration (N components), if declared.
    pub gravity: Option<Vec3>,
    /// Whether the derive writes `rhs_jacobian`: always (`jacobian(on)`),
    /// never (`jacobian(off)`), or (`None`) where it costs little.
    pub jacobian: Option<bool>,
    /// The squared length of every `norm(...)` and `unit(...)` argument, with
    /// where it occurs, so that the generated code can name a zero-length
    /// one at run time.
    pub norms: Vec<(Id, String)>,
    /// Every divisor made of parameters alone (`1 / k`), with where it
    /// occurs, so that `validate` can name a zero one.
    pub divisors: Vec<(Id, String)>,
    /// Frames oriented by a quaternion of coordinates: the indices (into
    /// `coords`) of its components, scalar first. The elimination solves
    /// their rates in closed form.
    pub quaternions: Vec<[usize; 4]>,
    /// The coordinates whose rates joints made privileged speeds, for
    /// errors that count speeds.
    pub joint_speeds: Vec<String>,
    /// Files the model was read from (absolute paths): the output includes
    /// them, so cargo builds the model again when one changes.
    pub files: Vec<String>,
    /// The kinematic tree, or why the model is not a plain tree of joints.
    pub tree: Result<tree::TreeSpec, String>,
}

impl Model {
    /// The symbols q̇_r of the coordinates' rates, in order.
    pub fn coordinate_rates(&self) -> Vec<Symbol> {
        self.coords.iter().map(|(_, c)| c.rate).collect()
    }

    /// `rules` with every driving input's rate (see
    /// [`Model::input_rates`]).
    pub fn with_input_rates(
        g: &mut Graph,
        input_rates: &[(Symbol, Symbol)],
        mut rules: RateRules,
    ) -> Result<RateRules, appell_symbolic::SymbolicError> {
        for &(s, rate) in input_rates {
            let r = g.sym(rate)?;
            rules = rules.with(s, r);
        }
        Ok(rules)
    }

    /// What the model declares about signs: parameters marked `positive`.
    pub fn assumptions(&self) -> appell_symbolic::Assumptions {
        let mut assume = appell_symbolic::Assumptions::new();
        for p in &self.params {
            if p.positive {
                assume = assume.positive(p.symbol);
            }
        }
        assume
    }
}

/// A direction cosine standing as a symbol in the twin model: its rate is a
/// component of ω × column, so a derivative through nested rotations stays
/// a few cross products instead of the product rule over every factor of
/// every direction cosine. [`Twin::uncut_substitution`] puts the values
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

/// The kinematics built again in the model's graph with each frame's
/// direction cosines standing as symbols (see [`Cut`]): the derivation
/// differentiates through it where it wants a constraint row or a velocity
/// as written, not multiplied out. Its entries match the model's one for
/// one (the same frames, bodies, constraints and contacts, in order).
#[derive(Clone)]
pub struct Twin {
    /// The frames, their matrices made of direction-cosine symbols.
    pub frames: Vec<Frame>,
    /// The bodies.
    pub bodies: Vec<Body>,
    /// The holonomic constraints.
    pub holonomic: Vec<Constraint>,
    /// The nonholonomic constraints.
    pub nonholonomic: Vec<Constraint>,
    /// The rolling contacts.
    pub rolling: Vec<Rolling>,
    /// The contacts.
    pub contacts: Vec<Contact>,
    /// The direction-cosine symbols.
    pub cuts: Vec<Cut>,
}

impl Twin {
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

/// What [`build`] makes: the resolved model and its twin, sharing one graph
/// (the model's).
pub struct Kinematics {
    /// The model.
    pub model: Model,
    /// The twin; `None` if it could not be built (it is then not needed:
    /// the derivation differentiates the model's own expressions).
    pub twin: Option<Twin>,
}

/// Resolves names and builds the kinematics; `None` when errors were
/// recorded.
pub fn build(cx: &Ctxt, ast: &ModelAst) -> Option<Kinematics> {
    let (mut model, _) = builder::build_in(cx, ast, Graph::new(), None)?;
    // The twin, built again in the same graph with direction cosines as
    // symbols; the first build found every error there is.
    let scratch = Ctxt::new();
    let frames: Vec<Mat3> = model.frames.iter().map(|f| f.rot).collect();
    let built = builder::build_in(&scratch, ast, model.g.clone(), Some(frames));
    let twin = match (scratch.check(), built) {
        (Ok(()), Some((mut t, cuts))) => {
            model.g = std::mem::replace(&mut t.g, Graph::new());
            Some(Twin {
                frames: t.frames,
                bodies: t.bodies,
                holonomic: t.constraints.holonomic,
                nonholonomic: t.constraints.nonholonomic,
                rolling: t.constraints.rolling,
                contacts: t.contacts,
                cuts,
            })
        }
        _ => None,
    };
    Some(Kinematics { model, twin })
}
