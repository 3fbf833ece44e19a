//! How a model call fails: [`ModelError`], and the contact events a
//! simulation reports through it.

#[cfg(doc)]
use crate::{Model, ModelInfo};

/// The rule a body's mass or inertia breaks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BodyRule {
    /// The mass is zero, negative or not a number.
    NonPositiveMass,
    /// An entry of the inertia is NaN or infinite.
    NonFiniteInertia,
    /// The inertia has a negative principal moment.
    NotSemidefinite,
    /// A principal moment exceeds the sum of the other two.
    Triangle,
}

impl BodyRule {
    /// What the rule says, as a sentence's predicate ("its mass is not
    /// positive").
    pub fn describe(self) -> &'static str {
        match self {
            BodyRule::NonPositiveMass => "its mass is not positive",
            BodyRule::NonFiniteInertia => "its inertia is not finite",
            BodyRule::NotSemidefinite => {
                "its inertia is not positive semidefinite (a principal moment is negative)"
            }
            BodyRule::Triangle => {
                "its inertia violates the triangle inequality: a principal moment exceeds the sum of the other two"
            }
        }
    }
}

/// How a one-sided contact was lost (see
/// `appell::contact_watch`): every `rolls(...)` contact is
/// a two-sided equality in the equations, so these are the states where
/// the equations hold but the world does not.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ContactViolation {
    /// The contact's normal force fell below the watch's tolerance: the
    /// ground would have to pull the body (it lifts off).
    LiftOff {
        /// The normal force (negative, in the model's force units).
        normal: f64,
    },
    /// The body's mass centre reached or crossed the contact's tangent
    /// plane (the rolling disc's lean at ±π/2): past it the model
    /// describes a body under the floor.
    LeftRegion {
        /// The cosine of the angle between the contact normal the
        /// declaration gives and the arm from the contact to the mass
        /// centre, signed so that it was positive where the watch started.
        side: f64,
    },
    /// The forces could not be computed because the configuration is
    /// singular (the mass matrix or the multiplier system), as the rolling
    /// disc's is at lean ±π/2.
    Singular,
}

/// A contact lost at time `t`: the contact (its index in
/// [`ModelInfo::contacts`], its body's and its point's names) and how.
///
/// ```
/// use appell_core::{ContactEvent, ContactViolation};
///
/// let event = ContactEvent {
///     t: 0.9,
///     contact: 0,
///     body: "rear_wheel",
///     point: "P",
///     kind: ContactViolation::LiftOff { normal: -69.5 },
/// };
/// assert_eq!(
///     event.to_string(),
///     "the contact of `rear_wheel` at `P` would have to pull (normal force -6.95e1) at t = 0.9: it lifts off"
/// );
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactEvent {
    /// When: where an integrator's event location put it, or the end of
    /// the accepted step or the frame where it was seen.
    pub t: f64,
    /// Index in [`ModelInfo::contacts`].
    pub contact: usize,
    /// The rolling body's name.
    pub body: &'static str,
    /// The contact point's name.
    pub point: &'static str,
    /// What happened.
    pub kind: ContactViolation,
}

impl core::fmt::Display for ContactEvent {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let (body, point, t) = (self.body, self.point, self.t);
        write!(f, "the contact of `{body}` at `{point}` ")?;
        match self.kind {
            ContactViolation::LiftOff { normal } => write!(
                f,
                "would have to pull (normal force {normal:e}) at t = {t}: it lifts off"
            ),
            ContactViolation::LeftRegion { side } => write!(
                f,
                "left the region where the model holds at t = {t}: the body's mass centre reached the contact plane (side {side:e})"
            ),
            ContactViolation::Singular => write!(
                f,
                "reached a singular configuration at t = {t}, where the model stops holding"
            ),
        }
    }
}

/// Why a generated function could not produce a result.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ModelError {
    /// A slice had the wrong length.
    Length {
        /// Which argument.
        argument: &'static str,
        /// The length required.
        expected: usize,
        /// The length given.
        found: usize,
    },
    /// The mass matrix of Appell's equations is not positive definite at
    /// this configuration (pivot `index` was `pivot`).
    SingularMassMatrix {
        /// The failing pivot's index.
        index: usize,
        /// Its value.
        pivot: f64,
    },
    /// The dependent-speed block D' of the constraints is singular here: the
    /// chosen privileged speeds do not determine the others.
    SingularConstraints {
        /// The column whose best pivot was negligible.
        column: usize,
        /// That pivot's magnitude.
        pivot: f64,
    },
    /// A parameter declared positive is not.
    NonPositiveParameter {
        /// Its name.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// A scene index past the model's scenes.
    UnknownScene {
        /// The index asked for.
        index: usize,
    },
    /// A privileged speed that is not a coordinate's rate, in a model that
    /// does not define it (see [`Model::speed_definitions`]).
    UnknownSpeed {
        /// The speed's name.
        name: &'static str,
    },
    /// An input, a state component or a result is NaN or infinite.
    NonFinite {
        /// Which quantity.
        what: &'static str,
    },
    /// A function `#[derive(Appell)]` generates, called on a model written
    /// by hand that does not provide it.
    NotGenerated {
        /// The function.
        function: &'static str,
    },
    /// A sliding contact's normal force could not be found: the momentum
    /// balances do not determine it, or its friction feeds back into it so
    /// strongly that no normal force is consistent (Painlevé's paradox).
    /// See `appell::sliding`.
    Contact {
        /// What went wrong.
        what: &'static str,
    },
    /// A body's mass or inertia, made of parameters, is one no body can
    /// have (see [`Model::validate`] and [`physical`](crate::physical)).
    ImpossibleBody {
        /// The body's name.
        body: &'static str,
        /// The rule it breaks.
        rule: BodyRule,
        /// The parameters its mass and inertia depend on.
        parameters: &'static [&'static str],
    },
    /// A divisor made of parameters (`1 / k`) is zero (see
    /// [`Model::validate`]).
    ZeroDivisor {
        /// Where the division is written (`point `P``, `body `rod``).
        place: &'static str,
        /// The parameters the divisor depends on.
        parameters: &'static [&'static str],
    },
    /// A function without an `inputs` argument, called on a model whose
    /// constraints read inputs (driven coordinates): its result depends on
    /// them, so use the `driven_` form that takes them.
    NeedsInputs {
        /// The function.
        function: &'static str,
    },
    /// A one-sided contact was lost along a simulation
    /// (`appell::animate::simulate` and the
    /// `appell::contact_watch`).
    ContactLost(ContactEvent),
}

impl core::fmt::Display for ModelError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            ModelError::Length {
                argument,
                expected,
                found,
            } => write!(f, "`{argument}` has length {found}, expected {expected}"),
            ModelError::SingularMassMatrix { index, pivot } => write!(
                f,
                "singular configuration: the mass matrix is not positive definite (pivot {index} = {pivot:e})"
            ),
            ModelError::SingularConstraints { column, pivot } => write!(
                f,
                "singular configuration: the dependent speeds are not determined by the privileged ones (pivot {column} = {pivot:e})"
            ),
            ModelError::NonPositiveParameter { name, value } => {
                write!(f, "parameter `{name}` is declared positive but is {value}")
            }
            ModelError::UnknownScene { index } => write!(f, "the model has no scene {index}"),
            ModelError::UnknownSpeed { name } => write!(
                f,
                "speed `{name}` is not a coordinate's rate, and the model does not define it"
            ),
            ModelError::NonFinite { what } => write!(f, "{what} is not finite"),
            ModelError::NotGenerated { function } => write!(
                f,
                "`{function}` is generated by `#[derive(Appell)]`; this model was written by hand and does not provide it"
            ),
            ModelError::Contact { what } => write!(f, "a sliding contact's normal force: {what}"),
            ModelError::ImpossibleBody {
                body,
                rule,
                parameters,
            } => {
                write!(f, "body `{body}` cannot be physical: {}", rule.describe())?;
                for (k, name) in parameters.iter().enumerate() {
                    let lead = if k == 0 { "; check parameter" } else { "," };
                    let plural = if k == 0 && parameters.len() > 1 { "s" } else { "" };
                    write!(f, "{lead}{plural} `{name}`")?;
                }
                Ok(())
            }
            ModelError::ZeroDivisor { place, parameters } => {
                write!(f, "division by zero in {place}")?;
                for (k, name) in parameters.iter().enumerate() {
                    let lead = if k == 0 { "; check parameter" } else { "," };
                    let plural = if k == 0 && parameters.len() > 1 { "s" } else { "" };
                    write!(f, "{lead}{plural} `{name}`")?;
                }
                Ok(())
            }
            ModelError::NeedsInputs { function } => write!(
                f,
                "the model's constraints read inputs (driven coordinates), so `{function}` needs them: call `driven_{function}`"
            ),
            ModelError::ContactLost(event) => write!(f, "{event}"),
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for ModelError {}

/// Checks a slice length.
#[doc(hidden)]
#[inline]
pub fn check_len<T>(argument: &'static str, s: &[T], expected: usize) -> Result<(), ModelError> {
    if s.len() == expected {
        Ok(())
    } else {
        Err(ModelError::Length {
            argument,
            expected,
            found: s.len(),
        })
    }
}
