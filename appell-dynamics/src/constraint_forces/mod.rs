//! Constraint forces by the multiplier route (Wang & Pao 2003, eqs. 69-70):
//! the multipliers λ, each constraint row's generalized reaction, the
//! reaction on the body at every rolling contact, with the friction
//! coefficient rolling without slip needs there, and the ground's force
//! (and moment) on every foot a scene holds ([`FootForce`]).
//!
//! # Sign convention
//!
//! The multipliers are those of the oracle ([`crate::oracle`]):
//!
//! ```text
//! M_full q̈ + h = Q + Dᵀ λ,      D q̇ + d = 0,
//! ```
//!
//! so `λ_s D_s` (row s of D times its multiplier) is the generalized force
//! the constraint exerts on the system. A rolling row constrains e·v_P, the
//! component along e of the velocity of the body's material point at the
//! contact P, so its row is eᵀ J_P and its reaction is the force `λ_s e` on
//! the body at P (eq. 70). Forces here are always *on the body*, from the
//! ground, in N components.
//!
//! # Normal forces
//!
//! Each contact's normal direction is taken from its declaration: for
//! `rolls(body, contact = P)` the N axis whose row was dropped as
//! identically zero (the coordinates keep the point on the ground, as in
//! the rolling disc); for `along = [e1, e2]` the direction of e1 × e2. It is
//! oriented from the ground into the body: towards the side of the body's
//! mass centre. The normal force then comes from
//!
//! * a holonomic row whose generalized reaction is exactly that of a force
//!   along the normal at the body's material point at P (the bicycle's
//!   front contact: `dot(Q - P, A.z) == 0`); checked numerically, row by
//!   row, to 1e-9 relative ([`NormalSource::HolonomicRow`]);
//! * otherwise, when the coordinates themselves keep the contacts on the
//!   ground (a reaction no multiplier carries), the whole system's linear
//!   and angular momentum balances: the forces along the normals at those
//!   contacts that close both balances, accepted only when the balances
//!   close to 1e-8 relative with them and they are determined
//!   ([`NormalSource::MomentumBalance`]). This needs every other row's
//!   reaction to be located (rolling rows, holonomic rows mapped to a
//!   contact); a model with a nonholonomic row or an unmapped holonomic row
//!   gets [`NormalUnavailable::NotDetermined`].
//!
//! Anything else is reported as [`Normal::Unavailable`], never guessed.
//!
//! # Two-sided constraints
//!
//! Every constraint the model language declares (`holonomic`,
//! `nonholonomic`, `rolls`, driven constraints) is a two-sided equality:
//! its multiplier takes whatever sign keeps it, so a normal force here can
//! be negative, the ground pulling the body. And since the normal is
//! oriented towards the mass centre, where the centre crosses the contact
//! plane (the rolling disc past lean ±π/2) the normal turns over without
//! an error. Contacts are one-sided in the world; that is checked outside
//! the equations, from these forces: by the contact watch every
//! integration of a model with contacts runs (the integrators' module
//! `contact_watch`), and in a hybrid run by the lift-off guard (the hybrid
//! driver's `Guard::lift_off`).

use crate::oracle::{self, finite_all as finite, mul, mul_bt, vee, OracleError};
use appell_core::dynamic::DynModel;
use appell_core::Scalar;
use appell_core::{Model, ModelInfo, RowSource};
use nalgebra::{DMatrix, DVector};
use num_dual::{Dual2_64, Dual64};

mod feet;
pub use feet::FootForce;

/// The reaction of one velocity constraint row.
#[derive(Clone, Debug, PartialEq)]
pub struct RowReaction {
    /// Where the row comes from.
    pub source: RowSource,
    /// Its multiplier λ_s.
    pub multiplier: f64,
    /// Its generalized reaction λ_s D_s, one entry per coordinate.
    pub generalized: Vec<f64>,
}

/// Where a contact's normal force comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NormalSource {
    /// The multiplier of the `index`-th holonomic constraint, whose row is
    /// a multiple of the normal velocity of the body's point at the contact.
    HolonomicRow {
        /// Declaration index among the holonomic constraints.
        index: usize,
    },
    /// The system's momentum balances (the coordinates keep the contact on
    /// the ground, so no multiplier carries it).
    MomentumBalance,
}

/// Why a contact's normal force is not available.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NormalUnavailable {
    /// The declaration does not give a normal direction: a contact without
    /// `along` that keeps all three N rows (or drops two), or an `along`
    /// list that is not two directions.
    NoDirection,
    /// The normal direction passes through the body's mass centre side
    /// ambiguously (the mass centre lies in the contact's tangent plane),
    /// so "into the body" is undefined here.
    Unorientable,
    /// No multiplier carries it and the momentum balances do not determine
    /// it (other supports, unlocated constraint reactions, or several
    /// contacts whose normals the balances cannot separate).
    NotDetermined,
}

/// A contact's normal force.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Normal {
    /// Known: `force` is the component along `direction` (a unit vector from
    /// the ground into the body) of the reaction on the body; positive when
    /// the ground pushes.
    Available {
        /// The unit normal, N components.
        direction: [f64; 3],
        /// The signed normal force.
        force: f64,
        /// Where it comes from.
        source: NormalSource,
    },
    /// Not available, and why.
    Unavailable(NormalUnavailable),
}

/// The friction a contact needs to roll without slip at this state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Friction {
    /// The coefficient |F_t| / N (N > 0).
    Required {
        /// |F_t| / N.
        mu: f64,
        /// The normal force N.
        normal: f64,
        /// The tangential force's magnitude |F_t|.
        tangential: f64,
    },
    /// The normal force is not positive (or so small that |F_t| / N
    /// overflows): the wheel would lift off (or is just touching) and no
    /// friction coefficient keeps it rolling.
    LiftOff {
        /// The normal force (≤ 0).
        normal: f64,
    },
    /// The normal force is not available (see [`Normal::Unavailable`]).
    NormalUnavailable(NormalUnavailable),
}

impl Friction {
    /// The friction a contact needs whose normal force is `normal` and whose
    /// force along the contact plane has the magnitude `tangential`.
    fn of(normal: f64, tangential: f64) -> Friction {
        if normal.is_nan() || normal <= 0.0 {
            return Friction::LiftOff { normal };
        }
        let mu = tangential / normal;
        if !mu.is_finite() {
            // A normal force so small that no coefficient holds: the
            // lift-off limit.
            return Friction::LiftOff { normal };
        }
        Friction::Required {
            mu,
            normal,
            tangential,
        }
    }
}

/// The reaction on the body at one rolling contact.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactForce {
    /// Index of the body in [`ModelInfo::bodies`].
    pub body: usize,
    /// The contact point's name.
    pub point: &'static str,
    /// The contact point's position, N components.
    pub position: [f64; 3],
    /// Σ λ_s e_s over the contact's rolling rows: the reaction those rows
    /// carry (tangential for a wheel), N components.
    pub rolling: [f64; 3],
    /// The whole reaction on the body at the contact: `rolling` plus the
    /// normal force along the normal when it is available.
    pub force: [f64; 3],
    /// The normal force.
    pub normal: Normal,
}

impl ContactForce {
    /// The friction coefficient rolling without slip needs here:
    /// |F_t| / N with F_t the part of [`ContactForce::force`] perpendicular
    /// to the normal; [`Friction::LiftOff`] when N ≤ 0.
    pub fn friction(&self) -> Friction {
        match self.normal {
            Normal::Unavailable(why) => Friction::NormalUnavailable(why),
            Normal::Available {
                direction, force, ..
            } => {
                let t = sub(self.force, scale(direction, dot(self.force, direction)));
                Friction::of(force, norm(t))
            }
        }
    }
}

/// Constraint forces at one state. Produced by [`contact_forces`].
#[derive(Clone, Debug, PartialEq)]
pub struct ConstraintForces {
    /// q̈ for every coordinate (the oracle's, consistent with λ).
    pub qddot: Vec<f64>,
    /// The multipliers λ, one per velocity constraint row (see the module
    /// documentation for the sign).
    pub multipliers: Vec<f64>,
    /// Each row's source and generalized reaction.
    pub rows: Vec<RowReaction>,
    /// The reaction at each rolling contact, in [`ModelInfo::contacts`]
    /// order.
    pub contacts: Vec<ContactForce>,
    /// The ground's reaction on each foot the rows hold
    /// (`contact(link, point | flat)` in a scene that names it), in
    /// [`Model::contact_links`] order.
    pub feet: Vec<FootForce>,
}

/// Relative tolerance for "this holonomic row is a normal force at that
/// contact".
const ROW_MATCH_TOLERANCE: f64 = 1e-9;
/// Relative tolerance for the momentum balances that attribute the
/// coordinates' own support to the contacts.
const BALANCE_TOLERANCE: f64 = 1e-8;

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}
fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn mat_vec(a: &[f64; 9], v: [f64; 3]) -> [f64; 3] {
    [
        a[0] * v[0] + a[1] * v[1] + a[2] * v[2],
        a[3] * v[0] + a[4] * v[1] + a[5] * v[2],
        a[6] * v[0] + a[7] * v[1] + a[8] * v[2],
    ]
}
/// Mass-centre acceleration, angular velocity and angular acceleration of
/// every body along the motion (q̇, q̈), by second-order dual numbers.
// Shared with the crates built on this one; not part of the API.
#[doc(hidden)]
pub struct BodyMotion {
    /// Mass-centre positions.
    pub position: Vec<[f64; 3]>,
    /// Rotation matrices (row-major, columns the body axes in N).
    pub rotation: Vec<[f64; 9]>,
    /// Mass-centre accelerations.
    pub acceleration: Vec<[f64; 3]>,
    /// Angular velocities.
    pub omega: Vec<[f64; 3]>,
    /// Angular accelerations.
    pub alpha: Vec<[f64; 3]>,
}

pub(crate) fn body_motion<K: DynModel + ?Sized>(
    model: &K,
    t: f64,
    q: &[f64],
    qdot: &[f64],
    qddot: &[f64],
) -> Result<BodyMotion, OracleError> {
    let nb = model.dyn_info().bodies.len();
    let path: Vec<Dual2_64> = q
        .iter()
        .zip(qdot)
        .zip(qddot)
        .map(|((&x, &v), &a)| Dual2_64::new(x, v, a))
        .collect();
    let mut pos = vec![[Dual2_64::zero(); 3]; nb];
    let mut rot = vec![[Dual2_64::zero(); 9]; nb];
    model.dyn_body_poses_dual2(Dual2_64::new(t, 1.0, 0.0), &path, &mut pos, &mut rot)?;
    let mut m = BodyMotion {
        position: Vec::with_capacity(nb),
        rotation: Vec::with_capacity(nb),
        acceleration: Vec::with_capacity(nb),
        omega: Vec::with_capacity(nb),
        alpha: Vec::with_capacity(nb),
    };
    for j in 0..nb {
        let r: [f64; 9] = core::array::from_fn(|i| rot[j][i].re);
        let rd: [f64; 9] = core::array::from_fn(|i| rot[j][i].v1);
        let rdd: [f64; 9] = core::array::from_fn(|i| rot[j][i].v2);
        m.position.push(core::array::from_fn(|i| pos[j][i].re));
        m.acceleration.push(core::array::from_fn(|i| pos[j][i].v2));
        m.omega.push(vee(&mul_bt(&rd, &r)));
        // d/dt(Ṙ Rᵀ) = R̈ Rᵀ + Ṙ Ṙᵀ, whose second term is symmetric.
        m.alpha.push(vee(&mul_bt(&rdd, &r)));
        m.rotation.push(r);
    }
    let all = m
        .position
        .iter()
        .chain(&m.acceleration)
        .chain(&m.omega)
        .chain(&m.alpha)
        .flatten()
        .copied();
    finite(all, "the body motion")?;
    Ok(m)
}

/// The constraint forces at full coordinates `q`, privileged speeds `u` and
/// `inputs`: λ and q̈ from the oracle's KKT solve (eqs. 69-70, same
/// arguments as [`oracle::reduced_rhs`]), each row's generalized reaction,
/// and the reaction and normal force at each rolling contact (see the
/// module documentation for the sign convention and the normal forces).
///
/// It works on any [`Model`]: the full model or a scene (whose loads are
/// the scene's effects only). A scene's `outputs(contact_forces)` asks
/// *tools* to report it (the command line's `eval --scene`).
///
/// Errors: those of [`oracle::coordinate_rates`] and
/// [`oracle::accelerations`] (wrong lengths, non-finite values, singular
/// configurations), and [`OracleError::InvalidInfo`] when the model's row
/// sources do not match its rows.
///
/// A runnable example on a derived rolling disc is on the front page of
/// the `appell` crate ("Contact forces").
pub fn contact_forces<M: Model>(
    model: &M,
    t: f64,
    q: &[f64],
    u: &[f64],
    inputs: &[f64],
) -> Result<ConstraintForces, OracleError> {
    contact_forces_dyn(model, t, q, u, inputs)
}

/// [`contact_forces`] of any [`DynModel`] (compiled once for `dyn DynModel`).
// Shared with the crates built on this one; not part of the API.
#[doc(hidden)]
pub fn contact_forces_dyn<K: DynModel + ?Sized>(
    model: &K,
    t: f64,
    q: &[f64],
    u: &[f64],
    inputs: &[f64],
) -> Result<ConstraintForces, OracleError> {
    contact_forces_parts(model, t, q, u, inputs, true).map(|(forces, _)| forces)
}

/// What [`rolling_contact`] finds: the contact's force (its normal force
/// still unknown), its oriented unit normal and its side.
type RollingContact = (ContactForce, Option<[f64; 3]>, Option<f64>);

/// Contact `c`'s reaction from its rolling rows, its unit normal (from
/// the ground into the body) where the declaration gives one and can be
/// oriented, and the side of the body's mass centre (see
/// [`ContactParts::sides`]); the normal force itself is left to the
/// callers.
fn rolling_contact(
    info: &ModelInfo,
    c: usize,
    ci: &appell_core::ContactInfo,
    points: &[[f64; 3]],
    directions: &[[f64; 3]],
    multipliers: &[f64],
    motion: &BodyMotion,
) -> Result<RollingContact, OracleError> {
    if ci.body >= info.bodies.len() {
        return Err(OracleError::InvalidInfo(format!(
            "contact {c} names body {} of {}",
            ci.body,
            info.bodies.len()
        )));
    }
    let mut rolling = [0.0; 3];
    let mut present = [false; 3];
    let mut count = 0;
    for (s, src) in info.row_sources.iter().enumerate() {
        if let RowSource::Rolling { contact, direction } = *src {
            if contact == c {
                rolling = add(rolling, scale(directions[s], multipliers[s]));
                if direction < 3 {
                    present[direction] = true;
                }
                count += 1;
            }
        }
    }
    let raw = if ci.along {
        let dirs: Vec<[f64; 3]> = info
            .row_sources
            .iter()
            .zip(directions)
            .filter(|(src, _)| matches!(src, RowSource::Rolling { contact, .. } if *contact == c))
            .map(|(_, d)| *d)
            .collect();
        (dirs.len() == 2).then(|| cross(dirs[0], dirs[1]))
    } else {
        let missing: Vec<usize> = (0..3).filter(|&i| !present[i]).collect();
        (missing.len() == 1 && count == 2).then(|| {
            let mut e = [0.0; 3];
            e[missing[0]] = 1.0;
            e
        })
    };
    let arm = sub(motion.position[ci.body], points[c]);
    let (normal, dir, cosine) = match raw {
        None => (
            Normal::Unavailable(NormalUnavailable::NoDirection),
            None,
            None,
        ),
        Some(v) => {
            let (len, side, reach) = (norm(v), dot(v, arm), norm(arm));
            // The side of the mass centre, as a cosine (0 where it is in
            // the tangent plane or the direction degenerates).
            let cosine = if len == 0.0 || reach == 0.0 {
                0.0
            } else {
                side / (len * reach)
            };
            if len == 0.0 || side.abs() <= 1e-9 * len * reach {
                (
                    Normal::Unavailable(NormalUnavailable::Unorientable),
                    None,
                    Some(cosine),
                )
            } else {
                let unit = scale(v, side.signum() / len);
                (
                    Normal::Unavailable(NormalUnavailable::NotDetermined),
                    Some(unit),
                    Some(cosine),
                )
            }
        }
    };
    let contact = ContactForce {
        body: ci.body,
        point: ci.point,
        position: points[c],
        rolling,
        force: rolling,
        normal,
    };
    Ok((contact, dir, cosine))
}

/// What [`contact_forces_parts`] found on the way: the motion, and each
/// contact's normal direction where the declaration gives one.
// Shared with the crates built on this one; not part of the API.
#[doc(hidden)]
pub struct ContactParts {
    /// q̇.
    pub qdot: Vec<f64>,
    /// The bodies' motion at the oracle's q̈.
    pub motion: BodyMotion,
    /// Each contact's unit normal (ground into body), if it has one.
    pub normals: Vec<Option<[f64; 3]>>,
    /// Each contact's side: the cosine of the angle between the normal
    /// direction the declaration gives (before it is oriented) and the arm
    /// from the contact to the body's mass centre, if the declaration
    /// gives a direction. It changes sign where the mass centre crosses
    /// the contact's tangent plane (the rolling disc's lean ±π/2), where
    /// the oriented normal silently turns over.
    pub sides: Vec<Option<f64>>,
    /// Whether every constraint row's reaction is placed (rolling rows,
    /// holonomic rows found to be normal forces at a contact).
    pub located: bool,
}

/// [`contact_forces_dyn`], with the momentum balances for the normals the
/// coordinates carry only when `balance` (a caller that has other
/// unknown forces balances them all together).
// Shared with the crates built on this one; not part of the API.
#[doc(hidden)]
pub fn contact_forces_parts<K: DynModel + ?Sized>(
    model: &K,
    t: f64,
    q: &[f64],
    u: &[f64],
    inputs: &[f64],
    balance: bool,
) -> Result<(ConstraintForces, ContactParts), OracleError> {
    let info = model.dyn_info();
    let (n, m) = (info.coordinates.len(), info.constraints);
    if info.row_sources.len() != m {
        return Err(OracleError::InvalidInfo(format!(
            "{} row sources for {m} constraint rows",
            info.row_sources.len()
        )));
    }
    let qdot = oracle::driven_coordinate_rates_dyn(model, t, q, u, inputs)?;
    let sol = oracle::accelerations_dyn(model, t, q, &qdot, inputs)?;
    let mut dmat = vec![0.0; m * n];
    let mut d0 = vec![0.0; m];
    model.dyn_driven_constraint_rows(t, q, inputs, &mut dmat, &mut d0)?;
    let rows: Vec<RowReaction> = (0..m)
        .map(|s| RowReaction {
            source: info.row_sources[s],
            multiplier: sol.multipliers[s],
            generalized: dmat[s * n..(s + 1) * n]
                .iter()
                .map(|d| d * sol.multipliers[s])
                .collect(),
        })
        .collect();

    let nc = info.contacts.len();
    let mut points = vec![[0.0; 3]; nc];
    let mut directions = vec![[0.0; 3]; m];
    model.dyn_contact_geometry(t, q, &mut points, &mut directions)?;
    finite(
        points.iter().chain(&directions).flatten().copied(),
        "the contact geometry",
    )?;
    let motion = body_motion(model, t, q, &qdot, &sol.qddot)?;

    let mut contacts: Vec<ContactForce> = Vec::with_capacity(nc);
    let mut normals: Vec<Option<[f64; 3]>> = Vec::with_capacity(nc);
    let mut sides: Vec<Option<f64>> = Vec::with_capacity(nc);
    for (c, ci) in info.contacts.iter().enumerate() {
        let (contact, dir, side) =
            rolling_contact(info, c, ci, &points, &directions, &sol.multipliers, &motion)?;
        contacts.push(contact);
        normals.push(dir);
        sides.push(side);
    }

    let rows_at = Rows {
        d: &dmat,
        d0: &d0,
        multipliers: &sol.multipliers,
    };
    let located = holonomic_normals(model, t, q, &rows_at, &points, &normals, &mut contacts)?;

    // The coordinates' own support at the remaining contacts, by the
    // system's momentum balances.
    let unknown: Vec<usize> = (0..nc)
        .filter(|&c| normals[c].is_some() && matches!(contacts[c].normal, Normal::Unavailable(_)))
        .collect();
    if balance && !unknown.is_empty() && located.iter().all(|&x| x) {
        if let Some(values) = balance_normals(
            model, t, q, &qdot, inputs, &motion, &contacts, &unknown, &normals,
        )? {
            for (&c, &force) in unknown.iter().zip(&values) {
                let dir = normals[c].expect("unknown contacts have a direction");
                contacts[c].normal = Normal::Available {
                    direction: dir,
                    force,
                    source: NormalSource::MomentumBalance,
                };
                contacts[c].force = add(contacts[c].force, scale(dir, force));
            }
        }
    }
    for c in &contacts {
        finite(c.force.iter().copied(), "a contact force")?;
    }
    let feet = feet::foot_forces(model, t, q, &sol.multipliers)?;
    let forces = ConstraintForces {
        qddot: sol.qddot,
        multipliers: sol.multipliers,
        rows,
        contacts,
        feet,
    };
    let parts = ContactParts {
        qdot,
        motion,
        normals,
        sides,
        located: located.iter().all(|&x| x),
    };
    Ok((forces, parts))
}

/// A model's velocity constraint rows at a state: D (m × n, row-major),
/// its time part d, and their multipliers.
struct Rows<'a> {
    d: &'a [f64],
    d0: &'a [f64],
    multipliers: &'a [f64],
}

/// Places the reactions of holonomic rows that are normal forces at a
/// contact (`normals`: each contact's direction, if it has one) into
/// `contacts`, and says which rows' reactions are placed: the rolling
/// rows', and those.
fn holonomic_normals<K: DynModel + ?Sized>(
    model: &K,
    t: f64,
    q: &[f64],
    rows: &Rows,
    points: &[[f64; 3]],
    normals: &[Option<[f64; 3]>],
    contacts: &mut [ContactForce],
) -> Result<Vec<bool>, OracleError> {
    let info = model.dyn_info();
    let (n, m, nc) = (
        info.coordinates.len(),
        info.constraints,
        info.contacts.len(),
    );
    let holonomic_rows: Vec<(usize, usize)> = info
        .row_sources
        .iter()
        .enumerate()
        .filter_map(|(s, src)| match src {
            RowSource::Holonomic { index } => Some((s, *index)),
            _ => None,
        })
        .collect();
    let mut located = vec![true; m];
    for (s, src) in info.row_sources.iter().enumerate() {
        if !matches!(src, RowSource::Rolling { .. }) {
            located[s] = false;
        }
    }
    if !holonomic_rows.is_empty() && normals.iter().any(Option::is_some) {
        let jac = point_jacobians(model, info, t, q, points)?;
        for &(s, index) in &holonomic_rows {
            let row = &rows.d[s * n..(s + 1) * n];
            for c in 0..nc {
                let Some(dir) = normals[c] else { continue };
                if !matches!(contacts[c].normal, Normal::Unavailable(_)) {
                    continue;
                }
                if let Some(k) = row_as_normal(row, rows.d0[s], &jac[c], dir) {
                    let force = k * rows.multipliers[s];
                    contacts[c].normal = Normal::Available {
                        direction: dir,
                        force,
                        source: NormalSource::HolonomicRow { index },
                    };
                    contacts[c].force = add(contacts[c].force, scale(dir, force));
                    located[s] = true;
                    break;
                }
            }
        }
    }
    Ok(located)
}

/// k where a holonomic row (its q̇ part `row`, its time part `time`) is k
/// times the normal velocity along `dir` of the body's material point at
/// a contact (`jac`: ∂v_P/∂q̇_r, then the time part), to
/// [`ROW_MATCH_TOLERANCE`]: then its reaction is a force along `dir` there.
fn row_as_normal(row: &[f64], time: f64, jac: &[[f64; 3]], dir: [f64; 3]) -> Option<f64> {
    let n = row.len();
    // g_r = n̂ · ∂v_P/∂q̇_r (and the time column for d).
    let g: Vec<f64> = (0..=n).map(|r| dot(jac[r], dir)).collect();
    let gg: f64 = g[..n].iter().map(|x| x * x).sum();
    if gg == 0.0 {
        return None;
    }
    let k = row.iter().zip(&g).map(|(a, b)| a * b).sum::<f64>() / gg;
    let resid = row
        .iter()
        .zip(&g)
        .map(|(a, b)| (a - k * b).powi(2))
        .sum::<f64>()
        .sqrt();
    let time_resid = (time - k * g[n]).abs();
    let row_norm = row.iter().map(|x| x * x).sum::<f64>().sqrt();
    let tol = ROW_MATCH_TOLERANCE * row_norm.max(f64::MIN_POSITIVE);
    (resid <= tol && time_resid <= tol).then_some(k)
}

/// For every contact, ∂v_P/∂q̇_r (r < n) and the time part (r = n) of the
/// velocity of the body's material point at the contact.
fn point_jacobians<K: DynModel + ?Sized>(
    model: &K,
    info: &ModelInfo,
    t: f64,
    q: &[f64],
    points: &[[f64; 3]],
) -> Result<Vec<Vec<[f64; 3]>>, OracleError> {
    let (n, nb) = (q.len(), info.bodies.len());
    let mut pos0 = vec![[0.0; 3]; nb];
    let mut rot0 = vec![[0.0; 9]; nb];
    model.dyn_body_poses(t, q, &mut pos0, &mut rot0)?;
    let mut out = vec![vec![[0.0; 3]; n + 1]; points.len()];
    let mut qd: Vec<Dual64> = q.iter().map(|&x| Dual64::new(x, 0.0)).collect();
    let mut pos = vec![[Dual64::zero(); 3]; nb];
    let mut rot = vec![[Dual64::zero(); 9]; nb];
    for r in 0..=n {
        let td = if r == n {
            Dual64::new(t, 1.0)
        } else {
            qd[r].eps = 1.0;
            Dual64::new(t, 0.0)
        };
        model.dyn_body_poses_dual(td, &qd, &mut pos, &mut rot)?;
        if r < n {
            qd[r].eps = 0.0;
        }
        for (c, ci) in info.contacts.iter().enumerate() {
            let b = ci.body;
            let dr: [f64; 9] = core::array::from_fn(|i| rot[b][i].eps);
            let w = vee(&mul_bt(&dr, &rot0[b]));
            let v: [f64; 3] = core::array::from_fn(|i| pos[b][i].eps);
            out[c][r] = add(v, cross(w, sub(points[c], pos0[b])));
        }
    }
    Ok(out)
}

/// The normal forces at the `unknown` contacts that close the system's
/// linear and angular momentum balances, or `None` when they do not close
/// or do not determine them.
#[allow(clippy::too_many_arguments)] // one internal step of `contact_forces`
fn balance_normals<K: DynModel + ?Sized>(
    model: &K,
    t: f64,
    q: &[f64],
    qdot: &[f64],
    inputs: &[f64],
    motion: &BodyMotion,
    contacts: &[ContactForce],
    unknown: &[usize],
    normals: &[Option<[f64; 3]>],
) -> Result<Option<Vec<f64>>, OracleError> {
    // Moments about the first unknown contact keep the numbers small.
    let o = contacts[unknown[0]].position;
    let known: Vec<([f64; 3], [f64; 3])> = contacts.iter().map(|c| (c.position, c.force)).collect();
    let balance = momentum_residual(model, t, q, qdot, inputs, motion, &known, o)?;
    let size = balance.size;
    let k = unknown.len();
    let mut a = DMatrix::<f64>::zeros(6, k);
    for (col, &c) in unknown.iter().enumerate() {
        let dir = normals[c].expect("unknown contacts have a direction");
        let arm = cross(sub(contacts[c].position, o), dir);
        for i in 0..3 {
            a[(i, col)] = dir[i];
            a[(3 + i, col)] = arm[i];
        }
    }
    let b = DVector::from_column_slice(&balance.residual);
    let svd = a.clone().svd(true, true);
    let smax = svd.singular_values.max();
    let smin = svd.singular_values.min();
    if smin.is_nan() || smin <= 1e-6 * smax {
        return Ok(None);
    }
    let Ok(x) = svd.solve(&b, 0.0) else {
        return Ok(None);
    };
    let resid = (&a * &x - &b).norm();
    if !x.iter().all(|v| v.is_finite()) || resid > BALANCE_TOLERANCE * size.max(f64::MIN_POSITIVE) {
        return Ok(None);
    }
    Ok(Some(x.iter().copied().collect()))
}

/// What the system's momentum balances leave over, about a point `o`:
/// Σ m a − Σ F (linear) and Σ (r × m a + I α + ω × I ω) − Σ (r × F + L)
/// (angular), the applied loads and the `known` external forces (point,
/// force) on the right; zero when those forces are all there is.
// Shared with the crates built on this one; not part of the API.
#[doc(hidden)]
pub struct MomentumResidual {
    /// Linear, then angular, N components.
    pub residual: [f64; 6],
    /// The largest term that went into it, for relative tolerances.
    pub size: f64,
}

/// [`MomentumResidual`] at a motion (q̇, and the accelerations in `motion`).
// both callers (balance_normals here, sliding's balance_at) pass the q̇ and motion
// contact_forces_parts already computed, so nothing is solved twice
#[allow(clippy::too_many_arguments)]
// Shared with the crates built on this one; not part of the API.
#[doc(hidden)]
pub fn momentum_residual<K: DynModel + ?Sized>(
    model: &K,
    t: f64,
    q: &[f64],
    qdot: &[f64],
    inputs: &[f64],
    motion: &BodyMotion,
    known: &[([f64; 3], [f64; 3])],
    o: [f64; 3],
) -> Result<MomentumResidual, OracleError> {
    let info = model.dyn_info();
    let nb = info.bodies.len();
    let mut masses = vec![0.0; nb];
    let mut inertias = vec![[0.0; 9]; nb];
    model.dyn_mass_properties(&mut masses, &mut inertias)?;
    let (nf, nt) = (info.force_points, info.torques);
    let mut fpoints = vec![[0.0; 3]; nf];
    let mut frames = vec![[0.0; 9]; nt];
    model.dyn_load_geometry(t, q, &mut fpoints, &mut frames)?;
    let mut forces = vec![[0.0; 3]; nf];
    let mut torques = vec![[0.0; 3]; nt];
    model.dyn_load_values(t, q, qdot, inputs, &mut forces, &mut torques)?;
    let mut lin = [0.0; 3];
    let mut ang = [0.0; 3];
    let mut size = 0.0_f64;
    let mut acc = |lin_t: [f64; 3], ang_t: [f64; 3], lin: &mut [f64; 3], ang: &mut [f64; 3]| {
        *lin = add(*lin, lin_t);
        *ang = add(*ang, ang_t);
        size = size.max(norm(lin_t)).max(norm(ang_t));
    };
    for j in 0..nb {
        let ma = scale(motion.acceleration[j], masses[j]);
        let r = sub(motion.position[j], o);
        let mut h = cross(r, ma);
        if info.bodies[j].rigid {
            let rot = &motion.rotation[j];
            let i_n = mul_bt(&mul(rot, &inertias[j]), rot);
            let w = motion.omega[j];
            h = add(
                h,
                add(mat_vec(&i_n, motion.alpha[j]), cross(w, mat_vec(&i_n, w))),
            );
        }
        acc(ma, h, &mut lin, &mut ang);
    }
    for p in 0..nf {
        let f = scale(forces[p], -1.0);
        acc(f, cross(sub(fpoints[p], o), f), &mut lin, &mut ang);
    }
    for tq in &torques {
        acc([0.0; 3], scale(*tq, -1.0), &mut lin, &mut ang);
    }
    for &(point, force) in known {
        let f = scale(force, -1.0);
        acc(f, cross(sub(point, o), f), &mut lin, &mut ang);
    }
    finite(lin.iter().chain(&ang).copied(), "the momentum balance")?;
    Ok(MomentumResidual {
        residual: [lin[0], lin[1], lin[2], ang[0], ang[1], ang[2]],
        size,
    })
}
