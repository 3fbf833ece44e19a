//! One-sided contacts along an integration.
//!
//! Every constraint of the model language is a two-sided equality:
//! `holonomic(...)`, `nonholonomic(...)`, `rolls(...)` and the driven
//! constraints hold whatever force it takes, pushing or pulling. A wheel
//! on the ground is one-sided in the world: the ground can push it, not
//! pull it, and a rolling disc whose lean passes ±π/2 is under the floor.
//! The equations know neither, so an integration carries such a motion on
//! without a word. [`ContactWatch`] is how one-sidedness is checked (and
//! the hybrid driver's `Guard::lift_off`
//! how a run switches scenes there): at each check it computes the contact
//! forces ([`constraint_forces`](appell_dynamics::constraint_forces)) and flags, per
//! `rolls` contact ([`ModelInfo::contacts`](appell_core::ModelInfo)),
//!
//! * a normal force below −tolerance × the largest contact force at that
//!   instant ([`ContactViolation::LiftOff`]: the ground would have to pull);
//! * the body's mass centre reaching or crossing the contact's tangent
//!   plane: the side of the centre, measured along the normal the
//!   declaration gives before it is oriented, vanishing or changing sign
//!   between two checks ([`ContactViolation::LeftRegion`]; an adaptive step
//!   that jumps over the rolling disc's lean π/2 is caught this way);
//! * forces that cannot be computed because the configuration is singular
//!   ([`ContactViolation::Singular`], the disc exactly at lean ±π/2).
//!
//! A watch that warns records each [`ContactEvent`] (once per passage:
//! a normal force must come back above the tolerance before it is flagged
//! again) and lets the integration go on; one that stops (the default)
//! ends it at the first.
//!
//! Every `solve_model*` of [`Dopri5`](crate::Dopri5),
//! [`Dop853`](crate::Dop853), [`TrBdf2`](crate::TrBdf2)
//! and [`Radau5`](crate::Radau5) of a model with contacts runs a
//! stopping watch and returns
//! [`IntegrateError::Contact`](crate::IntegrateError) naming the
//! contact; `.contact_watch(false)` on the integrator turns it off. It
//! checks the initial state, and then, when the run has no event function
//! of its own, its [`ContactWatch::margin`] is the event function: the
//! integrator locates where the first contact is lost on its dense output
//! and stops there, before the body goes through (the falling disc stops
//! a few µrad short of lean π/2). A run with its own event function
//! (`solve_model_until`) checks the end of every accepted step instead. To warn instead, turn it off and give a warning watch's
//! [`ContactWatch::check`] as the projection of `solve_model_projected`,
//! then read [`ContactWatch::events`]. `appell::animate::simulate`
//! checks every frame and stops with
//! [`ModelError::ContactLost`](appell_core::ModelError).
//!
//! Cost: one [`contact_forces`](appell_dynamics::constraint_forces::contact_forces)
//! per accepted step (a KKT solve, the bodies' motion by dual numbers and
//! the momentum balances), several times a step of a small model's
//! generated rhs, and a few more where a contact is lost (the event
//! location). Both ways see the ends of accepted steps only: a normal force
//! that dips below zero and back within one step goes unseen (bound the
//! step with `h_max` when that matters), and a check after each step sees
//! a region's edge once crossed, one step late at most.
//!
//! Not watched: the fixed-step functions ([`rk4`](crate::rk4)
//! and its siblings, without `std` and without allocation), the augmented
//! full-coordinate integrator ([`appell_dynamics::augmented`]), and the hybrid
//! driver's phases, whose scenes change where a guard says (give them a
//! `appell::hybrid::Guard::lift_off`).
//!
//! A model without contacts has nothing to watch:
//!
//! ```
//! use appell_integrate::contact_watch::ContactWatch;
//! # use appell_core::__doc_model::Oscillator;
//! use appell_integrate::Dop853;
//!
//! let model = Oscillator { w: 0.0 }; // x'' = 0: a free particle
//! let mut watch = ContactWatch::new(&model).warn();
//! Dop853::new()
//!     .solve_model_projected(&model, &[], &mut |t, x: &mut [f64; 2]| watch.check(t, x), 0.0, &[0.0, 1.0], 1.0)
//!     .unwrap();
//! assert!(watch.events.is_empty());
//! assert!(watch.checks > 0);
//! ```
//!
//! The `appell` crate's front page ("Contact watch") stops a rolling disc
//! that falls flat; `tests/rolling_disc.rs` has the disc with every
//! integrator, a warning watch and the cost, `tests/hybrid.rs` a disc
//! pulled off the ground (the watch's lift-off and the hybrid guard).

use crate::ProjectionFailed;
use appell_core::dynamic::DynModel;
use appell_core::{check_len, ContactEvent, ContactViolation, ModelError};
use appell_dynamics::constraint_forces::{contact_forces_parts, ConstraintForces, Normal};
use appell_dynamics::oracle::OracleError;

/// The relative tolerance [`ContactWatch::new`] starts with: a normal
/// force is negative when it is below −1e-9 × the largest contact force
/// at that instant (round-off of a force that is exactly zero stays
/// unflagged).
pub const DEFAULT_TOLERANCE: f64 = 1e-9;

/// A side (cosine) at or below this, relative to its sign at the start,
/// is on the wrong side of the contact plane: the threshold at which
/// [`contact_forces`](appell_dynamics::constraint_forces::contact_forces) calls the
/// normal unorientable.
const SIDE_TOLERANCE: f64 = 1e-9;

/// Watches a model's one-sided contacts along a motion (see the module
/// documentation): give `|t, x| watch.check(t, x)` as the projection of
/// any integrator's `solve_model_projected` (it leaves the state as it
/// is), or call [`ContactWatch::check_motion`] with every coordinate and
/// speed.
pub struct ContactWatch<'m, K: DynModel + ?Sized> {
    model: &'m K,
    stop: bool,
    tolerance: f64,
    inputs: Vec<f64>,
    /// Each contact's side at the start (+1 or −1; 0 before the first
    /// check).
    signs: Vec<f64>,
    /// Whether each contact's normal force is below the tolerance now
    /// (flagged once per passage).
    lifted: Vec<bool>,
    /// Whether the last check met a singular configuration.
    singular: bool,
    /// The contact whose mass centre was nearest its plane at the last
    /// check that had sides (a singular configuration is named after it).
    nearest: usize,
    stopped: Option<ContactEvent>,
    failure: Option<ModelError>,
    /// The contacts lost, in order (a stopping watch records the one it
    /// stopped at).
    pub events: Vec<ContactEvent>,
    /// Checks made.
    pub checks: usize,
}

impl<'m, K: DynModel + ?Sized> ContactWatch<'m, K> {
    /// A watch of `model`'s contacts that stops at the first contact lost,
    /// with [`DEFAULT_TOLERANCE`] and the inputs at zero.
    pub fn new(model: &'m K) -> Self {
        let nc = model.dyn_info().contacts.len();
        ContactWatch {
            model,
            stop: true,
            tolerance: DEFAULT_TOLERANCE,
            inputs: vec![0.0; model.dyn_info().inputs.len()],
            signs: vec![0.0; nc],
            lifted: vec![false; nc],
            singular: false,
            nearest: 0,
            stopped: None,
            failure: None,
            events: Vec::new(),
            checks: 0,
        }
    }

    /// Records each contact lost in [`ContactWatch::events`] and goes on,
    /// instead of stopping.
    pub fn warn(mut self) -> Self {
        self.stop = false;
        self
    }

    /// The relative tolerance of a negative normal force (see
    /// [`DEFAULT_TOLERANCE`]).
    pub fn tolerance(mut self, tolerance: f64) -> Self {
        self.tolerance = tolerance;
        self
    }

    /// The inputs at which to evaluate the forces (zeros by default).
    pub fn inputs(mut self, inputs: &[f64]) -> Self {
        self.inputs = inputs.to_vec();
        self
    }

    /// The contact lost that stopped the watch, if it did.
    pub fn stopped(&self) -> Option<ContactEvent> {
        self.stopped
    }

    /// Why the forces could not be evaluated at the last check, if they
    /// could not (for a reason other than a singular configuration).
    pub fn failure(&self) -> Option<ModelError> {
        self.failure
    }

    /// Checks the reduced state `state` (retained coordinates, then the
    /// privileged speeds) at `t`, the other coordinates (cyclic,
    /// ignorable) taken as 0: the equations, and with them the normal
    /// forces and sides, do not depend on them. For a projection hook: a
    /// stop is a [`ProjectionFailed`] (the event is in
    /// [`ContactWatch::stopped`]), and so is a failure to evaluate the
    /// forces ([`ContactWatch::failure`]).
    pub fn check(&mut self, t: f64, state: &[f64]) -> Result<(), ProjectionFailed> {
        let (q, u) = self.full(state);
        match self.check_motion(t, &q, u) {
            Ok(()) => Ok(()),
            Err(ModelError::ContactLost(_)) => Err(ProjectionFailed {
                reason: "a one-sided contact was lost (see the contact watch's events)",
            }),
            Err(_) => Err(ProjectionFailed {
                reason: "the contact watch could not evaluate the contact forces",
            }),
        }
    }

    /// Checks the motion at `t` with every coordinate `q` and the
    /// privileged speeds `u`. A stopping watch returns
    /// [`ModelError::ContactLost`] at the first contact lost; the forces'
    /// own errors other than a singular configuration are returned as they
    /// are (an [`OracleError`] that is not a model error as
    /// [`ModelError::Contact`]).
    pub fn check_motion(&mut self, t: f64, q: &[f64], u: &[f64]) -> Result<(), ModelError> {
        let info = self.model.dyn_info();
        check_len("q", q, info.coordinates.len())?;
        check_len("u", u, info.speeds.len())?;
        if info.contacts.is_empty() {
            self.checks += 1;
            return Ok(());
        }
        self.failure = None;
        let found = match contact_forces_parts(self.model, t, q, u, &self.inputs, true) {
            Ok((forces, parts)) => {
                self.singular = false;
                self.inspect(t, &forces, &parts.sides)
            }
            Err(e) if is_singular(&e) => self.singular_at(t),
            Err(e) => {
                let e = match e {
                    OracleError::Model(e) => e,
                    _ => ModelError::Contact {
                        what: "the contact forces could not be evaluated",
                    },
                };
                self.failure = Some(e);
                return Err(e);
            }
        };
        self.checks += 1;
        for event in &found {
            self.events.push(*event);
        }
        match found.first() {
            Some(event) if self.stop => {
                self.stopped = Some(*event);
                Err(ModelError::ContactLost(*event))
            }
            _ => Ok(()),
        }
    }

    /// How far the reduced state `state` at `t` is from losing a contact,
    /// as one continuous number for an integrator's event location: the
    /// least over the contacts of the side (relative to its sign at the
    /// first check, less the plane's tolerance) and of the normal force
    /// over the largest contact force (plus the tolerance). Positive while
    /// every contact holds; it comes down through zero where the first is
    /// lost, and [`ContactWatch::lost_at`] says which and how. A singular
    /// configuration is −1; forces that cannot be evaluated give NaN (the
    /// error is in [`ContactWatch::failure`]). Records nothing: call
    /// [`ContactWatch::check`] once first, on a state where every contact
    /// holds, so that the sides have their reference signs.
    pub fn margin(&mut self, t: f64, state: &[f64]) -> f64 {
        match self.nearest_loss(t, state) {
            Ok((margin, _)) => margin,
            Err(e) => {
                self.failure = Some(e);
                f64::NAN
            }
        }
    }

    /// The contact nearest to being lost at the reduced state `state` at
    /// `t` and how (the [`ContactWatch::margin`] there), as the event a
    /// stopping watch gives; recorded in [`ContactWatch::events`] and
    /// [`ContactWatch::stopped`]. For the state an integrator's event
    /// location stopped at.
    pub fn lost_at(&mut self, t: f64, state: &[f64]) -> Result<ContactEvent, ModelError> {
        let (_, event) = self.nearest_loss(t, state)?;
        self.events.push(event);
        self.stopped = Some(event);
        Ok(event)
    }

    /// [`ContactWatch::margin`] and the event of the contact it comes from.
    fn nearest_loss(&mut self, t: f64, state: &[f64]) -> Result<(f64, ContactEvent), ModelError> {
        let (q, u) = self.full(state);
        let info = self.model.dyn_info();
        let event = |c: usize, kind| {
            let ci = &info.contacts[c];
            ContactEvent {
                t,
                contact: c,
                body: info.bodies.get(ci.body).map_or("?", |b| b.name),
                point: ci.point,
                kind,
            }
        };
        let (forces, parts) = match contact_forces_parts(self.model, t, &q, u, &self.inputs, true) {
            Ok(found) => found,
            Err(e) if is_singular(&e) => {
                return Ok((-1.0, event(self.nearest, ContactViolation::Singular)))
            }
            Err(OracleError::Model(e)) => return Err(e),
            Err(_) => {
                return Err(ModelError::Contact {
                    what: "the contact forces could not be evaluated",
                })
            }
        };
        let scale = largest_force(&forces);
        let mut least = (f64::INFINITY, None);
        for (c, contact) in forces.contacts.iter().enumerate() {
            if let (Some(side), true) = (parts.sides[c], self.signs[c] != 0.0) {
                let relative = side * self.signs[c];
                let m = relative - SIDE_TOLERANCE;
                if m < least.0 {
                    least = (
                        m,
                        Some((c, ContactViolation::LeftRegion { side: relative })),
                    );
                }
            }
            if let (Normal::Available { force, .. }, true) = (contact.normal, scale > 0.0) {
                let m = force / scale + self.tolerance;
                if m < least.0 {
                    least = (m, Some((c, ContactViolation::LiftOff { normal: force })));
                }
            }
        }
        match least {
            (m, Some((c, kind))) => Ok((m, event(c, kind))),
            // Nothing to measure (no side, no normal force): never lost.
            _ => Ok((f64::MAX, event(0, ContactViolation::Singular))),
        }
    }

    /// Every coordinate and the speeds of a reduced state (see
    /// [`ContactWatch::check`]).
    fn full<'s>(&self, state: &'s [f64]) -> (Vec<f64>, &'s [f64]) {
        let info = self.model.dyn_info();
        let mut q = vec![0.0; info.coordinates.len()];
        for (k, name) in info.retained.iter().enumerate() {
            if let (Some(i), Some(&v)) = (info.coordinate_index(name), state.get(k)) {
                q[i] = v;
            }
        }
        (q, state.get(info.retained.len()..).unwrap_or(&[]))
    }

    /// The contacts lost at `t`, from the forces and each contact's side;
    /// updates the passage flags and the reference sides.
    fn inspect(
        &mut self,
        t: f64,
        forces: &ConstraintForces,
        sides: &[Option<f64>],
    ) -> Vec<ContactEvent> {
        let info = self.model.dyn_info();
        let scale = largest_force(forces);
        let mut found = Vec::new();
        let mut nearest = (f64::INFINITY, self.nearest);
        for (c, contact) in forces.contacts.iter().enumerate() {
            let ci = &info.contacts[c];
            let event = |kind| ContactEvent {
                t,
                contact: c,
                body: info.bodies.get(ci.body).map_or("?", |b| b.name),
                point: ci.point,
                kind,
            };
            if let Some(side) = sides.get(c).copied().flatten() {
                if self.signs[c] == 0.0 && side.abs() > SIDE_TOLERANCE {
                    self.signs[c] = side.signum();
                }
                let relative = side * self.signs[c];
                if relative.abs() < nearest.0 {
                    nearest = (relative.abs(), c);
                }
                if relative <= SIDE_TOLERANCE {
                    found.push(event(ContactViolation::LeftRegion { side: relative }));
                    // The new side is the reference from here on, so that a
                    // warning watch flags the next crossing, not every step.
                    if side != 0.0 {
                        self.signs[c] = side.signum();
                    }
                    self.lifted[c] = false;
                    continue;
                }
            }
            if let Normal::Available { force, .. } = contact.normal {
                let below = force < -self.tolerance * scale;
                if below && !self.lifted[c] {
                    found.push(event(ContactViolation::LiftOff { normal: force }));
                }
                self.lifted[c] = below;
            }
        }
        self.nearest = nearest.1;
        found
    }

    /// The event of a singular configuration at `t` (once per passage),
    /// named after the contact whose mass centre was nearest its plane.
    fn singular_at(&mut self, t: f64) -> Vec<ContactEvent> {
        if self.singular {
            return Vec::new();
        }
        self.singular = true;
        let info = self.model.dyn_info();
        let c = self.nearest;
        let Some(ci) = info.contacts.get(c) else {
            return Vec::new();
        };
        vec![ContactEvent {
            t,
            contact: c,
            body: info.bodies.get(ci.body).map_or("?", |b| b.name),
            point: ci.point,
            kind: ContactViolation::Singular,
        }]
    }
}

/// The largest magnitude of a contact's whole force: the scale of the
/// normal forces' tolerance.
fn largest_force(forces: &ConstraintForces) -> f64 {
    forces
        .contacts
        .iter()
        .map(|c| c.force.iter().map(|x| x * x).sum::<f64>().sqrt())
        .fold(0.0, f64::max)
}

/// Whether the forces failed because the configuration is singular.
fn is_singular(e: &OracleError) -> bool {
    matches!(
        e,
        OracleError::SingularKkt { .. }
            | OracleError::SingularConstraints { .. }
            | OracleError::Model(
                ModelError::SingularMassMatrix { .. } | ModelError::SingularConstraints { .. }
            )
    )
}
