//! What a [`TrBdf2`] integration returns: the end state and the work
//! counts.

// Items the documentation links to.
#[cfg(doc)]
use super::TrBdf2;

/// Work counts of a [`TrBdf2`] integration.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TrBdf2Stats {
    /// Evaluations of the right-hand side in `f64` (the initial one and one
    /// per Newton iteration; the Jacobian's evaluations are not included).
    pub rhs_calls: usize,
    /// Evaluations of the right-hand side in dual numbers for Jacobians
    /// ([`TrBdf2::solve_model`]: one per state component and Jacobian; 0
    /// with a user Jacobian or the model's generated one, see
    /// [`TrBdf2::jacobian_by_duals`]).
    pub jacobian_rhs_calls: usize,
    /// Accepted steps.
    pub accepted: usize,
    /// Rejected steps (error too large, or Newton failed).
    pub rejected: usize,
    /// Jacobian evaluations.
    pub jacobians: usize,
    /// LU factorizations of the iteration matrix `I − h d J`.
    pub lu_factorizations: usize,
    /// Newton iterations (over both implicit stages).
    pub newton_iterations: usize,
    /// Newton failures (divergence, slow convergence, a non-finite iterate or
    /// a singular iteration matrix); each rejects its step.
    pub newton_failures: usize,
}

/// The result of a [`TrBdf2`] integration.
#[derive(Clone, Debug, PartialEq)]
pub struct TrBdf2Solution {
    /// The final time (the end of the interval).
    pub t: f64,
    /// The state at [`TrBdf2Solution::t`].
    pub x: Vec<f64>,
    /// Work counts.
    pub stats: TrBdf2Stats,
    /// The size (magnitude) of the next step the error control proposed.
    pub h_next: f64,
    /// Whether the integration stopped at an event ([`TrBdf2::solve_until`]);
    /// [`TrBdf2Solution::t`] is then the event time, not the end of the
    /// interval.
    pub event: bool,
    /// How many output times were written ([`TrBdf2::solve_at`]).
    pub outputs: usize,
}
