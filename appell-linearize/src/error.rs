//! [`LinearizeError`]: why a linearization or a holonomic solve failed.

use appell_core::ModelError;

// Items the documentation links to.
#[cfg(doc)]
use super::{check_holonomic, eigenvalues, minimal_linearization};
#[cfg(doc)]
use appell_core::ModelInfo;

/// Why a linearization, an eigenvalue computation or a constraint solve
/// failed.
#[derive(Clone, Debug, PartialEq)]
pub enum LinearizeError {
    /// A model method failed, an argument had the wrong length
    /// ([`ModelError::Length`]) or an argument was not finite
    /// ([`ModelError::NonFinite`]).
    Model(ModelError),
    /// The model's [`ModelInfo`] is inconsistent (a retained, privileged or
    /// dependent name that is not a coordinate).
    InvalidInfo(String),
    /// A name given by the caller (a fixed speed) is not one of the model's.
    UnknownName(String),
    /// An argument is out of its domain (a coordinate index out of range or
    /// repeated, a negative or non-finite tolerance).
    InvalidArgument(String),
    /// A matrix that must be square is not.
    NotSquare {
        /// Its rows.
        rows: usize,
        /// Its columns.
        cols: usize,
    },
    /// An entry of a matrix given to [`eigenvalues`], or an eigenvalue, is
    /// NaN or infinite. (Non-finite arguments, residuals and derivatives of a
    /// model are [`ModelError::NonFinite`] inside [`LinearizeError::Model`].)
    NonFinite {
        /// Which quantity.
        what: &'static str,
    },
    /// Newton's method did not bring the holonomic residuals below the
    /// tolerance.
    NotConverged {
        /// Newton steps taken.
        iterations: usize,
        /// Euclidean norm of the holonomic residuals at the last iterate.
        residual: f64,
    },
    /// A Jacobian does not have the rank the computation needs: the
    /// coordinates being solved for are not determined by the constraints
    /// here.
    RankDeficient {
        /// Its numerical rank (singular values above
        /// `1e-10 ×` the largest entry of the full holonomic Jacobian).
        rank: usize,
        /// The rank required.
        expected: usize,
    },
    /// The holonomic constraints restrict the independent coordinates of the
    /// minimal state at first order (their Jacobian, after eliminating the
    /// dependent coordinates, is not zero): the chosen coordinates are
    /// singular at this configuration.
    SingularCoordinates {
        /// The largest remaining constraint derivative.
        residual: f64,
    },
    /// The configuration given to [`minimal_linearization`] does not satisfy
    /// the holonomic constraints.
    NotOnManifold {
        /// Euclidean norm of the holonomic residuals.
        residual: f64,
        /// The tolerance it exceeded.
        tolerance: f64,
    },
    /// A state violates one holonomic constraint ([`check_holonomic`]).
    HolonomicViolated {
        /// The constraint, in declaration order.
        index: usize,
        /// Its residual f(q, t).
        residual: f64,
        /// The tolerance it exceeded.
        tolerance: f64,
    },
    /// An iterative matrix decomposition (Schur, SVD) did not converge.
    DecompositionFailed {
        /// Which decomposition.
        what: &'static str,
    },
}

impl From<ModelError> for LinearizeError {
    fn from(e: ModelError) -> Self {
        LinearizeError::Model(e)
    }
}

impl core::fmt::Display for LinearizeError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            LinearizeError::Model(e) => write!(f, "{e}"),
            LinearizeError::InvalidInfo(why) => {
                write!(f, "inconsistent model description: {why}")
            }
            LinearizeError::UnknownName(name) => write!(f, "unknown name `{name}`"),
            LinearizeError::InvalidArgument(why) => write!(f, "invalid argument: {why}"),
            LinearizeError::NotSquare { rows, cols } => {
                write!(f, "the matrix is {rows}×{cols}, not square")
            }
            LinearizeError::NonFinite { what } => write!(f, "{what} is not finite"),
            LinearizeError::NotConverged {
                iterations,
                residual,
            } => write!(
                f,
                "the holonomic constraints were not solved: residual {residual:e} after {iterations} Newton steps"
            ),
            LinearizeError::RankDeficient { rank, expected } => write!(
                f,
                "singular configuration: the constraint Jacobian has rank {rank}, {expected} needed"
            ),
            LinearizeError::SingularCoordinates { residual } => write!(
                f,
                "singular configuration: the holonomic constraints restrict the independent coordinates (derivative {residual:e})"
            ),
            LinearizeError::NotOnManifold {
                residual,
                tolerance,
            } => write!(
                f,
                "the configuration violates the holonomic constraints: residual {residual:e} above {tolerance:e}"
            ),
            LinearizeError::HolonomicViolated {
                index,
                residual,
                tolerance,
            } => write!(
                f,
                "holonomic constraint {index} is violated: residual {residual:e} above {tolerance:e}"
            ),
            LinearizeError::DecompositionFailed { what } => {
                write!(f, "the {what} decomposition did not converge")
            }
        }
    }
}

impl std::error::Error for LinearizeError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            LinearizeError::Model(e) => Some(e),
            _ => None,
        }
    }
}

/// A failed [`project_holonomic`](super::project_holonomic) as the
/// integrators' projection failure, so that a projection callback is
/// `|t, x| project_holonomic(&model, t, x, 1e-14, 20).map(|_| ()).map_err(Into::into)`.
///
/// ```
/// use appell_integrate::ProjectionFailed;
/// use appell_linearize::LinearizeError;
///
/// let e = LinearizeError::NotConverged { iterations: 20, residual: 1e-3 };
/// let failed = ProjectionFailed::from(e);
/// assert_eq!(failed.reason, "Newton's method did not bring the holonomic residuals below the tolerance");
/// ```
impl From<LinearizeError> for appell_integrate::ProjectionFailed {
    fn from(e: LinearizeError) -> Self {
        let reason = match e {
            LinearizeError::NotConverged { .. } => {
                "Newton's method did not bring the holonomic residuals below the tolerance"
            }
            LinearizeError::RankDeficient { .. } => {
                "the holonomic Jacobian is rank deficient at this configuration"
            }
            LinearizeError::Model(ModelError::SingularConstraints { .. }) => {
                "the dependent constraint block is singular at this configuration"
            }
            LinearizeError::Model(_) => "a model function failed during the projection",
            LinearizeError::NonFinite { .. } => "the projection met a non-finite value",
            _ => "the projection's arguments are invalid (state length, tolerance)",
        };
        appell_integrate::ProjectionFailed { reason }
    }
}
