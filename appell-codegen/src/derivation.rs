//! Stage 3: Appell's equations by Method II (Wang & Pao 2003, Secs. III B-C
//! and IV B), in the symbolic engine.
//!
//! 1. Velocity constraints D(q,t) q̇ + d = 0 (eq. 25): holonomic ones are
//!    differentiated in time, nonholonomic ones must be linear in q̇.
//! 2. Partition q̇ into dependent ż and privileged ẏ and solve
//!    D' ż = −D'' ẏ − d (eq. 27): symbolically when every pivot is provably
//!    non-zero, otherwise by a pivoted numeric solve in the generated code
//!    (auxiliary symbols stand for B, b and their rates).
//! 3. q̇ = C ẏ + c (eqs. 30-31).
//! 4. Partial velocities β̄ and partial angular velocities γ̄ (eq. 54) as the
//!    coefficients of ẏ in the velocities with ż eliminated.
//! 5. Accelerations r̈ = Σ β̄_k ÿ_k + Σ β̄̇_k ẏ_k + β̄̇ (eq. 37, corrected), and
//!    likewise for angular accelerations; the parts free of ÿ are built
//!    directly from their pieces (never by substituting zeros).
//! 6. Appell's equations (eq. 56) as M ÿ = f with
//!    M_kl = Σ m β̄_k·β̄_l + γ̄_k·I γ̄_l and
//!    f_k = Σ F·β̄_k + L·γ̄_k − m a_rem·β̄_k − γ̄_k·(I α_rem + ω × I ω),
//!    rotational terms in the body frame where I is constant.
//! 7. Cyclic coordinates (Sec. III C): coordinates that appear in none of
//!    M, f, nor the rates of the coordinates that are kept.

use std::collections::BTreeSet;
use std::fmt::Write;

use appell_symbolic::{
    Assumptions, Id, Number, RateRules, Sign, Substitution, SymMatrix, Symbol, SymbolKind,
    SymbolSet, SymbolicError,
};

use crate::ctxt::Ctxt;
use crate::model::{cross, dot, Mat3, Model, Vec3};

/// How the dependent speeds are obtained.
#[derive(Clone)]
pub enum Elimination {
    /// B and b are expressions.
    Symbolic,
    /// B and b are solved numerically in the generated code.
    Numeric(NumericElimination),
}

/// The numeric part of the elimination: after the unknowns with safe
/// pivots are eliminated symbolically, the remaining k dependent rates solve
/// S X = R (X = the free rows of [B | b]); for the accelerations,
/// S w = (Ṙ − Ṡ X) [ẏ; 1] with w = Ẋ [ẏ; 1].
#[derive(Clone)]
pub struct NumericElimination {
    /// Number of unknowns solved numerically.
    pub k: usize,
    /// S (k×k), row-major.
    pub dp: Vec<Id>,
    /// R (k×(l+1)), row-major.
    pub rhs: Vec<Id>,
    /// (Ṙ − Ṡ X) [ẏ; 1] (k), the right side for w; contains X and ẏ.
    pub rhs_rate: Vec<Id>,
    /// The columns j of R that are not identically zero (X_fj = 0 in the
    /// others, and their symbols occur nowhere).
    pub columns: Vec<usize>,
    /// Symbols of X (k×(l+1)).
    pub x: Vec<Symbol>,
    /// Symbols of w = Ẋ [ẏ; 1] (k), the dependent acceleration remainder.
    pub w: Vec<Symbol>,
}

/// Per body: velocity pieces and, for rigid bodies, body-frame angular ones.
pub struct BodyTerms {
    /// β̄_k.
    pub beta: Vec<Vec3>,
    /// β̄ (the part of the velocity free of ẏ).
    pub beta0: Vec3,
    /// γ̄_k in body components.
    pub gamma_b: Vec<Vec3>,
    /// ω in body components.
    pub omega_b: Vec3,
}

/// The derived equations and everything the emitter needs.
pub struct Derivation {
    /// The model (its graph holds every expression below).
    pub model: Model,
    /// Number of coordinates n.
    pub n: usize,
    /// Number of constraint rows m.
    pub m: usize,
    /// Number of privileged speeds l.
    pub l: usize,
    /// Coordinate indices of the dependent speeds.
    pub dependent: Vec<usize>,
    /// Constraint rows D (m×n) and d (m).
    pub d_rows: Vec<Id>,
    /// Where each row of D comes from (for the constraint-force outputs).
    pub row_sources: Vec<RowSource>,
    /// d.
    pub d0: Vec<Id>,
    /// Holonomic residuals f(q, t).
    pub holonomic: Vec<Id>,
    /// C (n×l) and c (n).
    pub c: Vec<Id>,
    /// c.
    pub c0: Vec<Id>,
    /// How B and b are computed.
    pub elimination: Elimination,
    /// q̇_r = Σ C_rk ẏ_k + c_r.
    pub qdot: Vec<Id>,
    /// D q̇ + d, with q̇ the coordinate rate symbols.
    pub velocity_residuals: Vec<Id>,
    /// W (l×n) of the speeds' definitions u = W q̇ + w.
    pub speed_w: Vec<Id>,
    /// w (l).
    pub speed_w0: Vec<Id>,
    /// Symbols ÿ_k.
    pub accels: Vec<Symbol>,
    /// M (l×l), row-major, symmetric.
    pub mass: Vec<Id>,
    /// f (l).
    pub forcing: Vec<Id>,
    /// Kinetic energy.
    pub kinetic: Id,
    /// Potential energy of the gravity effect's loads.
    pub potential: Id,
    /// Power of the loads that depend on inputs.
    pub input_power: Id,
    /// Coordinates kept in the reduced state.
    pub retained: Vec<usize>,
    /// Cyclic (dependent, absent) coordinates.
    pub cyclic: Vec<usize>,
    /// All coordinates left out of the reduced state.
    pub ignorable: Vec<usize>,
    /// Readable equations.
    pub text: String,
    /// M before the ignorable coordinates were fixed (for scenes).
    pub raw_mass: Vec<Id>,
    /// The elimination before the ignorable coordinates were fixed.
    pub raw_elimination: Elimination,
    /// The inertial part of f, per speed (for scenes).
    pub inertial_terms: Vec<Vec<Id>>,
    /// Each effect's part of f, per speed (its loads summed and expanded
    /// together; for scenes).
    pub load_terms: Vec<(String, Vec<Id>)>,
    /// The power of each input-dependent load, with its effect (for scenes).
    pub power_terms: Vec<(String, Id)>,
    /// Bodies whose terms were folded together (composites and rotors), as
    /// readable lines.
    pub folded: Vec<String>,
}

/// Runs the derivation; errors go to `cx`.
pub fn derive(cx: &Ctxt, mut model: Model) -> Option<Derivation> {
    match derive_inner(cx, &mut model) {
        Ok(Some(parts)) => Some(parts.finish(model)),
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

struct Parts {
    n: usize,
    m: usize,
    l: usize,
    dependent: Vec<usize>,
    d_rows: Vec<Id>,
    row_sources: Vec<RowSource>,
    d0: Vec<Id>,
    holonomic: Vec<Id>,
    c: Vec<Id>,
    c0: Vec<Id>,
    elimination: Elimination,
    qdot: Vec<Id>,
    velocity_residuals: Vec<Id>,
    speed_w: Vec<Id>,
    speed_w0: Vec<Id>,
    accels: Vec<Symbol>,
    mass: Vec<Id>,
    forcing: Vec<Id>,
    kinetic: Id,
    potential: Id,
    input_power: Id,
    retained: Vec<usize>,
    cyclic: Vec<usize>,
    ignorable: Vec<usize>,
    raw_mass: Vec<Id>,
    raw_elimination: Elimination,
    inertial_terms: Vec<Vec<Id>>,
    load_terms: Vec<(String, Vec<Id>)>,
    power_terms: Vec<(String, Id)>,
    folded: Vec<String>,
}

impl Parts {
    fn finish(self, model: Model) -> Derivation {
        let mut d = Derivation {
            model,
            n: self.n,
            m: self.m,
            l: self.l,
            dependent: self.dependent,
            d_rows: self.d_rows,
            row_sources: self.row_sources,
            d0: self.d0,
            holonomic: self.holonomic,
            c: self.c,
            c0: self.c0,
            elimination: self.elimination,
            qdot: self.qdot,
            velocity_residuals: self.velocity_residuals,
            speed_w: self.speed_w,
            speed_w0: self.speed_w0,
            accels: self.accels,
            mass: self.mass,
            forcing: self.forcing,
            kinetic: self.kinetic,
            potential: self.potential,
            input_power: self.input_power,
            retained: self.retained,
            cyclic: self.cyclic,
            ignorable: self.ignorable,
            text: String::new(),
            raw_mass: self.raw_mass,
            raw_elimination: self.raw_elimination,
            inertial_terms: self.inertial_terms,
            load_terms: self.load_terms,
            power_terms: self.power_terms,
            folded: self.folded,
        };
        d.text = equations_text(&d);
        d
    }
}

fn derive_inner(cx: &Ctxt, model: &mut Model) -> Result<Option<Parts>, SymbolicError> {
    let n = model.coords.len();
    let rates: Vec<Symbol> = model.coords.iter().map(|(_, c)| c.rate).collect();
    let rules = RateRules::coordinates();
    // The twin (direction cosines as symbols) is used where expressions are
    // differentiated along q̇ and not expanded: the constraint rows' rates
    // and the acceleration remainders. `uncut` puts the values back.
    let twin = model.twin.take();
    let twin_rules = twin.as_ref().map(|t| t.rate_rules());
    let mut uncut = twin
        .as_ref()
        .map_or_else(Substitution::new, |t| t.uncut_substitution());
    // 1. Velocity constraint rows.
    // (row, its tokens, holonomic, the same row before expansion)
    let mut rows: Vec<(Id, proc_macro2::TokenStream, bool, Id)> = Vec::new();
    let mut origins: Vec<RowSource> = Vec::new();
    // For a rolling row (or a holonomic row found equal to one): the contact
    // and the row's direction (the twin's), so that its rate can be taken
    // as (rate of the material velocity)·e when that velocity vanishes.
    let mut forms: Vec<Option<(usize, Vec3)>> = Vec::new();
    let mut contact_velocity: Vec<Vec3> = Vec::new();
    let mut complete: Vec<bool> = Vec::new();
    let mut holonomic = Vec::new();
    for (index, c) in model.holonomic.iter().enumerate() {
        holonomic.push(c.residual);
        let bad: Vec<String> = model
            .g
            .dependencies(c.residual)
            .iter()
            .filter(|s| {
                !matches!(
                    model.g.symbol_kind(*s),
                    SymbolKind::Coordinate | SymbolKind::Parameter | SymbolKind::Time
                )
            })
            .map(|s| model.g.symbol_name(s).to_string())
            .collect();
        if !bad.is_empty() {
            cx.error_spanned_by(&c.at, format!("a holonomic constraint relates coordinates, parameters and time only; it uses {}", bad.join(", ")));
            continue;
        }
        let raw = match (&twin, &twin_rules) {
            (Some(t), Some(tr)) => model.g.time_derivative(t.holonomic[index].residual, tr),
            _ => model.g.time_derivative(c.residual, &rules),
        };
        match (model.g.time_derivative(c.residual, &rules), raw) {
            (Ok(r), Ok(raw)) => {
                rows.push((r, c.at.clone(), true, raw));
                forms.push(None);
                origins.push(RowSource::Holonomic(index));
            }
            (Err(e), _) | (_, Err(e)) => cx.error_spanned_by(&c.at, e),
        }
    }
    for (index, c) in model.nonholonomic.iter().enumerate() {
        let raw = twin
            .as_ref()
            .map_or(c.residual, |t| t.nonholonomic[index].residual);
        rows.push((c.residual, c.at.clone(), false, raw));
        forms.push(None);
        origins.push(RowSource::Nonholonomic(index));
    }
    // Rolling: v(material point at P) = v(centre) + ω × (P − centre) = 0.
    for (contact, r) in model.rolling.iter().enumerate() {
        let body = &model.bodies[r.body];
        let omega = model.frames[body.frame.expect("rigid")].omega;
        let g = &mut model.g;
        let mut v = [body.center[0]; 3];
        let mut arm = [body.center[0]; 3];
        for i in 0..3 {
            v[i] = g.time_derivative(body.center[i], &rules)?;
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
        // The same rows as written (not multiplied out), from the twin.
        // The material point's velocity as written (the twin's), and the
        // directions it is constrained along.
        let (raw_v, raw_dirs): (Vec<Id>, Vec<Vec3>) = match (&twin, &twin_rules) {
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
                rolling_components(g, body.center, omega, r.contact, None, &rules)?,
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
        // Every component of the material velocity vanishes on the
        // constrained motion when the rows cover N, or when the component
        // normal to two `along` directions is identically zero (the rear
        // wheel's: its centre stays at height rr); a holonomic row equal to
        // that component may complete it below.
        contact_velocity.push(raw_v);
        complete.push(match r.along.as_deref() {
            None => true,
            Some([d0, d1]) => {
                let n = cross(g, *d0, *d1)?;
                let c = dot(g, v, n)?;
                let c = expanded(g, c)?;
                g.is_zero(c)
            }
            Some(_) => false,
        });
        let before = rows.len();
        for (k, (c, raw_c)) in components.into_iter().zip(raw).enumerate() {
            if g.is_zero(c) {
                if r.along.is_some() {
                    cx.error_spanned_by(&r.at, format!("the velocity component along direction {} is identically zero: that direction constrains nothing", k + 1));
                }
                continue;
            }
            rows.push((c, r.at.clone(), false, raw_c));
            forms.push(Some((contact, raw_dirs[k])));
            origins.push(RowSource::Rolling {
                contact,
                direction: k,
            });
        }
        if rows.len() == before && r.along.is_none() {
            cx.error_spanned_by(&r.at, "this rolling contact constrains nothing: the contact point's velocity is identically zero");
        }
    }
    // A holonomic row that is, identically, a rolling contact's material
    // velocity along the normal of its two `along` directions (the
    // bicycle's pitch constraint: the front contact's height rate is the
    // vertical velocity of the wheel's material point there, since that
    // point is the lowest of the rim) completes the contact.
    for (row, form) in rows.iter().zip(forms.iter_mut()).filter(|(r, _)| r.2) {
        for (contact, r) in model.rolling.iter().enumerate() {
            let Some([d0, d1]) = r.along.as_deref() else {
                continue;
            };
            if complete[contact] {
                continue;
            }
            let g = &mut model.g;
            let body = &model.bodies[r.body];
            let omega = model.frames[body.frame.expect("rigid")].omega;
            let normal = cross(g, *d0, *d1)?;
            let candidate =
                rolling_components(g, body.center, omega, r.contact, Some(&[normal]), &rules)?[0];
            if same_function(g, row.0, candidate) != Some(true) {
                continue;
            }
            let normal = match &twin {
                Some(t) => match t.rolling[contact].along.as_deref() {
                    Some([e0, e1]) => cross(g, *e0, *e1)?,
                    _ => continue,
                },
                None => normal,
            };
            complete[contact] = true;
            *form = Some((contact, normal));
            break;
        }
    }
    let mut d_rows = Vec::new();
    let mut d0 = Vec::new();
    let mut row_sources = Vec::new();
    let mut kept_sources = Vec::new();
    let mut raw_rows = Vec::new();
    let mut raw_forms = Vec::new();
    for (index, ((row, span, holo, raw_row), origin)) in rows.iter().zip(&origins).enumerate() {
        let bad: Vec<String> = model
            .g
            .dependencies(*row)
            .iter()
            .filter(|s| {
                matches!(
                    model.g.symbol_kind(*s),
                    SymbolKind::Input | SymbolKind::Acceleration(_)
                )
            })
            .map(|s| model.g.symbol_name(s).to_string())
            .collect();
        if !bad.is_empty() {
            cx.error_spanned_by(
                span,
                format!("a velocity constraint cannot depend on {}", bad.join(", ")),
            );
            continue;
        }
        match model.g.linear_coefficients(*row, &rates) {
            Ok(form) => {
                if form.coefficients.iter().all(|c| model.g.is_zero(*c)) {
                    cx.error_spanned_by(
                        span,
                        "this constraint does not involve any coordinate rate",
                    );
                    continue;
                }
                d_rows.extend(form.coefficients);
                d0.push(form.remainder);
                raw_rows.push(*raw_row);
                raw_forms.push(forms[index]);
                row_sources.push(span.clone());
                kept_sources.push(*origin);
            }
            Err(SymbolicError::NonLinear { symbol, .. }) => {
                let what = if *holo {
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
    if cx.has_errors() {
        return Ok(None);
    }
    let m = d0.len();
    let l = model.speed_specs.len();
    let quasi = model.speed_specs.iter().any(|s| s.definition.is_some());
    // The speeds' definitions u = W q̇ + w: unit rows for coordinate rates
    // (Method II), the defining combination for quasi-velocities (Method III).
    let (zero, one) = (model.g.int(0)?, model.g.int(1)?);
    let mut speed_w = Vec::with_capacity(l * n);
    let mut speed_w0 = Vec::with_capacity(l);
    for spec in &model.speed_specs {
        match (spec.coordinate, spec.definition) {
            (Some(r), _) => {
                speed_w.extend((0..n).map(|c| if c == r { one } else { zero }));
                speed_w0.push(zero);
            }
            (None, Some(def)) => {
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
                        &model.speeds_at,
                        format!(
                            "the quasi-velocity `{}` cannot depend on {}",
                            spec.name,
                            bad.join(", ")
                        ),
                    );
                    continue;
                }
                match model.g.linear_coefficients(def, &rates) {
                    Ok(form) => {
                        if form.coefficients.iter().all(|c| model.g.is_zero(*c)) {
                            cx.error_spanned_by(
                                &model.speeds_at,
                                format!(
                                    "the quasi-velocity `{}` involves no coordinate rate",
                                    spec.name
                                ),
                            );
                            continue;
                        }
                        speed_w.extend(form.coefficients);
                        speed_w0.push(form.remainder);
                    }
                    Err(SymbolicError::NonLinear { symbol, .. }) => {
                        cx.error_spanned_by(
                            &model.speeds_at,
                            format!("the quasi-velocity `{}` must be linear in the coordinate rates (Method III, eq. 56), and it is not linear in `{symbol}`", spec.name),
                        );
                    }
                    Err(e) => cx.error_spanned_by(&model.speeds_at, e),
                }
            }
            (None, None) => unreachable!("a speed is a coordinate or a definition"),
        }
    }
    if cx.has_errors() {
        return Ok(None);
    }
    if let Some(row) = dependent_row(&model.g, &d_rows, n, m) {
        cx.error_spanned_by(
            &row_sources[row],
            "this constraint row is a linear combination of the others (the velocity constraints are linearly dependent); drop it, or give a rolling contact `along = [...]` directions",
        );
        return Ok(None);
    }
    if l + m != n {
        cx.error_spanned_by(
            &model.speeds_at,
            format!(
                "{l} privileged speed(s) with {m} velocity constraint(s) on {n} coordinates: the constraints leave {} independent speed(s), so `speeds(...)` must name {}",
                n.saturating_sub(m),
                n.saturating_sub(m)
            ),
        );
        return Ok(None);
    }
    if quasi {
        let mut full = d_rows.clone();
        full.extend(&speed_w);
        if let Some(row) = dependent_row(&model.g, &full, n, n) {
            let name = &model.speed_specs[row.saturating_sub(m).min(l - 1)].name;
            cx.error_spanned_by(
                &model.speeds_at,
                format!("the speeds' definitions are not invertible: with the constraints they do not determine the coordinate rates ([D; W] is singular; `{name}` depends on the others)"),
            );
            return Ok(None);
        }
    }
    // Unknowns: the dependent rates (Method II), or every rate when some
    // speed is a quasi-velocity (Method III, [D; W] q̇ = [−d; u − w]).
    let dependent: Vec<usize> = if quasi {
        (0..n).collect()
    } else {
        (0..n).filter(|i| !model.speeds.contains(i)).collect()
    };
    for c in &model.holonomic {
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
    if cx.has_errors() {
        return Ok(None);
    }
    let g = &mut model.g;
    let k_unknowns = dependent.len();
    let mut dp = Vec::with_capacity(k_unknowns * k_unknowns);
    let mut rhs = Vec::with_capacity(k_unknowns * (l + 1));
    if quasi {
        dp.extend(d_rows.iter().copied());
        dp.extend(speed_w.iter().copied());
        for r in 0..m {
            rhs.extend((0..l).map(|_| zero));
            rhs.push(g.neg(d0[r])?);
        }
        for k in 0..l {
            rhs.extend((0..l).map(|j| if j == k { one } else { zero }));
            rhs.push(g.neg(speed_w0[k])?);
        }
    } else {
        for r in 0..m {
            for &c in &dependent {
                dp.push(d_rows[r * n + c]);
            }
            for &k in &model.speeds {
                rhs.push(g.neg(d_rows[r * n + k])?);
            }
            rhs.push(g.neg(d0[r])?);
        }
    }
    // 2. Structural rank of the system (a matching of rows to unknowns).
    if let Some(col) = unmatched_column(g, &dp, k_unknowns) {
        let name = model.coords[dependent[col]].0.to_string();
        cx.error_spanned_by(
            &model.speeds_at,
            format!("with these privileged speeds the constraints cannot determine the rate of `{name}`: the dependent block D' is structurally singular; choose other speeds"),
        );
        return Ok(None);
    }
    let mut assume = Assumptions::new();
    for p in &model.params {
        if p.positive {
            assume = assume.positive(p.symbol);
        }
    }
    let dp_m = SymMatrix::from_rows(k_unknowns, k_unknowns, dp.clone())?;
    // Without quasi-velocities the rows are the constraint rows themselves:
    // an identity block carried beside the right sides records the row
    // operations T of the elimination (S x_f − R_s [ẏ; 1] = T (D q̇ + d)).
    let track = !quasi;
    let width = if track { l + 1 + k_unknowns } else { l + 1 };
    let mut rhs_aug = Vec::with_capacity(k_unknowns * width);
    for r in 0..k_unknowns {
        rhs_aug.extend(&rhs[r * (l + 1)..(r + 1) * (l + 1)]);
        if track {
            rhs_aug.extend((0..k_unknowns).map(|c| if c == r { one } else { zero }));
        }
    }
    let rhs_m = SymMatrix::from_rows(k_unknowns, width, rhs_aug)?;
    // Unknowns with safe pivots are eliminated symbolically; the rest (the
    // Schur complement S x_f = R_s) is solved numerically at run time, the
    // free unknowns standing as auxiliary symbols X_f in the expressions.
    let mut vanishing: Vec<Symbol> = Vec::new();
    #[allow(clippy::type_complexity)]
    // (aux symbols, their values, k, S, R_s, free columns) of the numeric part
    let (x_entries, numeric_part): (
        Vec<Id>,
        Option<(
            Vec<Symbol>,
            Vec<Id>,
            usize,
            Vec<Id>,
            Vec<Id>,
            Vec<usize>,
            Vec<Id>,
        )>,
    ) = if k_unknowns == 0 {
        (Vec::new(), None)
    } else {
        match g.eliminate(&dp_m, &rhs_m, &assume) {
            Ok(part) => {
                let k = part.free_cols.len();
                let zero = g.int(0)?;
                let mut x_entries = vec![zero; k_unknowns * (l + 1)];
                let mut syms = Vec::new();
                let mut ids = Vec::new();
                // A column of R that is identically zero has X = 0 there.
                // A speed column's symbols are replaced by zero at once;
                // the last column's (from d, zero for a scleronomic
                // system) stay through the differentiation, because their
                // rate carries w = Ẋ [ẏ; 1] into the accelerations, and
                // are set to zero afterwards.
                let zero_column: Vec<bool> = (0..=l)
                    .map(|j| (0..k).all(|i| g.is_zero(part.s_rhs[(i, j)])))
                    .collect();
                let nonzero = structural_solution(g, &part.s, &part.s_rhs, k, l + 1);
                for f in 0..k {
                    for j in 0..=l {
                        let s = g.declare(&format!("__x_{f}_{j}"), SymbolKind::Auxiliary)?;
                        ids.push(if (zero_column[j] || !nonzero[f][j]) && j < l {
                            zero
                        } else {
                            g.sym(s)?
                        });
                        if zero_column[j] && j == l {
                            vanishing.push(s);
                        }
                        syms.push(s);
                    }
                }
                for (f, &col) in part.free_cols.iter().enumerate() {
                    for j in 0..=l {
                        x_entries[col * (l + 1) + j] = ids[f * (l + 1) + j];
                    }
                }
                for (i, &col) in part.pivot_cols.iter().enumerate() {
                    for j in 0..=l {
                        let mut terms = vec![part.pivot_rhs[(i, j)]];
                        for f in 0..k {
                            let t = g.mul(part.pivot_free[(i, f)], ids[f * (l + 1) + j])?;
                            terms.push(g.neg(t)?);
                        }
                        let sum = g.sum(&terms)?;
                        x_entries[col * (l + 1) + j] = expanded(g, sum)?;
                    }
                }
                if k == 0 {
                    (x_entries, None)
                } else {
                    (
                        x_entries,
                        Some((
                            syms,
                            ids,
                            k,
                            part.s.entries().to_vec(),
                            (0..k)
                                .flat_map(|i| (0..=l).map(move |j| (i, j)))
                                .map(|(i, j)| part.s_rhs[(i, j)])
                                .collect(),
                            part.free_cols.clone(),
                            if track {
                                (0..k)
                                    .flat_map(|i| (0..k_unknowns).map(move |j| (i, j)))
                                    .map(|(i, j)| part.s_rhs[(i, l + 1 + j)])
                                    .collect()
                            } else {
                                Vec::new()
                            },
                        )),
                    )
                }
            }
            Err(SymbolicError::StructurallySingular { column }) => {
                let name = model.coords[dependent[column]].0.to_string();
                cx.error_spanned_by(
                    &model.speeds_at,
                    format!("with these privileged speeds the constraints cannot determine the rate of `{name}` (D' is singular after elimination); choose other speeds"),
                );
                return Ok(None);
            }
            Err(e) => return Err(e),
        }
    };
    // 3. C and c.
    let zero = g.int(0)?;
    let one = g.int(1)?;
    let mut c = vec![zero; n * l];
    let mut c0 = vec![zero; n];
    if !quasi {
        for (k, &s) in model.speeds.iter().enumerate() {
            c[s * l + k] = one;
        }
    }
    for (i, &r) in dependent.iter().enumerate() {
        for k in 0..l {
            c[r * l + k] = x_entries[i * (l + 1) + k];
        }
        c0[r] = x_entries[i * (l + 1) + l];
    }
    let speed_rates: Vec<Symbol> = model.speed_specs.iter().map(|s| s.symbol).collect();
    let accels: Vec<Symbol> = model.speed_specs.iter().map(|s| s.accel).collect();
    // q̇_r = Σ C_rk ẏ_k + c_r, as expressions.
    let mut qdot = Vec::with_capacity(n);
    for r in 0..n {
        let mut terms = vec![c0[r]];
        for k in 0..l {
            let y = g.sym(speed_rates[k])?;
            terms.push(g.mul(c[r * l + k], y)?);
        }
        qdot.push(g.sum(&terms)?);
    }
    // Rate rules of the reduced system: q̇ = C ẏ + c; auxiliary X → Ẋ.
    let mut reduced = RateRules::coordinates();
    for (r, (_, coord)) in model.coords.iter().enumerate() {
        reduced = reduced.with(coord.q, qdot[r]);
    }
    for spec in model.speed_specs.iter().filter(|s| s.definition.is_some()) {
        let a = g.sym(spec.accel)?;
        reduced = reduced.with(spec.symbol, a);
    }
    // Directional derivatives along q̇: the rates held constant, then
    // replaced by their values (the dependent ones by C ẏ + c).
    let mut along_rates = RateRules::coordinates();
    for &r in rates.iter().chain(&speed_rates) {
        along_rates = along_rates.constant(r);
    }
    if let Some(t) = &twin {
        for c in &t.cuts {
            along_rates = along_rates.with(c.symbol, c.rate);
        }
    }
    let mut fixed_rates = Substitution::new();
    for &r in &dependent {
        fixed_rates.insert(model.coords[r].1.rate, qdot[r]);
    }
    let mut elimination = Elimination::Symbolic;
    if let Some((xs, x_ids, k, mut s_mat, mut s_rhs, free_cols, row_ops)) = numeric_part {
        // S and R read off the rows as the model wrote them (T applied to
        // the twin's rows, whose coefficients keep their factored form)
        // rather than from the expanded D: the bicycle 1,025 -> 989 ops.
        // Kept only where every entry agrees with the elimination's at the
        // test points.
        if !row_ops.is_empty() {
            let speed_cols: Vec<Symbol> = model
                .speeds
                .iter()
                .map(|&sp| model.coords[sp].1.rate)
                .collect();
            let free: Vec<Symbol> = free_cols
                .iter()
                .map(|&c| model.coords[dependent[c]].1.rate)
                .collect();
            if let Some((new_s, new_r)) = schur_as_written(
                g,
                SchurRows {
                    rows: &raw_rows,
                    row_ops: &row_ops,
                    width: k_unknowns,
                    rates: &rates,
                    free: &free,
                    speeds: &speed_cols,
                },
                &mut uncut,
                (&s_mat, &s_rhs),
            )? {
                s_mat = new_s;
                s_rhs = new_r;
            }
        }
        // The accelerations need Ẋ only in the combination w = Ẋ [ẏ; 1]
        // (the dependent acceleration remainder): every β̄_k is linear in the
        // column X_k, so Σ_k β̄̇_k ẏ_k + β̄̇ sees Σ_k Ẋ_k ẏ_k + Ẋ_l. The rate
        // rules therefore give X_fk → 0 (k < l) and X_fl → w_f, and w solves
        // S w = (Ṙ − Ṡ X) [ẏ; 1]: one right-hand side instead of l + 1.
        let mut w = Vec::with_capacity(k);
        for f in 0..k {
            w.push(g.declare(&format!("__w_{f}"), SymbolKind::Auxiliary)?);
        }
        for f in 0..k {
            for j in 0..=l {
                let rate = if j == l { g.sym(w[f])? } else { zero };
                reduced = reduced.with(xs[f * (l + 1) + j], rate);
            }
        }
        // Differentiating S ż_f = R [ẏ; 1] gives S w = (Ṙ − Ṡ X) [ẏ; 1]:
        // minus the rate of the row S q̇_f − R [ẏ; 1] taken with the
        // rates held fixed (a directional derivative along q̇), the rates
        // then replaced by their values (the bicycle's rhs 2,120 -> 2,086
        // ops against Ṡ and Ṙ entry by entry). Those rows are T (D q̇ + d),
        // and D q̇ + d vanishes at the rates used, so the rate of T drops
        // out: S w = −T ∂(D q̇ + d), with each constraint row differentiated
        // as the model wrote it (a rolling contact's (v + ω × r)·e, not
        // multiplied out), which shares its work with the bodies'
        // remainders (1,805 -> 1,572 ops). With quasi-velocities the rows
        // include the speeds' definitions and the Schur rows are used.
        let mut rhs_rate = Vec::with_capacity(k);
        let free_rates: Vec<Id> = free_cols
            .iter()
            .map(|&c| g.sym(model.coords[dependent[c]].1.rate))
            .collect::<Result<_, _>>()?;
        let mut raw_rates = Vec::new();
        if !row_ops.is_empty() {
            for (&row, form) in raw_rows.iter().zip(&raw_forms) {
                // When the contact's material velocity v vanishes on the
                // constrained motion, the rate of v·e is (rate of v)·e:
                // the term v·ė is zero there, though only numerically once
                // the dependent rates are X [ẏ; 1].
                let rate = match form {
                    Some((contact, e)) if complete[*contact] => {
                        let v = contact_velocity[*contact];
                        let mut terms = Vec::with_capacity(3);
                        for i in 0..3 {
                            if g.is_zero(e[i]) {
                                continue;
                            }
                            let r = g.time_derivative(v[i], &along_rates)?;
                            terms.push(g.mul(r, e[i])?);
                        }
                        g.sum(&terms)?
                    }
                    _ => g.time_derivative(row, &along_rates)?,
                };
                let rate = uncut.apply(g, rate)?;
                raw_rates.push(fixed_rates.apply(g, rate)?);
            }
        }
        for i in 0..k {
            if !raw_rates.is_empty() {
                let mut terms = Vec::new();
                for (j, &rate) in raw_rates.iter().enumerate() {
                    let t = row_ops[i * k_unknowns + j];
                    if !g.is_zero(t) {
                        terms.push(g.mul(t, rate)?);
                    }
                }
                let sum = g.sum(&terms)?;
                rhs_rate.push(g.neg(sum)?);
                continue;
            }
            let mut terms = Vec::new();
            for f in 0..k {
                terms.push(g.mul(s_mat[i * k + f], free_rates[f])?);
            }
            for j in 0..=l {
                let weight = if j == l { one } else { g.sym(speed_rates[j])? };
                let t = g.mul(s_rhs[i * (l + 1) + j], weight)?;
                terms.push(g.neg(t)?);
            }
            let row = g.sum(&terms)?;
            let rate = g.time_derivative(row, &along_rates)?;
            let rate = fixed_rates.apply(g, rate)?;
            rhs_rate.push(g.neg(rate)?);
        }
        let columns = (0..=l)
            .filter(|&j| {
                (0..k).any(|f| !g.is_zero(x_ids[f * (l + 1) + j])) && !vanishing.contains(&xs[j])
            })
            .collect();
        elimination = Elimination::Numeric(NumericElimination {
            k,
            columns,
            dp: s_mat,
            rhs: s_rhs,
            rhs_rate,
            x: xs,
            w,
        });
    }
    // 4. Velocities with ż eliminated: substitute the dependent rates.
    let mut sub = fixed_rates.clone();
    let vel = |g: &mut appell_symbolic::Graph,
               sub: &mut Substitution,
               pos: Vec3|
     -> Result<(Vec<Vec3>, Vec3), SymbolicError> {
        let mut v = [zero; 3];
        for i in 0..3 {
            let d = g.time_derivative(pos[i], &rules)?;
            let d = sub.apply(g, d)?;
            v[i] = expanded(g, d)?;
        }
        split_linear(g, v, &speed_rates)
    };
    // β̄_k = Σ_r C_rk J_r and β̄ = J_t + Σ_r c_r J_r from the partial
    // velocities J_r = ∂v/∂q̇_r, each a function of q alone: C (with the
    // numeric elimination's X) is not multiplied into them, so each β̄_k
    // costs one short sum per component (the bicycle's rhs 1,962 -> 1,849
    // ops). Loads keep the expanded form, which is shorter for a constant
    // force's few components.
    let through_c = |g: &mut appell_symbolic::Graph,
                     parts: &[Vec3],
                     rest: Vec3|
     -> Result<(Vec<Vec3>, Vec3), SymbolicError> {
        let mut beta = vec![[zero; 3]; l];
        let mut beta0 = rest;
        for i in 0..3 {
            for (k, b) in beta.iter_mut().enumerate() {
                let mut terms = Vec::new();
                for (r, part) in parts.iter().enumerate() {
                    let coef = c[r * l + k];
                    if g.is_zero(coef) || g.is_zero(part[i]) {
                        continue;
                    }
                    terms.push(g.mul(coef, part[i])?);
                }
                b[i] = g.sum(&terms)?;
            }
            let mut terms = vec![rest[i]];
            for (r, part) in parts.iter().enumerate() {
                if g.is_zero(c0[r]) || g.is_zero(part[i]) {
                    continue;
                }
                terms.push(g.mul(c0[r], part[i])?);
            }
            beta0[i] = g.sum(&terms)?;
        }
        Ok((beta, beta0))
    };
    let raw_parts =
        |g: &mut appell_symbolic::Graph, v: Vec3| -> Result<(Vec<Vec3>, Vec3), SymbolicError> {
            // The coefficients stay as differentiated: multiplying them
            // out costs more than it cancels (the bicycle 1,397 -> 1,381).
            let (parts, rest) = split_linear(g, v, &rates)?;
            Ok((parts, expanded3(g, rest)?))
        };
    let mut body_terms: Vec<BodyTerms> = Vec::new();
    // Per body: (the earlier body whose frame it turns from, the direction
    // cosines between the two frames, the relative angular velocity in its
    // own frame) when its γ̄ were built from that body's.
    #[allow(clippy::type_complexity)]
    let mut relative_frames: Vec<Option<(usize, Mat3, Vec3)>> = Vec::new();
    let mut rotations = Vec::new();
    // ∂v/∂q̇_r of each body's mass centre.
    let mut center_parts: Vec<Vec<Vec3>> = Vec::new();
    for b in &model.bodies {
        let mut v = [zero; 3];
        for i in 0..3 {
            v[i] = g.time_derivative(b.center[i], &rules)?;
        }
        let (parts, rest) = raw_parts(g, v)?;
        let (beta, beta0) = through_c(g, &parts, rest)?;
        center_parts.push(parts);
        let (gamma_b, omega_b, rotation) = match b.frame {
            Some(fi) => {
                let frame = &model.frames[fi];
                let rot = frame.rot;
                // A frame turned from an earlier body's frame by a simple
                // rotation (every direction cosine between them a single
                // term) whose relative angular velocity has constant
                // components: γ̄ in this frame is the earlier γ̄ rotated,
                // plus the relative part, so the earlier body's values are
                // reused instead of expanding the chain of rotations again.
                let mut via = None;
                let mut relative = None;
                for (pb, pt) in body_terms.iter().enumerate() {
                    let Some(pf) = model.bodies[pb].frame else {
                        continue;
                    };
                    if pf == fi {
                        continue;
                    }
                    let Some((rel, dw)) = simple_turn(g, frame, &model.frames[pf], &rates)? else {
                        continue;
                    };
                    let (dparts, drest) = split_linear(g, dw, &rates)?;
                    let (dgamma, dgamma0) = through_c(g, &dparts, drest)?;
                    let gamma_b = (0..l)
                        .map(|k| turned(g, &rel, pt.gamma_b[k], dgamma[k]))
                        .collect::<Result<Vec<_>, _>>()?;
                    let domega = combine(g, &dgamma, dgamma0, &speed_rates)?;
                    let omega_b = turned(g, &rel, pt.omega_b, domega)?;
                    via = Some((gamma_b, omega_b));
                    relative = Some((pb, rel, dw));
                    break;
                }
                relative_frames.push(relative);
                if let Some((gamma_b, omega_b)) = via {
                    (gamma_b, omega_b, Some(rot))
                } else {
                    let (parts, rest) = split_linear(g, frame.omega, &rates)?;
                    let parts = parts
                        .iter()
                        .map(|v| mat_t_vec(g, &rot, *v).and_then(|x| expanded3(g, x)))
                        .collect::<Result<Vec<_>, _>>()?;
                    let rest = mat_t_vec(g, &rot, rest)?;
                    let rest = expanded3(g, rest)?;
                    let (gamma_b, gamma0_b) = through_c(g, &parts, rest)?;
                    let omega_b = combine(g, &gamma_b, gamma0_b, &speed_rates)?;
                    (gamma_b, omega_b, Some(rot))
                }
            }
            None => {
                relative_frames.push(None);
                (vec![[zero; 3]; l], [zero; 3], None)
            }
        };
        body_terms.push(BodyTerms {
            beta,
            beta0,
            gamma_b,
            omega_b,
        });
        rotations.push(rotation);
    }
    let mut force_beta = Vec::new();
    let mut force_beta0 = Vec::new();
    for f in &model.forces {
        let (beta, beta0) = vel(g, &mut sub, f.point)?;
        force_beta.push(beta);
        force_beta0.push(beta0);
    }
    let mut torque_gamma = Vec::new();
    let mut torque_gamma0 = Vec::new();
    for t in &model.torques {
        let omega = model.frames[t.frame].omega;
        let (gamma, gamma0) = split_omega(g, omega, &mut sub, &speed_rates)?;
        torque_gamma.push(gamma);
        torque_gamma0.push(gamma0);
    }
    // 5. Acceleration remainders (the accelerations with ÿ = 0): for a
    // velocity v(q, q̇, t) linear in q̇, Σ_s ∂v/∂q_s q̇_s + ∂v/∂t (the
    // directional derivative, rates held fixed, then replaced by C ẏ + c)
    // plus Σ_d ∂v/∂q̇_d r_d, with r_d the dependent rates' own remainder
    // (w for a numeric elimination). Differentiating each β̄_k through C
    // instead multiplies every partial derivative by q̇ = C ẏ + c once per
    // speed (the bicycle's rhs 2,416 -> 2,120 ops).
    let mut zero_accels = Substitution::new();
    for spec in &model.speed_specs {
        zero_accels.insert(spec.accel, zero);
    }
    let mut dependent_remainders: Vec<(Symbol, Id)> = Vec::new();
    for &d in &dependent {
        let e = g.time_derivative(qdot[d], &reduced)?;
        let e = zero_accels.apply(g, e)?;
        dependent_remainders.push((model.coords[d].1.rate, e));
    }
    // `v` is the twin's when there is one (see `uncut`).
    // `parts`, when given, are the partial velocities ∂v/∂q̇_r already
    // built for β̄ (the same values): the dependent rates' terms reuse them.
    let remainder = |g: &mut appell_symbolic::Graph,
                     fixed_rates: &mut Substitution,
                     uncut: &mut Substitution,
                     v: Vec3,
                     parts: Option<&[Vec3]>|
     -> Result<Vec3, SymbolicError> {
        let mut out = [zero; 3];
        for i in 0..3 {
            let along = g.time_derivative(v[i], &along_rates)?;
            let along = uncut.apply(g, along)?;
            let mut terms = vec![fixed_rates.apply(g, along)?];
            for (&(rate, r), &d) in dependent_remainders.iter().zip(&dependent) {
                let c = match parts {
                    Some(p) => p[d][i],
                    None => {
                        let c = g.diff(v[i], rate)?;
                        let c = uncut.apply(g, c)?;
                        fixed_rates.apply(g, c)?
                    }
                };
                if g.is_zero(c) {
                    continue;
                }
                terms.push(g.mul(c, r)?);
            }
            // Left factored: a remainder enters f only through dot products
            // with the partial velocities.
            out[i] = g.sum(&terms)?;
        }
        Ok(out)
    };
    // 6. Appell's equations.
    // α in each rigid body's frame.
    let mut alphas: Vec<Option<Vec3>> = Vec::new();
    for (bi, b) in model.bodies.iter().enumerate() {
        alphas.push(match &rotations[bi] {
            Some(rot) => match &relative_frames[bi] {
                Some((pb, rel, dw)) if alphas[*pb].is_some() => {
                    // α = (the earlier body's α, turned) + ω × ω_rel + the
                    // relative rates' own remainders (dependent ones).
                    let parent = alphas[*pb].expect("rigid");
                    let mut w_rel = [zero; 3];
                    for i in 0..3 {
                        w_rel[i] = fixed_rates.apply(g, dw[i])?;
                    }
                    let spin = cross(g, body_terms[bi].omega_b, w_rel)?;
                    let mut alpha = turned(g, rel, parent, spin)?;
                    for i in 0..3 {
                        let mut terms = vec![alpha[i]];
                        for &(rate, r) in &dependent_remainders {
                            let c = g.diff(dw[i], rate)?;
                            if !g.is_zero(c) {
                                terms.push(g.mul(c, r)?);
                            }
                        }
                        alpha[i] = g.sum(&terms)?;
                    }
                    Some(alpha)
                }
                _ => {
                    let f = b.frame.expect("rigid");
                    let omega = twin
                        .as_ref()
                        .map_or(model.frames[f].omega, |t| t.frames[f].omega);
                    let alpha_n = remainder(g, &mut fixed_rates, &mut uncut, omega, None)?;
                    let alpha_b = mat_t_vec(g, rot, alpha_n)?;
                    Some(expanded3(g, alpha_b)?)
                }
            },
            None => None,
        });
    }
    let mut assemble = |g: &mut appell_symbolic::Graph,
                        composites: &[Composite],
                        rotors: &[Option<Rotor>]|
     -> Result<(Vec<Id>, Vec<Vec<Id>>), SymbolicError> {
        let mut mass = vec![zero; l * l];
        let mut forcing_terms: Vec<Vec<Id>> = vec![Vec::new(); l];
        for (bi, b) in model.bodies.iter().enumerate() {
            let t = &body_terms[bi];
            // The translational terms of a composite's members are its
            // leader's, at the composite mass centre; the leader's inertia
            // gains the members' parallel-axis terms, and a carrier its
            // rotors' inertia but for the axial moment (the rotor's own
            // terms below carry it).
            let mut inertia = b.inertia;
            for (ri, r) in rotors.iter().enumerate() {
                if let Some(r) = r.filter(|r| r.carrier == bi) {
                    let rotor_inertia = &model.bodies[ri].inertia;
                    for (i, (row, rotor_row)) in inertia.iter_mut().zip(rotor_inertia).enumerate() {
                        for (j, (e, x)) in row.iter_mut().zip(rotor_row).enumerate() {
                            if r.whole && i == r.axis && j == r.axis {
                                continue;
                            }
                            *e = g.add(*e, *x)?;
                        }
                    }
                }
            }
            if let Some(r) = rotors[bi] {
                let c_t = &body_terms[r.carrier];
                let a = r.axis;
                let s: Vec<Id> = (0..l).map(|k| c[r.coordinate * l + k]).collect();
                let spin = qdot[r.coordinate];
                let spin_rate = g.time_derivative(spin, &reduced)?;
                let spin_rate = zero_accels.apply(g, spin_rate)?;
                let alpha = alphas[r.carrier].expect("rigid");
                let mut axis = [zero; 3];
                axis[a] = g.int(1)?;
                let w_cross_a = cross(g, c_t.omega_b, axis)?;
                if r.whole {
                    // The rotor's axial partial angular velocities
                    // o_k = s_k + γ̄ᶜ_k·a enter as λ o_k o_j, a product of two
                    // sums the expansion keeps whole (the bicycle 1,047 -> 1,031
                    // ops against λ (s_k γ̄ᶜ_j·a + s_j γ̄ᶜ_k·a + s_k s_j) beside
                    // the carrier's λ γ̄ᶜ_k·a γ̄ᶜ_j·a, multiplied out).
                    let o: Vec<Id> = (0..l)
                        .map(|k| g.add(s[k], c_t.gamma_b[k][a]))
                        .collect::<Result<_, _>>()?;
                    let axial_rate = g.add(c_t.omega_b[a], spin)?;
                    let axial_accel = g.add(alpha[a], spin_rate)?;
                    for k in 0..l {
                        for j in k..l {
                            let e = g.mul(o[k], o[j])?;
                            let e = g.mul(r.axial, e)?;
                            mass[k * l + j] = g.add(mass[k * l + j], e)?;
                        }
                        let x = g.mul(axial_accel, o[k])?;
                        let y = dot(g, c_t.gamma_b[k], w_cross_a)?;
                        let y = g.mul(axial_rate, y)?;
                        let sum = g.add(x, y)?;
                        let e = g.mul(r.axial, sum)?;
                        forcing_terms[k].push(g.neg(e)?);
                    }
                } else {
                    // Split: λ (s_k γ̄ᶜ_j·a + s_j γ̄ᶜ_k·a + s_k s_j) beside the
                    // carrier's λ γ̄ᶜ_k·a γ̄ᶜ_j·a, and
                    // λ (θ̈ γ̄ᶜ_k·a + θ̇ γ̄ᶜ_k·(ωᶜ × a) + s_k (αᶜ·a + θ̈)).
                    for k in 0..l {
                        for j in k..l {
                            let x = g.mul(s[k], c_t.gamma_b[j][a])?;
                            let y = g.mul(s[j], c_t.gamma_b[k][a])?;
                            let z = g.mul(s[k], s[j])?;
                            let sum = g.sum(&[x, y, z])?;
                            let e = g.mul(r.axial, sum)?;
                            mass[k * l + j] = g.add(mass[k * l + j], e)?;
                        }
                        let x = g.mul(spin_rate, c_t.gamma_b[k][a])?;
                        let y = dot(g, c_t.gamma_b[k], w_cross_a)?;
                        let y = g.mul(spin, y)?;
                        let z = g.add(alpha[a], spin_rate)?;
                        let z = g.mul(s[k], z)?;
                        let sum = g.sum(&[x, y, z])?;
                        let e = g.mul(r.axial, sum)?;
                        forcing_terms[k].push(g.neg(e)?);
                    }
                }
            }
            // (mass, β̄_k, the centre in the twin or the model)
            let translational = match &composites[bi] {
                Composite::Member(_) => None,
                Composite::Alone => Some((
                    b.mass,
                    t.beta.clone(),
                    twin.as_ref().map_or(b.center, |t| t.bodies[bi].center),
                    center_parts[bi].clone(),
                )),
                Composite::Leader {
                    mass: total,
                    center,
                    shift,
                    extra_inertia,
                } => {
                    for (r, row) in inertia.iter_mut().enumerate() {
                        for (c, e) in row.iter_mut().enumerate() {
                            *e = g.add(*e, extra_inertia[r][c])?;
                        }
                    }
                    let mut v = [zero; 3];
                    for i in 0..3 {
                        v[i] = g.time_derivative(center[i], &rules)?;
                    }
                    let (parts, rest) = raw_parts(g, v)?;
                    let (beta, _) = through_c(g, &parts, rest)?;
                    let twin_center = match &twin {
                        Some(t) => {
                            let rot = t.frames[b.frame.expect("rigid")].rot;
                            let mut c = t.bodies[bi].center;
                            for (i, c) in c.iter_mut().enumerate() {
                                let mut terms = vec![*c];
                                for (j, sh) in shift.iter().enumerate() {
                                    terms.push(g.mul(rot[i][j], *sh)?);
                                }
                                *c = g.sum(&terms)?;
                            }
                            c
                        }
                        None => *center,
                    };
                    Some((*total, beta, twin_center, parts))
                }
            };
            if let Some((m_total, beta, center, parts)) = &translational {
                let center_rules = twin_rules.as_ref().unwrap_or(&rules);
                let mut v = [zero; 3];
                for i in 0..3 {
                    v[i] = g.time_derivative(center[i], center_rules)?;
                }
                let a_rem = remainder(g, &mut fixed_rates, &mut uncut, v, Some(parts))?;
                for k in 0..l {
                    let ab = dot(g, a_rem, beta[k])?;
                    let inertial = g.mul(*m_total, ab)?;
                    forcing_terms[k].push(g.neg(inertial)?);
                }
            }
            for k in 0..l {
                for j in k..l {
                    let mut e = zero;
                    if let Some((m_total, beta, _, _)) = &translational {
                        let bb = dot(g, beta[k], beta[j])?;
                        e = g.mul(*m_total, bb)?;
                    }
                    if b.frame.is_some() && rotors[bi].is_none() {
                        let ig = mat_vec(g, &inertia, t.gamma_b[j])?;
                        let rot = dot(g, t.gamma_b[k], ig)?;
                        e = g.add(e, rot)?;
                    }
                    mass[k * l + j] = g.add(mass[k * l + j], e)?;
                }
            }
            if let (Some(alpha_b), None) = (alphas[bi], rotors[bi]) {
                let i_alpha = mat_vec(g, &inertia, alpha_b)?;
                let i_omega = mat_vec(g, &inertia, t.omega_b)?;
                let gyro = cross(g, t.omega_b, i_omega)?;
                let mut total = [zero; 3];
                for i in 0..3 {
                    total[i] = g.add(i_alpha[i], gyro[i])?;
                }
                for k in 0..l {
                    let e = dot(g, t.gamma_b[k], total)?;
                    forcing_terms[k].push(g.neg(e)?);
                }
            }
        }
        Ok((mass, forcing_terms))
    };
    // Composites pay off when the members' own translational terms are
    // long (the bicycle's wheels: 2,086 -> 1,964 ops) and not in small
    // models, whose fully expanded terms collect better body by body: the
    // variant with fewer operations is kept.
    let no_rotors: Vec<Option<Rotor>> = vec![None; model.bodies.len()];
    let mut chosen: Vec<Composite> = (0..model.bodies.len()).map(|_| Composite::Alone).collect();
    let (mut mass, mut forcing_terms) = assemble(g, &chosen, &no_rotors)?;
    let composites = composite_bodies(g, &model.bodies, &rotations, &assume)?;
    if composites.iter().any(|c| !matches!(c, Composite::Alone)) {
        let candidate = assemble(g, &composites, &no_rotors)?;
        if model.fold_always
            || assembled_ops(g, &candidate, l)?
                < assembled_ops(g, &(mass.clone(), forcing_terms.clone()), l)?
        {
            (mass, forcing_terms) = candidate;
            chosen = composites;
        }
    }
    let mut folded = Vec::new();
    for (bi, c) in chosen.iter().enumerate() {
        if matches!(c, Composite::Leader { .. }) {
            let members: Vec<String> = chosen
                .iter()
                .enumerate()
                .filter(|(_, m)| matches!(m, Composite::Member(leader) if *leader == bi))
                .map(|(i, _)| format!("`{}`", model.bodies[i].name))
                .collect();
            folded.push(format!(
                "composite: `{}` with {} (one translational term at their mass centre)",
                model.bodies[bi].name,
                members.join(", ")
            ));
        }
    }
    // Rotors folded into their carriers, kept when that costs fewer
    // operations.
    // Each rotor's terms are written whole or split, whichever the
    // assembled M and f count fewer operations with (the bicycle's front
    // wheel, whose spin rate is dependent, prefers whole; every combination
    // is tried for up to four rotors).
    let mut found = rotors(g, &model.bodies, &model.frames, &model.coords)?;
    if found.iter().any(Option::is_some) {
        let indices: Vec<usize> = (0..found.len()).filter(|&i| found[i].is_some()).collect();
        let combinations = match model.rotor_form {
            None if indices.len() <= 4 => 1usize << indices.len(),
            _ => 1,
        };
        let mut best: Option<(usize, Vec<Option<Rotor>>, Assembled)> = None;
        for mask in 0..combinations {
            let mut forms = found.clone();
            for (bit, &i) in indices.iter().enumerate() {
                if let Some(r) = forms[i].as_mut() {
                    r.whole = model.rotor_form.unwrap_or(mask & (1 << bit) == 0);
                }
            }
            let assembled = assemble(g, &chosen, &forms)?;
            let ops = assembled_ops(g, &assembled, l)?;
            if best.as_ref().is_none_or(|(b, _, _)| ops < *b) {
                best = Some((ops, forms, assembled));
            }
        }
        let (ops, forms, candidate) = best.expect("at least one combination");
        found = forms;
        if model.fold_always || ops < assembled_ops(g, &(mass.clone(), forcing_terms.clone()), l)? {
            (mass, forcing_terms) = candidate;
            for (bi, r) in found.iter().enumerate() {
                if let Some(r) = r {
                    folded.push(format!(
                        "rotor: `{}` spins about axis {} of `{}` (its rotational terms folded into the carrier's)",
                        model.bodies[bi].name,
                        ["x", "y", "z"][r.axis],
                        model.bodies[r.carrier].name
                    ));
                }
            }
        }
    }
    // Loads are kept apart (per effect) so scenes can pick them. The
    // weights of a composite's members act as one at its mass centre:
    // Σ mᵢ g·β̄ᵢ = M g·β̄_G.
    let mut inertial_terms = forcing_terms.clone();
    let mut load_terms: Vec<(String, Vec<Id>)> = Vec::new();
    for (fi, f) in model.forces.iter().enumerate() {
        let weight = match (f.weight_of.map(|b| &chosen[b]), model.gravity) {
            (Some(Composite::Member(_)), _) => Some(None),
            (
                Some(Composite::Leader {
                    mass: total,
                    center,
                    ..
                }),
                Some(gvec),
            ) => {
                let mut v = [zero; 3];
                for i in 0..3 {
                    v[i] = g.time_derivative(center[i], &rules)?;
                }
                let (parts, rest) = raw_parts(g, v)?;
                let (beta, _) = through_c(g, &parts, rest)?;
                let mut w = gvec;
                for x in w.iter_mut() {
                    *x = g.mul(*x, *total)?;
                }
                Some(Some((w, beta)))
            }
            _ => None,
        };
        let per_k: Vec<Id> = match weight {
            Some(None) => vec![zero; l],
            Some(Some((w, beta))) => (0..l)
                .map(|k| dot(g, w, beta[k]))
                .collect::<Result<_, _>>()?,
            None => (0..l)
                .map(|k| dot(g, f.vector, force_beta[fi][k]))
                .collect::<Result<_, _>>()?,
        };
        load_terms.push((f.effect.clone(), per_k));
    }
    for (ti, t) in model.torques.iter().enumerate() {
        let rot = model.frames[t.frame].rot;
        let vector = mat_t_vec(g, &rot, t.vector)?;
        let vector = expanded3(g, vector)?;
        let mut per_k = Vec::with_capacity(l);
        for k in 0..l {
            let gamma = mat_t_vec(g, &rot, torque_gamma[ti][k])?;
            let gamma = expanded3(g, gamma)?;
            per_k.push(dot(g, vector, gamma)?);
        }
        load_terms.push((t.effect.clone(), per_k));
    }
    // One sum per effect, expanded on its own: the loads of one effect
    // can cancel in part (a torque and its reaction on two bodies leave
    // only the relative rotation's partial velocity).
    let mut merged: Vec<(String, Vec<Id>)> = Vec::new();
    for (effect, per_k) in load_terms {
        match merged.iter_mut().find(|(e, _)| *e == effect) {
            Some((_, sum)) => {
                for (s, x) in sum.iter_mut().zip(per_k) {
                    *s = g.add(*s, x)?;
                }
            }
            None => merged.push((effect, per_k)),
        }
    }
    for (_, per_k) in merged.iter_mut() {
        for x in per_k.iter_mut() {
            *x = expanded(g, *x)?;
        }
        for k in 0..l {
            forcing_terms[k].push(per_k[k]);
        }
    }
    let mut load_terms = merged;
    for k in 0..l {
        for j in k..l {
            mass[k * l + j] = expanded(g, mass[k * l + j])?;
        }
        for j in 0..k {
            mass[k * l + j] = mass[j * l + k];
        }
    }
    let mut forcing: Vec<Id> = forcing_terms
        .iter()
        .map(|t| g.sum(t).and_then(|e| expanded(g, e)))
        .collect::<Result<_, _>>()?;
    // Kinetic energy ½ Σ m v·v + ½ ω·I ω.
    let mut ke_terms = Vec::new();
    for (bi, b) in model.bodies.iter().enumerate() {
        let t = &body_terms[bi];
        let v = combine(g, &t.beta, t.beta0, &speed_rates)?;
        let vv = dot(g, v, v)?;
        ke_terms.push(g.mul(b.mass, vv)?);
        if b.frame.is_some() {
            let iw = mat_vec(g, &b.inertia, t.omega_b)?;
            ke_terms.push(dot(g, t.omega_b, iw)?);
        }
    }
    let ke = g.sum(&ke_terms)?;
    let kinetic = g.scale(ke, Number::ratio(1, 2).expect("1/2"))?;
    let mut kinetic = expanded(g, kinetic)?;
    // V = −Σ F·r over the gravity effect's (constant) forces.
    let mut v_terms = Vec::new();
    for f in model.forces.iter().filter(|f| f.effect == "gravity") {
        let w = dot(g, f.vector, f.point)?;
        v_terms.push(g.neg(w)?);
    }
    let potential = g.sum(&v_terms)?;
    let mut potential = expanded(g, potential)?;
    // Power of the loads that depend on an input: F·v_P + L·ω.
    let inputs_set = SymbolSet::from_symbols(model.inputs.iter().map(|(_, s)| *s));
    let mut p_terms = Vec::new();
    let mut power_terms: Vec<(String, Id)> = Vec::new();
    for (fi, f) in model.forces.iter().enumerate() {
        if f.vector.iter().any(|&c| g.depends_on_any(c, &inputs_set)) {
            let v = combine(g, &force_beta[fi], force_beta0[fi], &speed_rates)?;
            let p = dot(g, f.vector, v)?;
            p_terms.push(p);
            power_terms.push((f.effect.clone(), p));
        }
    }
    for (ti, t) in model.torques.iter().enumerate() {
        if t.vector.iter().any(|&c| g.depends_on_any(c, &inputs_set)) {
            let w = combine(g, &torque_gamma[ti], torque_gamma0[ti], &speed_rates)?;
            let p = dot(g, t.vector, w)?;
            p_terms.push(p);
            power_terms.push((t.effect.clone(), p));
        }
    }
    let input_power = g.sum(&p_terms)?;
    let mut input_power = expanded(g, input_power)?;
    // 7. Retained and ignorable coordinates.
    // The zero last column of X has done its work (carrying w): set it to
    // zero everywhere.
    if !vanishing.is_empty() {
        let mut zero_x = Substitution::new();
        for &s in &vanishing {
            zero_x.insert(s, zero);
        }
        let mut fix = |g: &mut appell_symbolic::Graph, e: &mut Id| -> Result<(), SymbolicError> {
            *e = zero_x.apply(g, *e)?;
            Ok(())
        };
        for e in c.iter_mut().chain(c0.iter_mut()).chain(qdot.iter_mut()) {
            fix(g, e)?;
        }
        for e in mass.iter_mut().chain(forcing.iter_mut()) {
            fix(g, e)?;
        }
        for e in [&mut kinetic, &mut potential, &mut input_power] {
            fix(g, e)?;
        }
        for e in inertial_terms.iter_mut().flatten() {
            fix(g, e)?;
        }
        for (_, terms) in load_terms.iter_mut() {
            for e in terms.iter_mut() {
                fix(g, e)?;
            }
        }
        for (_, e) in power_terms.iter_mut() {
            fix(g, e)?;
        }
        if let Elimination::Numeric(ne) = &mut elimination {
            for e in ne
                .dp
                .iter_mut()
                .chain(ne.rhs.iter_mut())
                .chain(ne.rhs_rate.iter_mut())
            {
                fix(g, e)?;
            }
        }
    }
    let raw_mass = mass.clone();
    let raw_elimination = elimination.clone();
    let (retained, ignorable, cyclic) = reduce_state(
        g,
        &model.coords,
        &model.quadrature,
        &mut mass,
        &mut forcing,
        &mut elimination,
        &qdot,
        &dependent,
    )?;
    let mut velocity_residuals = Vec::with_capacity(m);
    for i in 0..m {
        let mut terms = vec![d0[i]];
        for (r, rate) in rates.iter().enumerate() {
            let q = g.sym(*rate)?;
            terms.push(g.mul(d_rows[i * n + r], q)?);
        }
        velocity_residuals.push(g.sum(&terms)?);
    }
    Ok(Some(Parts {
        n,
        m,
        l,
        dependent,
        d_rows,
        row_sources: kept_sources,
        d0,
        holonomic,
        c,
        c0,
        elimination,
        qdot,
        velocity_residuals,
        speed_w,
        speed_w0,
        accels,
        mass,
        forcing,
        kinetic,
        potential,
        input_power,
        retained,
        cyclic,
        ignorable,
        raw_mass,
        raw_elimination,
        inertial_terms,
        load_terms,
        power_terms,
        folded,
    }))
}

/// The retained, ignorable and cyclic coordinates. First, coordinates that
/// occur in the equations but on which they do not depend (an axisymmetric
/// wheel's angle, a bicycle's heading after the elimination) are found
/// numerically at pseudo-random points and set to zero in M, f and the
/// numeric elimination, so they drop out of the reduced state; then the
/// coordinates M and f need, and those the kept coordinates' rates need.
#[allow(clippy::type_complexity, clippy::too_many_arguments)] // (retained, ignorable, cyclic); the derivation pieces it reads and rewrites
fn reduce_state(
    g: &mut appell_symbolic::Graph,
    coords: &[(syn::Ident, appell_symbolic::Coordinate)],
    quadrature: &[usize],
    mass: &mut [Id],
    forcing: &mut [Id],
    elimination: &mut Elimination,
    qdot: &[Id],
    dependent: &[usize],
) -> Result<(Vec<usize>, Vec<usize>, Vec<usize>), SymbolicError> {
    let n = coords.len();
    let zero = g.int(0)?;
    {
        let mut core: Vec<Id> = mass.iter().chain(forcing.iter()).copied().collect();
        if let Elimination::Numeric(ne) = &*elimination {
            core.extend(ne.dp.iter().chain(&ne.rhs).chain(&ne.rhs_rate));
        }
        let mut deps = SymbolSet::new();
        for &e in &core {
            deps.union_with(g.dependencies(e));
        }
        let tape = appell_symbolic::Tape::new(g, &core);
        let independent: Vec<Symbol> = coords
            .iter()
            .map(|(_, c)| c.q)
            .filter(|&q| deps.contains(q) && numerically_independent(g, &tape, q))
            .collect();
        if !independent.is_empty() {
            let mut fix = Substitution::new();
            for &q in &independent {
                fix.insert(q, zero);
            }
            for e in mass.iter_mut().chain(forcing.iter_mut()) {
                *e = fix.apply(g, *e)?;
            }
            if let Elimination::Numeric(ne) = elimination {
                for e in ne
                    .dp
                    .iter_mut()
                    .chain(ne.rhs.iter_mut())
                    .chain(ne.rhs_rate.iter_mut())
                {
                    *e = fix.apply(g, *e)?;
                }
            }
        }
    }
    let aux_deps = match &*elimination {
        Elimination::Symbolic => Vec::new(),
        Elimination::Numeric(ne) => {
            let mut all = SymbolSet::new();
            for &e in ne.dp.iter().chain(&ne.rhs).chain(&ne.rhs_rate) {
                all.union_with(g.dependencies(e));
            }
            ne.x.iter()
                .chain(&ne.w)
                .map(|&s| (s, all.clone()))
                .collect::<Vec<_>>()
        }
    };
    let deps_of = |g: &appell_symbolic::Graph, e: Id| -> SymbolSet {
        let mut set = g.dependencies(e).clone();
        for (s, d) in &aux_deps {
            if set.contains(*s) {
                set.union_with(d);
            }
        }
        set
    };
    let coord_of = |set: &SymbolSet| -> BTreeSet<usize> {
        coords
            .iter()
            .enumerate()
            .filter(|(_, (_, c))| set.contains(c.q))
            .map(|(i, _)| i)
            .collect()
    };
    let mut retained: BTreeSet<usize> = quadrature.iter().copied().collect();
    for &e in mass.iter().chain(forcing.iter()) {
        retained.extend(coord_of(&deps_of(g, e)));
    }
    loop {
        let before = retained.len();
        for r in retained.clone() {
            retained.extend(coord_of(&deps_of(g, qdot[r])));
        }
        if retained.len() == before {
            break;
        }
    }
    let retained: Vec<usize> = retained.into_iter().collect();
    let ignorable: Vec<usize> = (0..n).filter(|i| !retained.contains(i)).collect();
    let cyclic: Vec<usize> = ignorable
        .iter()
        .copied()
        .filter(|i| dependent.contains(i))
        .collect();
    Ok((retained, ignorable, cyclic))
}

/// A scene of a derived model: its loads only, its quadrature outputs kept
/// in the state. Reuses the full derivation (kinematics, M, elimination); only
/// the forcing and the reduced state are derived again.
pub fn derive_scene(
    cx: &Ctxt,
    full: &Derivation,
    scene: &crate::model::Scene,
) -> Option<Derivation> {
    let r: Result<Derivation, SymbolicError> = (|| {
        let mut model = crate::model::scene_model(&full.model, scene);
        let g = &mut model.g;
        let l = full.l;
        let mut mass = full.raw_mass.clone();
        let mut forcing = Vec::with_capacity(l);
        for k in 0..l {
            let mut terms = full.inertial_terms[k].clone();
            for (effect, per_k) in &full.load_terms {
                if scene.effects.contains(effect) {
                    terms.push(per_k[k]);
                }
            }
            let sum = g.sum(&terms)?;
            forcing.push(expanded(g, sum)?);
        }
        let mut elimination = full.raw_elimination.clone();
        let potential = if scene.effects.iter().any(|e| e == "gravity") {
            full.potential
        } else {
            g.int(0)?
        };
        let scene_power: Vec<Id> = full
            .power_terms
            .iter()
            .filter(|(e, _)| scene.effects.contains(e))
            .map(|(_, p)| *p)
            .collect();
        let input_power = g.sum(&scene_power)?;
        let input_power = expanded(g, input_power)?;
        let (retained, ignorable, cyclic) = reduce_state(
            g,
            &model.coords,
            &model.quadrature,
            &mut mass,
            &mut forcing,
            &mut elimination,
            &full.qdot,
            &full.dependent,
        )?;
        let mut d = Derivation {
            model,
            n: full.n,
            m: full.m,
            l,
            dependent: full.dependent.clone(),
            d_rows: full.d_rows.clone(),
            row_sources: full.row_sources.clone(),
            d0: full.d0.clone(),
            holonomic: full.holonomic.clone(),
            c: full.c.clone(),
            c0: full.c0.clone(),
            elimination,
            qdot: full.qdot.clone(),
            velocity_residuals: full.velocity_residuals.clone(),
            speed_w: full.speed_w.clone(),
            speed_w0: full.speed_w0.clone(),
            accels: full.accels.clone(),
            mass,
            forcing,
            kinetic: full.kinetic,
            potential,
            input_power,
            retained,
            cyclic,
            ignorable,
            text: String::new(),
            raw_mass: full.raw_mass.clone(),
            raw_elimination: full.raw_elimination.clone(),
            inertial_terms: full.inertial_terms.clone(),
            load_terms: Vec::new(),
            power_terms: Vec::new(),
            folded: full.folded.clone(),
        };
        d.text = equations_text(&d);
        Ok(d)
    })();
    match r {
        Ok(d) => Some(d),
        Err(e) => {
            cx.error_spanned_by(
                &scene.name,
                format!("deriving scene `{}` failed: {e}", scene.name),
            );
            None
        }
    }
}

/// Where a velocity constraint row comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RowSource {
    /// The time derivative of the i-th `holonomic(...)`.
    Holonomic(usize),
    /// The i-th `nonholonomic(...)`.
    Nonholonomic(usize),
    /// A component of the i-th `rolls(...)`: `direction` indexes N.x, N.y,
    /// N.z, or the `along` list.
    Rolling {
        /// Index into `Model::rolling`.
        contact: usize,
        /// The component.
        direction: usize,
    },
}

/// The components of a rolling contact's velocity, (v + ω × (P − centre))
/// along each direction (or in N), as written: not multiplied out.
fn rolling_components(
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

/// Operations of M (upper triangle) and f, expanded as they will be.
fn assembled_ops(
    g: &mut appell_symbolic::Graph,
    (mass, forcing_terms): &(Vec<Id>, Vec<Vec<Id>>),
    l: usize,
) -> Result<usize, SymbolicError> {
    let mut roots = Vec::new();
    for k in 0..l {
        for j in k..l {
            roots.push(expanded(g, mass[k * l + j])?);
        }
    }
    for terms in forcing_terms {
        let f = g.sum(terms)?;
        roots.push(expanded(g, f)?);
    }
    Ok(g.op_count(&roots)?.total())
}

/// S's and R's entries, row by row.
type SchurParts = (Vec<Id>, Vec<Id>);

/// The constraint rows as written and what [`schur_as_written`] reads off
/// them.
struct SchurRows<'a> {
    /// The rows as the model wrote them (the twin's, when there is one).
    rows: &'a [Id],
    /// T, the elimination's row operations, k × `width`.
    row_ops: &'a [Id],
    width: usize,
    /// Every coordinate rate (set to zero for the rows' remainders).
    rates: &'a [Symbol],
    /// The rates of the free unknowns (S's columns).
    free: &'a [Symbol],
    /// The rates of the privileged speeds (R's first columns).
    speeds: &'a [Symbol],
}

/// S and R of the numeric elimination read off T (D q̇ + d) with the rows
/// as written: S_if = ∂(T rows)_i/∂ż_f, R_ik = −∂(T rows)_i/∂ẏ_k and
/// R_il = −(T rows)_i at q̇ = 0, the twin's symbols put back by `uncut`.
/// The rows' coefficients stay in the form the model gave them (a rolling
/// contact's (v + ω × r)·e with its unit vector unexpanded), which the
/// emitter shares with the other terms. `None` unless every nonzero entry
/// equals the elimination's (`known`) at the test points of
/// [`same_function`].
fn schur_as_written(
    g: &mut appell_symbolic::Graph,
    rows: SchurRows<'_>,
    uncut: &mut Substitution,
    known: (&[Id], &[Id]),
) -> Result<Option<SchurParts>, SymbolicError> {
    let (s_known, r_known) = known;
    let k = rows.free.len();
    let l = rows.speeds.len();
    let zero = g.int(0)?;
    let mut no_rates = Substitution::new();
    for &r in rows.rates {
        no_rates.insert(r, zero);
    }
    let mut s = s_known.to_vec();
    let mut r = r_known.to_vec();
    for i in 0..k {
        let mut terms = Vec::new();
        for (j, &row) in rows.rows.iter().enumerate() {
            let t = rows.row_ops[i * rows.width + j];
            if !g.is_zero(t) {
                terms.push(g.mul(t, row)?);
            }
        }
        let combined = g.sum(&terms)?;
        // (entry, its value: a coefficient or the remainder, and its sign)
        let mut entries: Vec<(&mut Id, Option<Symbol>, bool)> = Vec::new();
        let (s_row, r_row) = (
            &mut s[i * k..(i + 1) * k],
            &mut r[i * (l + 1)..(i + 1) * (l + 1)],
        );
        for (e, &rate) in s_row.iter_mut().zip(rows.free) {
            entries.push((e, Some(rate), false));
        }
        let (r_speeds, r_rest) = r_row.split_at_mut(l);
        for (e, &rate) in r_speeds.iter_mut().zip(rows.speeds) {
            entries.push((e, Some(rate), true));
        }
        entries.push((&mut r_rest[0], None, true));
        for (entry, rate, negate) in entries {
            if g.is_zero(*entry) {
                continue;
            }
            let c = match rate {
                Some(rate) => g.diff(combined, rate)?,
                None => no_rates.apply(g, combined)?,
            };
            let c = uncut.apply(g, c)?;
            let c = if negate { g.neg(c)? } else { c };
            if same_function(g, *entry, c) != Some(true) {
                return Ok(None);
            }
            *entry = c;
        }
    }
    Ok(Some((s, r)))
}

/// M's entries and f's terms per speed, as `assemble` builds them.
type Assembled = (Vec<Id>, Vec<Vec<Id>>);

/// An axisymmetric body turning about its symmetry axis, which is fixed in
/// another body's frame (a wheel on its axle; see [`rotors`]).
#[derive(Clone, Copy)]
struct Rotor {
    /// The body whose frame carries the axis.
    carrier: usize,
    /// The axis: 0, 1 or 2 of the carrier's (and the rotor's) frame.
    axis: usize,
    /// The coordinate whose rate is the spin rate.
    coordinate: usize,
    /// The moment of inertia about the axis.
    axial: Id,
    /// Its terms written with its axial partial angular velocities whole
    /// (λ o_k o_j), or split against the carrier's (see [`rotors`]).
    whole: bool,
}

/// Finds rotors: a rigid body whose frame is a carrier body's frame turned
/// about one of its axes by a coordinate, with an inertia symmetric about
/// that axis. Its inertia is then the same matrix in the carrier's frame,
/// so its rotational terms fold into the carrier's. With a the axis, λ the
/// axial and μ the transverse moment, θ the spin angle, s_k = ∂θ̇/∂ẏ_k,
/// o_k = s_k + γ̄ᶜ_k·a the rotor's axial partial angular velocity,
/// Ω = ωᶜ·a + θ̇ its axial angular velocity and ν = αᶜ·a + θ̈ the remainder
/// of its axial angular acceleration: the carrier's inertia gains μ (1 − a aᵀ),
/// γ̄_k·I γ̄_j adds λ o_k o_j, and γ̄_k·(I α + ω × I ω) adds
/// λ (ν o_k + Ω γ̄ᶜ_k·(ωᶜ × a)).
fn rotors(
    g: &mut appell_symbolic::Graph,
    bodies: &[crate::model::Body],
    frames: &[crate::model::Frame],
    coords: &[(syn::Ident, appell_symbolic::Coordinate)],
) -> Result<Vec<Option<Rotor>>, SymbolicError> {
    let nb = bodies.len();
    let mut out: Vec<Option<Rotor>> = vec![None; nb];
    for b in 0..nb {
        let Some(fb) = bodies[b].frame else { continue };
        let inertia = bodies[b].inertia;
        for p in 0..nb {
            let Some(fp) = bodies[p].frame else { continue };
            if p == b || fp == fb || out[p].is_some() {
                continue;
            }
            if out.iter().flatten().any(|r| r.carrier == b) {
                break;
            }
            let (rb, rp) = (frames[fb].rot, frames[fp].rot);
            // The relative rotation, carrier to rotor, and the relative
            // angular velocity in the carrier's frame.
            let mut rel = [[g.int(0)?; 3]; 3];
            for (i, row) in rel.iter_mut().enumerate() {
                for (j, e) in row.iter_mut().enumerate() {
                    let d = dot(
                        g,
                        [rp[0][i], rp[1][i], rp[2][i]],
                        [rb[0][j], rb[1][j], rb[2][j]],
                    )?;
                    *e = expanded(g, d)?;
                }
            }
            let mut dw = [g.int(0)?; 3];
            for i in 0..3 {
                dw[i] = g.sub(frames[fb].omega[i], frames[fp].omega[i])?;
            }
            let dw = mat_t_vec(g, &rp, dw)?;
            let dw = expanded3(g, dw)?;
            let one = g.int(1)?;
            for k in 0..3 {
                let others = [(k + 1) % 3, (k + 2) % 3];
                let axis_fixed = rel[k][k] == one
                    && others
                        .iter()
                        .all(|&i| g.is_zero(rel[i][k]) && g.is_zero(rel[k][i]));
                let symmetric = (0..3).all(|i| (0..3).all(|j| i == j || g.is_zero(inertia[i][j])))
                    && inertia[others[0]][others[0]] == inertia[others[1]][others[1]];
                let spin = coords
                    .iter()
                    .position(|(_, c)| g.sym(c.rate).is_ok_and(|r| r == dw[k]));
                if axis_fixed && symmetric && others.iter().all(|&i| g.is_zero(dw[i])) {
                    if let Some(coordinate) = spin {
                        out[b] = Some(Rotor {
                            carrier: p,
                            axis: k,
                            coordinate,
                            axial: inertia[k][k],
                            whole: true,
                        });
                        break;
                    }
                }
            }
            if out[b].is_some() {
                break;
            }
        }
    }
    Ok(out)
}

/// A body's part in a composite (see [`composite_bodies`]).
enum Composite {
    /// Its translational terms are its own.
    Alone,
    /// It carries the group's translational terms: the total mass, the
    /// composite mass centre (N components) and the members' parallel-axis
    /// inertia about it (in its frame).
    Leader {
        mass: Id,
        center: Vec3,
        shift: Vec3,
        extra_inertia: Mat3,
    },
    /// Its translational terms are carried by its group's leader (the
    /// index).
    Member(usize),
}

/// Groups bodies whose mass centres are fixed in a rigid body's frame (a
/// wheel's centre in the frame that carries its axle). For such a group,
/// Σ mᵢ β̄ᵢ·β̄ⱼ and Σ mᵢ aᵢ·β̄ are those of one particle of the total mass
/// at the composite mass centre G plus the parallel-axis inertia
/// Σ mᵢ (|dᵢ|² 1 − dᵢ dᵢᵀ), dᵢ = rᵢ − G, turning with the leader's frame:
/// one translational term instead of one per body. A group is formed only
/// when its total mass is provably positive (parameters declared
/// `positive`), since G divides by it.
fn composite_bodies(
    g: &mut appell_symbolic::Graph,
    bodies: &[crate::model::Body],
    rotations: &[Option<Mat3>],
    assume: &Assumptions,
) -> Result<Vec<Composite>, SymbolicError> {
    let nb = bodies.len();
    let zero = g.int(0)?;
    let mut out: Vec<Composite> = (0..nb).map(|_| Composite::Alone).collect();
    let mut taken = vec![false; nb];
    for a in 0..nb {
        let Some(rot) = rotations[a] else { continue };
        if taken[a] {
            continue;
        }
        // Members and their offsets from the leader's centre, in its frame.
        let mut members: Vec<(usize, Vec3)> = vec![(a, [zero; 3])];
        for (b, body) in bodies.iter().enumerate().skip(a + 1) {
            if taken[b] {
                continue;
            }
            let mut diff = [zero; 3];
            for i in 0..3 {
                diff[i] = g.sub(body.center[i], bodies[a].center[i])?;
            }
            let offset = mat_t_vec(g, &rot, diff)?;
            let offset = expanded3(g, offset)?;
            if offset.iter().all(|&c| g.is_parameter_only(c)) {
                members.push((b, offset));
            }
        }
        if members.len() < 2 {
            continue;
        }
        let masses: Vec<Id> = members.iter().map(|(i, _)| bodies[*i].mass).collect();
        let total = g.sum(&masses)?;
        if g.sign(total, assume) != Sign::Positive {
            continue;
        }
        let inv = g.recip(total)?;
        // G − r_a = Σ mᵢ eᵢ / M, in the leader's frame.
        let mut shift = [zero; 3];
        for i in 0..3 {
            let mut terms = Vec::new();
            for (b, e) in &members {
                terms.push(g.mul(bodies[*b].mass, e[i])?);
            }
            let s = g.sum(&terms)?;
            shift[i] = g.mul(s, inv)?;
        }
        let mut center = bodies[a].center;
        for (i, c) in center.iter_mut().enumerate() {
            let mut terms = vec![*c];
            for (j, s) in shift.iter().enumerate() {
                terms.push(g.mul(rot[i][j], *s)?);
            }
            *c = g.sum(&terms)?;
        }
        let mut extra = [[zero; 3]; 3];
        for (b, e) in &members {
            let mut d = [zero; 3];
            for i in 0..3 {
                d[i] = g.sub(e[i], shift[i])?;
            }
            let dd = dot(g, d, d)?;
            for r in 0..3 {
                for c in 0..3 {
                    let outer = g.mul(d[r], d[c])?;
                    let term = if r == c {
                        g.sub(dd, outer)?
                    } else {
                        g.neg(outer)?
                    };
                    let term = g.mul(bodies[*b].mass, term)?;
                    extra[r][c] = g.add(extra[r][c], term)?;
                }
            }
        }
        for (b, _) in &members {
            taken[*b] = true;
            out[*b] = Composite::Member(a);
        }
        out[a] = Composite::Leader {
            mass: total,
            center,
            shift,
            extra_inertia: extra,
        };
    }
    Ok(out)
}

/// Multiplies out products of sums when that makes the expression no
/// larger: cancellations then happen (the velocity terms of the wheel-axle's
/// forcing vanish only after expansion), while an expansion that would blow
/// up (a bicycle's nested rotations) is abandoned early by a term budget and
/// the factored form is kept.
/// The order in which a square system S x = r is solved when rows with a
/// single entry among the unknowns not yet solved go first, one by one
/// (see [`singleton_rows`]).
pub struct SingletonOrder {
    /// (row, unknown) pairs, in solving order.
    pub peeled: Vec<(usize, usize)>,
    /// The rows left to a dense solve, in order.
    pub rows_left: Vec<usize>,
    /// The unknowns left to a dense solve, in order.
    pub cols_left: Vec<usize>,
}

/// Rows of a k×k matrix with a single nonzero entry among the unknowns not
/// yet solved, peeled in order (each solved by one division; no other
/// entry changes, so there is nothing for pivoting to protect); `entry`
/// says whether an entry can be nonzero. The generated code and
/// `structural_solution` both follow this order.
///
/// ```
/// use appell_codegen::derivation::singleton_rows;
/// // Row 0 reads only unknown 1; then rows 1 and 2 share unknowns 0 and 2.
/// let nonzero = [[false, true, false], [true, true, true], [true, false, true]];
/// let order = singleton_rows(3, |i, j| nonzero[i][j]);
/// assert_eq!(order.peeled, vec![(0, 1)]);
/// assert_eq!((order.rows_left, order.cols_left), (vec![1, 2], vec![0, 2]));
/// ```
pub fn singleton_rows(k: usize, entry: impl Fn(usize, usize) -> bool) -> SingletonOrder {
    let mut rows_left: Vec<usize> = (0..k).collect();
    let mut cols_left: Vec<usize> = (0..k).collect();
    let mut peeled = Vec::new();
    while let Some((at, col)) = rows_left.iter().enumerate().find_map(|(at, &i)| {
        let mut found = cols_left.iter().filter(|&&j| entry(i, j));
        match (found.next(), found.next()) {
            (Some(&j), None) => Some((at, j)),
            _ => None,
        }
    }) {
        let row = rows_left.remove(at);
        cols_left.retain(|&j| j != col);
        peeled.push((row, col));
    }
    SingletonOrder {
        peeled,
        rows_left,
        cols_left,
    }
}

/// Which entries of X in S X = R can be nonzero, from where S and R are
/// identically zero: rows of S with a single entry among the unknowns not
/// yet solved are solved one by one (as the generated code does), and an
/// unknown so solved is zero in a column where its row of R and every
/// earlier unknown its row reads are zero; the unknowns of the remaining
/// block are taken as nonzero wherever the block's right side can be. (The
/// bicycle's pitch rate does not depend on the rear wheel's rate.)
fn structural_solution(
    g: &appell_symbolic::Graph,
    s: &SymMatrix,
    r: &SymMatrix,
    k: usize,
    width: usize,
) -> Vec<Vec<bool>> {
    let entry = |i: usize, j: usize| !g.is_zero(s[(i, j)]);
    let order = singleton_rows(k, entry);
    let mut nonzero = vec![vec![true; width]; k];
    for (t, &(row, col)) in order.peeled.iter().enumerate() {
        for c in 0..width {
            nonzero[col][c] = !g.is_zero(r[(row, c)])
                || order.peeled[..t]
                    .iter()
                    .any(|&(_, jj)| entry(row, jj) && nonzero[jj][c]);
        }
    }
    let (rows_left, cols_left) = (&order.rows_left, &order.cols_left);
    let peeled: Vec<usize> = order.peeled.iter().map(|&(_, j)| j).collect();
    for c in 0..width {
        let block = rows_left.iter().any(|&row| {
            !g.is_zero(r[(row, c)]) || peeled.iter().any(|&jj| entry(row, jj) && nonzero[jj][c])
        });
        for &j in cols_left {
            nonzero[j][c] = block;
        }
    }
    nonzero
}

fn expanded(g: &mut appell_symbolic::Graph, e: Id) -> Result<Id, SymbolicError> {
    const TERM_BUDGET: usize = 32;
    match g.expand_outside_functions(e, TERM_BUDGET) {
        Ok(x) if x == e => Ok(e),
        Ok(x) => {
            if g.dag_size(&[x]) <= g.dag_size(&[e]) {
                Ok(x)
            } else {
                Ok(e)
            }
        }
        Err(SymbolicError::TermLimit { .. }) => Ok(e),
        Err(other) => Err(other),
    }
}

fn expanded3(g: &mut appell_symbolic::Graph, v: Vec3) -> Result<Vec3, SymbolicError> {
    Ok([expanded(g, v[0])?, expanded(g, v[1])?, expanded(g, v[2])?])
}

/// Splits a vector linear in `speeds` into coefficient vectors and the rest.
fn split_linear(
    g: &mut appell_symbolic::Graph,
    v: Vec3,
    speeds: &[Symbol],
) -> Result<(Vec<Vec3>, Vec3), SymbolicError> {
    let zero = g.int(0)?;
    let mut parts = vec![[zero; 3]; speeds.len()];
    let mut rest = [zero; 3];
    for i in 0..3 {
        let form = g.linear_coefficients(v[i], speeds)?;
        for (k, c) in form.coefficients.into_iter().enumerate() {
            parts[k][i] = c;
        }
        rest[i] = form.remainder;
    }
    Ok((parts, rest))
}

fn split_omega(
    g: &mut appell_symbolic::Graph,
    omega: Vec3,
    sub: &mut Substitution,
    speeds: &[Symbol],
) -> Result<(Vec<Vec3>, Vec3), SymbolicError> {
    let mut w = omega;
    for x in w.iter_mut() {
        *x = sub.apply(g, *x)?;
    }
    split_linear(g, w, speeds)
}

/// Σ parts_k ẏ_k + p0.
fn combine(
    g: &mut appell_symbolic::Graph,
    parts: &[Vec3],
    p0: Vec3,
    speeds: &[Symbol],
) -> Result<Vec3, SymbolicError> {
    let mut out = p0;
    for i in 0..3 {
        let mut terms = vec![p0[i]];
        for (k, s) in speeds.iter().enumerate() {
            let y = g.sym(*s)?;
            terms.push(g.mul(parts[k][i], y)?);
        }
        out[i] = g.sum(&terms)?;
    }
    Ok(out)
}

/// Rᵀ v: N components to body components.
fn mat_t_vec(g: &mut appell_symbolic::Graph, r: &Mat3, v: Vec3) -> Result<Vec3, SymbolicError> {
    let col = |k: usize| [r[0][k], r[1][k], r[2][k]];
    Ok([dot(g, col(0), v)?, dot(g, col(1), v)?, dot(g, col(2), v)?])
}

/// I v.
fn mat_vec(g: &mut appell_symbolic::Graph, m: &Mat3, v: Vec3) -> Result<Vec3, SymbolicError> {
    Ok([dot(g, m[0], v)?, dot(g, m[1], v)?, dot(g, m[2], v)?])
}

/// A value in [0.5, 1.5] for parameters and [−1, 1] for everything else,
/// fixed by the symbol and the trial number (the numeric rank and
/// independence checks evaluate at such points).
///
/// ```
/// use appell_codegen::derivation::pseudo_value;
/// let mut g = appell_symbolic::Graph::new();
/// let m = g.parameter("m").unwrap();
/// let q = g.coordinate("q").unwrap().q;
/// assert!((0.5..=1.5).contains(&pseudo_value(&g, m, 0)));
/// assert!((-1.0..=1.0).contains(&pseudo_value(&g, q, 0)));
/// assert_eq!(pseudo_value(&g, q, 3), pseudo_value(&g, q, 3));
/// ```
pub fn pseudo_value(g: &appell_symbolic::Graph, s: Symbol, trial: u64) -> f64 {
    let mut h = (s.index() as u64 + 1).wrapping_mul(0x9e37_79b9_7f4a_7c15)
        ^ (trial + 1).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    h ^= h >> 31;
    h = h.wrapping_mul(0x94d0_49bb_1331_11eb);
    h ^= h >> 29;
    let u = (h >> 11) as f64 / (1u64 << 53) as f64;
    match g.symbol_kind(s) {
        SymbolKind::Parameter => 0.5 + u,
        _ => 2.0 * u - 1.0,
    }
}

/// Whether the values of `tape` stay the same (to 1e-9, relative) when the
/// symbol `q` alone changes, at three pseudo-random points and two shifts.
/// Any evaluation failure counts as a dependence.
fn numerically_independent(
    g: &appell_symbolic::Graph,
    tape: &appell_symbolic::Tape,
    q: Symbol,
) -> bool {
    for trial in 0..3u64 {
        let base = |s: Symbol| Some(pseudo_value(g, s, trial));
        let Ok(v0) = tape.eval(&base) else {
            return false;
        };
        for shift in [0.7, 1.9] {
            let moved =
                |s: Symbol| Some(pseudo_value(g, s, trial) + if s == q { shift } else { 0.0 });
            let Ok(v1) = tape.eval(&moved) else {
                return false;
            };
            let same = v0
                .iter()
                .zip(&v1)
                .all(|(a, b)| (a - b).abs() <= 1e-9 * (1.0 + a.abs().max(b.abs())));
            if !same {
                return false;
            }
        }
    }
    true
}

/// `rel · v + plus`, componentwise, skipping the zero direction cosines
/// (v and plus in the frames `rel` maps between; see [`simple_turn`]).
fn turned(
    g: &mut appell_symbolic::Graph,
    rel: &Mat3,
    v: Vec3,
    plus: Vec3,
) -> Result<Vec3, SymbolicError> {
    let mut out = plus;
    for i in 0..3 {
        let mut terms = vec![plus[i]];
        for j in 0..3 {
            if !g.is_zero(rel[i][j]) {
                terms.push(g.mul(rel[i][j], v[j])?);
            }
        }
        out[i] = g.sum(&terms)?;
    }
    Ok(out)
}

/// When `frame` is `parent` turned by a simple rotation: every direction
/// cosine between the two is a single term (no sum), and the relative
/// angular velocity, in `frame`'s components, is a combination of the
/// coordinate rates with constant coefficients (the steer, a wheel's spin).
/// Returns the direction cosines (`rel[i][j]` = frame axis i · parent axis
/// j, so v_frame = rel · v_parent) and that relative angular velocity.
fn simple_turn(
    g: &mut appell_symbolic::Graph,
    frame: &crate::model::Frame,
    parent: &crate::model::Frame,
    rates: &[Symbol],
) -> Result<Option<(Mat3, Vec3)>, SymbolicError> {
    let (rot, prot) = (frame.rot, parent.rot);
    let zero = g.int(0)?;
    let mut rel = [[zero; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            let d = dot(
                g,
                [rot[0][i], rot[1][i], rot[2][i]],
                [prot[0][j], prot[1][j], prot[2][j]],
            )?;
            rel[i][j] = expanded(g, d)?;
            if matches!(g.node(rel[i][j]), appell_symbolic::Node::Add { .. }) {
                return Ok(None);
            }
        }
    }
    let mut dw = [zero; 3];
    for i in 0..3 {
        dw[i] = g.sub(frame.omega[i], parent.omega[i])?;
    }
    let dw = mat_t_vec(g, &rot, dw)?;
    let dw = expanded3(g, dw)?;
    let (parts, rest) = split_linear(g, dw, rates)?;
    if !parts
        .iter()
        .flatten()
        .chain(&rest)
        .all(|&c| g.is_parameter_only(c))
    {
        return Ok(None);
    }
    Ok(Some((rel, dw)))
}

/// Whether `a` and `b` are the same function: equal to 1e-10, relative, at
/// three pseudo-random points (see [`pseudo_value`]) where they are not
/// zero. `None` when some evaluation fails.
fn same_function(g: &appell_symbolic::Graph, a: Id, b: Id) -> Option<bool> {
    let tape = appell_symbolic::Tape::new(g, &[a, b]);
    for trial in 0..3u64 {
        let v = tape.eval(&|s| Some(pseudo_value(g, s, trial))).ok()?;
        let (x, y) = (v[0], v[1]);
        if !(x.is_finite() && y.is_finite()) {
            return None;
        }
        if x.abs() < 1e-6 || (x - y).abs() > 1e-10 * x.abs().max(y.abs()) {
            return Some(false);
        }
    }
    Some(true)
}

/// The first row of D that is numerically a combination of the rows before
/// it at every one of three pseudo-random configurations (parameters in
/// [0.5, 1.5], coordinates and rates in [−1, 1]). A dependence that holds only
/// at special configurations is not reported.
fn dependent_row(g: &appell_symbolic::Graph, d: &[Id], n: usize, m: usize) -> Option<usize> {
    if m < 2 {
        return None;
    }
    let tape = appell_symbolic::Tape::new(g, d);
    let mut first_dependent: Option<usize> = None;
    let mut trials = 0;
    for trial in 0..6u64 {
        let value = |s: Symbol| {
            let mut h = (s.index() as u64 + 1).wrapping_mul(0x9e37_79b9_7f4a_7c15)
                ^ (trial + 1).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            h ^= h >> 31;
            let u = (h >> 11) as f64 / (1u64 << 53) as f64;
            Some(match g.symbol_kind(s) {
                SymbolKind::Parameter => 0.5 + u,
                _ => 2.0 * u - 1.0,
            })
        };
        let Ok(vals) = tape.eval(&value) else {
            continue;
        };
        trials += 1;
        // Incremental Gram–Schmidt rank test, row by row.
        let mut basis: Vec<Vec<f64>> = Vec::new();
        let mut dep = None;
        for r in 0..m {
            let mut v: Vec<f64> = vals[r * n..(r + 1) * n].to_vec();
            let norm0 = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            for b in &basis {
                let p: f64 = v.iter().zip(b).map(|(x, y)| x * y).sum();
                for (x, y) in v.iter_mut().zip(b) {
                    *x -= p * y;
                }
            }
            let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            if norm <= 1e-9 * norm0.max(1e-300) {
                dep = Some(r);
                break;
            }
            basis.push(v.iter().map(|x| x / norm).collect());
        }
        match dep {
            None => return None,
            Some(r) => first_dependent = Some(first_dependent.map_or(r, |f: usize| f.min(r))),
        }
        if trials == 3 {
            break;
        }
    }
    first_dependent
}

/// A column (unknown rate) of the square system that no row can be matched to, by
/// augmenting paths over the non-zero pattern.
fn unmatched_column(g: &appell_symbolic::Graph, a: &[Id], size: usize) -> Option<usize> {
    let nonzero = |r: usize, c: usize| !g.is_zero(a[r * size + c]);
    let mut row_of_col: Vec<Option<usize>> = vec![None; size];
    fn augment(
        r: usize,
        seen: &mut [bool],
        row_of_col: &mut [Option<usize>],
        size: usize,
        nonzero: &dyn Fn(usize, usize) -> bool,
    ) -> bool {
        for c in 0..size {
            if nonzero(r, c) && !seen[c] {
                seen[c] = true;
                if row_of_col[c].is_none_or(|r2| augment(r2, seen, row_of_col, size, nonzero)) {
                    row_of_col[c] = Some(r);
                    return true;
                }
            }
        }
        false
    }
    for r in 0..size {
        let mut seen = vec![false; size];
        augment(r, &mut seen, &mut row_of_col, size, &nonzero);
    }
    row_of_col.iter().position(|x| x.is_none())
}

/// The readable form of the derived equations.
fn equations_text(d: &Derivation) -> String {
    let g = &d.model.g;
    let name = |i: usize| d.model.coords[i].0.to_string();
    let show = |e: Id| -> String {
        if g.dag_size(&[e]) > 400 {
            format!(
                "<expression of {} nodes; see the generated code>",
                g.dag_size(&[e])
            )
        } else {
            g.display(e).to_string()
        }
    };
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{}: Appell's equations (Wang & Pao 2003, eq. 56), reduced (eq. 42)",
        d.model.name
    );
    let _ = writeln!(
        s,
        "coordinates q: {}",
        (0..d.n).map(name).collect::<Vec<_>>().join(", ")
    );
    let speeds: Vec<String> = d
        .model
        .speed_specs
        .iter()
        .map(|sp| g.symbol_name(sp.symbol).to_string())
        .collect();
    let _ = writeln!(s, "privileged speeds: {}", speeds.join(", "));
    for (k, sp) in d.model.speed_specs.iter().enumerate() {
        if let Some(def) = sp.definition {
            let _ = writeln!(s, "  {} = {} (quasi-velocity)", speeds[k], show(def));
        }
    }
    if !d.dependent.is_empty() {
        let how = match d.elimination {
            Elimination::Symbolic => "solved symbolically",
            Elimination::Numeric(_) => {
                "solved numerically at run time (no provably non-zero pivot)"
            }
        };
        let _ = writeln!(s, "dependent speeds (q_dot = C y_dot + c, {how}):");
        for &r in &d.dependent {
            let mut terms = Vec::new();
            for k in 0..d.l {
                let c = d.c[r * d.l + k];
                if !g.is_zero(c) {
                    terms.push(format!("({}) * {}", show(c), speeds[k]));
                }
            }
            if !g.is_zero(d.c0[r]) {
                terms.push(show(d.c0[r]));
            }
            if terms.is_empty() {
                terms.push("0".into());
            }
            let _ = writeln!(s, "  {}_dot = {}", name(r), terms.join(" + "));
        }
    }
    let list = |v: &[usize]| {
        if v.is_empty() {
            "none".to_string()
        } else {
            v.iter().map(|&i| name(i)).collect::<Vec<_>>().join(", ")
        }
    };
    for line in &d.folded {
        let _ = writeln!(s, "{line}");
    }
    let _ = writeln!(s, "cyclic coordinates: {}", list(&d.cyclic));
    let _ = writeln!(
        s,
        "ignorable coordinates (not integrated): {}",
        list(&d.ignorable)
    );
    let mut state: Vec<String> = d.retained.iter().map(|&i| name(i)).collect();
    state.extend(speeds.iter().cloned());
    let _ = writeln!(s, "reduced state: ({})", state.join(", "));
    let accels: Vec<String> = d
        .model
        .speed_specs
        .iter()
        .map(|sp| g.symbol_name(sp.accel).to_string())
        .collect();
    let _ = writeln!(
        s,
        "M(q) y_ddot = f(q, y_dot, t) with y_ddot = ({}):",
        accels.join(", ")
    );
    for k in 0..d.l {
        for j in k..d.l {
            let _ = writeln!(
                s,
                "  M[{}, {}] = {}",
                speeds[k],
                speeds[j],
                show(d.mass[k * d.l + j])
            );
        }
    }
    for k in 0..d.l {
        let _ = writeln!(s, "  f[{}] = {}", speeds[k], show(d.forcing[k]));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn simple_turn_finds_a_rotation_about_a_parent_axis() {
        let mut g = appell_symbolic::Graph::new();
        let a = g.coordinate("a").unwrap();
        let b = g.coordinate("b").unwrap();
        let rates = [a.rate, b.rate];
        let frame = |g: &mut appell_symbolic::Graph, rot: [[&str; 3]; 3], omega: [&str; 3]| {
            crate::model::Frame {
                name: String::new(),
                rot: rot.map(|row| row.map(|e| g.parse(e).unwrap())),
                omega: omega.map(|e| g.parse(e).unwrap()),
            }
        };
        // P turns about N.z by a; F turns about P.z by b.
        let p = frame(
            &mut g,
            [
                ["cos(a)", "-sin(a)", "0"],
                ["sin(a)", "cos(a)", "0"],
                ["0", "0", "1"],
            ],
            ["0", "0", "a_dot"],
        );
        let f = frame(
            &mut g,
            [
                [
                    "cos(a)*cos(b) - sin(a)*sin(b)",
                    "-cos(a)*sin(b) - sin(a)*cos(b)",
                    "0",
                ],
                [
                    "sin(a)*cos(b) + cos(a)*sin(b)",
                    "cos(a)*cos(b) - sin(a)*sin(b)",
                    "0",
                ],
                ["0", "0", "1"],
            ],
            ["0", "0", "a_dot + b_dot"],
        );
        let (rel, dw) = simple_turn(&mut g, &f, &p, &rates).unwrap().unwrap();
        let expect = |g: &mut appell_symbolic::Graph, t: &str| g.parse(t).unwrap();
        assert_eq!(rel[0][0], expect(&mut g, "cos(b)"));
        assert_eq!(rel[0][1], expect(&mut g, "sin(b)"));
        assert_eq!(rel[2][2], expect(&mut g, "1"));
        let (zero, b_dot) = (g.int(0).unwrap(), g.sym(b.rate).unwrap());
        assert_eq!(dw, [zero, zero, b_dot]);
        // G turns about P.x by b: simple from P, not from F.
        let h = frame(
            &mut g,
            [
                ["cos(a)", "-sin(a)*cos(b)", "sin(a)*sin(b)"],
                ["sin(a)", "cos(a)*cos(b)", "-cos(a)*sin(b)"],
                ["0", "sin(b)", "cos(b)"],
            ],
            ["b_dot*cos(a)", "b_dot*sin(a)", "a_dot"],
        );
        assert!(simple_turn(&mut g, &h, &p, &rates).unwrap().is_some());
        assert!(simple_turn(&mut g, &h, &f, &rates).unwrap().is_none());
    }

    #[test]
    fn same_function_sees_identities_the_expansion_does_not() {
        let mut g = appell_symbolic::Graph::new();
        g.coordinate("q").unwrap();
        g.parameter("r").unwrap();
        let a = g.parse("r*sin(q)^2 + r*cos(q)^2").unwrap();
        let b = g.parse("r").unwrap();
        let c = g.parse("r*sin(q)").unwrap();
        assert_eq!(same_function(&g, a, b), Some(true));
        assert_eq!(same_function(&g, a, c), Some(false));
        let nan = g.parse("sqrt(-r)").unwrap();
        assert_eq!(same_function(&g, nan, nan), None);
    }

    #[test]
    fn structural_solution_follows_the_singleton_rows() {
        let mut g = appell_symbolic::Graph::new();
        // Row 0 has one entry (column 1): x1 = r0 / a, zero where r0 is.
        // The block (rows 1, 2; columns 0, 2) is then dense: its unknowns
        // are nonzero where any of its rows' right sides, or x1 through
        // the entries b and e, can be.
        let s = SymMatrix::parse(
            &mut g,
            &[&["0", "a", "0"], &["c", "b", "d"], &["f", "0", "h"]],
        )
        .unwrap();
        let r = SymMatrix::parse(
            &mut g,
            &[&["p", "0", "0"], &["0", "0", "0"], &["0", "0", "q"]],
        )
        .unwrap();
        let nz = structural_solution(&g, &s, &r, 3, 3);
        assert_eq!(nz[1], vec![true, false, false]);
        // Column 0 reaches the block through b·x1; column 1 is zero
        // throughout; column 2 through q.
        assert_eq!(nz[0], vec![true, false, true]);
        assert_eq!(nz[2], vec![true, false, true]);
    }
}
