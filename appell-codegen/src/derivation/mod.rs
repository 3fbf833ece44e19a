//! Appell's equations by Method II (Wang & Pao 2003, Secs. III B-C and
//! IV B), in the symbolic engine, one module per stage:
//!
//! | stage | module | input → output |
//! | --- | --- | --- |
//! | 1. velocity constraints D q̇ + d = 0 (eq. 25) | [`rows`] | `Model`, [`ConstraintSet`] → [`ConstraintRows`] |
//! | 2. privileged speeds, u = W q̇ + w | [`speeds`] | rows → [`SpeedDefinitions`] |
//! | 3. elimination of the unknown rates (eqs. 27-29) | [`elimination`] | D, d, speeds → [`SolvedRates`] |
//! | 4. q̇ = C ẏ + c (eqs. 30-31) | [`speed_map`] | solved rates → [`SpeedMap`], [`Rates`] |
//! | 5. numeric elimination, S X = R, S w = (Ṙ − Ṡ X)[ẏ; 1] | [`numeric`] | [`SchurComplement`] → [`NumericElimination`] |
//! | 6. partial velocities β̄_k, γ̄_k (eq. 54) | [`partials`] | speed map → [`PartialVelocities`] |
//! | 7. acceleration remainders (eq. 37) | [`remainders`] | partials → [`Remainders`] |
//! | 8. M and f's inertial terms (eq. 56) | [`assembly`] | partials, remainders → [`Assembled`] |
//! | 9. composites and rotors, by cost | [`folding`] | assembler → [`Folded`] |
//! | 10. loads; M and f final | [`loads`] | folded → [`Equations`] |
//! | 11. energies | [`energies`] | partials → [`Energies`] |
//! | 12. reduced state, cyclic coordinates (eq. 42) | [`reduction`] | equations → [`Reduction`] |
//! | 13. structured form of a tree of joints (ABA, RNEA, CRBA) | [`tree`] | `TreeSpec` → [`tree::Structured`] |
//! | 14. derivatives of the reduced rhs | [`jacobian`] | equations, structured form → [`jacobian::Jacobians`] |
//!
//! A tree of [`tree::STRUCTURED_ONLY_LINKS`] moving links or more skips
//! stages 6 to 11: its M, f and energies come from the structured form
//! ([`tree::equations`]), whose cost grows linearly with the links.
//!
//! Between stages 11 and 12, X's identically zero last column (kept so far
//! because its rate carries w) is set to zero everywhere
//! ([`numeric::drop_vanishing`]). Scenes ([`scenes`]) re-derive only stages
//! 10-12 from a full derivation.
//! [`algebra`](crate::algebra) holds the vector helpers, [`probe`](crate::probe) the
//! numeric identity and rank tests, [`structure`] the sparsity analysis of
//! square systems, [`text`] the readable equations.
//!
//! The stages take the constraints and privileged speeds they derive
//! with, a [`ConstraintSet`]: the model's own ([`Model::constraints`]) or
//! a scene's ([`ConstraintSet::of_scene`]); the [`Derivation`] keeps it
//! ([`Derivation::constraint_set`]) for the stages after it and the
//! emitter.
//!
//! Every expression lives in the model's one graph, whose node ids follow
//! construction order and decide the order of terms in sums: the stages run
//! in a fixed order, and a change of that order changes the generated code
//! (the snapshot test of every model's expansion shows it).

pub mod assembly;
pub mod elimination;
pub mod energies;
pub mod folding;
pub mod jacobian;
pub mod loads;
pub mod numeric;
pub mod partials;
pub mod reduction;
pub mod remainders;
pub mod rows;
pub mod scenes;
pub mod speed_map;
pub mod speeds;
pub mod structure;
pub mod text;
pub mod tree;

use appell_symbolic::{Id, RateRules, Substitution, SymbolicError};

pub use assembly::Assembled;
pub use elimination::{SchurComplement, SolvedRates};
pub use energies::Energies;
pub use folding::Folded;
pub use loads::Equations;
pub use numeric::{Elimination, NumericElimination};
pub use partials::{BodyTerms, PartialVelocities};
pub use reduction::Reduction;
pub use remainders::Remainders;
pub use rows::{ConstraintRows, RowSource};
pub use speed_map::{Rates, SpeedMap};
pub use speeds::SpeedDefinitions;
pub use structure::{singleton_rows, SingletonOrder};

use crate::ctxt::Ctxt;
use crate::model::tree as tree_spec;
use crate::model::{ConstraintSet, Kinematics, Model, Scene, Twin};

/// Choices the derivation makes by operation count, forced for tests that
/// compare the forms.
#[derive(Clone, Copy, Debug, Default)]
pub struct Options {
    /// Fold composites and rotors even where that costs operations.
    pub fold_always: bool,
    /// Write every rotor's terms whole (`Some(true)`) or split
    /// (`Some(false)`) instead of the cheaper.
    pub rotor_form: Option<bool>,
    /// Leave out the structured form of a tree of joints.
    pub closed_form_only: bool,
}

/// The derivatives every stage takes: d/dt under the coordinates' rules,
/// and the twin (the kinematics again with direction cosines as symbols),
/// used where expressions are differentiated along q̇ and not expanded;
/// `uncut` puts the values back.
pub struct Calculus {
    /// q → q̇ → q̈, t → 1.
    pub rules: RateRules,
    /// The twin, when the model has one.
    pub twin: Option<Twin>,
    /// The twin's rate rules (direction cosines turning with their frames).
    pub twin_rules: Option<RateRules>,
    /// Direction-cosine symbols → their values.
    pub uncut: Substitution,
}

impl Calculus {
    /// The derivatives, with `twin` where the model has one; the inputs
    /// that drive constraints have their companions as rates.
    pub fn new(model: &mut Model, twin: Option<Twin>) -> Result<Calculus, SymbolicError> {
        let rates = model.input_rates.clone();
        let g = &mut model.g;
        let twin_rules = match twin.as_ref() {
            Some(t) => Some(Model::with_input_rates(g, &rates, t.rate_rules())?),
            None => None,
        };
        let uncut = twin
            .as_ref()
            .map_or_else(Substitution::new, |t| t.uncut_substitution());
        Ok(Calculus {
            rules: Model::with_input_rates(g, &rates, RateRules::coordinates())?,
            twin,
            twin_rules,
            uncut,
        })
    }
}

/// A model's derivations: the full equations and each scene's, their
/// expressions all in the model's one graph.
pub struct Derived {
    /// The model; its graph holds every expression of the derivations.
    pub model: Model,
    /// The full model's equations.
    pub full: Derivation,
    /// Each declared scene with its equations (a scene whose derivation
    /// failed is reported and left out).
    pub scenes: Vec<(Scene, Derivation)>,
}

/// The derived equations of the model or of one scene, and everything the
/// emitter needs besides the model.
pub struct Derivation {
    /// Number of coordinates n.
    pub n: usize,
    /// Number of constraint rows m.
    pub m: usize,
    /// Number of privileged speeds l.
    pub l: usize,
    /// D, d and where each row comes from (stage 1).
    pub constraints: ConstraintRows,
    /// D q̇ + d, with q̇ the coordinate rate symbols.
    pub velocity_residuals: Vec<Id>,
    /// W, w and the unknowns (stage 2).
    pub speeds: SpeedDefinitions,
    /// C, c and q̇ = C ẏ + c (stage 4).
    pub map: SpeedMap,
    /// How B and b are computed (stage 5), with the ignorable coordinates
    /// fixed.
    pub elimination: Elimination,
    /// M and f (stage 10), with the ignorable coordinates fixed.
    pub equations: Equations,
    /// T, V and the input power (stage 11).
    pub energies: Energies,
    /// The reduced state (stage 12).
    pub reduction: Reduction,
    /// M and the elimination before the ignorable coordinates were fixed
    /// (what scenes start from).
    pub unreduced: Unreduced,
    /// Bodies whose terms were folded together (composites and rotors), as
    /// readable lines.
    pub folded: Vec<String>,
    /// Readable equations.
    pub text: String,
    /// Whether M and f are Appell's closed form (false: a large tree's,
    /// from the structured form; see [`tree::STRUCTURED_ONLY_LINKS`]).
    pub closed_form: bool,
    /// The structured form (a plain tree of joints), or why there is none.
    pub structured: Result<tree::Structured, String>,
    /// For a tree under constraints, what its projected M and f cost
    /// against the closed form's; where they cost less, `equations` holds
    /// them and `closed_form` is false.
    pub projection: Option<Projection>,
    /// The constraints and privileged speeds it was derived with: the
    /// model's, or a scene's own.
    pub constraint_set: ConstraintSet,
    /// Whether they are a scene's own, where they differ from the model's.
    pub own_constraints: bool,
    /// The derivatives of the reduced rhs (stage 14); `None` until the
    /// stage ran.
    pub jacobians: Option<jacobian::Jacobians>,
}

/// The operations per call of a constrained tree's M and f (lower
/// triangle and f, parameter-only work hoisted), projected and closed.
#[derive(Clone, Copy, Debug)]
pub struct Projection {
    /// The projected tree's.
    pub ops: usize,
    /// The closed form's.
    pub closed_ops: usize,
}

impl Projection {
    /// Whether the projected form is used.
    pub fn chosen(&self) -> bool {
        self.ops < self.closed_ops
    }
}

/// M and the elimination before stage 12 fixed the coordinates they do not
/// depend on.
#[derive(Clone)]
pub struct Unreduced {
    /// M (l×l).
    pub mass: Vec<Id>,
    /// The elimination.
    pub elimination: Elimination,
}

/// Runs the derivation, the full model's and then each scene's; errors go
/// to `cx`.
///
/// ```
/// use appell_codegen::{ctxt::Ctxt, derivation, model, parse};
///
/// // A particle on a rod of length l, angle q from the downward vertical.
/// let input: syn::DeriveInput = syn::parse_str(r#"
///     #[appell(coordinates(q), speeds(q))]
///     #[appell(point(P = O + l * sin(q) * N.x - l * cos(q) * N.y), particle(P, mass = m))]
///     #[appell(gravity(-g * N.y))]
///     struct Pendulum { m: f64, l: f64, g: f64 }
/// "#).unwrap();
/// let cx = Ctxt::new();
/// let ast = parse::parse(&cx, &input);
/// let kinematics = model::build(&cx, &ast).expect("a model");
/// let derived = derivation::derive(&cx, kinematics).expect("equations");
/// cx.check().expect("no errors");
///
/// // M = m l², f = −m g l sin q (Appell's equations, eq. 56).
/// let g = &derived.model.g;
/// let (m, f) = (derived.full.equations.mass[0], derived.full.equations.forcing[0]);
/// let at = [("m", 2.0), ("l", 0.5), ("g", 9.81), ("q", 0.3)];
/// let value = |e| g.eval_named(e, &at).unwrap();
/// assert!((value(m) - 2.0 * 0.25).abs() < 1e-12);
/// assert!((value(f) + 2.0 * 9.81 * 0.5 * 0.3_f64.sin()).abs() < 1e-12);
/// assert!(derived.full.text.contains("M[q_dot, q_dot]"));
/// ```
pub fn derive(cx: &Ctxt, kinematics: Kinematics) -> Option<Derived> {
    derive_with(cx, kinematics, &Options::default())
}

/// [`derive()`] with the cost-driven choices forced by `options`.
pub fn derive_with(cx: &Ctxt, kinematics: Kinematics, options: &Options) -> Option<Derived> {
    let Kinematics { mut model, twin } = kinematics;
    let scenes_twin = twin.clone();
    let set = model.constraints.clone();
    let mut full = complete(cx, &mut model, &set, twin, options)?;
    let mut jacobians = jacobian::differentiate(&mut model, &full);
    jacobians.inverse = jacobian::inverse_dynamics(&mut model, &full);
    full.jacobians = Some(jacobians);
    let mut scenes = Vec::new();
    for scene in model.scenes.clone() {
        let d = if ConstraintSet::of_scene(&model, &scene).is_some() {
            scenes::derive_constrained_scene(cx, &mut model, scenes_twin.as_ref(), &scene, options)
        } else {
            scenes::derive_scene(cx, &mut model, &full, &scene)
        };
        if let Some(d) = d {
            scenes.push((scene, d));
        }
    }
    Some(Derived {
        model,
        full,
        scenes,
    })
}

/// Stages 1 to 13 of `model` with the constraints and speeds of `set`;
/// errors go to `cx`.
fn complete(
    cx: &Ctxt,
    model: &mut Model,
    set: &ConstraintSet,
    twin: Option<Twin>,
    options: &Options,
) -> Option<Derivation> {
    match Calculus::new(model, twin).and_then(|calculus| stages(cx, model, set, calculus, options))
    {
        Ok(Some(d)) => {
            let mut d = d.finish(model, set);
            d.structured = if options.closed_form_only {
                Err(String::new())
            } else {
                structured_form(model, set, &d.reduction.ignorable)
            };
            if !options.closed_form_only {
                if let Err(e) = project(model, &mut d) {
                    cx.error_at(
                        model.name.span(),
                        format!("projecting the tree's equations failed: {e}"),
                    );
                    return None;
                }
            }
            Some(d)
        }
        Ok(None) => None,
        Err(e) => {
            cx.error_at(
                model.name.span(),
                format!("deriving the equations failed: {e}"),
            );
            None
        }
    }
}

/// Whether the model under `set` is its plain tree: a scene that holds
/// contacts (or names speeds of its own) makes it a constrained one.
fn plain_under(model: &Model, set: &ConstraintSet, spec: &tree_spec::TreeSpec) -> bool {
    let own = &model.constraints.speed_specs;
    let same_speeds = set.speed_specs.len() == own.len()
        && set
            .speed_specs
            .iter()
            .zip(own)
            .all(|(a, b)| a.name == b.name);
    spec.plain.is_ok() && set.nonholonomic.is_empty() && same_speeds
}

/// The structured form of a plain tree of joints (stage 13), the
/// `ignorable` coordinates fixed at zero in its accelerations; else why
/// there is none.
fn structured_form(
    model: &mut Model,
    set: &ConstraintSet,
    ignorable: &[usize],
) -> Result<tree::Structured, String> {
    let spec = model.tree.clone()?;
    spec.plain.clone()?;
    if !plain_under(model, set, &spec) {
        return Err("the scene holds contacts".into());
    }
    tree::structured(model, &spec, ignorable)
        .map_err(|e| format!("the structured form failed: {e}"))
}

/// Stage 13 for a tree under constraints (symbolic elimination): M and f
/// projected from the tree's recursions, the ignorable coordinates at
/// zero, put in place of the closed form's where they cost less per call.
fn project(model: &mut Model, d: &mut Derivation) -> Result<(), SymbolicError> {
    let Ok(spec) = model.tree.clone() else {
        return Ok(());
    };
    // Scenes keep some effects' loads of the closed form's terms, which the
    // projected tree does not separate.
    // A ball's speeds are not its coordinates' rates, which the projection
    // runs the recursions in.
    let ball = spec.links.iter().any(|k| {
        matches!(
            k.motion,
            Some(crate::model::tree::Motion::Spherical | crate::model::tree::Motion::Free)
        )
    });
    if spec.plain.is_ok()
        || !matches!(d.elimination, Elimination::Symbolic)
        || !model.scenes.is_empty()
        || ball
    {
        return Ok(());
    }
    let p = tree::projected::projected(model, &spec, &d.map, &d.reduction.ignorable)?;
    let cost = |g: &appell_symbolic::Graph, mass: &[Id], forcing: &[Id]| {
        let l = forcing.len();
        let mut roots: Vec<Id> = (0..l)
            .flat_map(|i| (0..=i).map(move |j| (i, j)))
            .map(|(i, j)| mass[i * l + j])
            .collect();
        roots.extend(forcing);
        let options = appell_symbolic::EmitOptions {
            fused: true,
            ..Default::default()
        };
        let program = appell_symbolic::Program::lower(g, &roots);
        program.to_tokens(g, &options).ops.total()
    };
    let projection = Projection {
        ops: cost(&model.g, &p.mass, &p.forcing),
        closed_ops: cost(&model.g, &d.equations.mass, &d.equations.forcing),
    };
    if projection.chosen() {
        d.equations = Equations {
            inertial_terms: p.forcing.iter().map(|&f| vec![f]).collect(),
            load_terms: Vec::new(),
            mass: p.mass,
            forcing: p.forcing,
        };
        d.closed_form = false;
    }
    d.projection = Some(projection);
    d.text = text::equations_text(model, d);
    Ok(())
}

/// The stage outputs before they are bound to the model.
struct Stages {
    constraints: ConstraintRows,
    velocity_residuals: Vec<Id>,
    speeds: SpeedDefinitions,
    map: SpeedMap,
    elimination: Elimination,
    equations: Equations,
    energies: Energies,
    reduction: Reduction,
    unreduced: Unreduced,
    closed_form: bool,
    folded: Vec<String>,
}

impl Stages {
    fn finish(self, model: &Model, set: &ConstraintSet) -> Derivation {
        let mut d = Derivation {
            n: model.coords.len(),
            m: self.constraints.d0.len(),
            l: set.speed_specs.len(),
            constraints: self.constraints,
            velocity_residuals: self.velocity_residuals,
            speeds: self.speeds,
            map: self.map,
            elimination: self.elimination,
            equations: self.equations,
            energies: self.energies,
            reduction: self.reduction,
            unreduced: self.unreduced,
            folded: self.folded,
            closed_form: self.closed_form,
            text: String::new(),
            structured: Err(String::new()),
            projection: None,
            constraint_set: set.clone(),
            own_constraints: false,
            jacobians: None,
        };
        d.text = text::equations_text(model, &d);
        d
    }
}

/// Stages 1 to 12 in order.
fn stages(
    cx: &Ctxt,
    model: &mut Model,
    set: &ConstraintSet,
    mut calculus: Calculus,
    options: &Options,
) -> Result<Option<Stages>, SymbolicError> {
    let Some(constraints) = rows::constraint_rows(cx, model, set, &calculus)? else {
        return Ok(None);
    };
    let Some(speeds) = speeds::speed_definitions(cx, model, set, &constraints)? else {
        return Ok(None);
    };
    let Some(solved) =
        elimination::eliminate(cx, model, set, &constraints.d, &constraints.d0, &speeds)?
    else {
        return Ok(None);
    };
    let (mut map, mut rates) = speed_map::speed_map(model, set, &speeds, &solved, &calculus)?;
    let mut elimination = match solved.schur {
        Some(schur) => Elimination::Numeric(numeric::numeric_elimination(
            model,
            schur,
            numeric::NumericInputs {
                set,
                rows: &constraints,
                dependent: &speeds.dependent,
                map: &map,
                vanishing: &solved.vanishing,
            },
            &mut rates,
            &mut calculus.uncut,
        )?),
        None => Elimination::Symbolic,
    };
    let large_tree = model.tree.clone().ok().filter(|spec| {
        !options.closed_form_only && tree::moving_links(spec) >= tree::STRUCTURED_ONLY_LINKS
    });
    let plain = large_tree.as_ref().filter(|spec| {
        plain_under(model, set, spec) && matches!(elimination, Elimination::Symbolic)
    });
    // A large tree whose scene holds contacts: its recursions projected
    // onto the scene's speeds.
    let contacts = large_tree
        .as_ref()
        .filter(|spec| spec.plain.is_ok() && !plain_under(model, set, spec));
    let projected = match contacts {
        Some(spec) => {
            let own = model.constraints.speed_specs.clone();
            tree::projected::in_speeds(model, set, spec, &map, &rates.reduced, &own)?
        }
        None => None,
    };
    let (mut equations, mut energies, folded_lines) = match (plain.cloned(), projected) {
        (Some(spec), _) => {
            let s = tree::controller(model, &spec)?;
            let (equations, energies) = tree::equations::equations(model, set, &s)?;
            (equations, energies, None)
        }
        (None, Some(p)) => {
            let (equations, energies) = tree::equations::projected(model, p)?;
            (equations, energies, None)
        }
        (None, None) => {
            let parts = ClosedForm {
                speeds: &speeds,
                map: &map,
                rates: &mut rates,
                calculus: &mut calculus,
            };
            let (equations, energies, lines) = closed_form(model, parts, options)?;
            (equations, energies, Some(lines))
        }
    };
    numeric::drop_vanishing(
        &mut model.g,
        &solved.vanishing,
        &mut map,
        &mut equations,
        &mut energies,
        &mut elimination,
    )?;
    let unreduced = Unreduced {
        mass: equations.mass.clone(),
        elimination: elimination.clone(),
    };
    let reduction = reduction::reduce_state(
        &mut model.g,
        reduction::ReductionInputs {
            coords: &model.coords,
            quadrature: &[],
            qdot: &map.qdot,
            dependent: &speeds.dependent,
        },
        &mut equations.mass,
        &mut equations.forcing,
        &mut elimination,
    )?;
    let velocity_residuals = velocity_residuals(model, &constraints)?;
    Ok(Some(Stages {
        constraints,
        velocity_residuals,
        speeds,
        map,
        elimination,
        equations,
        energies,
        reduction,
        unreduced,
        closed_form: folded_lines.is_some(),
        folded: folded_lines.unwrap_or_default(),
    }))
}

/// What stages 6 to 11 of the closed form read and update.
struct ClosedForm<'a> {
    speeds: &'a SpeedDefinitions,
    map: &'a SpeedMap,
    rates: &'a mut Rates,
    calculus: &'a mut Calculus,
}

/// Stages 6 to 11: partial velocities, remainders, M and f, energies;
/// with the folded bodies' lines.
fn closed_form(
    model: &mut Model,
    parts: ClosedForm<'_>,
    options: &Options,
) -> Result<(Equations, Energies, Vec<String>), SymbolicError> {
    let ClosedForm {
        speeds,
        map,
        rates,
        calculus,
    } = parts;
    let partials = partials::partial_velocities(model, map, &calculus.rules, &rates.fixed)?;
    let mut remainders =
        remainders::remainders(model, &speeds.dependent, map, &partials, rates, calculus)?;
    let folded = assemble_and_fold(
        model,
        &partials,
        &mut remainders,
        map,
        rates,
        calculus,
        options,
    )?;
    let equations = loads::equations(
        model,
        folded.assembled,
        &folded.composites,
        &partials,
        map,
        &calculus.rules,
        &mut rates.fixed,
    )?;
    let energies = energies::energies(model, &partials, map, &mut rates.fixed)?;
    Ok((equations, energies, folded.lines))
}

/// Stages 8 and 9: M and f's inertial terms, folded where that is
/// cheaper.
fn assemble_and_fold(
    model: &mut Model,
    partials: &PartialVelocities,
    remainders: &mut Remainders,
    map: &SpeedMap,
    rates: &mut Rates,
    calculus: &mut Calculus,
    options: &Options,
) -> Result<Folded, SymbolicError> {
    let assume = model.assumptions();
    let coordinate_rates = model.coordinate_rates();
    let mut assembler = assembly::Assembler {
        bodies: &model.bodies,
        partials,
        remainders,
        map,
        rates,
        calculus,
        coordinate_rates,
    };
    folding::fold(
        &mut model.g,
        (&model.bodies, &model.frames, &model.coords),
        &mut assembler,
        &partials.rotations,
        &assume,
        options,
    )
}

/// D q̇ + d, row by row, with q̇ the coordinate rate symbols.
fn velocity_residuals(model: &mut Model, rows: &ConstraintRows) -> Result<Vec<Id>, SymbolicError> {
    let n = model.coords.len();
    let g = &mut model.g;
    let mut out = Vec::with_capacity(rows.d0.len());
    for i in 0..rows.d0.len() {
        let mut terms = vec![rows.d0[i]];
        for (r, (_, coord)) in model.coords.iter().enumerate() {
            let q = g.sym(coord.rate)?;
            terms.push(g.mul(rows.d[i * n + r], q)?);
        }
        out.push(g.sum(&terms)?);
    }
    Ok(out)
}

#[cfg(test)]
mod testing;
