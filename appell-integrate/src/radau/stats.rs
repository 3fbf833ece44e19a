//! What a [`Radau5`] integration returns: the end state and the work
//! counts.

// Items the documentation links to.
#[cfg(doc)]
use super::Radau5;

/// Work counts of a [`Radau5`] integration.
///
/// ```
/// use appell_integrate::Radau5;
/// use appell_core::ModelError;
///
/// let f = |_t: f64, x: &[f64], dx: &mut [f64]| -> Result<(), ModelError> {
///     dx[0] = -x[0] * x[0];
///     Ok(())
/// };
/// let jac = |_t: f64, x: &[f64], j: &mut [f64]| -> Result<(), ModelError> {
///     j[0] = -2.0 * x[0];
///     Ok(())
/// };
/// let s = Radau5::new().solve(f, jac, 0.0, &[1.0], 10.0).unwrap().stats;
/// // Three rhs calls per Newton iteration and the initial one (plus the
/// // refined error estimates).
/// assert!(s.rhs_calls >= 3 * s.newton_iterations + 1);
/// assert!(s.jacobians >= 1 && s.jacobians <= s.accepted + s.rejected);
/// assert!(s.lu_factorizations <= s.accepted + s.rejected + s.jacobians);
/// assert_eq!(s.jacobian_rhs_calls, 0); // a user Jacobian
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Radau5Stats {
    /// Evaluations of the right-hand side in `f64`: the initial one, three
    /// per Newton iteration, one per refined error estimate and one per
    /// projection that moved the state (the derivative at the end of a step
    /// otherwise comes from its collocation polynomial). The Jacobian's
    /// evaluations are not included.
    pub rhs_calls: usize,
    /// Evaluations of the right-hand side in dual numbers for Jacobians
    /// ([`Radau5::solve_model`]: one per state component and Jacobian; 0
    /// with a user Jacobian or the model's generated one, see
    /// [`Radau5::jacobian_by_duals`]).
    pub jacobian_rhs_calls: usize,
    /// Jacobian evaluations.
    pub jacobians: usize,
    /// LU factorizations of the iteration matrices: each is one real n×n
    /// (`γ/h − J`) and one complex n×n (`(α − iβ)/h − J`) factorization.
    pub lu_factorizations: usize,
    /// Accepted steps.
    pub accepted: usize,
    /// Rejected steps (error too large, Newton failed, or a singular
    /// iteration matrix).
    pub rejected: usize,
    /// Newton iterations (each solves the real and the complex system).
    pub newton_iterations: usize,
    /// Newton failures (divergence, too slow convergence, a non-finite
    /// iterate or a singular iteration matrix); each rejects its step.
    pub newton_failures: usize,
}

/// The result of a [`Radau5`] integration.
///
/// ```
/// use appell_integrate::Radau5;
/// use appell_core::ModelError;
///
/// let f = |_t: f64, x: &[f64], dx: &mut [f64]| -> Result<(), ModelError> {
///     dx[0] = -x[0];
///     Ok(())
/// };
/// let jac = |_t: f64, _x: &[f64], j: &mut [f64]| -> Result<(), ModelError> {
///     j[0] = -1.0;
///     Ok(())
/// };
/// let sol = Radau5::new().solve(f, jac, 0.0, &[1.0], 2.0).unwrap();
/// assert_eq!((sol.t, sol.event, sol.outputs), (2.0, false, 0));
/// assert!(sol.h_next > 0.0);
/// // Continuing from the end with the proposed step.
/// let more = Radau5::new().h0(Some(sol.h_next)).solve(f, jac, sol.t, &sol.x, 3.0).unwrap();
/// assert!((more.x[0] - (-3.0_f64).exp()).abs() < 1e-7);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Radau5Solution {
    /// The final time: the end of the interval, or the event time.
    pub t: f64,
    /// The state at [`Radau5Solution::t`].
    pub x: Vec<f64>,
    /// Work counts.
    pub stats: Radau5Stats,
    /// The size (magnitude) of the next step the error control proposed, a
    /// good initial step for continuing.
    pub h_next: f64,
    /// Whether the integration stopped at an event ([`Radau5::solve_until`]);
    /// [`Radau5Solution::t`] is then the event time.
    pub event: bool,
    /// How many output times were written ([`Radau5::solve_at`]).
    pub outputs: usize,
}
