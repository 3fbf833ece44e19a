//! # appell-hybrid
//!
//! A simulation that moves between scenes when an event says the physics
//! changed: a foot lands or lifts off, a wheel starts or stops slipping.
//!
//! Each [`Phase`] is a scene (any [`DynModel`] of the same coordinates)
//! with its inputs and its [`Guard`]s: functions of the motion that stay
//! positive while the phase holds. [`Hybrid::run`] integrates the current
//! phase with DOP853 ([`Hybrid::solver`]) or, for stiff phases, Radau5
//! ([`Hybrid::stiff_solver`]) on every coordinate and the phase's speeds (so
//! coordinates a scene leaves out of its reduced state are kept), stops
//! where a guard crosses zero (the integrator's event location), maps the
//! motion into the guard's target phase with [`switch_state`] (nothing
//! jumps where a constraint is released; the impulse Appell's equations in
//! impulsive form give where one is imposed) and goes on, logging each
//! switch: time, phases, reason, impulses, kinetic energy lost. A guard
//! may make its switch an impact with a coefficient of restitution
//! ([`Guard::impact`]): a ball that bounces and stays in flight.
//!
//! A phase entered with a guard already below zero (by more than
//! [`Hybrid::guard_tolerance`]) is left at once, through that guard: a
//! disc whose slip dies where rolling would need more friction than there
//! is slides the other way. A guard marked [`Guard::after_rising`] is the
//! exception: it waits until it has been positive (and never fires if it
//! never rises). A phase's [`Phase::state_inputs`] set inputs from the
//! motion at every evaluation (a sliding contact's normal force,
//! [`crate::sliding`]). Positions are put back on the target's
//! holonomic constraints at each switch.
//!
//! Limits, by design: a guard fires where it comes down through zero, so a
//! guard that starts a phase at zero or within the tolerance below it (a
//! foot on the ground it just left) is armed only once it has been
//! positive, and two guards crossing within the event
//! tolerance of each other fire as one, the one with the smaller value at
//! the event. A motion that switches faster and faster (Zeno: a ball
//! bouncing to rest) ends with [`HybridError::TooManySwitches`] after
//! [`Hybrid::max_switches`], with the run so far in the error.
//!
//! Every constraint is a two-sided equality in the equations; a contact's
//! one-sidedness is a guard: [`Guard::lift_off`] leaves a scene where a
//! `rolls` contact's normal force comes down through zero.
//!
//! `tests/hybrid.rs` runs a hopping leg (flight and stance, the lift-off
//! where the ground's normal force vanishes) against closed forms.

#![warn(missing_docs)]

use std::cell::RefCell;

use appell_core::dynamic::DynModel;
use appell_core::ModelError;
use appell_dynamics::constraint_forces::{contact_forces_dyn, Normal};
use appell_dynamics::oracle::OracleError;
use appell_dynamics::switch::{impact_state, switch_state, SwitchError};
use appell_integrate::{Dop853, IntegrateError, Radau5};
use phase_ode::PhaseOde;

mod phase_ode;
pub mod sliding;

/// A guard's value at `(t, q, u)`: every coordinate, the phase's speeds.
pub type GuardFn<'a> = Box<dyn Fn(f64, &[f64], &[f64]) -> Result<f64, ModelError> + 'a>;

/// A condition for leaving a phase: while `value` is positive the phase
/// holds; where it crosses zero the run switches to phase `to`.
pub struct Guard<'a> {
    /// Why the switch happens (`"lift-off"`), for the log.
    pub reason: &'static str,
    /// The index of the phase to switch to.
    pub to: usize,
    /// The guard function.
    pub value: GuardFn<'a>,
    /// An impact first, against the constraints of a scene, with a
    /// coefficient of restitution (see [`Guard::impact`]).
    pub impact: Option<(&'a dyn DynModel, f64)>,
    /// Whether the guard ends a phase entered with it below zero (see
    /// [`Guard::after_rising`]).
    pub on_entry: bool,
}

impl<'a> Guard<'a> {
    /// A guard named `reason` that switches to phase `to` where `value`
    /// crosses zero.
    pub fn new(
        reason: &'static str,
        to: usize,
        value: impl Fn(f64, &[f64], &[f64]) -> Result<f64, ModelError> + 'a,
    ) -> Self {
        Guard {
            reason,
            to,
            value: Box::new(value),
            impact: None,
            on_entry: true,
        }
    }

    /// A lift-off guard: switches to phase `to` where the normal force at
    /// contact `contact` of `model` (its index in
    /// [`ModelInfo::contacts`](appell_core::ModelInfo), of the phase's scene) comes
    /// down through zero, from [`contact_forces`](appell_dynamics::constraint_forces::contact_forces)
    /// at `inputs`. Every `rolls` contact is a two-sided equality in the
    /// equations, so this is how a hybrid run takes the ground's
    /// one-sidedness: the scene that holds the contact until the ground
    /// would have to pull, then one without it. Its reason is `"lift-off"`.
    ///
    /// The value's errors: a contact index out of range or a normal force
    /// the forces do not give ([`ModelError::Contact`]), and the forces'
    /// own errors.
    ///
    /// ```
    /// # use appell_core::ModelError;
    /// # use appell_core::__doc_model::Oscillator;
    /// use appell_hybrid::Guard;
    ///
    /// // A model without contacts: the guard names none, and says so.
    /// let free = Oscillator { w: 0.0 }; // x'' = 0: a free particle
    /// let guard = Guard::lift_off(1, &free, 0, &[]);
    /// assert_eq!(guard.reason, "lift-off");
    /// assert!(matches!((guard.value)(0.0, &[0.0], &[0.0]), Err(ModelError::Contact { .. })));
    /// ```
    ///
    /// `tests/hybrid.rs` lifts a disc off the ground with it.
    pub fn lift_off(to: usize, model: &'a dyn DynModel, contact: usize, inputs: &[f64]) -> Self {
        let inputs = inputs.to_vec();
        Guard::new("lift-off", to, move |t, q: &[f64], u: &[f64]| {
            normal_force(model, contact, t, q, u, &inputs)
        })
    }

    /// A lift-off guard for a `contact(link, ...)` the phase's scene holds
    /// on level ground: switches to phase `to` where the ground's push on
    /// the link along N.z (the multiplier of the contact's
    /// [`RowSource::Contact`](appell_core::RowSource::Contact) row of axis 2, from
    /// [`contact_forces`](appell_dynamics::constraint_forces::contact_forces) at
    /// `inputs`) comes down through zero: a foot that would have to be
    /// pulled leaves the ground. `contact` indexes
    /// [`Model::contact_links`](appell_core::Model::contact_links). Its reason
    /// is `"lift-off"`; a scene that does not hold the contact is
    /// [`ModelError::Contact`].
    pub fn contact_lift_off(
        to: usize,
        model: &'a dyn DynModel,
        contact: usize,
        inputs: &[f64],
    ) -> Self {
        let inputs = inputs.to_vec();
        let row = model
            .dyn_info()
            .row_sources
            .iter()
            .position(|r| *r == appell_core::RowSource::Contact { contact, axis: 2 });
        Guard::new("lift-off", to, move |t, q: &[f64], u: &[f64]| {
            let row = row.ok_or(ModelError::Contact {
                what: "the lift-off guard names a contact its scene does not hold",
            })?;
            let forces =
                contact_forces_dyn(model, t, q, u, &inputs).map_err(|_| ModelError::NonFinite {
                    what: "the contact forces",
                })?;
            Ok(forces.multipliers[row])
        })
    }

    /// A touchdown guard for a `contact(link, ...)` on level ground at
    /// height zero: switches to phase `to` where the link's origin (from
    /// [`Model::contact_points`](appell_core::Model::contact_points) of `model`)
    /// comes down through N.z = 0. Give it [`Guard::impact`] with the scene
    /// that holds the contact, so the foot lands with the impulse that
    /// stops it. Its reason is `"touchdown"`; an index past
    /// [`Model::contact_links`](appell_core::Model::contact_links) is
    /// [`ModelError::Contact`].
    pub fn touchdown(to: usize, model: &'a dyn DynModel, contact: usize) -> Self {
        // The contacts' points, allocated once: the guard runs every step.
        let count = model.dyn_contact_links().len();
        let points = core::cell::RefCell::new(vec![[0.0; 3]; count]);
        Guard::new("touchdown", to, move |t, q: &[f64], _u: &[f64]| {
            if contact >= count {
                return Err(ModelError::Contact {
                    what: "the touchdown guard names a contact the model does not declare",
                });
            }
            let mut points = points.borrow_mut();
            model.dyn_contact_points(t, q, &mut points)?;
            Ok(points[contact][2])
        })
    }

    /// A guard that never ends the phase it starts: below zero on entry,
    /// it waits until it has been positive and fires where it comes down
    /// again. For guards below zero on entry by design: a slip speed less
    /// a threshold, at the start of a slide whose slip starts at zero.
    pub fn after_rising(mut self) -> Self {
        self.on_entry = false;
        self
    }

    /// Makes the switch an impact against `contact`'s constraints with
    /// Newton's coefficient of `restitution` (see
    /// [`impact_state`]) before the motion is
    /// mapped into phase `to`: a ball that bounces stays in flight (`to`
    /// its own phase) with its normal velocity reversed and scaled by e.
    /// `contact` is evaluated without inputs.
    pub fn impact(mut self, contact: &'a dyn DynModel, restitution: f64) -> Self {
        self.impact = Some((contact, restitution));
        self
    }
}

/// The normal force at contact `contact` of `model` (the value of
/// [`Guard::lift_off`]).
fn normal_force(
    model: &dyn DynModel,
    contact: usize,
    t: f64,
    q: &[f64],
    u: &[f64],
    inputs: &[f64],
) -> Result<f64, ModelError> {
    if contact >= model.dyn_info().contacts.len() {
        return Err(ModelError::Contact {
            what: "the lift-off guard names a contact its scene does not have",
        });
    }
    let forces = contact_forces_dyn(model, t, q, u, inputs).map_err(|e| match e {
        OracleError::Model(e) => e,
        _ => ModelError::Contact {
            what: "the contact forces could not be evaluated",
        },
    })?;
    match forces.contacts[contact].normal {
        Normal::Available { force, .. } => Ok(force),
        Normal::Unavailable(_) => Err(ModelError::Contact {
            what: "the lift-off guard's contact has no normal force here (see constraint_forces::Normal)",
        }),
    }
}

/// Inputs computed from the motion: called with `(t, q, u, inputs)`, the
/// inputs starting from the phase's own.
pub type StateInputs<'a> =
    Box<dyn Fn(f64, &[f64], &[f64], &mut [f64]) -> Result<(), ModelError> + 'a>;

/// One scene of a hybrid run.
pub struct Phase<'a> {
    /// Its name, for the log.
    pub name: &'static str,
    /// The scene (the same coordinates as every other phase).
    pub model: &'a dyn DynModel,
    /// Its inputs, held constant unless `state_inputs` sets them.
    pub inputs: Vec<f64>,
    /// The ways out of it.
    pub guards: Vec<Guard<'a>>,
    /// Inputs that follow the motion, set at every evaluation of the
    /// phase's equations and at its switches: a sliding contact's normal
    /// force ([`crate::sliding::normal_inputs`]), a feedback law. Radau5's
    /// Jacobian holds them at their values for the state it is taken at.
    pub state_inputs: Option<StateInputs<'a>>,
}

impl<'a> Phase<'a> {
    /// A phase named `name` of scene `model`, without inputs or guards.
    pub fn new(name: &'static str, model: &'a dyn DynModel) -> Self {
        Phase {
            name,
            model,
            inputs: vec![0.0; model.dyn_info().inputs.len()],
            guards: Vec::new(),
            state_inputs: None,
        }
    }

    /// Its inputs (held constant unless [`Phase::state_inputs`] sets them).
    pub fn inputs(mut self, inputs: Vec<f64>) -> Self {
        self.inputs = inputs;
        self
    }

    /// One more way out.
    pub fn guard(mut self, guard: Guard<'a>) -> Self {
        self.guards.push(guard);
        self
    }

    /// Inputs that follow the motion (see the field).
    pub fn state_inputs(mut self, f: StateInputs<'a>) -> Self {
        self.state_inputs = Some(f);
        self
    }

    /// The inputs at `(t, q, u)`.
    fn inputs_at(&self, t: f64, q: &[f64], u: &[f64]) -> Result<Vec<f64>, ModelError> {
        let mut inputs = self.inputs.clone();
        if let Some(f) = &self.state_inputs {
            f(t, q, u, &mut inputs)?;
        }
        Ok(inputs)
    }
}

/// One switch of a hybrid run.
#[derive(Clone, Debug, PartialEq)]
pub struct SwitchRecord {
    /// When.
    pub t: f64,
    /// The phase left (index).
    pub from: usize,
    /// The phase entered (index).
    pub to: usize,
    /// The guard's reason.
    pub reason: &'static str,
    /// The impulses: for a guard with an impact, the impact scene's rows'
    /// first, then those of each of the target's constraint rows (its
    /// [`ModelInfo::row_sources`](appell_core::ModelInfo) order; none where
    /// nothing was imposed).
    pub impulses: Vec<f64>,
    /// Kinetic energy lost at the switch.
    pub energy_lost: f64,
}

/// The motion at one instant of a hybrid run.
#[derive(Clone, Debug, PartialEq)]
pub struct Sample {
    /// Time.
    pub t: f64,
    /// The phase (index).
    pub phase: usize,
    /// Every coordinate.
    pub q: Vec<f64>,
    /// The phase's privileged speeds.
    pub u: Vec<f64>,
}

/// What [`Hybrid::run`] returns.
#[derive(Clone, Debug, PartialEq)]
pub struct HybridRun {
    /// The motion at the end.
    pub end: Sample,
    /// The switches, in order.
    pub switches: Vec<SwitchRecord>,
    /// The motion at every sampling time ([`Hybrid::sample_every`]), at
    /// each switch (before and after) and at the end.
    pub samples: Vec<Sample>,
}

impl HybridRun {
    /// The samples as animation frames (`appell::animate::svg`), one per
    /// instant: a switch's second sample (the same time, after the map)
    /// is left out.
    pub fn frames(&self) -> Vec<appell_dynamics::motion::Frame> {
        let mut frames: Vec<appell_dynamics::motion::Frame> =
            Vec::with_capacity(self.samples.len());
        for s in &self.samples {
            if frames.last().is_none_or(|f| s.t > f.t) {
                frames.push(appell_dynamics::motion::Frame {
                    t: s.t,
                    q: s.q.clone(),
                });
            }
        }
        frames
    }
}

/// Why a hybrid run stopped early.
#[derive(Debug)]
pub enum HybridError {
    /// The integrator failed in a phase.
    Integrate(IntegrateError),
    /// A guard function failed.
    Guard(ModelError),
    /// A state map failed.
    Switch(SwitchError),
    /// More than [`Hybrid::max_switches`] switches (Zeno behaviour); the
    /// run up to there.
    TooManySwitches(Box<HybridRun>),
    /// A phase index out of range, phases of different coordinates, or a
    /// phase whose state does not fit `S`.
    BadPhase(String),
}

impl core::fmt::Display for HybridError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            HybridError::Integrate(e) => write!(f, "{e}"),
            HybridError::Guard(e) => write!(f, "a guard failed: {e}"),
            HybridError::Switch(e) => write!(f, "{e}"),
            HybridError::TooManySwitches(run) => write!(
                f,
                "more than {} switches by t = {} (Zeno behaviour?)",
                run.switches.len(),
                run.end.t
            ),
            HybridError::BadPhase(why) => write!(f, "{why}"),
        }
    }
}

impl std::error::Error for HybridError {}

/// The integrator of a hybrid run's phases.
enum Integrator {
    Dop853(Dop853),
    Radau5(Radau5),
}

/// A hybrid simulation over `phases`.
pub struct Hybrid<'a> {
    phases: Vec<Phase<'a>>,
    integrator: Integrator,
    max_switches: usize,
    sample_every: Option<f64>,
    guard_tolerance: f64,
}

impl<'a> Hybrid<'a> {
    /// A run over `phases` with DOP853 at rtol 1e-10, atol 1e-12, at most
    /// 1000 switches and no sampling.
    pub fn new(phases: Vec<Phase<'a>>) -> Self {
        Hybrid {
            phases,
            integrator: Integrator::Dop853(Dop853::new().rtol(1e-10).atol(1e-12)),
            max_switches: 1000,
            sample_every: None,
            guard_tolerance: 1e-9,
        }
    }

    /// DOP853 as the integrator of every phase (its tolerances, step
    /// bounds and event tolerance).
    pub fn solver(mut self, solver: Dop853) -> Self {
        self.integrator = Integrator::Dop853(solver);
        self
    }

    /// Radau5 as the integrator of every phase, for stiff ones (a stiff
    /// spring, a regularised friction law). The Jacobian of each phase's
    /// equations takes u̇'s rows from the phase model's generated
    /// [`Model::rhs_jacobian`](appell_core::Model::rhs_jacobian) where it has one
    /// (unless [`Radau5::jacobian_by_duals`]), and the rest by dual
    /// numbers, one pass per coordinate and speed (q̇'s rows only, where
    /// u̇'s are generated).
    pub fn stiff_solver(mut self, solver: Radau5) -> Self {
        self.integrator = Integrator::Radau5(solver);
        self
    }

    /// The most switches before [`HybridError::TooManySwitches`].
    pub fn max_switches(mut self, n: usize) -> Self {
        self.max_switches = n;
        self
    }

    /// How far below zero a guard may start a phase and still wait to be
    /// armed (a value a round-off or an event tolerance from zero) instead
    /// of switching at once; in the guards' own units, 1e-9 by default.
    pub fn guard_tolerance(mut self, tolerance: f64) -> Self {
        self.guard_tolerance = tolerance;
        self
    }

    /// Records the motion every `dt` besides the switches.
    pub fn sample_every(mut self, dt: f64) -> Self {
        self.sample_every = Some(dt);
        self
    }

    /// Runs from phase `phase` at `t0` with coordinates `q0` (every one)
    /// and that phase's speeds `u0` to `t_end`. `S` bounds every phase's
    /// n + l (the integrated state is padded to it).
    pub fn run<const S: usize>(
        &self,
        phase: usize,
        t0: f64,
        q0: &[f64],
        u0: &[f64],
        t_end: f64,
    ) -> Result<HybridRun, HybridError> {
        self.check::<S>(phase, q0, u0)?;
        let mut now = Sample {
            t: t0,
            phase,
            q: q0.to_vec(),
            u: u0.to_vec(),
        };
        let mut run = HybridRun {
            end: now.clone(),
            switches: Vec::new(),
            samples: vec![now.clone()],
        };
        // Whether the phase was just entered, and which of its guards are
        // armed (kept across sampling stops, reset at a switch).
        let (mut entered, mut armed) = (true, vec![false; self.phases[phase].guards.len()]);
        let mut k = 0usize;
        while now.t < t_end {
            // A phase entered with a guard already below zero is left at
            // once (the slip dies where rolling would need more friction
            // than there is: the disc slides the other way).
            let leave = if entered { self.violated(&now)? } else { None };
            entered = false;
            let fired = match leave {
                Some(guard) => Some(guard),
                None => {
                    let stop = match self.sample_every {
                        Some(dt) => {
                            while t0 + (k as f64) * dt <= now.t {
                                k += 1;
                            }
                            (t0 + k as f64 * dt).min(t_end)
                        }
                        None => t_end,
                    };
                    let (after, fired) = self.advance::<S>(&now, stop, &mut armed)?;
                    now = after;
                    run.samples.push(now.clone());
                    fired
                }
            };
            if let Some(guard) = fired {
                if run.switches.len() == self.max_switches {
                    run.end = now;
                    return Err(HybridError::TooManySwitches(Box::new(run)));
                }
                let (next, record) = self.switch(&now, guard)?;
                run.switches.push(record);
                now = next;
                run.samples.push(now.clone());
                entered = true;
                armed = vec![false; self.phases[now.phase].guards.len()];
            }
        }
        run.end = now;
        Ok(run)
    }

    /// The phases' consistency and the start's lengths.
    fn check<const S: usize>(
        &self,
        phase: usize,
        q0: &[f64],
        u0: &[f64],
    ) -> Result<(), HybridError> {
        let bad = |why: String| Err(HybridError::BadPhase(why));
        let Some(first) = self.phases.get(phase) else {
            return bad(format!("no phase {phase}"));
        };
        let coords = first.model.dyn_info().coordinates;
        for p in &self.phases {
            let info = p.model.dyn_info();
            if info.coordinates != coords {
                return bad(format!("phase `{}` has other coordinates", p.name));
            }
            if coords.len() + info.speeds.len() > S {
                return bad(format!(
                    "phase `{}` needs a state of {}, more than S = {S}",
                    p.name,
                    coords.len() + info.speeds.len()
                ));
            }
            if info.state_len() != info.retained.len() + info.speeds.len() {
                return bad(format!(
                    "phase `{}` carries quadrature outputs in its state",
                    p.name
                ));
            }
            if p.inputs.len() != info.inputs.len() {
                return bad(format!(
                    "phase `{}` has {} inputs, its scene {}",
                    p.name,
                    p.inputs.len(),
                    info.inputs.len()
                ));
            }
            p.model
                .dyn_validate()
                .map_err(|e| HybridError::Integrate(IntegrateError::Model(e)))?;
            if let Some(g) = p.guards.iter().find(|g| g.to >= self.phases.len()) {
                return bad(format!(
                    "guard `{}` of phase `{}` leads to no phase",
                    g.reason, p.name
                ));
            }
        }
        if let Some(dt) = self.sample_every {
            if !(dt.is_finite() && dt > 0.0) {
                return bad(format!("`sample_every` must be a positive time, not {dt}"));
            }
        }
        let l = first.model.dyn_info().speeds.len();
        if q0.len() != coords.len() || u0.len() != l {
            return bad(format!(
                "the start needs {} coordinates and {l} speeds",
                coords.len()
            ));
        }
        Ok(())
    }

    /// Integrates `now`'s phase to `stop` or to its first guard crossing
    /// (returned with the guard's index).
    fn advance<const S: usize>(
        &self,
        now: &Sample,
        stop: f64,
        armed: &mut [bool],
    ) -> Result<(Sample, Option<usize>), HybridError> {
        let phase = &self.phases[now.phase];
        let ode = PhaseOde::new(phase);
        let (n, l) = (ode.n, ode.l);
        // A guard is armed once it is positive: one that starts the phase
        // at or below zero (the foot a hair below the ground it just left)
        // fires only after it has risen above zero and comes down again.
        let failure = RefCell::new(None);
        let armed = RefCell::new(armed);
        let g = |t: f64, x: &[f64]| -> f64 {
            let (q, u) = (&x[..n], &x[n..n + l]);
            let mut low = 1.0f64;
            for (guard, armed) in phase.guards.iter().zip(armed.borrow_mut().iter_mut()) {
                match (guard.value)(t, q, u) {
                    Ok(v) => {
                        *armed |= v > 0.0;
                        if *armed {
                            low = low.min(v);
                        }
                    }
                    Err(e) => {
                        failure.borrow_mut().get_or_insert(e);
                    }
                }
            }
            low
        };
        let mut x0 = vec![0.0; n + l];
        x0[..n].copy_from_slice(&now.q);
        x0[n..].copy_from_slice(&now.u);
        let (t, x, event) = match &self.integrator {
            Integrator::Dop853(solver) => {
                let f = |t: f64, x: &[f64; S], dx: &mut [f64; S]| -> Result<(), ModelError> {
                    dx.fill(0.0);
                    ode.rates(t, &x[..n + l], &mut dx[..n + l])
                };
                let mut padded = [0.0; S];
                padded[..n + l].copy_from_slice(&x0);
                let sol = solver.solve_until(f, |t, x: &[f64; S]| g(t, x), now.t, &padded, stop);
                let sol = first_failure(&failure, sol)?;
                (sol.t, sol.x[..n + l].to_vec(), sol.event)
            }
            Integrator::Radau5(solver) => {
                let f = |t: f64, x: &[f64], dx: &mut [f64]| ode.rates(t, x, dx);
                let by_duals = solver.wants_duals();
                let jac = |t: f64, x: &[f64], j: &mut [f64]| ode.jacobian(t, x, j, by_duals);
                let sol = solver.solve_until(f, jac, g, now.t, &x0, stop);
                let sol = first_failure(&failure, sol)?;
                (sol.t, sol.x, sol.event)
            }
        };
        if let Some(e) = failure.into_inner() {
            return Err(HybridError::Guard(e));
        }
        let after = Sample {
            t,
            phase: now.phase,
            q: x[..n].to_vec(),
            u: x[n..].to_vec(),
        };
        let fired = if event {
            let armed = armed.into_inner();
            let values: Vec<f64> = phase
                .guards
                .iter()
                .map(|guard| (guard.value)(after.t, &after.q, &after.u))
                .collect::<Result<_, _>>()
                .map_err(HybridError::Guard)?;
            values
                .iter()
                .enumerate()
                .filter(|(k, _)| armed[*k])
                .min_by(|a, b| a.1.total_cmp(b.1))
                .map(|(k, _)| k)
        } else {
            None
        };
        Ok((after, fired))
    }

    /// The guard of `now`'s phase furthest below `-guard_tolerance`, if
    /// any.
    fn violated(&self, now: &Sample) -> Result<Option<usize>, HybridError> {
        let phase = &self.phases[now.phase];
        let mut worst: Option<(usize, f64)> = None;
        for (k, guard) in phase.guards.iter().enumerate() {
            if !guard.on_entry {
                continue;
            }
            let v = (guard.value)(now.t, &now.q, &now.u).map_err(HybridError::Guard)?;
            if v < -self.guard_tolerance && worst.is_none_or(|(_, w)| v < w) {
                worst = Some((k, v));
            }
        }
        Ok(worst.map(|(k, _)| k))
    }

    /// The switch through guard `guard` of `now`'s phase.
    fn switch(&self, now: &Sample, guard: usize) -> Result<(Sample, SwitchRecord), HybridError> {
        let from = &self.phases[now.phase];
        let g = &from.guards[guard];
        let to = &self.phases[g.to];
        // The target's state inputs are not known before its speeds are;
        // the map reads its constant ones (they matter to driven
        // constraints only).
        let inputs_from = from
            .inputs_at(now.t, &now.q, &now.u)
            .map_err(|e| HybridError::Switch(SwitchError::Model(e)))?;
        let (q, u, mut impulses, mut lost) = match g.impact {
            Some((contact, e)) => {
                let hit = impact_state(
                    from.model,
                    contact,
                    now.t,
                    &now.q,
                    &now.u,
                    &inputs_from,
                    &[],
                    e,
                )
                .map_err(HybridError::Switch)?;
                let lost = hit.energy_lost();
                (hit.q, hit.speeds, hit.impulses, lost)
            }
            None => (now.q.clone(), now.u.clone(), Vec::new(), 0.0),
        };
        let out = switch_state(
            from.model,
            to.model,
            now.t,
            &q,
            &u,
            &inputs_from,
            &to.inputs,
        )
        .map_err(HybridError::Switch)?;
        lost += out.energy_lost();
        impulses.extend(out.impulses.iter());
        let record = SwitchRecord {
            t: now.t,
            from: now.phase,
            to: g.to,
            reason: g.reason,
            energy_lost: lost,
            impulses,
        };
        let next = Sample {
            t: now.t,
            phase: g.to,
            q: out.q,
            u: out.speeds,
        };
        Ok((next, record))
    }
}

/// The integrator's result, unless a guard failed first (the guard's error
/// is the cause of whatever the integrator did after it).
fn first_failure<T>(
    failure: &RefCell<Option<ModelError>>,
    result: Result<T, IntegrateError>,
) -> Result<T, HybridError> {
    if let Some(e) = failure.borrow_mut().take() {
        return Err(HybridError::Guard(e));
    }
    result.map_err(HybridError::Integrate)
}
