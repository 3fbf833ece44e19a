//! Sliding contacts whose normal force the motion decides.
//!
//! Coulomb friction at a sliding contact is μ N against the slip, with N
//! the contact's normal force. Where the coordinates keep the body on the
//! surface (a disc whose centre is at height r cos(lean)), no multiplier
//! carries N: it is whatever the system's momentum balances need, which
//! depends on the accelerations, which depend on the friction. The
//! equations are implicit in N.
//!
//! The model declares each sliding contact's normal force as an input and
//! uses it as the friction's normal force (`inputs(n_p)`,
//! `friction(P, mu = mu, normal = n_p, frame = B, center = C)`).
//! [`sliding_normals`] finds the N that makes the motion consistent:
//!
//! 1. Loads are affine in N, so the accelerations (and every constraint
//!    reaction) are affine in N too. With N = 0 and then each unit in
//!    turn, the system's linear and angular momentum balances leave an
//!    affine residual R(N) = R₀ + K N. This costs k + 1 evaluations for k
//!    contacts.
//! 2. The normal forces must close that residual: W N = R₀ + K N, with W's
//!    columns each contact's normal and its moment. Rolling contacts of
//!    the scene whose normal force no multiplier carries join as further
//!    unknowns, with no feedback. The six equations are solved by least
//!    squares, and the solution must close them (to 1e-8 relative).
//! 3. One more evaluation at the solution reports the residual that is
//!    left.
//!
//! A contact's own feedback κ is the normal force its friction demands of
//! itself per unit of normal force, through all the balances: (W⁺ K)_ii,
//! with W's columns the unknowns' wrenches. Where κ ≥ 1, friction pushes
//! the contact into the ground faster than the normal force can answer.
//! No normal force is then consistent, or several are (Painlevé's
//! paradox). This is reported as [`SlidingError::Paradox`], never solved
//! through.
//!
//! A rolling contact whose declaration gives no normal (`along = [A.x]`,
//! as one of two wheels on an axle is declared) joins as a support
//! ([`SlidingContact::support_at_rolling_contact`]).
//!
//! Limits: every other constraint reaction must be placed (rolling rows
//! at their contacts). A scene with loop-closing holonomic rows or
//! nonholonomic rows besides rolling ones gets
//! [`SlidingError::OtherSupports`]. The friction's direction is the model's
//! (a regularised Coulomb law in `friction(...)`); this module finds only
//! its magnitude.
//!
//! [`crate::Phase::state_inputs`] runs this at every evaluation of
//! a phase: see [`normal_inputs`]. The guide's scenes page
//! (`docs/guide/scenes.md`, "Sliding contacts") has a runnable example on
//! a derived disc, and `tests/sliding_contacts.rs` checks it against
//! closed forms.

use nalgebra::{DMatrix, DVector};

use appell_core::dynamic::DynModel;
use appell_core::ModelError;
use appell_dynamics::constraint_forces::{contact_forces_parts, momentum_residual, Normal};
use appell_dynamics::oracle::OracleError;

/// A contact point's position at `(t, q)`, N components.
pub type PointFn<'a> = Box<dyn Fn(f64, &[f64]) -> Result<[f64; 3], ModelError> + 'a>;

/// One contact whose normal force the momentum balances decide: a body
/// sliding over a fixed surface, its friction reading the normal force
/// from an input, or a plain support (`input: None`): a rolling contact
/// whose declaration does not give its normal (`along = [A.x]`).
pub struct SlidingContact<'a> {
    /// The index of the scene's input that carries the contact's normal
    /// force (the `normal = ...` of its friction); `None` for a support.
    pub input: Option<usize>,
    /// The surface's unit normal, from the ground into the body, N
    /// components.
    pub normal: [f64; 3],
    /// Where the contact is.
    pub point: PointFn<'a>,
}

impl<'a> SlidingContact<'a> {
    /// A contact whose normal force is input `input`, on a surface of unit
    /// normal `normal`, at the point `point(t, q)`.
    pub fn new(
        input: usize,
        normal: [f64; 3],
        point: impl Fn(f64, &[f64]) -> [f64; 3] + 'a,
    ) -> Self {
        SlidingContact {
            input: Some(input),
            normal,
            point: Box::new(move |t, q| Ok(point(t, q))),
        }
    }

    /// The contact at `model`'s rolling contact named `point` (its
    /// `rolls(..., contact = P)`), its normal force the input named
    /// `input` of `scene` (the sliding scene the contact is used in): the
    /// form that cannot mix up the model's contact numbers and the scene's
    /// input numbers, which differ.
    pub fn named(
        model: &'a dyn DynModel,
        point: &str,
        scene: &dyn DynModel,
        input: &str,
        normal: [f64; 3],
    ) -> Result<Self, SlidingError> {
        let index = scene
            .dyn_info()
            .inputs
            .iter()
            .position(|name| *name == input)
            .ok_or_else(|| {
                SlidingError::BadContact(format!(
                    "the scene has no input `{input}` (its inputs: {:?})",
                    scene.dyn_info().inputs
                ))
            })?;
        let contact = Self::contact_named(model, point)?;
        Ok(Self::at_rolling_contact(model, contact, index, normal))
    }

    /// A support without friction at `model`'s rolling contact named
    /// `point` (see [`SlidingContact::support_at_rolling_contact`]).
    pub fn support_named(
        model: &'a dyn DynModel,
        point: &str,
        normal: [f64; 3],
    ) -> Result<Self, SlidingError> {
        let contact = Self::contact_named(model, point)?;
        Ok(Self::support_at_rolling_contact(model, contact, normal))
    }

    /// The index of `model`'s rolling contact at `point`.
    fn contact_named(model: &dyn DynModel, point: &str) -> Result<usize, SlidingError> {
        let contacts = model.dyn_info().contacts;
        contacts
            .iter()
            .position(|c| c.point == point)
            .ok_or_else(|| {
                let names: Vec<&str> = contacts.iter().map(|c| c.point).collect();
                SlidingError::BadContact(format!(
                    "the model has no rolling contact at `{point}` (its contacts: {names:?})"
                ))
            })
    }

    /// A support without friction at `point(t, q)`, normal `normal`: its
    /// normal force is solved for with the others.
    pub fn support(normal: [f64; 3], point: impl Fn(f64, &[f64]) -> [f64; 3] + 'a) -> Self {
        SlidingContact {
            input: None,
            normal,
            point: Box::new(move |t, q| Ok(point(t, q))),
        }
    }

    /// A support without friction at `model`'s rolling contact `contact`:
    /// a rolling contact of the scene whose declaration does not give its
    /// normal (`along = [A.x]`), so that its normal force is solved for
    /// with the others.
    pub fn support_at_rolling_contact(
        model: &'a dyn DynModel,
        contact: usize,
        normal: [f64; 3],
    ) -> Self {
        SlidingContact {
            input: None,
            ..Self::at_rolling_contact(model, contact, 0, normal)
        }
    }

    /// A contact at the point of `model`'s rolling contact `contact` (its
    /// position from [`DynModel::dyn_contact_geometry`]): usually the model
    /// whose sliding scene this is, which declares `rolls(..., contact = P)`
    /// where the scene drops it.
    pub fn at_rolling_contact(
        model: &'a dyn DynModel,
        contact: usize,
        input: usize,
        normal: [f64; 3],
    ) -> Self {
        let point = move |t: f64, q: &[f64]| -> Result<[f64; 3], ModelError> {
            let info = model.dyn_info();
            if contact >= info.contacts.len() {
                return Err(ModelError::Contact {
                    what: "the model has no such rolling contact",
                });
            }
            let mut points = vec![[0.0; 3]; info.contacts.len()];
            let mut directions = vec![[0.0; 3]; info.constraints];
            model.dyn_contact_geometry(t, q, &mut points, &mut directions)?;
            Ok(points[contact])
        };
        SlidingContact {
            input: Some(input),
            normal,
            point: Box::new(point),
        }
    }
}

/// The normal forces [`sliding_normals`] found.
#[derive(Clone, Debug, PartialEq)]
pub struct SlidingNormals {
    /// Each contact's normal force, in the order given. It is
    /// positive where the ground pushes. A negative value means the body
    /// would be pulled down: it lifts off.
    pub forces: Vec<f64>,
    /// Each contact's feedback κ: the normal force its friction demands of
    /// itself per unit normal force, through all the balances (below 1, or
    /// the call fails; 0 for a support).
    pub feedback: Vec<f64>,
    /// The normal forces at the scene's rolling contacts that no
    /// multiplier carries, solved together with the sliding ones (in
    /// [`ModelInfo::contacts`](appell_core::ModelInfo::contacts) order, the
    /// contacts already known left out).
    pub rolling: Vec<f64>,
    /// The momentum balances' residual at the solution, relative to their
    /// largest term.
    pub residual: f64,
}

/// Why [`sliding_normals`] found no normal force.
#[derive(Clone, Debug, PartialEq)]
pub enum SlidingError {
    /// Evaluating the model failed.
    Oracle(OracleError),
    /// A contact names an input the scene does not have, or its normal is
    /// not a unit vector.
    BadContact(String),
    /// The scene has constraint reactions the balances cannot place.
    OtherSupports,
    /// The momentum balances do not determine the normal forces (several
    /// contacts on one line, or none).
    NotDetermined,
    /// The balances do not close with any normal forces (by more than
    /// 1e-8 relative): the contacts are not all the supports there are,
    /// or a load is not affine in the normal-force inputs (a friction
    /// written with `max(n, 0)`).
    Unbalanced {
        /// The relative residual.
        residual: f64,
    },
    /// Friction feeds back into the normal forces so strongly that no
    /// normal force is consistent, or several are (Painlevé's paradox): a
    /// contact's own feedback κ ≥ 1, or a group of contacts that drive
    /// each other's normal forces.
    Paradox {
        /// The contacts (indices into the list given), the smallest group
        /// that fails.
        contacts: Vec<usize>,
        /// The principal minor of I − D over that group (≤ 0; 1 − κ for
        /// one contact), D the feedback matrix.
        minor: f64,
    },
}

impl core::fmt::Display for SlidingError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            SlidingError::Oracle(e) => write!(f, "{e}"),
            SlidingError::BadContact(why) => write!(f, "bad sliding contact: {why}"),
            SlidingError::OtherSupports => write!(
                f,
                "the scene has constraint reactions the momentum balances cannot place"
            ),
            SlidingError::NotDetermined => {
                write!(f, "the momentum balances do not determine the normal forces")
            }
            SlidingError::Unbalanced { residual } => write!(
                f,
                "the momentum balances do not close with any normal forces (residual {residual:e})"
            ),
            SlidingError::Paradox { contacts, minor } => write!(
                f,
                "sliding contacts {contacts:?}: their friction feeds back into their normal forces too strongly: the principal minor of I − κ over them is {minor} ≤ 0 (Painlevé's paradox)"
            ),
        }
    }
}

impl std::error::Error for SlidingError {}

impl From<OracleError> for SlidingError {
    fn from(e: OracleError) -> Self {
        SlidingError::Oracle(e)
    }
}

impl From<ModelError> for SlidingError {
    fn from(e: ModelError) -> Self {
        SlidingError::Oracle(OracleError::Model(e))
    }
}

impl From<SlidingError> for ModelError {
    fn from(e: SlidingError) -> Self {
        let what = match e {
            SlidingError::Oracle(OracleError::Model(e)) => return e,
            SlidingError::Oracle(_) => "the model could not be evaluated",
            SlidingError::BadContact(_) => "a contact is declared wrongly",
            SlidingError::OtherSupports => "other constraint reactions cannot be placed",
            SlidingError::NotDetermined => "the momentum balances do not determine it",
            SlidingError::Unbalanced { .. } => "the momentum balances do not close",
            SlidingError::Paradox { .. } => "friction feeds back too strongly (Painlevé)",
        };
        ModelError::Contact { what }
    }
}

/// Relative residual the momentum balances must close to.
const BALANCE_TOLERANCE: f64 = 1e-8;

/// The normal forces at `contacts` that make the motion of `model` (a
/// scene with those contacts' friction, normal forces as inputs) at
/// `(t, q, u)` consistent (see the module documentation). `inputs` are
/// the scene's inputs; the contacts' own entries are ignored.
pub fn sliding_normals<K: DynModel + ?Sized>(
    model: &K,
    t: f64,
    q: &[f64],
    u: &[f64],
    inputs: &[f64],
    contacts: &[SlidingContact],
) -> Result<SlidingNormals, SlidingError> {
    let k = contacts.len();
    check_contacts(model, inputs, contacts)?;
    let points: Vec<[f64; 3]> = contacts
        .iter()
        .map(|c| (c.point)(t, q))
        .collect::<Result<_, _>>()?;
    if points.iter().flatten().any(|v| !v.is_finite()) {
        return Err(SlidingError::BadContact(
            "a contact point is not finite".into(),
        ));
    }
    let o = points.first().copied().unwrap_or([0.0; 3]);
    let mut trial = inputs.to_vec();
    let mut residuals: Vec<[f64; 6]> = Vec::with_capacity(k + 1);
    let mut rolling: Vec<([f64; 3], [f64; 3])> = Vec::new();
    for j in 0..=k {
        if j > 0 && contacts[j - 1].input.is_none() {
            // A support feeds nothing back.
            residuals.push(residuals[0]);
            continue;
        }
        for (i, c) in contacts.iter().enumerate() {
            if let Some(input) = c.input {
                trial[input] = if j == i + 1 { 1.0 } else { 0.0 };
            }
        }
        let (residual, unknown) = balance_at(model, t, q, u, &trial, o, &[])?;
        residuals.push(residual.residual);
        rolling = unknown;
    }
    let columns = k + rolling.len();
    if columns == 0 {
        return Ok(SlidingNormals {
            forces: Vec::new(),
            feedback: Vec::new(),
            rolling: Vec::new(),
            residual: 0.0,
        });
    }
    let wrenches: Vec<[f64; 6]> = contacts
        .iter()
        .zip(&points)
        .map(|(c, &p)| (p, c.normal))
        .chain(rolling.iter().copied())
        .map(|(point, n)| {
            let arm = cross(sub(point, o), n);
            [n[0], n[1], n[2], arm[0], arm[1], arm[2]]
        })
        .collect();
    let fed: Vec<[f64; 6]> = (0..k)
        .map(|i| core::array::from_fn(|r| residuals[i + 1][r] - residuals[0][r]))
        .collect();
    let (x, feedback) = solve_normals(&wrenches, &fed, &residuals[0])?;
    for (i, c) in contacts.iter().enumerate() {
        if let Some(input) = c.input {
            trial[input] = x[i];
        }
    }
    let placed: Vec<([f64; 3], [f64; 3])> = rolling
        .iter()
        .enumerate()
        .map(|(j, &(point, n))| (point, scale(n, x[k + j])))
        .collect();
    let mut known = placed;
    known.extend(
        contacts
            .iter()
            .enumerate()
            .map(|(i, c)| (points[i], scale(c.normal, x[i]))),
    );
    let (last, _) = balance_at(model, t, q, u, &trial, o, &known)?;
    let residual =
        last.residual.iter().map(|v| v * v).sum::<f64>().sqrt() / last.size.max(f64::MIN_POSITIVE);
    if residual.is_nan() || residual > BALANCE_TOLERANCE {
        return Err(SlidingError::Unbalanced { residual });
    }
    Ok(SlidingNormals {
        forces: x.iter().take(k).copied().collect(),
        feedback,
        rolling: x.iter().skip(k).copied().collect(),
        residual,
    })
}

/// The normal forces x that close the balance W x = R₀ + K x₁..ₖ (W's
/// columns the unknowns' wrenches, sliding contacts first; K's the
/// residual each sliding contact's unit normal force feeds back), and
/// each sliding contact's own feedback κ_i = (W⁺ K)_ii: the normal force
/// its friction demands of itself per unit, through all the balances.
fn solve_normals(
    wrenches: &[[f64; 6]],
    fed: &[[f64; 6]],
    r0: &[f64; 6],
) -> Result<(DVector<f64>, Vec<f64>), SlidingError> {
    let (columns, k) = (wrenches.len(), fed.len());
    if columns > 6 {
        // Six balances cannot determine more than six forces.
        return Err(SlidingError::NotDetermined);
    }
    let w = DMatrix::from_fn(6, columns, |r, c| wrenches[c][r]);
    let kmat = DMatrix::from_fn(6, k, |r, c| fed[c][r]);
    let determined = |m: &DMatrix<f64>| {
        let svd = m.clone().svd(true, true);
        let (smax, smin) = (svd.singular_values.max(), svd.singular_values.min());
        (smin.is_finite() && smin > 1e-9 * smax).then_some(svd)
    };
    let wsvd = determined(&w).ok_or(SlidingError::NotDetermined)?;
    let demanded = wsvd
        .solve(&kmat, 0.0)
        .map_err(|_| SlidingError::NotDetermined)?;
    let feedback: Vec<f64> = (0..k).map(|i| demanded[(i, i)]).collect();
    if demanded.iter().any(|v| !v.is_finite()) {
        return Err(SlidingError::NotDetermined);
    }
    paradox_check(&demanded, k)?;
    let mut a = w;
    for c in 0..k {
        for r in 0..6 {
            a[(r, c)] -= kmat[(r, c)];
        }
    }
    let x = determined(&a)
        .ok_or(SlidingError::NotDetermined)?
        .solve(&DVector::from_column_slice(r0), 0.0)
        .map_err(|_| SlidingError::NotDetermined)?;
    Ok((x, feedback))
}

/// Painlevé's condition on the sliding contacts' feedback D = (W⁺ K)₁..ₖ:
/// every principal minor of I − D positive (for one contact, κ < 1; for
/// several, also no group of contacts that drive each other's normal
/// forces). The smallest group that fails is reported.
fn paradox_check(demanded: &DMatrix<f64>, k: usize) -> Result<(), SlidingError> {
    let mut subsets: Vec<u32> = (1..1u32 << k).collect();
    subsets.sort_by_key(|s| s.count_ones());
    for set in subsets {
        let members: Vec<usize> = (0..k).filter(|i| set & (1 << i) != 0).collect();
        let n = members.len();
        let minor = DMatrix::from_fn(n, n, |r, c| {
            let identity = if r == c { 1.0 } else { 0.0 };
            identity - demanded[(members[r], members[c])]
        })
        .determinant();
        if minor.is_nan() || minor <= 0.0 {
            return Err(SlidingError::Paradox {
                contacts: members,
                minor,
            });
        }
    }
    Ok(())
}

/// The contacts' inputs exist and their normals are unit vectors.
fn check_contacts<K: DynModel + ?Sized>(
    model: &K,
    inputs: &[f64],
    contacts: &[SlidingContact],
) -> Result<(), SlidingError> {
    let declared = model.dyn_info().inputs.len();
    if inputs.len() != declared {
        return Err(SlidingError::BadContact(format!(
            "{} inputs given, the scene has {declared}",
            inputs.len()
        )));
    }
    for (i, c) in contacts.iter().enumerate() {
        if c.input.is_some_and(|input| input >= declared) {
            return Err(SlidingError::BadContact(format!(
                "contact {i} names input {:?}, the scene has {declared}",
                c.input
            )));
        }
        let len = dot(c.normal, c.normal).sqrt();
        if len.is_nan() || (len - 1.0).abs() > 1e-12 {
            return Err(SlidingError::BadContact(format!(
                "contact {i}'s normal has length {len}, not 1"
            )));
        }
        if c.input.is_some() && contacts[..i].iter().any(|other| other.input == c.input) {
            return Err(SlidingError::BadContact(format!(
                "contacts share input {:?}",
                c.input
            )));
        }
    }
    Ok(())
}

/// The momentum residual at `inputs`, with the scene's placed constraint
/// reactions and the `extra` forces known, and the rolling contacts whose
/// normal force no multiplier carries (point, unit normal).
#[allow(clippy::type_complexity)]
fn balance_at<K: DynModel + ?Sized>(
    model: &K,
    t: f64,
    q: &[f64],
    u: &[f64],
    inputs: &[f64],
    o: [f64; 3],
    extra: &[([f64; 3], [f64; 3])],
) -> Result<
    (
        appell_dynamics::constraint_forces::MomentumResidual,
        Vec<([f64; 3], [f64; 3])>,
    ),
    SlidingError,
> {
    let (forces, parts) = contact_forces_parts(model, t, q, u, inputs, false)?;
    if !parts.located {
        return Err(SlidingError::OtherSupports);
    }
    let mut known: Vec<([f64; 3], [f64; 3])> = Vec::with_capacity(forces.contacts.len());
    let mut unknown = Vec::new();
    for (c, contact) in forces.contacts.iter().enumerate() {
        known.push((contact.position, contact.force));
        // A contact without a normal direction (`along = [A.x]`) needs a
        // support given for it, or the balances do not close.
        if let (Normal::Unavailable(_), Some(n)) = (contact.normal, parts.normals[c]) {
            unknown.push((contact.position, n));
        }
    }
    known.extend_from_slice(extra);
    let residual = momentum_residual(model, t, q, &parts.qdot, inputs, &parts.motion, &known, o)?;
    Ok((residual, unknown))
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// A phase's [`state_inputs`](crate::Phase::state_inputs): at
/// every evaluation, the normal forces of `contacts` in `model` (the
/// phase's scene) from [`sliding_normals`], written into their inputs.
/// A negative normal force (a contact that lifts off, here or at one of
/// the scene's rolling contacts) is the error [`ModelError::Contact`]:
/// give the phase a guard on the normal force that switches to a scene
/// without the contact before it reaches zero.
pub fn normal_inputs<'a>(
    model: &'a dyn DynModel,
    contacts: Vec<SlidingContact<'a>>,
) -> crate::StateInputs<'a> {
    Box::new(move |t, q, u, inputs: &mut [f64]| {
        let found = sliding_normals(model, t, q, u, inputs, &contacts)?;
        if found.forces.iter().chain(&found.rolling).any(|&n| n < 0.0) {
            // A negative normal force would make friction push along the
            // slip: the body lifts off, and no scene of these contacts
            // holds.
            return Err(ModelError::Contact {
                what: "a contact lifts off (its normal force is negative)",
            });
        }
        for (c, n) in contacts.iter().zip(&found.forces) {
            if let Some(input) = c.input {
                inputs[input] = *n;
            }
        }
        Ok(())
    })
}
