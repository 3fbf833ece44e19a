//! What a generated model says about itself: [`ModelInfo`] (names, state
//! layout, scenes, operation counts) and the descriptions it is made of.

#[cfg(doc)]
use crate::Model;

/// Operation counts of a generated function.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OpCounts {
    /// Additions and subtractions.
    pub add: usize,
    /// Multiplications.
    pub mul: usize,
    /// Divisions.
    pub div: usize,
    /// Function calls (sin, cos, sqrt, ...).
    pub calls: usize,
    /// Everything, including negations and the numeric solves.
    pub total: usize,
}

/// How a model's generated Jacobian ([`Model::rhs_jacobian`]) is computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct JacobianInfo {
    /// What is differentiated: `closed form: ...` (∂M and ∂f, and
    /// ∂ÿ = M⁻¹ (∂f − ∂M ÿ) with M factored once), `structured: ...`
    /// (the unrolled articulated-body algorithm differentiated), `inverse
    /// dynamics ...` (recursive Newton–Euler's derivatives, some with the
    /// columns solved "in loops over the columns"), with the operation
    /// counts of the candidates the derive compared, or `dual numbers: ...` (the
    /// rhs evaluated in dual numbers, so many directions a pass, and why
    /// not symbolically).
    pub form: &'static str,
    /// Operations per call, the values of the rhs included.
    pub ops: OpCounts,
}

/// A rigid body or particle of the model, for the independent solver.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BodyInfo {
    /// The name given in `body(...)` or the point of `particle(...)`.
    pub name: &'static str,
    /// False for a particle (no rotational inertia).
    pub rigid: bool,
}

/// Where a velocity constraint row (a row of D in D q̇ + d = 0) comes from.
///
/// Rows are ordered: the differentiated `holonomic(...)` constraints, then
/// the `nonholonomic(...)` ones and after them the rows of the
/// `contact(...)`s a scene holds, then the components of each `rolls(...)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RowSource {
    /// The time derivative of the `index`-th holonomic constraint.
    Holonomic {
        /// Index among the scalar holonomic constraints, in declaration
        /// order (an equation between points contributes one per
        /// component it keeps).
        index: usize,
    },
    /// A holonomic or nonholonomic constraint that reads an input (a
    /// driven coordinate): its multiplier is the generalized force the
    /// drive applies.
    Driven {
        /// Whether it is a holonomic constraint (differentiated).
        holonomic: bool,
        /// Index among the holonomic or the nonholonomic constraints.
        index: usize,
        /// The constraint as written, e.g. `nonholonomic: dt(psi1) == w_cmd`.
        constraint: &'static str,
    },
    /// The `index`-th nonholonomic constraint.
    Nonholonomic {
        /// Index among the scalar nonholonomic constraints, in declaration
        /// order (an equation between vectors contributes one per
        /// component it keeps).
        index: usize,
    },
    /// The velocity component e·v of the body's material point at a rolling
    /// contact along one direction e ([`Model::contact_geometry`] gives e).
    Rolling {
        /// Index into [`ModelInfo::contacts`].
        contact: usize,
        /// 0, 1, 2 for N.x, N.y, N.z (a contact without `along`), or the
        /// index into the contact's `along = [...]` list.
        direction: usize,
    },
    /// A row of a `contact(link, point | flat)` that a scene holds.
    Contact {
        /// Index into [`Model::contact_links`] (declaration order).
        contact: usize,
        /// 0, 1, 2: the link origin's velocity along N.x, N.y, N.z (its
        /// multiplier is the ground's force on the link along that axis);
        /// 3, 4, 5: the link's angular velocity about N.x, N.y, N.z (a
        /// `flat` contact; the multiplier is the ground's moment).
        axis: usize,
    },
}

/// A joint's limits as the URDF gives them (`<limit>`): Pinocchio's
/// `lowerPositionLimit`, `upperPositionLimit`, `velocityLimit` and
/// `effortLimit`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointLimit {
    /// The joint (its coordinate).
    pub joint: &'static str,
    /// The lowest position (−∞ for a continuous joint or none given).
    pub lower: f64,
    /// The highest position (+∞ for a continuous joint or none given).
    pub upper: f64,
    /// The largest speed (0 where the file gives none).
    pub velocity: f64,
    /// The largest torque or force (0 where the file gives none).
    pub effort: f64,
}

/// A `rolls(...)` contact of the model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ContactInfo {
    /// Index of the rolling body in [`ModelInfo::bodies`].
    pub body: usize,
    /// The name of the contact point.
    pub point: &'static str,
    /// True when the contact constrains only the `along = [...]`
    /// directions; false when it constrains the N components (rows that
    /// are identically zero dropped).
    pub along: bool,
}

/// Everything about a model that does not depend on numbers.
#[derive(Clone, Copy, Debug)]
pub struct ModelInfo {
    /// The struct's name.
    pub name: &'static str,
    /// Parameter names (the struct's fields), in declaration order.
    pub parameters: &'static [&'static str],
    /// Generalized coordinates q_r, in declaration order.
    pub coordinates: &'static [&'static str],
    /// The privileged speeds ẏ_k, in order: a coordinate's name when the
    /// speed is that coordinate's rate (Method II), else the name of a
    /// quasi-velocity (Method III, defined by
    /// [`Model::speed_definitions`]).
    pub speeds: &'static [&'static str],
    /// Coordinates whose rates are dependent (solved from the constraints).
    pub dependent: &'static [&'static str],
    /// Cyclic coordinates (Sec. III C): dependent coordinates that appear
    /// nowhere in the reduced equations.
    pub cyclic: &'static [&'static str],
    /// All coordinates left out of the integrated state (the cyclic ones and
    /// privileged ones that appear nowhere either).
    pub ignorable: &'static [&'static str],
    /// Coordinates kept in the reduced state, in order.
    pub retained: &'static [&'static str],
    /// Inputs supplied at every call.
    pub inputs: &'static [&'static str],
    /// Names of the load effects.
    pub effects: &'static [&'static str],
    /// Outputs the scene asked for in `outputs(...)` (`"quadrature"`,
    /// `"energies"`, `"contact_forces"`), in declaration order; empty for a
    /// full model. Tools (the command line's `eval --scene`) report these
    /// beside the state; the library functions compute them for any model.
    pub outputs: &'static [&'static str],
    /// Number of holonomic constraints (configuration level).
    pub holonomic: usize,
    /// Number of velocity constraint rows (holonomic ones differentiated
    /// plus nonholonomic ones): m.
    pub constraints: usize,
    /// The source of each velocity constraint row, one per row.
    pub row_sources: &'static [RowSource],
    /// The rolling contacts, in declaration order.
    pub contacts: &'static [ContactInfo],
    /// Bodies and particles, in declaration order.
    pub bodies: &'static [BodyInfo],
    /// Number of force application points.
    pub force_points: usize,
    /// Number of torques.
    pub torques: usize,
    /// How the rhs is computed, and why: `structured: ...` (the
    /// articulated-body algorithm unrolled over a tree of joints) or
    /// `closed form ...` (Appell's equations M ÿ = f solved by LDLᵀ), with
    /// the operation counts the derive compared or the reason a model has
    /// no structured form.
    pub form: &'static str,
    /// Whether the dependent speeds are solved symbolically (true) or by a
    /// pivoted numeric solve in the generated code (false).
    pub symbolic_elimination: bool,
    /// Operations per call of the generated reduced rhs.
    pub rhs_ops: OpCounts,
    /// The generated Jacobian of the reduced rhs
    /// ([`Model::rhs_jacobian`]): how it is computed and what it costs;
    /// `None` where the model has none (`jacobian(off)`, or written by
    /// hand: tools then run the rhs in dual numbers, one evaluation per
    /// column).
    pub jacobian: Option<JacobianInfo>,
    /// The derived reduced equations, as text.
    pub equations: &'static str,
}

/// The name of one entry of the reduced state ([`ModelInfo::state_names`]):
/// a retained coordinate, or a privileged speed. Displayed as the
/// coordinate's name, or the speed's with `_dot` (the rate the state
/// holds), the names the command line and the Python package print.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StateName {
    /// A retained coordinate q_r.
    Coordinate(&'static str),
    /// A privileged speed ẏ_k.
    Speed(&'static str),
}

impl core::fmt::Display for StateName {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            StateName::Coordinate(name) => f.write_str(name),
            StateName::Speed(name) => write!(f, "{name}_dot"),
        }
    }
}

impl ModelInfo {
    /// Length of the reduced state.
    pub fn state_len(&self) -> usize {
        self.retained.len() + self.speeds.len()
    }

    /// The reduced state's entries in order: the retained coordinates,
    /// then the speeds.
    ///
    /// ```
    /// use appell_core::__doc_model::Pendulum;
    /// use appell_core::{Model, StateName};
    /// let info = Pendulum::info();
    /// let names: Vec<String> = info.state_names().map(|n| n.to_string()).collect();
    /// assert_eq!(names, ["theta", "theta_dot"]);
    /// assert_eq!(info.state_names().nth(1), Some(StateName::Speed("theta")));
    /// ```
    pub fn state_names(&self) -> impl Iterator<Item = StateName> + '_ {
        let coordinates = self.retained.iter().map(|&r| StateName::Coordinate(r));
        coordinates.chain(self.speeds.iter().map(|&s| StateName::Speed(s)))
    }

    /// Whether the scene asked for an output (`outputs(...)`), by name.
    pub fn has_output(&self, name: &str) -> bool {
        self.outputs.contains(&name)
    }

    /// The index of a coordinate by name.
    pub fn coordinate_index(&self, name: &str) -> Option<usize> {
        self.coordinates.iter().position(|c| *c == name)
    }
}
