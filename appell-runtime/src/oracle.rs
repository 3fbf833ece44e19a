//! The independent solver: accelerations by the full-coordinate multiplier
//! route (Wang & Pao 2003, eqs. 69-70), used as an oracle for the equations
//! `#[derive(Appell)]` derives.
//!
//! Nothing here shares derivation code with the macro. Only the *kinematic
//! description* of a [`Model`] is used ([`Model::mass_properties`],
//! [`Model::body_poses`], [`Model::constraint_rows`],
//! [`Model::load_geometry`], [`Model::load_values`]) and its [`ModelInfo`];
//! every derivative is taken numerically-exactly with dual numbers, and the
//! equations
//!
//! ```text
//! M_full(q) q̈ + h(q, q̇, t) = Q(q, q̇, t) + Dᵀ λ,
//! D q̈ + (Ḋ q̇ + ḋ) = 0
//! ```
//!
//! are solved together as one dense KKT system by LU with partial pivoting.
//!
//! For body j with mass m_j, body-frame central inertia I_j, mass-centre
//! position r_j(q, t) and rotation R_j(q, t):
//!
//! * J_j = ∂r_j/∂q and the angular-velocity Jacobian G_j (column r is
//!   vee((∂R_j/∂q_r) R_jᵀ)) come from [`Dual64`] seeds on one coordinate at a
//!   time;
//! * the velocity v_j, angular velocity ω_j and the acceleration remainders
//!   a_j, α_j (the accelerations when q̈ = 0, including every time-explicit
//!   term) come from second-order [`Dual2_64`] seeds along the path
//!   s ↦ (q + s q̇, t + s): v_j and Ṙ_j are the first derivatives, a_j and
//!   R̈_j the second ones, ω̃_j = Ṙ_j R_jᵀ and α̃_j = skew(R̈_j R_jᵀ);
//! * M_full = Σ_j m_j J_jᵀ J_j + G_jᵀ I_N G_j with I_N = R_j I_j R_jᵀ (no
//!   rotational part for particles);
//! * h = Σ_j m_j J_jᵀ a_j + G_jᵀ (I_N α_j + ω_j × I_N ω_j);
//! * Q = Σ_P J_Pᵀ F_P + Σ_F G_Fᵀ L_F over the force application points and
//!   torque frames of [`Model::load_geometry`], with the loads of
//!   [`Model::load_values`];
//! * Ḋ q̇ + ḋ is the derivative part of D(q + ε q̇, t + ε) q̇ + d(q + ε q̇, t + ε).
//!
//! The privileged accelerations are the entries of q̈ at the coordinates named
//! in [`ModelInfo::speeds`]. [`reduced_rhs`] produces the same layout as
//! [`Model::rhs`], computing the dependent rates from the constraint rows
//! itself (never through [`Model::coordinate_rates`]).
//!
//! # Example
//!
//! A planar pendulum (a particle at (l sin θ, −l cos θ, 0) under gravity),
//! written by hand here:
//!
//! ```
//! use appell_runtime::oracle::{accelerations, coordinate_rates, full_dynamics, reduced_rhs};
//! use appell_runtime::{check_len, BodyInfo, Model, ModelError, ModelInfo, OpCounts, Scalar};
//! # struct Pendulum { m: f64, l: f64, g: f64 }
//! # static INFO: ModelInfo = ModelInfo {
//! #     name: "Pendulum", parameters: &["m", "l", "g"], coordinates: &["theta"],
//! #     speeds: &["theta"], dependent: &[], cyclic: &[], ignorable: &[],
//! #     retained: &["theta"], inputs: &[], effects: &["gravity"], outputs: &[], row_sources: &[], contacts: &[], holonomic: 0,
//! #     constraints: 0, bodies: &[BodyInfo { name: "P", rigid: false }],
//! #     force_points: 1, torques: 0, symbolic_elimination: true,
//! #     rhs_ops: OpCounts { add: 0, mul: 1, div: 1, calls: 1, total: 4 },
//! #     equations: "theta'' = -(g/l) sin(theta)",
//! # };
//! # fn unused() -> Result<(), ModelError> { Err(ModelError::NonFinite { what: "unused" }) }
//! # impl Model for Pendulum {
//! #     type Prepared<T: Scalar> = ();
//! #     fn info() -> &'static ModelInfo { &INFO }
//! #     fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> {
//! #         check_len("out", out, 3)?; out.copy_from_slice(&[self.m, self.l, self.g]); Ok(())
//! #     }
//! #     fn set_parameter(&mut self, _: &str, _: f64) -> bool { false }
//! #     fn prepare<T: Scalar>(&self) {}
//! #     fn rhs<T: Scalar>(&self, _: &(), _t: T, s: &[T], _i: &[T], ds: &mut [T]) -> Result<(), ModelError> {
//! #         check_len("state", s, 2)?; check_len("dstate", ds, 2)?;
//! #         ds[0] = s[1]; ds[1] = -(T::from_f64(self.g / self.l) * s[0].sin()); Ok(())
//! #     }
//! #     fn mass_matrix_and_forcing<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
//! #     fn speed_transform<T: Scalar>(&self, _: T, _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
//! #     fn coordinate_rates<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T]) -> Result<(), ModelError> { unused() }
//! #     fn constraint_residuals<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &mut [T], _: &mut [T]) -> Result<(), ModelError> { unused() }
//! #     fn kinetic_energy<T: Scalar>(&self, _: T, _: &[T], _: &[T]) -> Result<T, ModelError> { unused().map(|_| T::zero()) }
//! #     fn mass_properties(&self, m: &mut [f64], i: &mut [[f64; 9]]) -> Result<(), ModelError> {
//! #         check_len("masses", m, 1)?; check_len("inertias", i, 1)?; m[0] = self.m; i[0] = [0.0; 9]; Ok(())
//! #     }
//! #     fn body_poses<T: Scalar>(&self, _t: T, q: &[T], p: &mut [[T; 3]], r: &mut [[T; 9]]) -> Result<(), ModelError> {
//! #         check_len("q", q, 1)?; check_len("positions", p, 1)?; check_len("rotations", r, 1)?;
//! #         let l = T::from_f64(self.l);
//! #         p[0] = [l * q[0].sin(), -(l * q[0].cos()), T::zero()];
//! #         let (o, z) = (T::one(), T::zero());
//! #         r[0] = [o, z, z, z, o, z, z, z, o]; Ok(())
//! #     }
//! #     fn constraint_rows<T: Scalar>(&self, _: T, q: &[T], d: &mut [T], d0: &mut [T]) -> Result<(), ModelError> {
//! #         check_len("q", q, 1)?; check_len("d", d, 0)?; check_len("d0", d0, 0)
//! #     }
//! #     fn load_geometry<T: Scalar>(&self, t: T, q: &[T], p: &mut [[T; 3]], f: &mut [[T; 9]]) -> Result<(), ModelError> {
//! #         check_len("frames", f, 0)?;
//! #         let mut r = [[T::zero(); 9]];
//! #         self.body_poses(t, q, p, &mut r)
//! #     }
//! #     fn load_values<T: Scalar>(&self, _: T, _: &[T], _: &[T], _: &[T], f: &mut [[T; 3]], l: &mut [[T; 3]]) -> Result<(), ModelError> {
//! #         check_len("forces", f, 1)?; check_len("torques", l, 0)?;
//! #         f[0] = [T::zero(), T::from_f64(-self.m * self.g), T::zero()]; Ok(())
//! #     }
//! # }
//! let model = Pendulum { m: 2.0, l: 1.5, g: 9.81 };
//! let (theta, omega) = (0.4, 1.3);
//!
//! // θ̈ = −(g/l) sin θ.
//! let sol = accelerations(&model, 0.0, &[theta], &[omega], &[]).unwrap();
//! let exact = -(9.81 / 1.5) * f64::sin(theta);
//! assert!((sol.privileged[0] - exact).abs() < 1e-12);
//! assert!(sol.multipliers.is_empty());
//!
//! // Same layout as Model::rhs: [θ̇, θ̈].
//! let d = reduced_rhs(&model, 0.0, &[theta], &[omega], &[]).unwrap();
//! assert!((d[0] - omega).abs() < 1e-15 && (d[1] - exact).abs() < 1e-12);
//! assert_eq!(coordinate_rates(&model, 0.0, &[theta], &[omega]).unwrap(), vec![omega]);
//!
//! // The assembled equations: M_full = m l², T = m l² θ̇² / 2.
//! let full = full_dynamics(&model, 0.0, &[theta], &[omega], &[]).unwrap();
//! assert!((full.mass[0] - 2.0 * 1.5 * 1.5).abs() < 1e-12);
//! assert!((full.kinetic_energy - 0.5 * 2.0 * 1.5 * 1.5 * omega * omega).abs() < 1e-12);
//!
//! // Bad input is an error, never a panic.
//! assert!(accelerations(&model, 0.0, &[theta, 0.0], &[omega], &[]).is_err());
//! assert!(accelerations(&model, 0.0, &[f64::NAN], &[omega], &[]).is_err());
//! ```

use crate::model::{check_len, Model, ModelError, ModelInfo};
use crate::scalar::Scalar;
use nalgebra::{DMatrix, DVector};
use num_dual::{Dual2_64, Dual64};

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

/// The result of [`accelerations`].
#[derive(Clone, Debug, PartialEq)]
pub struct OracleSolution {
    /// q̈ for every coordinate, in [`ModelInfo::coordinates`] order.
    pub qddot: Vec<f64>,
    /// The multipliers λ, one per velocity constraint row.
    pub multipliers: Vec<f64>,
    /// The privileged accelerations: q̈ at the coordinates named in
    /// [`ModelInfo::speeds`], in that order.
    pub privileged: Vec<f64>,
}

/// The assembled full-coordinate equations at one state (see the module
/// documentation for the definitions). Produced by [`full_dynamics`].
#[derive(Clone, Debug, PartialEq)]
pub struct FullDynamics {
    /// Number of coordinates n.
    pub n: usize,
    /// Number of velocity constraint rows m.
    pub m: usize,
    /// M_full, n×n row-major.
    pub mass: Vec<f64>,
    /// h: the inertia forces when q̈ = 0 (velocity- and time-explicit terms).
    pub bias: Vec<f64>,
    /// Q: the generalized applied forces.
    pub forces: Vec<f64>,
    /// D, m×n row-major.
    pub constraint_matrix: Vec<f64>,
    /// d (so the velocity constraints read D q̇ + d = 0).
    pub constraint_offset: Vec<f64>,
    /// Ḋ q̇ + ḋ (so the acceleration constraints read D q̈ + Ḋ q̇ + ḋ = 0).
    pub constraint_bias: Vec<f64>,
    /// Kinetic energy Σ ½ m v·v + ½ ω·I ω at this state.
    pub kinetic_energy: f64,
    /// Power of the applied loads Σ F·v_P + L·ω_F at this state (the
    /// velocities include time-explicit motion of the geometry).
    pub power: f64,
}

/// Coordinate index sets derived from a validated [`ModelInfo`].
struct Layout {
    n: usize,
    m: usize,
    bodies: usize,
    points: usize,
    frames: usize,
    inputs: usize,
    l: usize,
    retained: Vec<usize>,
}

fn index_of(info: &ModelInfo, name: &str, list: &str) -> Result<usize, OracleError> {
    info.coordinate_index(name).ok_or_else(|| {
        OracleError::InvalidInfo(format!("`{name}` in `{list}` is not a coordinate"))
    })
}

impl Layout {
    fn new(info: &ModelInfo) -> Result<Self, OracleError> {
        let n = info.coordinates.len();
        for (i, c) in info.coordinates.iter().enumerate() {
            if info.coordinates[..i].contains(c) {
                return Err(OracleError::InvalidInfo(format!(
                    "coordinate `{c}` is declared twice"
                )));
            }
        }
        let l = info.speeds.len();
        if info.constraints + l != n {
            return Err(OracleError::InvalidInfo(format!(
                "{n} coordinates, {l} privileged speeds and {} constraint rows: the rows and the speeds' definitions must determine exactly the {n} rates",
                info.constraints
            )));
        }
        let retained = info
            .retained
            .iter()
            .map(|r| index_of(info, r, "retained"))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Layout {
            n,
            m: info.constraints,
            bodies: info.bodies.len(),
            points: info.force_points,
            frames: info.torques,
            inputs: info.inputs.len(),
            l,
            retained,
        })
    }
}

/// Everything position-like a model gives at one `(q, t)`, in one scalar.
struct Geometry<T> {
    positions: Vec<[T; 3]>,
    rotations: Vec<[T; 9]>,
    points: Vec<[T; 3]>,
    frames: Vec<[T; 9]>,
}

impl<T: Scalar> Geometry<T> {
    fn eval<M: Model>(model: &M, lay: &Layout, t: T, q: &[T]) -> Result<Self, OracleError> {
        let mut g = Geometry {
            positions: vec![[T::zero(); 3]; lay.bodies],
            rotations: vec![[T::zero(); 9]; lay.bodies],
            points: vec![[T::zero(); 3]; lay.points],
            frames: vec![[T::zero(); 9]; lay.frames],
        };
        model.body_poses(t, q, &mut g.positions, &mut g.rotations)?;
        model.load_geometry(t, q, &mut g.points, &mut g.frames)?;
        Ok(g)
    }
}

pub(crate) fn finite_all(
    xs: impl IntoIterator<Item = f64>,
    what: &'static str,
) -> Result<(), OracleError> {
    for x in xs {
        if !x.is_finite() {
            return Err(ModelError::NonFinite { what }.into());
        }
    }
    Ok(())
}

/// `a bᵀ` for row-major 3×3 matrices.
pub(crate) fn mul_bt(a: &[f64; 9], b: &[f64; 9]) -> [f64; 9] {
    let mut out = [0.0; 9];
    for i in 0..3 {
        for j in 0..3 {
            out[3 * i + j] = (0..3).map(|k| a[3 * i + k] * b[3 * j + k]).sum();
        }
    }
    out
}

/// `a b` for row-major 3×3 matrices.
pub(crate) fn mul(a: &[f64; 9], b: &[f64; 9]) -> [f64; 9] {
    let mut out = [0.0; 9];
    for i in 0..3 {
        for j in 0..3 {
            out[3 * i + j] = (0..3).map(|k| a[3 * i + k] * b[3 * k + j]).sum();
        }
    }
    out
}

/// The axial vector of the skew-symmetric part of `s`.
pub(crate) fn vee(s: &[f64; 9]) -> [f64; 3] {
    [
        0.5 * (s[7] - s[5]),
        0.5 * (s[2] - s[6]),
        0.5 * (s[3] - s[1]),
    ]
}

fn mat_vec(a: &[f64; 9], v: &[f64; 3]) -> [f64; 3] {
    [
        a[0] * v[0] + a[1] * v[1] + a[2] * v[2],
        a[3] * v[0] + a[4] * v[1] + a[5] * v[2],
        a[6] * v[0] + a[7] * v[1] + a[8] * v[2],
    ]
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn map3<T: Copy, const K: usize>(x: &[T; K], f: impl Fn(T) -> f64) -> [f64; K] {
    let mut out = [0.0; K];
    for (o, v) in out.iter_mut().zip(x) {
        *o = f(*v);
    }
    out
}

/// Relative size (in units of `dim · ε · scale`) below which an LU pivot
/// counts as zero: a little above the rounding noise of the elimination.
const PIVOT_TOLERANCE: f64 = 64.0;

/// Solves the square system `a x = b` by LU with partial pivoting; a pivot
/// below `PIVOT_TOLERANCE · dim · ε · scale` is reported through
/// `singular(index, pivot, tol)`. `scale` is the magnitude the entries are
/// measured against (the largest entry of the whole system they come from).
fn lu_solve_checked(
    a: DMatrix<f64>,
    b: DVector<f64>,
    scale: f64,
    singular: impl Fn(usize, f64, f64) -> OracleError,
) -> Result<DVector<f64>, OracleError> {
    let dim = a.nrows();
    if dim == 0 {
        return Ok(b);
    }
    let tol = PIVOT_TOLERANCE * scale * dim as f64 * f64::EPSILON;
    let lu = a.lu();
    let u = lu.u();
    let (mut index, mut pivot) = (0, f64::INFINITY);
    for i in 0..dim {
        let p = u[(i, i)].abs();
        if p < pivot {
            pivot = p;
            index = i;
        }
    }
    if scale == 0.0 || pivot <= tol {
        return Err(singular(index, pivot, tol));
    }
    lu.solve(&b).ok_or_else(|| singular(index, pivot, tol))
}

/// Assembles the full-coordinate equations of motion at `(t, q, q̇)` and
/// `inputs` from the model's kinematic description (see the module
/// documentation; example there).
///
/// Lengths: `q` and `qdot` have one entry per coordinate, `inputs` one per
/// [`ModelInfo::inputs`]. Errors: wrong lengths and non-finite arguments or
/// results as [`OracleError::Model`], an inconsistent [`ModelInfo`] as
/// [`OracleError::InvalidInfo`], and any error of the model's methods.
pub fn full_dynamics<M: Model>(
    model: &M,
    t: f64,
    q: &[f64],
    qdot: &[f64],
    inputs: &[f64],
) -> Result<FullDynamics, OracleError> {
    let lay = Layout::new(M::info())?;
    full_dynamics_with(model, &lay, t, q, qdot, inputs)
}

fn full_dynamics_with<M: Model>(
    model: &M,
    lay: &Layout,
    t: f64,
    q: &[f64],
    qdot: &[f64],
    inputs: &[f64],
) -> Result<FullDynamics, OracleError> {
    let (n, m) = (lay.n, lay.m);
    check_len("q", q, n)?;
    check_len("qdot", qdot, n)?;
    check_len("inputs", inputs, lay.inputs)?;
    finite_all([t], "t")?;
    finite_all(q.iter().copied(), "q")?;
    finite_all(qdot.iter().copied(), "qdot")?;
    finite_all(inputs.iter().copied(), "inputs")?;

    let info = M::info();
    let mut masses = vec![0.0; lay.bodies];
    let mut inertias = vec![[0.0; 9]; lay.bodies];
    model.mass_properties(&mut masses, &mut inertias)?;
    finite_all(masses.iter().copied(), "a body mass")?;
    finite_all(inertias.iter().flatten().copied(), "a body inertia")?;

    // Values at (q, t).
    let g0 = Geometry::<f64>::eval(model, lay, t, q)?;
    finite_all(g0.positions.iter().flatten().copied(), "a body position")?;
    finite_all(g0.rotations.iter().flatten().copied(), "a body rotation")?;
    finite_all(g0.points.iter().flatten().copied(), "a force point")?;
    finite_all(g0.frames.iter().flatten().copied(), "a torque frame")?;

    // Jacobians, one coordinate at a time: [body or load][coordinate].
    let mut jac_body = vec![[0.0; 3]; lay.bodies * n];
    let mut ang_body = vec![[0.0; 3]; lay.bodies * n];
    let mut jac_point = vec![[0.0; 3]; lay.points * n];
    let mut ang_frame = vec![[0.0; 3]; lay.frames * n];
    let mut qd: Vec<Dual64> = q.iter().map(|&x| Dual64::new(x, 0.0)).collect();
    for r in 0..n {
        qd[r].eps = 1.0;
        let g = Geometry::<Dual64>::eval(model, lay, Dual64::new(t, 0.0), &qd)?;
        qd[r].eps = 0.0;
        for j in 0..lay.bodies {
            jac_body[j * n + r] = map3(&g.positions[j], |x| x.eps);
            let dr = map3(&g.rotations[j], |x| x.eps);
            ang_body[j * n + r] = vee(&mul_bt(&dr, &g0.rotations[j]));
        }
        for p in 0..lay.points {
            jac_point[p * n + r] = map3(&g.points[p], |x| x.eps);
        }
        for f in 0..lay.frames {
            let dr = map3(&g.frames[f], |x| x.eps);
            ang_frame[f * n + r] = vee(&mul_bt(&dr, &g0.frames[f]));
        }
    }

    // Velocities and acceleration remainders along (q + s q̇, t + s).
    let q2: Vec<Dual2_64> = q
        .iter()
        .zip(qdot)
        .map(|(&x, &v)| Dual2_64::new(x, v, 0.0))
        .collect();
    let mut pos2 = vec![[Dual2_64::zero(); 3]; lay.bodies];
    let mut rot2 = vec![[Dual2_64::zero(); 9]; lay.bodies];
    model.body_poses(Dual2_64::new(t, 1.0, 0.0), &q2, &mut pos2, &mut rot2)?;

    // Constraint rows, their rate along the motion, and load point velocities.
    let q1: Vec<Dual64> = q
        .iter()
        .zip(qdot)
        .map(|(&x, &v)| Dual64::new(x, v))
        .collect();
    let t1 = Dual64::new(t, 1.0);
    let mut dmat = vec![Dual64::zero(); m * n];
    let mut doff = vec![Dual64::zero(); m];
    model.constraint_rows(t1, &q1, &mut dmat, &mut doff)?;
    let g1 = Geometry::<Dual64>::eval(model, lay, t1, &q1)?;

    let mut forces = vec![[0.0; 3]; lay.points];
    let mut torques = vec![[0.0; 3]; lay.frames];
    model.load_values(t, q, qdot, inputs, &mut forces, &mut torques)?;
    finite_all(forces.iter().flatten().copied(), "a force")?;
    finite_all(torques.iter().flatten().copied(), "a torque")?;

    let mut mass = vec![0.0; n * n];
    let mut bias = vec![0.0; n];
    let mut kinetic_energy = 0.0;
    for j in 0..lay.bodies {
        let mj = masses[j];
        let v = map3(&pos2[j], |x| x.v1);
        let a = map3(&pos2[j], |x| x.v2);
        kinetic_energy += 0.5 * mj * dot(&v, &v);
        let jac = &jac_body[j * n..(j + 1) * n];
        for r in 0..n {
            for c in 0..n {
                mass[r * n + c] += mj * dot(&jac[r], &jac[c]);
            }
            bias[r] += mj * dot(&jac[r], &a);
        }
        if !info.bodies[j].rigid {
            continue;
        }
        let rot = &g0.rotations[j];
        let inertia_n = mul_bt(&mul(rot, &inertias[j]), rot);
        let rdot = map3(&rot2[j], |x| x.v1);
        let rddot = map3(&rot2[j], |x| x.v2);
        let w = vee(&mul_bt(&rdot, rot));
        let alpha = vee(&mul_bt(&rddot, rot));
        let iw = mat_vec(&inertia_n, &w);
        kinetic_energy += 0.5 * dot(&w, &iw);
        let ia = mat_vec(&inertia_n, &alpha);
        let gyro = cross(&w, &iw);
        let rot_bias = [ia[0] + gyro[0], ia[1] + gyro[1], ia[2] + gyro[2]];
        let ang = &ang_body[j * n..(j + 1) * n];
        for c in 0..n {
            let ig = mat_vec(&inertia_n, &ang[c]);
            for r in 0..n {
                mass[r * n + c] += dot(&ang[r], &ig);
            }
        }
        for r in 0..n {
            bias[r] += dot(&ang[r], &rot_bias);
        }
    }

    let mut gen_forces = vec![0.0; n];
    let mut power = 0.0;
    for p in 0..lay.points {
        for r in 0..n {
            gen_forces[r] += dot(&jac_point[p * n + r], &forces[p]);
        }
        power += dot(&map3(&g1.points[p], |x| x.eps), &forces[p]);
    }
    for f in 0..lay.frames {
        for r in 0..n {
            gen_forces[r] += dot(&ang_frame[f * n + r], &torques[f]);
        }
        let fdot = map3(&g1.frames[f], |x| x.eps);
        power += dot(&vee(&mul_bt(&fdot, &g0.frames[f])), &torques[f]);
    }

    let constraint_matrix: Vec<f64> = dmat.iter().map(|x| x.re).collect();
    let constraint_offset: Vec<f64> = doff.iter().map(|x| x.re).collect();
    let constraint_bias: Vec<f64> = (0..m)
        .map(|i| (0..n).map(|c| dmat[i * n + c].eps * qdot[c]).sum::<f64>() + doff[i].eps)
        .collect();

    let what = "the full-coordinate equations";
    finite_all(mass.iter().copied(), what)?;
    finite_all(bias.iter().copied(), what)?;
    finite_all(gen_forces.iter().copied(), what)?;
    finite_all(constraint_matrix.iter().copied(), what)?;
    finite_all(constraint_offset.iter().copied(), what)?;
    finite_all(constraint_bias.iter().copied(), what)?;
    finite_all([kinetic_energy, power], what)?;

    Ok(FullDynamics {
        n,
        m,
        mass,
        bias,
        forces: gen_forces,
        constraint_matrix,
        constraint_offset,
        constraint_bias,
        kinetic_energy,
        power,
    })
}

/// Solves the KKT system of `full`.
fn solve_kkt(full: &FullDynamics) -> Result<(Vec<f64>, Vec<f64>), OracleError> {
    let (n, m) = (full.n, full.m);
    let dim = n + m;
    let mut a = DMatrix::<f64>::zeros(dim, dim);
    let mut b = DVector::<f64>::zeros(dim);
    for r in 0..n {
        for c in 0..n {
            a[(r, c)] = full.mass[r * n + c];
        }
        b[r] = full.forces[r] - full.bias[r];
    }
    for i in 0..m {
        for c in 0..n {
            let dic = full.constraint_matrix[i * n + c];
            a[(n + i, c)] = dic;
            a[(c, n + i)] = dic;
        }
        b[n + i] = -full.constraint_bias[i];
    }
    let scale = a.amax();
    let x = lu_solve_checked(a, b, scale, |index, pivot, tolerance| {
        OracleError::SingularKkt {
            index,
            pivot,
            tolerance,
        }
    })?;
    finite_all(x.iter().copied(), "the accelerations")?;
    let qddot = x.rows(0, n).iter().copied().collect();
    let multipliers = x.rows(n, m).iter().map(|v| -v).collect();
    Ok((qddot, multipliers))
}

/// The accelerations q̈, the multipliers λ and the privileged accelerations at
/// `(t, q, q̇)` and `inputs`, by the full-coordinate multiplier route (example
/// in the module documentation).
///
/// `q̇` should satisfy the velocity constraints D q̇ + d = 0 (the result
/// answers "what would q̈ be at this state"; it is computed for any q̇).
/// Errors as for [`full_dynamics`], plus [`OracleError::SingularKkt`] when
/// the KKT matrix is singular.
pub fn accelerations<M: Model>(
    model: &M,
    t: f64,
    q: &[f64],
    qdot: &[f64],
    inputs: &[f64],
) -> Result<OracleSolution, OracleError> {
    let lay = Layout::new(M::info())?;
    accelerations_with(model, &lay, t, q, qdot, inputs)
}

fn accelerations_with<M: Model>(
    model: &M,
    lay: &Layout,
    t: f64,
    q: &[f64],
    qdot: &[f64],
    inputs: &[f64],
) -> Result<OracleSolution, OracleError> {
    let full = full_dynamics_with(model, lay, t, q, qdot, inputs)?;
    let (qddot, multipliers) = solve_kkt(&full)?;
    // u = W q̇ + w  ⇒  u̇ = W q̈ + (Ẇ q̇ + ẇ), the bias by a dual number
    // along (q̇, 1).
    let (n, l) = (lay.n, lay.l);
    let mut w = vec![0.0; l * n];
    let mut w0 = vec![0.0; l];
    model.speed_definitions(t, q, &mut w, &mut w0)?;
    let qd: Vec<Dual64> = q
        .iter()
        .zip(qdot)
        .map(|(&a, &b)| Dual64::new(a, b))
        .collect();
    let mut wd = vec![Dual64::from(0.0); l * n];
    let mut w0d = vec![Dual64::from(0.0); l];
    model.speed_definitions(Dual64::new(t, 1.0), &qd, &mut wd, &mut w0d)?;
    let privileged: Vec<f64> = (0..l)
        .map(|k| {
            let mut acc = w0d[k].eps;
            for c in 0..n {
                acc += w[k * n + c] * qddot[c] + wd[k * n + c].eps * qdot[c];
            }
            acc
        })
        .collect();
    finite_all(privileged.iter().copied(), "the privileged accelerations")?;
    Ok(OracleSolution {
        qddot,
        multipliers,
        privileged,
    })
}

/// All coordinate rates q̇ from the privileged speeds `u` (one per
/// [`ModelInfo::speeds`], in that order): the privileged rates are `u` and
/// the others solve D q̇ + d = 0 (LU with partial pivoting on the columns of
/// D at the dependent coordinates; a pivot within rounding noise of zero,
/// relative to the largest entry of D, counts as singular). Independent of
/// [`Model::coordinate_rates`]; example in the module documentation.
///
/// Errors: wrong lengths, non-finite values, an inconsistent [`ModelInfo`],
/// model errors, and [`OracleError::SingularConstraints`] when the dependent
/// block of D is singular.
pub fn coordinate_rates<M: Model>(
    model: &M,
    t: f64,
    q_full: &[f64],
    u: &[f64],
) -> Result<Vec<f64>, OracleError> {
    let lay = Layout::new(M::info())?;
    coordinate_rates_with(model, &lay, t, q_full, u)
}

fn coordinate_rates_with<M: Model>(
    model: &M,
    lay: &Layout,
    t: f64,
    q_full: &[f64],
    u: &[f64],
) -> Result<Vec<f64>, OracleError> {
    let (n, m, l) = (lay.n, lay.m, lay.l);
    check_len("q", q_full, n)?;
    check_len("u", u, l)?;
    finite_all([t], "t")?;
    finite_all(q_full.iter().copied(), "q")?;
    finite_all(u.iter().copied(), "u")?;
    let mut dmat = vec![0.0; m * n];
    let mut doff = vec![0.0; m];
    model.constraint_rows(t, q_full, &mut dmat, &mut doff)?;
    finite_all(dmat.iter().chain(&doff).copied(), "the constraint rows")?;
    let mut w = vec![0.0; l * n];
    let mut w0 = vec![0.0; l];
    model.speed_definitions(t, q_full, &mut w, &mut w0)?;
    finite_all(w.iter().chain(&w0).copied(), "the speed definitions")?;
    // [D; W] q̇ = [−d; u − w]
    let mut a = DMatrix::<f64>::zeros(n, n);
    let mut b = DVector::<f64>::zeros(n);
    for row in 0..m {
        for c in 0..n {
            a[(row, c)] = dmat[row * n + c];
        }
        b[row] = -doff[row];
    }
    for k in 0..l {
        for c in 0..n {
            a[(m + k, c)] = w[k * n + c];
        }
        b[m + k] = u[k] - w0[k];
    }
    let info = M::info();
    // Measured against the whole system: a column can be negligible only
    // relative to the rows it belongs to.
    let scale = dmat.iter().chain(&w).fold(0.0_f64, |s, x| s.max(x.abs()));
    let qdot = lu_solve_checked(a, b, scale, |k, pivot, tolerance| {
        OracleError::SingularConstraints {
            coordinate: info.coordinates[k.min(n - 1)],
            pivot,
            tolerance,
        }
    })?;
    finite_all(qdot.iter().copied(), "the coordinate rates")?;
    Ok(qdot.iter().copied().collect())
}

/// The reduced right-hand side in the layout of [`Model::rhs`]'s `dstate`:
/// the rates of the [`ModelInfo::retained`] coordinates, then the privileged
/// accelerations, at full coordinates `q_full` (ignorable ones included),
/// privileged speeds `u` and `inputs`.
///
/// q̇ comes from [`coordinate_rates`] (this module's, not the model's), q̈
/// from [`accelerations`]; errors are theirs. Example in the module
/// documentation.
pub fn reduced_rhs<M: Model>(
    model: &M,
    t: f64,
    q_full: &[f64],
    u: &[f64],
    inputs: &[f64],
) -> Result<Vec<f64>, OracleError> {
    let lay = Layout::new(M::info())?;
    let qdot = coordinate_rates_with(model, &lay, t, q_full, u)?;
    let sol = accelerations_with(model, &lay, t, q_full, &qdot, inputs)?;
    let mut out = Vec::with_capacity(lay.retained.len() + lay.l);
    out.extend(lay.retained.iter().map(|&i| qdot[i]));
    out.extend(sol.privileged);
    Ok(out)
}
