//! How close a configuration is to a singular dependent block D′ (the
//! columns of the constraint rows D that belong to the dependent rates,
//! eq. 25 solved for them, eqs. 30–31): the generated rhs returns
//! [`ModelError::SingularConstraints`] only where D′ is singular to
//! working precision, but near such a configuration (a four-bar at a dead
//! centre, Andrews' squeezer with a badly chosen privileged speed) the
//! dependent rates lose about log₁₀ κ(D′) digits, silently.
//! [`dependent_block_condition`] measures κ(D′); [`ConditionWatch`]
//! checks it after every accepted step of any integrator (through the
//! `solve_model_projected` hook, leaving the state unchanged) and records
//! a warning each time it passes a threshold, or stops the integration.
//!
//! ```
//! use appell_integrate::conditioning::ConditionWatch;
//! # use appell_core::__doc_model::Oscillator;
//! use appell_integrate::Dop853;
//!
//! // A model without constraints has nothing to warn about.
//! let model = Oscillator { w: 0.0 }; // x'' = 0: a free particle
//! let mut watch = ConditionWatch::new(&model, 1e8);
//! Dop853::new()
//!     .solve_model_projected(&model, &[], &mut |t, x: &mut [f64; 2]| watch.check(t, x), 0.0, &[0.0, 1.0], 1.0)
//!     .unwrap();
//! assert!(watch.warnings.is_empty());
//! assert_eq!(watch.worst.1, 1.0);
//! ```

use nalgebra::DMatrix;

use crate::ProjectionFailed;
use appell_core::dynamic::DynModel;
use appell_core::{check_len, ModelError};

/// The threshold [`ConditionWatch::new`] is usually given: κ(D′) = 1e8
/// leaves about 8 of f64's 16 digits in the dependent rates.
pub const DEFAULT_THRESHOLD: f64 = 1e8;

/// κ(D′) = σ_max / σ_min, the 2-norm condition number of the dependent
/// block of the constraint rows at `(t, q)` (every coordinate), by a
/// singular value decomposition: 1 for a model without constraints,
/// infinity where D′ is singular. The block is D's columns of the
/// coordinates [`ModelInfo::dependent`](appell_core::ModelInfo::dependent)
/// names, so a model whose speeds are quasi-velocities is measured in its
/// coordinates' rates.
///
/// Errors: a wrong length of `q`, a non-finite entry of D′, and any error
/// of [`Model::constraint_rows`](appell_core::Model::constraint_rows).
pub fn dependent_block_condition<K: DynModel + ?Sized>(
    model: &K,
    t: f64,
    q: &[f64],
) -> Result<f64, ModelError> {
    condition(model, t, q, &[])
}

/// [`dependent_block_condition`] at `inputs`, for a model whose
/// constraints read inputs (driven coordinates).
fn condition<K: DynModel + ?Sized>(
    model: &K,
    t: f64,
    q: &[f64],
    inputs: &[f64],
) -> Result<f64, ModelError> {
    let Some(block) = dependent_block(model, t, q, inputs)? else {
        return Ok(1.0);
    };
    let sigma = block.singular_values();
    let (max, min) = sigma.iter().fold((0.0f64, f64::INFINITY), |(hi, lo), &s| {
        (hi.max(s), lo.min(s))
    });
    Ok(if min > 0.0 { max / min } else { f64::INFINITY })
}

/// D′ at `(t, q)`, or `None` for a model without dependent rates.
fn dependent_block<K: DynModel + ?Sized>(
    model: &K,
    t: f64,
    q: &[f64],
    inputs: &[f64],
) -> Result<Option<DMatrix<f64>>, ModelError> {
    let info = model.dyn_info();
    let n = info.coordinates.len();
    check_len("q", q, n)?;
    let m = info.constraints;
    if m == 0 || info.dependent.is_empty() {
        return Ok(None);
    }
    let mut d = vec![0.0; m * n];
    let mut d0 = vec![0.0; m];
    model.dyn_driven_constraint_rows(t, q, inputs, &mut d, &mut d0)?;
    let columns: Vec<usize> = info
        .dependent
        .iter()
        .filter_map(|name| info.coordinate_index(name))
        .collect();
    let block = DMatrix::from_fn(m, columns.len(), |i, j| d[i * n + columns[j]]);
    if block.iter().any(|x| !x.is_finite()) {
        return Err(ModelError::NonFinite {
            what: "the dependent constraint block",
        });
    }
    Ok(Some(block))
}

/// Watches κ(D′) along an integration: give
/// `|t, x| watch.check(t, x)` as the projection of any integrator's
/// `solve_model_projected` (it leaves the state as it is). Each time κ
/// rises past the threshold a warning `(t, κ)` is recorded (once per
/// passage: it must fall below again before the next); with
/// [`ConditionWatch::stop_past_threshold`] the integration stops there
/// instead, with
/// [`IntegrateError::Projection`](crate::IntegrateError) saying
/// why. Only accepted steps are checked, and an adaptive integrator's
/// steps can jump across the narrow region around a dead centre where κ
/// is large (the four-bar's κ ≈ 3.6/|θ|: above 1e3 only within 3.6e-3 rad
/// of it) and on through it, with no error and no warning: bound the step
/// (`h_max`) by the time the motion takes to cross that region when the
/// warning matters. `tests/hard_cases` shows both.
pub struct ConditionWatch<'m, K: DynModel + ?Sized> {
    model: &'m K,
    threshold: f64,
    stop: bool,
    pivots: bool,
    inputs: Vec<f64>,
    above: bool,
    /// `(t, κ)` where κ passed the threshold, in order.
    pub warnings: Vec<(f64, f64)>,
    /// The largest κ seen and its time `(t, κ)` (`(NaN, 1)` before any
    /// check).
    pub worst: (f64, f64),
    /// Checks made (accepted steps).
    pub checks: usize,
}

impl<'m, K: DynModel + ?Sized> ConditionWatch<'m, K> {
    /// A watch that warns past `threshold` (see [`DEFAULT_THRESHOLD`]).
    pub fn new(model: &'m K, threshold: f64) -> Self {
        ConditionWatch {
            model,
            threshold,
            stop: false,
            pivots: false,
            inputs: Vec::new(),
            above: false,
            warnings: Vec::new(),
            worst: (f64::NAN, 1.0),
            checks: 0,
        }
    }

    /// Stops the integration where κ passes the threshold, instead of
    /// warning.
    pub fn stop_past_threshold(mut self) -> Self {
        self.stop = true;
        self
    }

    /// Measures with the cheap estimate 1 / [`Model::dependent_block_margin`]
    /// (the smallest LU pivot of D′ relative to its largest entry) instead
    /// of κ(D′) by a singular value decomposition: the generated D′ and one
    /// LU factorization per check, without allocation, instead of the
    /// constraint rows, a matrix copy and an SVD. On the mechanisms in
    /// `tests/hard_cases` the estimate is between a quarter and a half of
    /// κ(D′) (it is not κ, so a threshold may need adjusting).
    ///
    /// [`Model::dependent_block_margin`]: appell_core::Model::dependent_block_margin
    pub fn from_pivots(mut self) -> Self {
        self.pivots = true;
        self
    }

    /// The inputs at which to evaluate the constraint rows, for a model
    /// whose constraints read inputs (driven coordinates); none by default.
    pub fn inputs(mut self, inputs: &[f64]) -> Self {
        self.inputs = inputs.to_vec();
        self
    }

    /// Checks the reduced state `state` at `t`: the retained coordinates
    /// are its first entries, the other coordinates (cyclic, ignorable)
    /// are taken as 0, which D′ does not depend on.
    pub fn check(&mut self, t: f64, state: &[f64]) -> Result<(), ProjectionFailed> {
        let info = self.model.dyn_info();
        let mut q = vec![0.0; info.coordinates.len()];
        for (k, name) in info.retained.iter().enumerate() {
            if let (Some(i), Some(&v)) = (info.coordinate_index(name), state.get(k)) {
                q[i] = v;
            }
        }
        let failed = |_| ProjectionFailed {
            reason: "the dependent constraint block could not be evaluated",
        };
        let kappa = if self.pivots {
            let margin = self
                .model
                .dyn_dependent_block_margin(t, &q, &self.inputs)
                .map_err(failed)?;
            if margin > 0.0 {
                1.0 / margin
            } else {
                f64::INFINITY
            }
        } else {
            condition(self.model, t, &q, &self.inputs).map_err(failed)?
        };
        self.checks += 1;

        if kappa > self.worst.1 {
            self.worst = (t, kappa);
        }
        let above = kappa >= self.threshold;
        if above && !self.above {
            self.warnings.push((t, kappa));
            if self.stop {
                return Err(ProjectionFailed {
                    reason:
                        "the dependent constraint block's condition number passed the threshold",
                });
            }
        }
        self.above = above;
        Ok(())
    }
}
