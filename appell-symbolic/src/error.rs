//! The one error type of the engine.

use std::fmt;

/// Everything that can go wrong while building, transforming or evaluating
/// expressions. Every fallible operation of the engine returns this; none
/// panics on bad input.
///
/// ```
/// use appell_symbolic::{Graph, SymbolicError};
/// let mut g = Graph::new();
/// let x = g.parse("x").unwrap();
/// let zero = g.int(0).unwrap();
/// assert!(matches!(g.div(x, zero), Err(SymbolicError::DivisionByZero { .. })));
/// ```
#[derive(Clone, Debug, PartialEq)]
pub enum SymbolicError {
    /// The graph would exceed [`crate::Limits::max_nodes`].
    NodeLimit {
        /// The limit in force.
        limit: usize,
    },
    /// A sum or an expansion would exceed [`crate::Limits::max_terms`] terms.
    TermLimit {
        /// The limit in force.
        limit: usize,
    },
    /// Division by (or a negative power of) an expression that is identically zero.
    DivisionByZero {
        /// The numerator or base, as text.
        expr: String,
    },
    /// A NaN or infinite float constant.
    NonFiniteConstant,
    /// An integer exponent left the `i32` range.
    ExponentOverflow,
    /// An expression required to be linear in some symbols is not.
    NonLinear {
        /// The symbol in which it is not linear.
        symbol: String,
        /// The offending expression, as text.
        expr: String,
    },
    /// A name that is not a declared symbol.
    UnknownSymbol {
        /// The name.
        name: String,
    },
    /// A symbol was declared twice with different kinds.
    SymbolKindConflict {
        /// The name.
        name: String,
    },
    /// A total time derivative met a symbol without a rate rule.
    NoRateRule {
        /// The symbol's name.
        symbol: String,
    },
    /// Text that does not parse.
    Parse {
        /// Byte offset of the problem.
        position: usize,
        /// What was expected or found.
        message: String,
    },
    /// A linear system whose matrix is singular by structure (a column of zeros
    /// after elimination).
    StructurallySingular {
        /// The column (unknown) that has no pivot.
        column: usize,
    },
    /// No entry of a column can be proven non-zero, so a symbolic pivot would
    /// risk a division by zero; solve numerically instead.
    NoProvablyNonzeroPivot {
        /// The column (unknown) without a safe pivot.
        column: usize,
        /// The candidate entries, as text.
        candidates: Vec<String>,
    },
    /// Matrix or vector sizes that do not fit together.
    DimensionMismatch {
        /// What was expected.
        expected: String,
        /// What was given.
        found: String,
    },
    /// Evaluation met a symbol with no value.
    UnboundSymbol {
        /// The symbol's name.
        symbol: String,
    },
    /// Evaluation produced NaN or an infinity.
    NonFiniteValue {
        /// The sub-expression that did, as text (shortened).
        expr: String,
    },
}

fn shorten(s: &str) -> &str {
    match s.char_indices().nth(120) {
        Some((i, _)) => &s[..i],
        None => s,
    }
}

impl fmt::Display for SymbolicError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SymbolicError::NodeLimit { limit } => write!(
                f,
                "expression graph exceeded its node limit of {limit}; the model is too large or an expansion ran away"
            ),
            SymbolicError::TermLimit { limit } => {
                write!(f, "a sum exceeded the term limit of {limit}")
            }
            SymbolicError::DivisionByZero { expr } => {
                write!(f, "division by zero: `{}` divided by an expression that is identically zero", shorten(expr))
            }
            SymbolicError::NonFiniteConstant => {
                write!(f, "a constant is NaN or infinite")
            }
            SymbolicError::ExponentOverflow => write!(f, "an integer exponent overflowed i32"),
            SymbolicError::NonLinear { symbol, expr } => write!(
                f,
                "`{}` is not linear in `{symbol}`",
                shorten(expr)
            ),
            SymbolicError::UnknownSymbol { name } => write!(f, "unknown symbol `{name}`"),
            SymbolicError::SymbolKindConflict { name } => {
                write!(f, "symbol `{name}` is already declared with another kind")
            }
            SymbolicError::NoRateRule { symbol } => write!(
                f,
                "the time derivative needs the rate of `{symbol}`, and no rule gives it"
            ),
            SymbolicError::Parse { position, message } => {
                write!(f, "parse error at byte {position}: {message}")
            }
            SymbolicError::StructurallySingular { column } => write!(
                f,
                "the matrix is structurally singular: unknown {column} has only zero coefficients after elimination"
            ),
            SymbolicError::NoProvablyNonzeroPivot { column, candidates } => write!(
                f,
                "no pivot for unknown {column} can be proven non-zero (candidates: {}); solve numerically with pivoting",
                candidates.iter().map(|c| shorten(c)).collect::<Vec<_>>().join(", ")
            ),
            SymbolicError::DimensionMismatch { expected, found } => {
                write!(f, "dimension mismatch: expected {expected}, found {found}")
            }
            SymbolicError::UnboundSymbol { symbol } => {
                write!(f, "no value given for symbol `{symbol}`")
            }
            SymbolicError::NonFiniteValue { expr } => {
                write!(f, "`{}` evaluated to a non-finite value", shorten(expr))
            }
        }
    }
}

impl std::error::Error for SymbolicError {}

/// Result alias of the engine.
pub type Result<T, E = SymbolicError> = std::result::Result<T, E>;
