//! Linearization of a model's reduced equations, exactly, by dual numbers
//! through the generic generated code: no symbolic Jacobian, no finite
//! differences.
//!
//! * [`linearize`]: A = ∂rhs/∂state and B = ∂rhs/∂inputs of [`Model::rhs`]
//!   at an operating point, one [`Dual64`] evaluation per column.
//! * [`eigenvalues`]: the complex eigenvalues of a real square matrix, sorted.
//! * [`solve_holonomic`]: Newton (Gauss-Newton when the counts differ) on the
//!   holonomic residuals of [`Model::constraint_residuals`], to put a
//!   configuration on the constraint manifold; [`holonomic_unknowns`] picks
//!   the dependent coordinates the residuals involve.
//! * [`minimal_linearization`]: the linearization in a minimal state, with
//!   the retained coordinates fixed by holonomic constraints eliminated and
//!   the privileged speeds an operating point holds fixed dropped.
//!
//! # Example
//!
//! A particle on a circle x² + y² = l² in Cartesian coordinates (privileged
//! speed ẋ, y dependent), pushed along N.x by an input force `f`, written by
//! hand here. Its reduced state is (x, y, ẋ), but y is fixed by x and the
//! constraint, so the minimal linearization at the bottom is the pendulum's
//! 2×2 system in (x, ẋ):
//!
//! ```
//! use appell_runtime::linearize::{
//!     eigenvalues, holonomic_unknowns, linearize, minimal_linearization, solve_holonomic,
//! };
//! # use appell_runtime::{check_len, BodyInfo, Model, ModelError, ModelInfo, OpCounts, Scalar};
//! # struct Ring { m: f64, l: f64, g: f64 }
//! # static INFO: ModelInfo = ModelInfo {
//! #     name: "Ring", parameters: &["m", "l", "g"], coordinates: &["x", "y"],
//! #     speeds: &["x"], dependent: &["y"], cyclic: &[], ignorable: &[],
//! #     retained: &["x", "y"], inputs: &["f"], effects: &["gravity", "push"], outputs: &[], row_sources: &[], contacts: &[], holonomic: 1,
//! #     constraints: 1, bodies: &[BodyInfo { name: "P", rigid: false }],
//! #     force_points: 1, torques: 0, symbolic_elimination: true,
//! #     rhs_ops: OpCounts { add: 5, mul: 9, div: 3, calls: 0, total: 18 },
//! #     equations: "x'' = f/m + x (g y - x f/m - x'^2 - y'^2) / (x^2 + y^2)",
//! # };
//! # fn unused() -> Result<(), ModelError> { Err(ModelError::NonFinite { what: "unused" }) }
//! # impl Model for Ring {
//! #     type Prepared<T: Scalar> = ();
//! #     fn info() -> &'static ModelInfo { &INFO }
//! #     fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> {
//! #         check_len("out", out, 3)?; out.copy_from_slice(&[self.m, self.l, self.g]); Ok(())
//! #     }
//! #     fn set_parameter(&mut self, _: &str, _: f64) -> bool { false }
//! #     fn prepare<T: Scalar>(&self) {}
//! #     fn rhs<T: Scalar>(&self, _: &(), _t: T, s: &[T], i: &[T], ds: &mut [T]) -> Result<(), ModelError> {
//! #         check_len("state", s, 3)?; check_len("inputs", i, 1)?; check_len("dstate", ds, 3)?;
//! #         let (x, y, u) = (s[0], s[1], s[2]);
//! #         if y.re() == 0.0 { return Err(ModelError::SingularConstraints { column: 0, pivot: 0.0 }); }
//! #         let ydot = -(x * u) / y;
//! #         let a = i[0] / T::from_f64(self.m);
//! #         let mu = (T::from_f64(self.g) * y - x * a - u * u - ydot * ydot) / (x * x + y * y);
//! #         ds[0] = u; ds[1] = ydot; ds[2] = a + x * mu; Ok(())
//! #     }
//! #     fn constraint_residuals<T: Scalar>(&self, _: T, q: &[T], qd: &[T], h: &mut [T], v: &mut [T]) -> Result<(), ModelError> {
//! #         check_len("q", q, 2)?; check_len("qdot", qd, 2)?;
//! #         check_len("holonomic", h, 1)?; check_len("velocity", v, 1)?;
//! #         h[0] = q[0] * q[0] + q[1] * q[1] - T::from_f64(self.l * self.l);
//! #         v[0] = q[0] * qd[0] + q[1] * qd[1]; Ok(())
//! #     }
//! #     fn mass_matrix_and_forcing<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
//! #     fn speed_transform<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
//! #     fn coordinate_rates<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { unused() }
//! #     fn kinetic_energy<T: Scalar>(&self, _: T, _: &[T], _: &[T]) -> Result<T, ModelError> { unused().map(|_| T::zero()) }
//! #     fn mass_properties(&self, _: &mut [f64], _: &mut [[f64; 9]]) -> Result<(), ModelError> { unused() }
//! #     fn body_poses<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
//! #     fn constraint_rows<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
//! #     fn load_geometry<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
//! #     fn load_values<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [[T; 3]], _: &mut [[T; 3]]) -> Result<(), ModelError> { unused() }
//! # }
//! let (m, l, g) = (0.5, 2.0, 9.81);
//! let model = Ring { m, l, g };
//!
//! // The reduced state (x, y, ẋ) at the bottom, at rest, with no push.
//! let lin = linearize(&model, 0.0, &[0.0, -l, 0.0], &[0.0]).unwrap();
//! assert_eq!(lin.state_names, ["x", "y", "x_dot"]);
//! assert_eq!(lin.input_names, ["f"]);
//! assert!((lin.a[(2, 0)] + g / l).abs() < 1e-14); // ∂ẍ/∂x = −g/l
//! assert!((lin.b[(2, 0)] - 1.0 / m).abs() < 1e-14); // ∂ẍ/∂f = 1/m
//!
//! // Put a configuration on the circle: y is the coordinate to adjust.
//! let mut q = [0.6, -1.7];
//! let unknowns = holonomic_unknowns(&model, 0.0, &q).unwrap();
//! assert_eq!(unknowns, [1]);
//! let iterations = solve_holonomic(&model, 0.0, &mut q, &unknowns, 1e-13, 20).unwrap();
//! assert!(iterations <= 6);
//! assert!((q[1] + (l * l - 0.6 * 0.6_f64).sqrt()).abs() < 1e-14);
//!
//! // The minimal system in (x, ẋ): y is eliminated through the constraint.
//! let min = minimal_linearization(&model, 0.0, &[0.0, -l], &[0.0], &[0.0], &[]).unwrap();
//! assert_eq!(min.state_names, ["x", "x_dot"]);
//! let w = (g / l).sqrt();
//! let eig = eigenvalues(&min.a).unwrap();
//! assert_eq!(eig.len(), 2);
//! assert!(eig[0].0.abs() < 1e-14 && (eig[0].1 + w).abs() < 1e-14);
//! assert!(eig[1].0.abs() < 1e-14 && (eig[1].1 - w).abs() < 1e-14);
//! assert!((min.b[(1, 0)] - 1.0 / m).abs() < 1e-14);
//!
//! // Bad input is an error, never a panic.
//! assert!(linearize(&model, 0.0, &[0.0, -l], &[0.0]).is_err());
//! assert!(linearize(&model, 0.0, &[f64::NAN, -l, 0.0], &[0.0]).is_err());
//! assert!(minimal_linearization(&model, 0.0, &[0.0, -l], &[0.0], &[0.0], &["z"]).is_err());
//! ```
//!
//! # Cost
//!
//! [`linearize`] evaluates [`Model::rhs`] once per state component and input
//! in [`Dual64`] (one instantiation of the generated code). The alternative,
//! num-dual's vector dual number `DualSVec64<W>` carrying W columns per pass,
//! was measured against it on derived models (release build, this project's
//! 2-core machine, shared with other builds: medians of 7 runs, about ±15%):
//!
//! | model | columns | rhs ops | Dual64 columns | one `DualSVec64` pass | chunks of 4 | chunks of 8 |
//! | --- | ---: | ---: | ---: | ---: | ---: | ---: |
//! | triple pendulum | 6 | 125 | 0.48 µs | 0.79× | 0.90× | 1.10× |
//! | triple pendulum on a cart (s = 7, one input) | 8 | 186 | 0.80 µs | 0.96× | 0.99× | 0.96× |
//! | quadruple pendulum | 8 | 286 | 1.1 µs | 1.11× | 1.07× | 1.11× |
//! | Whipple bicycle | 6 | 4,303 | 16 µs | 0.73× | 0.88× | 0.90× |
//!
//! The vector pass shares the real parts and the function calls, but every
//! operation carries W derivatives behind an `Option`. It gains about a
//! quarter on the large bicycle rhs, and only when W is the exact column
//! count (a compile-time constant: one more instantiation of the generated
//! rhs per width); on small models it is even or slower. The columns are
//! therefore Dual64. `tests/linearize.rs` repeats the comparison on
//! hand-written models (ignored test `dual64_vs_dualsvec64_timing`).

use crate::model::{check_len, Model, ModelError, ModelInfo};
use nalgebra::{DMatrix, DVector};
use num_dual::Dual64;

/// A linearization `ẋ ≈ f(x0, u0) + A (x − x0) + B (u − u0)` of a model's
/// reduced equations at an operating point `(x0, u0)`. Produced by
/// [`linearize`] and [`minimal_linearization`] (example in the module
/// documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct Linearization {
    /// ∂rhs/∂state, one row and one column per state component.
    pub a: DMatrix<f64>,
    /// ∂rhs/∂inputs, one row per state component, one column per input.
    pub b: DMatrix<f64>,
    /// The state components, in order: coordinate names, then the
    /// privileged speeds as `"{coordinate}_dot"`.
    pub state_names: Vec<String>,
    /// The inputs, in [`ModelInfo::inputs`] order.
    pub input_names: Vec<String>,
}

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

/// Singular values below this fraction of the largest entry of the full
/// holonomic Jacobian count as zero.
const RANK_RTOL: f64 = 1e-10;

/// What remains of the constraint derivatives on the independent coordinates
/// after the elimination must be below this fraction of the Jacobian's scale.
const CONSISTENCY_RTOL: f64 = 1e-8;

/// A configuration is on the manifold when its holonomic residuals are below
/// this fraction of the first-order scale `max(1, ‖J‖ ‖q‖)`.
const MANIFOLD_RTOL: f64 = 1e-8;

/// Halvings of a Newton step before giving up on decreasing the residual.
const MAX_BACKTRACKS: usize = 30;

fn finite(xs: &[f64], what: &'static str) -> Result<(), ModelError> {
    if xs.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(ModelError::NonFinite { what })
    }
}

/// The names of the reduced state: the retained coordinates, then the
/// privileged speeds suffixed `_dot`.
fn state_names(info: &ModelInfo) -> Vec<String> {
    info.retained
        .iter()
        .map(|r| r.to_string())
        .chain(info.speeds.iter().map(|s| format!("{s}_dot")))
        .collect()
}

/// A = ∂rhs/∂state and B = ∂rhs/∂inputs of the reduced equations
/// ([`Model::rhs`], after [`Model::prepare`]) at time `t`, reduced `state`
/// (the [retained](ModelInfo::retained) coordinates, then the privileged
/// speeds) and `inputs`.
///
/// Each column is one evaluation of the generated code in [`Dual64`], seeded
/// on that state component or input: the derivatives are exact to rounding.
/// The operating point need not be an equilibrium (A and B are the Jacobians
/// there; the affine term is `rhs(t, state, inputs)`). The state names are
/// the retained coordinates, then the speeds' coordinates suffixed `_dot`.
///
/// Errors: wrong lengths ([`ModelError::Length`]), a non-finite argument or
/// derivative ([`ModelError::NonFinite`]), and any error of
/// [`Model::rhs`] at this point (a singular configuration). Example in the
/// module documentation.
pub fn linearize<M: Model>(
    model: &M,
    t: f64,
    state: &[f64],
    inputs: &[f64],
) -> Result<Linearization, ModelError> {
    let info = M::info();
    let s = info.state_len();
    let ni = info.inputs.len();
    check_len("state", state, s)?;
    check_len("inputs", inputs, ni)?;
    finite(&[t], "t")?;
    finite(state, "state")?;
    finite(inputs, "inputs")?;

    let prepared = model.prepare::<Dual64>();
    let td = Dual64::from_re(t);
    let mut x: Vec<Dual64> = state.iter().map(|&v| Dual64::from_re(v)).collect();
    let mut w: Vec<Dual64> = inputs.iter().map(|&v| Dual64::from_re(v)).collect();
    let mut out = vec![Dual64::from_re(0.0); s];
    let mut a = DMatrix::<f64>::zeros(s, s);
    let mut b = DMatrix::<f64>::zeros(s, ni);
    for j in 0..s {
        x[j].eps = 1.0;
        let r = model.rhs(&prepared, td, &x, &w, &mut out);
        x[j].eps = 0.0;
        r?;
        for (i, o) in out.iter().enumerate() {
            a[(i, j)] = o.eps;
        }
    }
    for j in 0..ni {
        w[j].eps = 1.0;
        let r = model.rhs(&prepared, td, &x, &w, &mut out);
        w[j].eps = 0.0;
        r?;
        for (i, o) in out.iter().enumerate() {
            b[(i, j)] = o.eps;
        }
    }
    if s + ni == 0 {
        // Nothing to differentiate; still report a failing rhs.
        model.rhs(&model.prepare::<f64>(), t, state, inputs, &mut [])?;
    }
    finite(a.as_slice(), "the state Jacobian")?;
    finite(b.as_slice(), "the input Jacobian")?;
    Ok(Linearization {
        a,
        b,
        state_names: state_names(info),
        input_names: info.inputs.iter().map(|s| s.to_string()).collect(),
    })
}

/// The eigenvalues `(re, im)` of a real square matrix, by nalgebra's real
/// Schur decomposition, sorted by real part, then imaginary part (a complex
/// pair appears as `(re, −im)`, `(re, im)`; a zero imaginary part is `+0.0`).
///
/// Errors: [`LinearizeError::NotSquare`], [`LinearizeError::NonFinite`] for a
/// NaN or infinite entry, and [`LinearizeError::DecompositionFailed`] if the
/// Schur iteration does not converge (within `100 n` iterations).
///
/// ```
/// use appell_runtime::linearize::eigenvalues;
/// use nalgebra::DMatrix;
///
/// // The undamped oscillator ẍ = −4 x: ±2i.
/// let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -4.0, 0.0]);
/// let eig = eigenvalues(&a).unwrap();
/// assert!(eig[0].0.abs() < 1e-15 && (eig[0].1 + 2.0).abs() < 1e-15);
/// assert!(eig[1].0.abs() < 1e-15 && (eig[1].1 - 2.0).abs() < 1e-15);
///
/// // Triangular: the diagonal, sorted.
/// let t = DMatrix::from_row_slice(3, 3, &[3.0, 1.0, 2.0, 0.0, -1.0, 5.0, 0.0, 0.0, 0.5]);
/// let re: Vec<f64> = eigenvalues(&t).unwrap().iter().map(|e| e.0).collect();
/// assert_eq!(re, [-1.0, 0.5, 3.0]);
///
/// assert!(eigenvalues(&DMatrix::<f64>::zeros(2, 3)).is_err());
/// assert!(eigenvalues(&DMatrix::from_element(2, 2, f64::NAN)).is_err());
/// ```
pub fn eigenvalues(a: &DMatrix<f64>) -> Result<Vec<(f64, f64)>, LinearizeError> {
    let (rows, cols) = a.shape();
    if rows != cols {
        return Err(LinearizeError::NotSquare { rows, cols });
    }
    if !a.iter().all(|x| x.is_finite()) {
        return Err(LinearizeError::NonFinite { what: "the matrix" });
    }
    if rows == 0 {
        return Ok(Vec::new());
    }
    let schur = nalgebra::Schur::try_new(a.clone(), f64::EPSILON, 100 * rows)
        .ok_or(LinearizeError::DecompositionFailed { what: "Schur" })?;
    // −0.0 → +0.0, so the order does not depend on the sign of a zero.
    let clean = |x: f64| if x == 0.0 { 0.0 } else { x };
    let mut out: Vec<(f64, f64)> = schur
        .complex_eigenvalues()
        .iter()
        .map(|z| (clean(z.re), clean(z.im)))
        .collect();
    if !out.iter().all(|(re, im)| re.is_finite() && im.is_finite()) {
        return Err(LinearizeError::NonFinite {
            what: "an eigenvalue",
        });
    }
    out.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.total_cmp(&y.1)));
    Ok(out)
}

/// The index of every coordinate named in `names`.
fn indices(info: &ModelInfo, names: &[&str], list: &str) -> Result<Vec<usize>, LinearizeError> {
    names
        .iter()
        .map(|name| {
            info.coordinate_index(name).ok_or_else(|| {
                LinearizeError::InvalidInfo(format!("`{name}` in `{list}` is not a coordinate"))
            })
        })
        .collect()
}

/// The holonomic residuals at `q` and their Jacobian columns at the
/// coordinates `cols` (h × cols.len()), one [`Dual64`] pass per column. The
/// coordinate rates passed to the model are zero.
fn holonomic_jacobian<M: Model>(
    model: &M,
    t: f64,
    q: &[f64],
    cols: &[usize],
) -> Result<(DVector<f64>, DMatrix<f64>), LinearizeError> {
    let info = M::info();
    let (n, h, m) = (info.coordinates.len(), info.holonomic, info.constraints);
    let mut values = DVector::<f64>::zeros(h);
    let mut jac = DMatrix::<f64>::zeros(h, cols.len());
    if cols.is_empty() {
        let mut vel = vec![0.0; m];
        model.constraint_residuals(t, q, &vec![0.0; n], values.as_mut_slice(), &mut vel)?;
    } else {
        let td = Dual64::from_re(t);
        let mut qd: Vec<Dual64> = q.iter().map(|&x| Dual64::from_re(x)).collect();
        let qdot = vec![Dual64::from_re(0.0); n];
        let mut res = vec![Dual64::from_re(0.0); h];
        let mut vel = vec![Dual64::from_re(0.0); m];
        for (k, &c) in cols.iter().enumerate() {
            qd[c].eps = 1.0;
            let r = model.constraint_residuals(td, &qd, &qdot, &mut res, &mut vel);
            qd[c].eps = 0.0;
            r?;
            for (i, v) in res.iter().enumerate() {
                jac[(i, k)] = v.eps;
            }
        }
        for (i, v) in res.iter().enumerate() {
            values[i] = v.re;
        }
    }
    finite(values.as_slice(), "a holonomic residual")?;
    finite(jac.as_slice(), "the holonomic Jacobian")?;
    Ok((values, jac))
}

/// Checks `t` and a full configuration `q`.
fn check_configuration(info: &ModelInfo, t: f64, q: &[f64]) -> Result<(), ModelError> {
    check_len("q", q, info.coordinates.len())?;
    finite(&[t], "t")?;
    finite(q, "q")
}

/// A thin SVD of `j` (non-empty), or a typed error if it does not converge.
fn svd(
    j: DMatrix<f64>,
) -> Result<nalgebra::SVD<f64, nalgebra::Dyn, nalgebra::Dyn>, LinearizeError> {
    let iterations = 100 * j.nrows().max(j.ncols());
    nalgebra::SVD::try_new(j, true, true, f64::EPSILON, iterations)
        .ok_or(LinearizeError::DecompositionFailed { what: "SVD" })
}

/// Solves the holonomic constraints f(q, t) = 0 of [`Model::constraint_residuals`]
/// for the coordinates at the indices `unknowns` (into
/// [`ModelInfo::coordinates`]), starting from and updating `q` (all
/// coordinates); the other coordinates are held.
///
/// Newton's method on the Jacobian of the residuals with respect to the
/// unknowns ([`Dual64`] seeds through the generated code; the coordinate
/// rates passed are zero and the velocity rows are ignored). With as many
/// unknowns as residuals it is Newton's method; with more residuals it is
/// Gauss-Newton (least squares); with more unknowns, the minimum-norm step.
/// A step that does not decrease the residual norm is halved (up to 30
/// times). Converged when the Euclidean norm of the residuals is at most
/// `tol` (absolute, in the residuals' units; it must be above their rounding
/// level). Returns the number of Newton steps taken (0 when `q` already
/// satisfies the constraints).
///
/// Errors (`q` then holds the last iterate): wrong lengths or non-finite
/// arguments ([`LinearizeError::Model`]); an index out of range or repeated,
/// or a negative or non-finite `tol` ([`LinearizeError::InvalidArgument`]);
/// [`LinearizeError::RankDeficient`] when the Jacobian with respect to the
/// unknowns has rank below min(residuals, unknowns) (relative to the largest
/// entry of the Jacobian over all coordinates); [`LinearizeError::NotConverged`]
/// after `max_iter` steps, when no step decreases the residual (an
/// inconsistent least-squares problem), or when there are no unknowns and the
/// constraints are violated; and any error of the model. Example in the
/// module documentation.
pub fn solve_holonomic<M: Model>(
    model: &M,
    t: f64,
    q: &mut [f64],
    unknowns: &[usize],
    tol: f64,
    max_iter: usize,
) -> Result<usize, LinearizeError> {
    let info = M::info();
    let n = info.coordinates.len();
    check_configuration(info, t, q)?;
    if !(tol.is_finite() && tol >= 0.0) {
        return Err(LinearizeError::InvalidArgument(format!(
            "the tolerance must be finite and non-negative, not {tol}"
        )));
    }
    for (k, &i) in unknowns.iter().enumerate() {
        if i >= n {
            return Err(LinearizeError::InvalidArgument(format!(
                "unknown index {i} is out of range for {n} coordinates"
            )));
        }
        if unknowns[..k].contains(&i) {
            return Err(LinearizeError::InvalidArgument(format!(
                "unknown index {i} is repeated"
            )));
        }
    }
    let h = info.holonomic;
    let all: Vec<usize> = (0..n).collect();
    let mut trial = q.to_vec();
    let mut vel = vec![0.0; info.constraints];
    let zeros = vec![0.0; n];
    let mut res = vec![0.0; h];
    let mut iter = 0;
    loop {
        let (r, jfull) = holonomic_jacobian(model, t, q, &all)?;
        let norm = r.norm();
        if norm <= tol {
            return Ok(iter);
        }
        if iter >= max_iter || unknowns.is_empty() {
            return Err(LinearizeError::NotConverged {
                iterations: iter,
                residual: norm,
            });
        }
        let j = jfull.select_columns(unknowns);
        let scale = jfull.amax();
        let dec = svd(j)?;
        let cutoff = RANK_RTOL * scale;
        let rank = dec.singular_values.iter().filter(|&&s| s > cutoff).count();
        let expected = h.min(unknowns.len());
        if scale == 0.0 || rank < expected {
            return Err(LinearizeError::RankDeficient { rank, expected });
        }
        let step = dec
            .solve(&(-&r), cutoff)
            .map_err(|_| LinearizeError::DecompositionFailed { what: "SVD" })?;
        // Backtracking: the first step length that decreases ‖f‖.
        let mut alpha = 1.0;
        let mut accepted = false;
        for _ in 0..=MAX_BACKTRACKS {
            trial.copy_from_slice(q);
            for (k, &i) in unknowns.iter().enumerate() {
                trial[i] += alpha * step[k];
            }
            if trial.iter().all(|x| x.is_finite()) {
                model.constraint_residuals(t, &trial, &zeros, &mut res, &mut vel)?;
                let trial_norm = res.iter().map(|x| x * x).sum::<f64>().sqrt();
                if trial_norm < norm {
                    accepted = true;
                    break;
                }
            }
            alpha *= 0.5;
        }
        if !accepted {
            return Err(LinearizeError::NotConverged {
                iterations: iter,
                residual: norm,
            });
        }
        q.copy_from_slice(&trial);
        iter += 1;
    }
}

/// The dependent coordinates ([`ModelInfo::dependent`]) that the holonomic
/// residuals involve at `(q, t)`: those whose [`Dual64`] seed gives a
/// non-zero derivative of some residual. Indices into
/// [`ModelInfo::coordinates`], ascending; the natural `unknowns` of
/// [`solve_holonomic`]. Example in the module documentation.
///
/// Errors: wrong length or non-finite arguments, an inconsistent
/// [`ModelInfo`], and any error of [`Model::constraint_residuals`].
pub fn holonomic_unknowns<M: Model>(
    model: &M,
    t: f64,
    q: &[f64],
) -> Result<Vec<usize>, LinearizeError> {
    let info = M::info();
    check_configuration(info, t, q)?;
    let mut dep = indices(info, info.dependent, "dependent")?;
    dep.sort_unstable();
    dep.dedup();
    if info.holonomic == 0 {
        return Ok(Vec::new());
    }
    let (_, jac) = holonomic_jacobian(model, t, q, &dep)?;
    Ok(dep
        .iter()
        .enumerate()
        .filter(|&(k, _)| jac.column(k).iter().any(|&x| x != 0.0))
        .map(|(_, &c)| c)
        .collect())
}

/// Projects a reduced state (retained coordinates, then privileged speeds,
/// as [`Model::rhs`] takes it) back onto the holonomic constraint manifold:
/// the dependent retained coordinates the constraints involve are corrected
/// by [`solve_holonomic`] with the others held; the speeds are left alone
/// (the reduced equations satisfy the velocity constraints by construction).
/// Integrators drift off the manifold at the size of their local error; a
/// projection between output times (or after every step) keeps a bicycle's
/// pitch consistent with its lean and steer over long runs.
///
/// Coordinates the reduced state does not carry are taken as 0, as in the
/// command line's `eval`. Returns the Euclidean norm of the residuals before
/// the projection and the number of Newton steps taken.
///
/// Errors: a state of the wrong length or with non-finite values
/// ([`LinearizeError::Model`]); [`LinearizeError::InvalidArgument`] when a
/// constraint involves a coordinate outside the reduced state (it cannot be
/// projected there); and the errors of [`solve_holonomic`] (`state` is then
/// unchanged).
///
/// ```
/// # use appell_runtime::{check_len, BodyInfo, Model, ModelError, ModelInfo, OpCounts, Scalar};
/// # struct Ring { l: f64 }
/// # static INFO: ModelInfo = ModelInfo {
/// #     name: "Ring", parameters: &["l"], coordinates: &["x", "y"],
/// #     speeds: &["x"], dependent: &["y"], cyclic: &[], ignorable: &[],
/// #     retained: &["x", "y"], inputs: &[], effects: &[], outputs: &[], row_sources: &[], contacts: &[], holonomic: 1,
/// #     constraints: 1, bodies: &[BodyInfo { name: "P", rigid: false }],
/// #     force_points: 0, torques: 0, symbolic_elimination: true,
/// #     rhs_ops: OpCounts { add: 0, mul: 0, div: 0, calls: 0, total: 0 }, equations: "",
/// # };
/// # fn unused() -> Result<(), ModelError> { Err(ModelError::NonFinite { what: "unused" }) }
/// # impl Model for Ring {
/// #     type Prepared<T: Scalar> = ();
/// #     fn info() -> &'static ModelInfo { &INFO }
/// #     fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> {
/// #         check_len("out", out, 1)?; out[0] = self.l; Ok(())
/// #     }
/// #     fn set_parameter(&mut self, _: &str, _: f64) -> bool { false }
/// #     fn prepare<T: Scalar>(&self) {}
/// #     fn rhs<T: Scalar>(&self, _: &(), _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn coordinate_rates<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn mass_matrix_and_forcing<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn speed_transform<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn constraint_residuals<T: Scalar>(&self, _: T, q: &[T], qd: &[T], h: &mut [T], v: &mut [T]) -> Result<(), ModelError> {
/// #         check_len("q", q, 2)?; check_len("qdot", qd, 2)?;
/// #         let l = T::from_f64(self.l);
/// #         h[0] = (q[0] * q[0] + q[1] * q[1] - l * l) / T::from_f64(2.0);
/// #         v[0] = q[0] * qd[0] + q[1] * qd[1];
/// #         Ok(())
/// #     }
/// #     fn kinetic_energy<T: Scalar>(&self, _: T, _: &[T], _: &[T]) -> Result<T, ModelError> { unused().map(|_| T::zero()) }
/// #     fn mass_properties(&self, _: &mut [f64], _: &mut [[f64; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn body_poses<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn constraint_rows<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn load_geometry<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn load_values<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [[T; 3]], _: &mut [[T; 3]]) -> Result<(), ModelError> { unused() }
/// # }
/// use appell_runtime::linearize::project_holonomic;
///
/// // A particle on a circle of radius 1 in Cartesian coordinates, state
/// // (x, y, ẋ), drifted off the circle.
/// let mut state = [0.6, -0.81, 0.3];
/// let (residual, steps) = project_holonomic(&Ring { l: 1.0 }, 0.0, &mut state, 1e-14, 20).unwrap();
/// assert!(residual > 1e-3 && steps > 0);
/// assert!((state[0] * state[0] + state[1] * state[1] - 1.0).abs() < 1e-13);
/// assert_eq!((state[0], state[2]), (0.6, 0.3)); // x and the speed are held
/// ```
pub fn project_holonomic<M: Model>(
    model: &M,
    t: f64,
    state: &mut [f64],
    tol: f64,
    max_iter: usize,
) -> Result<(f64, usize), LinearizeError> {
    let info = M::info();
    check_len("state", state, info.state_len())?;
    finite(state, "state")?;
    if info.holonomic == 0 {
        return Ok((0.0, 0));
    }
    let retained = indices(info, info.retained, "retained")?;
    let mut q = vec![0.0; info.coordinates.len()];
    for (k, &i) in retained.iter().enumerate() {
        q[i] = state[k];
    }
    let all: Vec<usize> = (0..q.len()).collect();
    let (r, jac) = holonomic_jacobian(model, t, &q, &all)?;
    if let Some(c) =
        (0..q.len()).find(|&c| !retained.contains(&c) && jac.column(c).iter().any(|&x| x != 0.0))
    {
        return Err(LinearizeError::InvalidArgument(format!(
            "the holonomic constraints involve `{}`, which the reduced state does not carry",
            info.coordinates[c]
        )));
    }
    let unknowns: Vec<usize> = holonomic_unknowns(model, t, &q)?
        .into_iter()
        .filter(|i| retained.contains(i))
        .collect();
    let steps = solve_holonomic(model, t, &mut q, &unknowns, tol, max_iter)?;
    for (k, &i) in retained.iter().enumerate() {
        state[k] = q[i];
    }
    Ok((r.norm(), steps))
}

/// Checks a reduced state (retained coordinates, then speeds, as
/// [`Model::rhs`] takes it) against the holonomic constraints: their
/// residuals f(q, t) with the ignorable coordinates at zero (they do not
/// enter the reduced equations). Returns the residuals when every one is
/// within `tol`, and [`LinearizeError::HolonomicViolated`] naming the first
/// one that is not, so a caller can refuse (or project, with
/// [`project_holonomic`]) a state the reduced equations were not derived
/// for. Errors also for wrong lengths and non-finite values.
///
/// ```
/// # use appell_runtime::{Model, ModelError, ModelInfo, OpCounts, Scalar};
/// # struct Ring { l: f64 }
/// # static INFO: ModelInfo = ModelInfo {
/// #     name: "Ring", parameters: &["l"], coordinates: &["x", "y"], speeds: &["x"],
/// #     dependent: &["y"], cyclic: &[], ignorable: &[], retained: &["x", "y"], inputs: &[],
/// #     effects: &[], outputs: &[], row_sources: &[], contacts: &[], holonomic: 1, constraints: 1, bodies: &[], force_points: 0,
/// #     torques: 0, symbolic_elimination: false,
/// #     rhs_ops: OpCounts { add: 0, mul: 0, div: 0, calls: 0, total: 0 }, equations: "",
/// # };
/// # fn unused() -> Result<(), ModelError> { Err(ModelError::NonFinite { what: "unused" }) }
/// # impl Model for Ring {
/// #     type Prepared<T: Scalar> = ();
/// #     fn info() -> &'static ModelInfo { &INFO }
/// #     fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> { out[0] = self.l; Ok(()) }
/// #     fn set_parameter(&mut self, _: &str, _: f64) -> bool { false }
/// #     fn prepare<T: Scalar>(&self) {}
/// #     fn rhs<T: Scalar>(&self, _: &(), _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn mass_matrix_and_forcing<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn speed_transform<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn coordinate_rates<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn constraint_residuals<T: Scalar>(&self, _: T, q: &[T], _: &[T], h: &mut [T], _: &mut [T]) -> Result<(), ModelError> {
/// #         let l = T::from_f64(self.l);
/// #         h[0] = q[0] * q[0] + q[1] * q[1] - l * l;
/// #         Ok(())
/// #     }
/// #     fn kinetic_energy<T: Scalar>(&self, _: T, _: &[T], _: &[T]) -> Result<T, ModelError> { unused().map(|_| T::zero()) }
/// #     fn mass_properties(&self, _: &mut [f64], _: &mut [[f64; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn body_poses<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn constraint_rows<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
/// #     fn load_geometry<T: Scalar>(&self, _: T, _: &[T], _: &mut [[T; 3]], _: &mut [[T; 9]]) -> Result<(), ModelError> { unused() }
/// #     fn load_values<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [[T; 3]], _: &mut [[T; 3]]) -> Result<(), ModelError> { unused() }
/// # }
/// use appell_runtime::linearize::{check_holonomic, LinearizeError};
/// // A particle on a circle of radius 1, state (x, y, ẋ).
/// assert!(check_holonomic(&Ring { l: 1.0 }, 0.0, &[0.6, -0.8, 0.3], 1e-12).is_ok());
/// assert!(matches!(
///     check_holonomic(&Ring { l: 1.0 }, 0.0, &[0.6, -0.81, 0.3], 1e-12),
///     Err(LinearizeError::HolonomicViolated { index: 0, .. })
/// ));
/// ```
pub fn check_holonomic<M: Model>(
    model: &M,
    t: f64,
    state: &[f64],
    tol: f64,
) -> Result<Vec<f64>, LinearizeError> {
    let info = M::info();
    check_len("state", state, info.state_len())?;
    finite(state, "state")?;
    if tol.is_nan() || tol < 0.0 {
        return Err(LinearizeError::InvalidArgument(format!(
            "the tolerance must be non-negative, not {tol}"
        )));
    }
    let retained = indices(info, info.retained, "retained")?;
    let n = info.coordinates.len();
    let mut q = vec![0.0; n];
    for (k, &i) in retained.iter().enumerate() {
        q[i] = state[k];
    }
    let (mut h, mut v) = (vec![0.0; info.holonomic], vec![0.0; info.constraints]);
    model.constraint_residuals(t, &q, &vec![0.0; n], &mut h, &mut v)?;
    if let Some((index, &residual)) = h
        .iter()
        .enumerate()
        .find(|(_, r)| r.is_nan() || r.abs() > tol)
    {
        return Err(LinearizeError::HolonomicViolated {
            index,
            residual,
            tolerance: tol,
        });
    }
    Ok(h)
}

/// The linearization in a minimal state at a full configuration `q_full`
/// (every coordinate, ignorable ones included), privileged speeds `u` (one
/// per [`ModelInfo::speeds`]) and `inputs`.
///
/// A reduced state can hold more than the motion needs:
///
/// * a retained coordinate fixed by a holonomic constraint (a bicycle's
///   pitch, determined by its lean and steer; `y` of a pendulum in
///   Cartesian coordinates) is eliminated: with J = ∂f/∂q at `q_full`, the
///   dependent retained coordinates the constraints involve follow the
///   others at first order, δq_dep = −J_dep⁺ J_indep δq_indep. The ignorable
///   coordinates (not retained) are free in this relation (they do not enter
///   the reduced rhs; any constraint they take up does not restrict the
///   retained ones), so J is first projected onto the complement of their
///   columns' range;
/// * the privileged speeds named in `fixed_speeds` (by their coordinate's
///   name, as in [`ModelInfo::speeds`], or as the state name
///   `"{coordinate}_dot"`) are held at their values in `u`: their rows and
///   columns are dropped (a bicycle's rear-wheel rate, i.e. its forward
///   speed, is a parameter of the steady motion being linearized about).
///
/// With x the reduced state (retained coordinates, then speeds) and z the
/// minimal one (the retained coordinates not eliminated, then the speeds not
/// fixed, in that order), `x − x0 = T (z − z0)` to first order, and the
/// result is `A_z = P A T`, `B_z = P B` where A, B come from [`linearize`]
/// and P selects z's rows.
///
/// Assumptions: first order about the point; `q_full` satisfies the
/// holonomic constraints (use [`solve_holonomic`]); the fixed speeds are
/// parameters of the operating point (their own dynamics, and any drift of
/// them, are ignored); the point need not be an equilibrium.
///
/// Errors: wrong lengths and non-finite values ([`LinearizeError::Model`]),
/// [`LinearizeError::UnknownName`] for a name that is not a speed,
/// [`LinearizeError::InvalidInfo`] for an inconsistent [`ModelInfo`],
/// [`LinearizeError::NotOnManifold`] when the residuals exceed
/// `1e-8 · max(1, ‖J‖ ‖q‖)`, [`LinearizeError::RankDeficient`] when the
/// constraints do not determine the dependent retained coordinates they
/// involve, [`LinearizeError::SingularCoordinates`] when they restrict the
/// others at first order, and any error of the model. Example in the module
/// documentation.
pub fn minimal_linearization<M: Model>(
    model: &M,
    t: f64,
    q_full: &[f64],
    u: &[f64],
    inputs: &[f64],
    fixed_speeds: &[&str],
) -> Result<Linearization, LinearizeError> {
    let info = M::info();
    let n = info.coordinates.len();
    let (nr, nl) = (info.retained.len(), info.speeds.len());
    check_configuration(info, t, q_full)?;
    check_len("u", u, nl)?;
    finite(u, "u")?;
    let retained = indices(info, info.retained, "retained")?;
    let dependent = indices(info, info.dependent, "dependent")?;
    indices(info, info.speeds, "speeds")?;

    let mut fixed = vec![false; nl];
    for name in fixed_speeds {
        let k = info
            .speeds
            .iter()
            .position(|s| s == name)
            .or_else(|| {
                info.speeds
                    .iter()
                    .position(|s| name.strip_suffix("_dot") == Some(*s))
            })
            .ok_or_else(|| LinearizeError::UnknownName(name.to_string()))?;
        fixed[k] = true;
    }

    let state: Vec<f64> = retained
        .iter()
        .map(|&i| q_full[i])
        .chain(u.iter().copied())
        .collect();
    let full = linearize(model, t, &state, inputs)?;

    // Retained positions eliminated, and their first-order dependence on the
    // kept retained coordinates (|eliminated| × |kept|).
    let mut eliminated: Vec<usize> = Vec::new();
    let mut kept: Vec<usize> = (0..nr).collect();
    let mut follow = DMatrix::<f64>::zeros(0, nr);
    if info.holonomic > 0 {
        let all: Vec<usize> = (0..n).collect();
        let (f0, jac) = holonomic_jacobian(model, t, q_full, &all)?;
        let residual = f0.norm();
        let q_scale = q_full.iter().fold(0.0_f64, |s, x| s.max(x.abs()));
        let tolerance = MANIFOLD_RTOL * (jac.norm() * q_scale).max(1.0);
        if residual > tolerance {
            return Err(LinearizeError::NotOnManifold {
                residual,
                tolerance,
            });
        }
        let scale = jac.amax();
        let cutoff = RANK_RTOL * scale;
        // Project out what the ignorable coordinates can take up.
        let free: Vec<usize> = (0..n).filter(|i| !retained.contains(i)).collect();
        let jg = jac.select_columns(&free);
        let projected = if jg.amax() > cutoff {
            let h = info.holonomic;
            let pinv = svd(jg.clone())?
                .pseudo_inverse(cutoff)
                .map_err(|_| LinearizeError::DecompositionFailed { what: "SVD" })?;
            (DMatrix::<f64>::identity(h, h) - &jg * pinv) * &jac
        } else {
            jac
        };
        let involved = |c: usize| -> bool { projected.column(c).iter().any(|x| x.abs() > cutoff) };
        eliminated = (0..nr)
            .filter(|&p| dependent.contains(&retained[p]) && involved(retained[p]))
            .collect();
        kept = (0..nr).filter(|p| !eliminated.contains(p)).collect();
        let cols = |ps: &[usize]| -> Vec<usize> { ps.iter().map(|&p| retained[p]).collect() };
        let j_kept = projected.select_columns(&cols(&kept));
        let remainder;
        if eliminated.is_empty() {
            follow = DMatrix::zeros(0, kept.len());
            remainder = j_kept;
        } else {
            let j_elim = projected.select_columns(&cols(&eliminated));
            let dec = svd(j_elim.clone())?;
            let rank = dec.singular_values.iter().filter(|&&s| s > cutoff).count();
            if rank < eliminated.len() {
                return Err(LinearizeError::RankDeficient {
                    rank,
                    expected: eliminated.len(),
                });
            }
            follow = -dec
                .solve(&j_kept, cutoff)
                .map_err(|_| LinearizeError::DecompositionFailed { what: "SVD" })?;
            remainder = &j_elim * &follow + &j_kept;
        }
        // Whatever the elimination leaves must vanish: otherwise the
        // constraints restrict the kept coordinates themselves.
        let left = remainder.amax();
        if left > CONSISTENCY_RTOL * scale * follow.amax().max(1.0) {
            return Err(LinearizeError::SingularCoordinates { residual: left });
        }
        finite(follow.as_slice(), "the constraint elimination")?;
    }

    // z: the kept retained coordinates, then the speeds not fixed.
    let speeds: Vec<usize> = (0..nl).filter(|&k| !fixed[k]).collect();
    let rows: Vec<usize> = kept
        .iter()
        .copied()
        .chain(speeds.iter().map(|&k| nr + k))
        .collect();
    let nz = rows.len();
    let mut tmat = DMatrix::<f64>::zeros(nr + nl, nz);
    for (col, &row) in rows.iter().enumerate() {
        tmat[(row, col)] = 1.0;
    }
    for (e, &p) in eliminated.iter().enumerate() {
        for k in 0..kept.len() {
            tmat[(p, k)] = follow[(e, k)];
        }
    }
    let a = full.a.select_rows(&rows) * tmat;
    let b = full.b.select_rows(&rows);
    finite(a.as_slice(), "the minimal state Jacobian")?;
    let state_names = rows.iter().map(|&r| full.state_names[r].clone()).collect();
    Ok(Linearization {
        a,
        b,
        state_names,
        input_names: full.input_names,
    })
}
