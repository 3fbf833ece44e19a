//! [`OracleError`]: why the oracle could not produce accelerations.

use appell_core::ModelError;

// Items the documentation links to.
#[cfg(doc)]
use appell_core::ModelInfo;

/// Why the oracle could not produce accelerations.
#[derive(Clone, Debug, PartialEq)]
pub enum OracleError {
    /// A model method failed, an argument had the wrong length
    /// ([`ModelError::Length`]) or a value was not finite
    /// ([`ModelError::NonFinite`]).
    Model(ModelError),
    /// The model's [`ModelInfo`] is inconsistent (for example a privileged
    /// speed that is not a coordinate, or a constraint count that does not
    /// match the number of dependent coordinates).
    InvalidInfo(String),
    /// The KKT matrix `[M_full Dᵀ; D 0]` is singular at this configuration:
    /// the constraint rows are dependent or the mass matrix is singular on
    /// their null space.
    SingularKkt {
        /// Index of the smallest LU pivot (a coordinate index below n, then
        /// n + constraint row).
        index: usize,
        /// That pivot's magnitude.
        pivot: f64,
        /// The tolerance it fell below (relative to the matrix's scale).
        tolerance: f64,
    },
    /// The constraint rows restricted to the dependent coordinates are
    /// singular: the privileged rates do not determine the others.
    SingularConstraints {
        /// The dependent coordinate at the smallest LU pivot.
        coordinate: &'static str,
        /// That pivot's magnitude.
        pivot: f64,
        /// The tolerance it fell below (relative to the block's scale).
        tolerance: f64,
    },
}

impl From<ModelError> for OracleError {
    fn from(e: ModelError) -> Self {
        OracleError::Model(e)
    }
}

impl core::fmt::Display for OracleError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            OracleError::Model(e) => write!(f, "{e}"),
            OracleError::InvalidInfo(why) => write!(f, "inconsistent model description: {why}"),
            OracleError::SingularKkt {
                index,
                pivot,
                tolerance,
            } => write!(
                f,
                "singular configuration: the multiplier (KKT) system is singular (pivot {index} = {pivot:e}, tolerance {tolerance:e})"
            ),
            OracleError::SingularConstraints {
                coordinate,
                pivot,
                tolerance,
            } => write!(
                f,
                "singular configuration: the rate of `{coordinate}` is not determined by the privileged speeds (pivot {pivot:e}, tolerance {tolerance:e})"
            ),
        }
    }
}

impl std::error::Error for OracleError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            OracleError::Model(e) => Some(e),
            _ => None,
        }
    }
}
