//! Linearization by dual numbers against closed forms and central
//! differences; eigenvalues; the holonomic Newton solve; the minimal
//! linearization on the constraint manifold (elimination of dependent
//! retained coordinates, fixed speeds); errors.
//!
//! The timing of Dual64 columns against one DualSVec64 pass is the ignored
//! test `dual64_vs_dualsvec64_timing`:
//! `cargo test -p appell-linearize --release --test linearize -- --ignored --nocapture`.

use appell_core::linalg::ldlt_solve;
use appell_core::{check_len, BodyInfo, Model, ModelError, ModelInfo, OpCounts, Scalar};
use appell_linearize::{
    eigenvalues, holonomic_unknowns, linearize, minimal_linearization, solve_holonomic,
    Linearization, LinearizeError,
};
use appell_test_models::*;
use nalgebra::DMatrix;
use num_dual::DualSVec64;
use std::f64::consts::PI;

const PENDULUM: Pendulum = Pendulum {
    m: 1.7,
    l: 0.8,
    g: 9.81,
};

const KNIFE: KnifeEdge = KnifeEdge {
    m: 2.5,
    i: 0.35,
    gx: 1.2,
    c: 0.4,
};

/// Constant length (b = 0): x² + y² = l².
const CARTESIAN: CartesianPendulum = CartesianPendulum {
    m: 0.9,
    l: 1.3,
    g: 9.81,
    b: 0.0,
    w: 0.0,
};

/// Time-dependent length ℓ(t) = l + b sin(w t).
const BREATHING: CartesianPendulum = CartesianPendulum {
    m: 0.9,
    l: 1.3,
    g: 9.81,
    b: 0.2,
    w: 1.7,
};

// ---------------------------------------------------------------------------
// Helpers.

fn max_abs_diff(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    assert_eq!(a.shape(), b.shape(), "shapes differ");
    a.iter()
        .zip(b.iter())
        .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()))
}

/// Central differences of `f` (n inputs, m outputs) at `x`.
fn central_jacobian(
    f: impl Fn(&[f64]) -> Vec<f64>,
    x: &[f64],
    m: usize,
    step: f64,
) -> DMatrix<f64> {
    let mut jac = DMatrix::zeros(m, x.len());
    let mut xp = x.to_vec();
    for j in 0..x.len() {
        xp[j] = x[j] + step;
        let fp = f(&xp);
        xp[j] = x[j] - step;
        let fm = f(&xp);
        xp[j] = x[j];
        for i in 0..m {
            jac[(i, j)] = (fp[i] - fm[i]) / (2.0 * step);
        }
    }
    jac
}

fn rhs_f64<M: Model>(model: &M, t: f64, state: &[f64], inputs: &[f64]) -> Vec<f64> {
    let p = model.prepare::<f64>();
    let mut out = vec![0.0; state.len()];
    model.rhs(&p, t, state, inputs, &mut out).unwrap();
    out
}

fn names(v: &[&str]) -> Vec<String> {
    v.iter().map(|s| s.to_string()).collect()
}

fn unused() -> ModelError {
    ModelError::NonFinite {
        what: "a method these tests do not use",
    }
}

/// The kinematic and energy methods, which the linearization never calls.
macro_rules! unused_methods {
    () => {
        fn mass_matrix_and_forcing<T: Scalar>(
            &self,
            _: T,
            _: &[T],
            _: &[T],
            _: &[T],
            _: &mut [T],
            _: &mut [T],
        ) -> Result<(), ModelError> {
            Err(unused())
        }
        fn speed_transform<T: Scalar>(
            &self,
            _: T,
            _: &[T],
            _: &mut [T],
            _: &mut [T],
        ) -> Result<(), ModelError> {
            Err(unused())
        }
        fn coordinate_rates<T: Scalar>(
            &self,
            _: T,
            _: &[T],
            _: &[T],
            _: &mut [T],
        ) -> Result<(), ModelError> {
            Err(unused())
        }
        fn kinetic_energy<T: Scalar>(&self, _: T, _: &[T], _: &[T]) -> Result<T, ModelError> {
            Err(unused())
        }
        fn mass_properties(&self, _: &mut [f64], _: &mut [[f64; 9]]) -> Result<(), ModelError> {
            Err(unused())
        }
        fn body_poses<T: Scalar>(
            &self,
            _: T,
            _: &[T],
            _: &mut [[T; 3]],
            _: &mut [[T; 9]],
        ) -> Result<(), ModelError> {
            Err(unused())
        }
        fn constraint_rows<T: Scalar>(
            &self,
            _: T,
            _: &[T],
            _: &mut [T],
            _: &mut [T],
        ) -> Result<(), ModelError> {
            Err(unused())
        }
        fn load_geometry<T: Scalar>(
            &self,
            _: T,
            _: &[T],
            _: &mut [[T; 3]],
            _: &mut [[T; 9]],
        ) -> Result<(), ModelError> {
            Err(unused())
        }
        fn load_values<T: Scalar>(
            &self,
            _: T,
            _: &[T],
            _: &[T],
            _: &[T],
            _: &mut [[T; 3]],
            _: &mut [[T; 3]],
        ) -> Result<(), ModelError> {
            Err(unused())
        }
    };
}

const NO_OPS: OpCounts = OpCounts {
    add: 0,
    mul: 0,
    div: 0,
    calls: 0,
    total: 0,
};

const BASE_INFO: ModelInfo = ModelInfo {
    name: "",
    parameters: &[],
    coordinates: &[],
    speeds: &[],
    dependent: &[],
    cyclic: &[],
    ignorable: &[],
    retained: &[],
    inputs: &[],
    effects: &[],
    outputs: &[],
    row_sources: &[],
    contacts: &[],
    holonomic: 0,
    constraints: 0,
    bodies: &[BodyInfo {
        name: "P",
        rigid: false,
    }],
    force_points: 0,
    torques: 0,
    form: "closed form",
    symbolic_elimination: true,
    rhs_ops: NO_OPS,
    jacobian: None,
    equations: "",
};

// ---------------------------------------------------------------------------
// Small hand-written models for the constraint bookkeeping. Their rates are
// arbitrary smooth functions (only the bookkeeping is under test), except
// `SpinCart`, whose x'' is the Cartesian pendulum's.

/// `Toy<0>` "Sphere": coordinates (x, y, z), speed x, y and z dependent and
/// retained, one constraint x² + y² + z² = 1: it cannot fix both y and z.
/// `Toy<1>` "Cusp": coordinates (x, y), speed x, y dependent, x² + y³ = 1:
/// at (1, 0) the constraint fixes x, not y, at first order.
/// `Toy<2>` "Absorbed": coordinates (x, y, c), speed x, y and c dependent, c
/// ignorable, x² + y² + c = 1: c takes the constraint up, y stays free.
/// `Toy<3>` "Shared": as Absorbed, with x² + y² = 1 and c = x y: y follows x.
/// `Toy<4>` "SpinCart": coordinates (phi, x, y), speeds phi and x, y
/// dependent, x² + y² = l²; a torsional rotor phi coupled to the Cartesian
/// pendulum (x, y).
/// `Toy<5>` "CircleLine": coordinates (x, y), no speeds, x² + y² = 1 and
/// x + s y = c (two holonomic constraints, for the Newton solve).
#[derive(Clone, Copy, Debug)]
struct Toy<const K: u8> {
    /// A parameter (l for SpinCart, s for CircleLine).
    p: f64,
    /// Another (the line's offset c for CircleLine).
    q: f64,
}

static SPHERE_INFO: ModelInfo = ModelInfo {
    name: "Sphere",
    coordinates: &["x", "y", "z"],
    speeds: &["x"],
    dependent: &["y", "z"],
    retained: &["x", "y", "z"],
    holonomic: 1,
    constraints: 2,
    ..BASE_INFO
};

static CUSP_INFO: ModelInfo = ModelInfo {
    name: "Cusp",
    coordinates: &["x", "y"],
    speeds: &["x"],
    dependent: &["y"],
    retained: &["x", "y"],
    holonomic: 1,
    constraints: 1,
    ..BASE_INFO
};

static ABSORBED_INFO: ModelInfo = ModelInfo {
    name: "Absorbed",
    coordinates: &["x", "y", "c"],
    speeds: &["x"],
    dependent: &["y", "c"],
    ignorable: &["c"],
    cyclic: &["c"],
    retained: &["x", "y"],
    holonomic: 1,
    constraints: 2,
    ..BASE_INFO
};

static SHARED_INFO: ModelInfo = ModelInfo {
    name: "Shared",
    holonomic: 2,
    ..ABSORBED_INFO
};

static SPIN_CART_INFO: ModelInfo = ModelInfo {
    name: "SpinCart",
    parameters: &["l"],
    coordinates: &["phi", "x", "y"],
    speeds: &["phi", "x"],
    dependent: &["y"],
    retained: &["phi", "x", "y"],
    inputs: &["tau"],
    holonomic: 1,
    constraints: 1,
    ..BASE_INFO
};

static CIRCLE_LINE_INFO: ModelInfo = ModelInfo {
    name: "CircleLine",
    parameters: &["s", "c"],
    coordinates: &["x", "y"],
    dependent: &["x", "y"],
    holonomic: 2,
    constraints: 2,
    ..BASE_INFO
};

const SPIN_K: f64 = 3.0;
const SPIN_E: f64 = 0.7;
const SPIN_G: f64 = 9.81;

impl<const K: u8> Model for Toy<K> {
    type Prepared<T: Scalar> = ();

    fn info() -> &'static ModelInfo {
        match K {
            0 => &SPHERE_INFO,
            1 => &CUSP_INFO,
            2 => &ABSORBED_INFO,
            3 => &SHARED_INFO,
            4 => &SPIN_CART_INFO,
            _ => &CIRCLE_LINE_INFO,
        }
    }

    fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> {
        let params = Self::info().parameters.len();
        check_len("out", out, params)?;
        out.copy_from_slice(&[self.p, self.q][..params]);
        Ok(())
    }

    fn set_parameter(&mut self, _: &str, _: f64) -> bool {
        false
    }

    fn prepare<T: Scalar>(&self) {}

    fn rhs<T: Scalar>(
        &self,
        _: &(),
        _t: T,
        s: &[T],
        inputs: &[T],
        ds: &mut [T],
    ) -> Result<(), ModelError> {
        let info = Self::info();
        check_len("state", s, info.state_len())?;
        check_len("inputs", inputs, info.inputs.len())?;
        check_len("dstate", ds, info.state_len())?;
        let c = T::from_f64;
        match K {
            // (x, y, z, u)
            0 => ds.copy_from_slice(&[s[3], -(s[0] * s[3]), s[1] * s[3], -s[0] - s[2]]),
            // (x, y, u)
            1 => ds.copy_from_slice(&[s[2], s[0] * s[2], -s[0] - s[1] * s[1]]),
            // (x, y, u)
            2 | 3 => ds.copy_from_slice(&[s[2], -(s[0] * s[2]), -s[0] - c(0.5) * s[1].sin()]),
            // (phi, x, y, w, u)
            4 => {
                let (phi, x, y, w, u) = (s[0], s[1], s[2], s[3], s[4]);
                if y.re() == 0.0 {
                    return Err(ModelError::SingularConstraints {
                        column: 0,
                        pivot: 0.0,
                    });
                }
                let ydot = -(x * u) / y;
                let l2 = c(self.p * self.p);
                ds[0] = w;
                ds[1] = u;
                ds[2] = ydot;
                ds[3] = -(c(SPIN_K) * phi.sin()) + c(SPIN_E) * u * x + inputs[0];
                ds[4] = x * (c(SPIN_G) * y - u * u - ydot * ydot) / l2 + c(SPIN_E) * w * w * x;
            }
            _ => {}
        }
        Ok(())
    }

    fn constraint_residuals<T: Scalar>(
        &self,
        _t: T,
        q: &[T],
        qdot: &[T],
        holonomic: &mut [T],
        velocity: &mut [T],
    ) -> Result<(), ModelError> {
        let info = Self::info();
        check_len("q", q, info.coordinates.len())?;
        check_len("qdot", qdot, info.coordinates.len())?;
        check_len("holonomic", holonomic, info.holonomic)?;
        check_len("velocity", velocity, info.constraints)?;
        let c = T::from_f64;
        let one = T::one();
        match K {
            0 => {
                holonomic[0] = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] - one;
                velocity[0] = q[0] * qdot[0] + q[1] * qdot[1] + q[2] * qdot[2];
                velocity[1] = qdot[2] - q[0] * qdot[0];
            }
            1 => {
                holonomic[0] = q[0] * q[0] + q[1] * q[1] * q[1] - one;
                velocity[0] = c(2.0) * q[0] * qdot[0] + c(3.0) * q[1] * q[1] * qdot[1];
            }
            2 => {
                holonomic[0] = q[0] * q[0] + q[1] * q[1] + q[2] - one;
                velocity[0] = c(2.0) * (q[0] * qdot[0] + q[1] * qdot[1]) + qdot[2];
                velocity[1] = qdot[1] + q[0] * qdot[0];
            }
            3 => {
                holonomic[0] = q[0] * q[0] + q[1] * q[1] - one;
                holonomic[1] = q[2] - q[0] * q[1];
                velocity[0] = q[0] * qdot[0] + q[1] * qdot[1];
                velocity[1] = qdot[2] - q[0] * qdot[1] - q[1] * qdot[0];
            }
            4 => {
                holonomic[0] = q[1] * q[1] + q[2] * q[2] - c(self.p * self.p);
                velocity[0] = q[1] * qdot[1] + q[2] * qdot[2];
            }
            _ => {
                holonomic[0] = q[0] * q[0] + q[1] * q[1] - one;
                holonomic[1] = q[0] + c(self.p) * q[1] - c(self.q);
                velocity[0] = q[0] * qdot[0] + q[1] * qdot[1];
                velocity[1] = qdot[0] + c(self.p) * qdot[1];
            }
        }
        Ok(())
    }

    unused_methods!();
}

const SPHERE: Toy<0> = Toy { p: 0.0, q: 0.0 };
const CUSP: Toy<1> = Toy { p: 0.0, q: 0.0 };
const ABSORBED: Toy<2> = Toy { p: 0.0, q: 0.0 };
const SHARED: Toy<3> = Toy { p: 0.0, q: 0.0 };
const SPIN_CART: Toy<4> = Toy { p: 1.1, q: 0.0 };
/// The line x + 0.5 y = 0.2 and the unit circle: they meet at (0.6, −0.8)
/// (see `circle_line_point`) and at (−0.28, 0.96).
const CIRCLE_LINE: Toy<5> = Toy { p: 0.5, q: 0.2 };

/// The intersection of the unit circle with x + s y = c that has y < 0.
fn circle_line_point(s: f64, c: f64) -> [f64; 2] {
    // (c − s y)² + y² = 1  →  (1 + s²) y² − 2 c s y + c² − 1 = 0.
    let (a, b, cc) = (1.0 + s * s, -2.0 * c * s, c * c - 1.0);
    let y = (-b - (b * b - 4.0 * a * cc).sqrt()) / (2.0 * a);
    [c - s * y, y]
}

// ---------------------------------------------------------------------------
// (a) The pendulum: A exactly, eigenvalues at both equilibria.

#[test]
fn pendulum_a_is_exact() {
    let gl = PENDULUM.g / PENDULUM.l;
    for theta in [0.0, 0.3, -1.1, 2.5, PI] {
        for omega in [0.0, 1.7] {
            let lin = linearize(&PENDULUM, 0.4, &[theta, omega], &[]).unwrap();
            let exact = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -gl * theta.cos(), 0.0]);
            assert!(
                max_abs_diff(&lin.a, &exact) <= 1e-14,
                "θ = {theta}: {} vs {exact}",
                lin.a
            );
            assert_eq!(lin.b.shape(), (2, 0));
            assert_eq!(lin.state_names, names(&["theta", "theta_dot"]));
            assert!(lin.input_names.is_empty());
        }
    }
}

#[test]
fn pendulum_eigenvalues_at_both_equilibria() {
    let w = (PENDULUM.g / PENDULUM.l).sqrt();
    let bottom = linearize(&PENDULUM, 0.0, &[0.0, 0.0], &[]).unwrap();
    let eig = eigenvalues(&bottom.a).unwrap();
    assert_eq!(eig.len(), 2);
    assert_close(eig[0].0, 0.0, 1e-14, "re");
    assert_close(eig[0].1, -w, 1e-14, "im");
    assert_close(eig[1].0, 0.0, 1e-14, "re");
    assert_close(eig[1].1, w, 1e-14, "im");

    let top = linearize(&PENDULUM, 0.0, &[PI, 0.0], &[]).unwrap();
    let eig = eigenvalues(&top.a).unwrap();
    assert_close(eig[0].0, -w, 1e-14, "re");
    assert_eq!(eig[0].1, 0.0);
    assert_close(eig[1].0, w, 1e-14, "re");
    assert_eq!(eig[1].1, 0.0);
}

// ---------------------------------------------------------------------------
// (b) Inputs: B, and A off equilibrium, in closed form.

#[test]
fn knife_edge_a_and_b_in_closed_form() {
    let k = KNIFE;
    let mut rng = Rng(11);
    for _ in 0..50 {
        let (phi, ux, uphi, tau) = (
            rng.uniform(-1.2, 1.2),
            rng.uniform(-2.0, 2.0),
            rng.uniform(-2.0, 2.0),
            rng.uniform(-1.0, 1.0),
        );
        let lin = linearize(&k, 0.0, &[phi, ux, uphi], &[tau]).unwrap();
        assert_eq!(lin.state_names, names(&["phi", "x_dot", "phi_dot"]));
        assert_eq!(lin.input_names, names(&["tau"]));
        // ẍ = gx cos²φ − (c/m) ẋ − ẋ φ̇ tan φ, φ̈ = τ / i.
        let sec2 = 1.0 / (phi.cos() * phi.cos());
        let exact_a = DMatrix::from_row_slice(
            3,
            3,
            &[
                0.0,
                0.0,
                1.0,
                -2.0 * k.gx * phi.cos() * phi.sin() - ux * uphi * sec2,
                -k.c / k.m - uphi * phi.tan(),
                -ux * phi.tan(),
                0.0,
                0.0,
                0.0,
            ],
        );
        let exact_b = DMatrix::from_row_slice(3, 1, &[0.0, 0.0, 1.0 / k.i]);
        assert!(max_abs_diff(&lin.a, &exact_a) <= 1e-13, "{}", lin.a);
        assert!(max_abs_diff(&lin.b, &exact_b) <= 1e-15, "{}", lin.b);
    }
}

#[test]
fn gyro_matches_central_differences() {
    let mut rng = Rng(5);
    for _ in 0..10 {
        let state: Vec<f64> = (0..6).map(|_| rng.uniform(-0.8, 0.8)).collect();
        let inputs: Vec<f64> = (0..3).map(|_| rng.uniform(-1.0, 1.0)).collect();
        let t = rng.uniform(0.0, 2.0);
        let lin = linearize(&GYRO, t, &state, &inputs).unwrap();
        assert_eq!(
            lin.state_names,
            names(&["psi", "theta", "phi", "psi_dot", "theta_dot", "phi_dot"])
        );
        let fd_a = central_jacobian(|x| rhs_f64(&GYRO, t, x, &inputs), &state, 6, 1e-6);
        let fd_b = central_jacobian(|u| rhs_f64(&GYRO, t, &state, u), &inputs, 6, 1e-6);
        assert!(max_abs_diff(&lin.a, &fd_a) < 1e-7, "{}\n{}", lin.a, fd_a);
        assert!(max_abs_diff(&lin.b, &fd_b) < 1e-7, "{}\n{}", lin.b, fd_b);
    }
}

#[test]
fn linearize_reports_bad_input() {
    let len = |argument, expected, found| ModelError::Length {
        argument,
        expected,
        found,
    };
    assert_eq!(
        linearize(&KNIFE, 0.0, &[0.1, 0.2], &[0.0]),
        Err(len("state", 3, 2))
    );
    assert_eq!(
        linearize(&KNIFE, 0.0, &[0.1, 0.2, 0.3], &[]),
        Err(len("inputs", 1, 0))
    );
    assert!(matches!(
        linearize(&KNIFE, 0.0, &[0.1, f64::NAN, 0.3], &[0.0]),
        Err(ModelError::NonFinite { .. })
    ));
    assert!(matches!(
        linearize(&KNIFE, 0.0, &[0.1, 0.2, 0.3], &[f64::INFINITY]),
        Err(ModelError::NonFinite { .. })
    ));
    assert!(matches!(
        linearize(&KNIFE, f64::NAN, &[0.1, 0.2, 0.3], &[0.0]),
        Err(ModelError::NonFinite { .. })
    ));
    // The model's own error at a singular configuration (cos φ = 0).
    assert!(matches!(
        linearize(&KNIFE, 0.0, &[PI / 2.0, 0.2, 0.3], &[0.0]),
        Err(ModelError::SingularConstraints { .. })
    ));
    // y = 0: the Cartesian pendulum's dependent rate is undetermined.
    assert!(matches!(
        linearize(&CARTESIAN, 0.0, &[1.3, 0.0, 0.0], &[]),
        Err(ModelError::SingularConstraints { .. })
    ));
}

// ---------------------------------------------------------------------------
// Eigenvalues.

#[test]
fn eigenvalues_sorted_and_deterministic() {
    // Block diagonal: a rotation-like block (−0.5 ± 2i), 3, −1, (1 ± 0.25i).
    let mut a = DMatrix::<f64>::zeros(6, 6);
    a[(0, 0)] = -0.5;
    a[(0, 1)] = 2.0;
    a[(1, 0)] = -2.0;
    a[(1, 1)] = -0.5;
    a[(2, 2)] = 3.0;
    a[(3, 3)] = -1.0;
    a[(4, 4)] = 1.0;
    a[(4, 5)] = 0.25;
    a[(5, 4)] = -0.25;
    a[(5, 5)] = 1.0;
    // A similarity transform mixes everything; the eigenvalues stay.
    let mut rng = Rng(3);
    let s = DMatrix::from_fn(
        6,
        6,
        |i, j| {
            if i == j {
                2.0
            } else {
                rng.uniform(-0.5, 0.5)
            }
        },
    );
    let mixed = &s * &a * s.clone().try_inverse().unwrap();
    let eig = eigenvalues(&mixed).unwrap();
    let expected = [
        (-1.0, 0.0),
        (-0.5, -2.0),
        (-0.5, 2.0),
        (1.0, -0.25),
        (1.0, 0.25),
        (3.0, 0.0),
    ];
    assert_eq!(eig.len(), 6);
    for (got, want) in eig.iter().zip(expected) {
        assert!(
            (got.0 - want.0).abs() < 1e-12 && (got.1 - want.1).abs() < 1e-12,
            "{eig:?}"
        );
    }
    assert_eq!(eigenvalues(&mixed).unwrap(), eig);
}

#[test]
fn eigenvalues_edge_cases() {
    assert_eq!(eigenvalues(&DMatrix::<f64>::zeros(0, 0)).unwrap(), vec![]);
    assert_eq!(
        eigenvalues(&DMatrix::from_element(1, 1, -2.5)).unwrap(),
        vec![(-2.5, 0.0)]
    );
    assert_eq!(
        eigenvalues(&DMatrix::<f64>::zeros(3, 3)).unwrap(),
        vec![(0.0, 0.0); 3]
    );
    assert_eq!(
        eigenvalues(&DMatrix::<f64>::zeros(2, 3)),
        Err(LinearizeError::NotSquare { rows: 2, cols: 3 })
    );
    let mut bad = DMatrix::<f64>::identity(3, 3);
    bad[(1, 2)] = f64::INFINITY;
    assert!(matches!(
        eigenvalues(&bad),
        Err(LinearizeError::NonFinite { .. })
    ));
    // A nilpotent Jordan block and a defective matrix do not break it.
    let jordan = DMatrix::from_row_slice(3, 3, &[0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]);
    let eig = eigenvalues(&jordan).unwrap();
    assert!(eig.iter().all(|e| e.0.abs() < 1e-12 && e.1.abs() < 1e-12));
}

// ---------------------------------------------------------------------------
// (c) The holonomic Newton solve.

#[test]
fn newton_recovers_the_cartesian_pendulum() {
    let l = CARTESIAN.l;
    for x in [0.0, 0.3, -0.9, 1.2] {
        for dy in [0.3, -0.2, 1e-3] {
            let exact = -(l * l - x * x).sqrt();
            let mut q = [x, exact + dy];
            let iterations = solve_holonomic(&CARTESIAN, 0.0, &mut q, &[1], 1e-14, 20).unwrap();
            assert!(
                iterations <= 6,
                "x = {x}, dy = {dy}: {iterations} iterations"
            );
            assert!(iterations >= 1);
            assert!((q[1] - exact).abs() <= 1e-14, "{} vs {exact}", q[1]);
            assert_eq!(q[0], x, "x is held");
        }
    }
}

#[test]
fn newton_with_a_time_dependent_constraint() {
    let t = 0.8;
    let (len, _, _) = BREATHING.length(t);
    let mut q = [0.5, -1.0];
    solve_holonomic(&BREATHING, t, &mut q, &[1], 1e-14, 20).unwrap();
    assert_close(q[1], -(len * len - 0.25).sqrt(), 1e-14, "y");
}

#[test]
fn newton_already_satisfied_takes_no_step() {
    let mut q = [0.0, -CARTESIAN.l];
    assert_eq!(
        solve_holonomic(&CARTESIAN, 0.0, &mut q, &[1], 1e-14, 20),
        Ok(0)
    );
    // No holonomic constraints: trivially satisfied.
    let mut theta = [0.4];
    assert_eq!(
        solve_holonomic(&PENDULUM, 0.0, &mut theta, &[0], 0.0, 5),
        Ok(0)
    );
    assert_eq!(theta, [0.4]);
}

#[test]
fn newton_underdetermined_takes_minimum_norm_steps() {
    // Both coordinates free: the nearest point of the circle, roughly.
    let l = CARTESIAN.l;
    let mut q = [0.9, -0.7];
    let iterations = solve_holonomic(&CARTESIAN, 0.0, &mut q, &[0, 1], 1e-13, 20).unwrap();
    assert!(iterations <= 6);
    assert!((q[0] * q[0] + q[1] * q[1] - l * l).abs() <= 1e-13);
    // Minimum-norm steps on x² + y² are radial: the direction is kept.
    assert_close(q[1].atan2(q[0]), (-0.7_f64).atan2(0.9), 1e-12, "angle");
}

#[test]
fn newton_square_and_overdetermined_systems() {
    let exact = circle_line_point(CIRCLE_LINE.p, CIRCLE_LINE.q);
    // Two residuals, two unknowns.
    let mut q = [exact[0] + 0.1, exact[1] - 0.15];
    let iterations = solve_holonomic(&CIRCLE_LINE, 0.0, &mut q, &[0, 1], 1e-14, 20).unwrap();
    assert!(iterations <= 6);
    assert!((q[0] - exact[0]).abs() < 1e-14 && (q[1] - exact[1]).abs() < 1e-14);

    // Two residuals, one unknown, consistent (x is already right): Gauss-Newton.
    let mut q = [exact[0], exact[1] + 0.1];
    let iterations = solve_holonomic(&CIRCLE_LINE, 0.0, &mut q, &[1], 1e-14, 20).unwrap();
    assert!(iterations <= 8, "{iterations}");
    assert!((q[1] - exact[1]).abs() < 1e-14);

    // Inconsistent (x is wrong): the least-squares point, not a solution.
    let mut q = [exact[0] + 0.05, exact[1]];
    match solve_holonomic(&CIRCLE_LINE, 0.0, &mut q, &[1], 1e-12, 50) {
        Err(LinearizeError::NotConverged { residual, .. }) => {
            assert!(residual > 1e-3 && residual.is_finite(), "{residual}")
        }
        other => panic!("expected NotConverged, got {other:?}"),
    }
}

#[test]
fn newton_failures_are_typed() {
    let l = CARTESIAN.l;
    // Too few iterations.
    let mut q = [0.3, -0.2];
    match solve_holonomic(&CARTESIAN, 0.0, &mut q, &[1], 1e-14, 1) {
        Err(LinearizeError::NotConverged {
            iterations,
            residual,
        }) => {
            assert_eq!(iterations, 1);
            assert!(residual > 1e-3);
        }
        other => panic!("expected NotConverged, got {other:?}"),
    }
    // No solution: x beyond the circle.
    let x = 1.5 * l;
    let mut q = [x, -0.5];
    match solve_holonomic(&CARTESIAN, 0.0, &mut q, &[1], 1e-12, 40) {
        Err(LinearizeError::NotConverged { residual, .. }) => {
            assert!(residual >= x * x - l * l - 1e-12, "{residual}")
        }
        Err(LinearizeError::RankDeficient { .. }) => {}
        other => panic!("expected a failure, got {other:?}"),
    }
    assert!(q.iter().all(|v| v.is_finite()));
    // ∂f/∂y = 2y = 0: y is not determined at first order.
    let mut q = [0.5, 0.0];
    assert_eq!(
        solve_holonomic(&CARTESIAN, 0.0, &mut q, &[1], 1e-14, 20),
        Err(LinearizeError::RankDeficient {
            rank: 0,
            expected: 1
        })
    );
    // The whole Jacobian vanishes at the origin.
    let mut q = [0.0, 0.0];
    assert_eq!(
        solve_holonomic(&CARTESIAN, 0.0, &mut q, &[0, 1], 1e-14, 20),
        Err(LinearizeError::RankDeficient {
            rank: 0,
            expected: 1
        })
    );
    // Nothing to adjust, constraint violated.
    let mut q = [0.3, -0.2];
    assert!(matches!(
        solve_holonomic(&CARTESIAN, 0.0, &mut q, &[], 1e-14, 20),
        Err(LinearizeError::NotConverged { iterations: 0, .. })
    ));
}

#[test]
fn newton_rejects_bad_arguments() {
    let mut q = [0.3, -1.0];
    for (unknowns, tol) in [
        (&[2][..], 1e-14),
        (&[1, 1][..], 1e-14),
        (&[1][..], -1.0),
        (&[1][..], f64::NAN),
    ] {
        assert!(
            matches!(
                solve_holonomic(&CARTESIAN, 0.0, &mut q, unknowns, tol, 20),
                Err(LinearizeError::InvalidArgument(_))
            ),
            "{unknowns:?}, {tol}"
        );
    }
    assert!(matches!(
        solve_holonomic(&CARTESIAN, 0.0, &mut [0.3], &[0], 1e-14, 20),
        Err(LinearizeError::Model(ModelError::Length { .. }))
    ));
    assert!(matches!(
        solve_holonomic(&CARTESIAN, 0.0, &mut [0.3, f64::NAN], &[1], 1e-14, 20),
        Err(LinearizeError::Model(ModelError::NonFinite { .. }))
    ));
    assert_eq!(q, [0.3, -1.0], "untouched by rejected calls");
    let e = LinearizeError::NotConverged {
        iterations: 3,
        residual: 0.5,
    };
    assert!(e.to_string().contains("3 Newton steps"));
    let e: LinearizeError = ModelError::NonFinite { what: "q" }.into();
    assert!(std::error::Error::source(&e).is_some());
}

#[test]
fn holonomic_unknowns_pick_the_involved_dependents() {
    assert_eq!(
        holonomic_unknowns(&CARTESIAN, 0.0, &[0.3, -1.0]).unwrap(),
        [1]
    );
    // No holonomic constraints.
    assert!(holonomic_unknowns(&PENDULUM, 0.0, &[0.3])
        .unwrap()
        .is_empty());
    assert!(holonomic_unknowns(&KNIFE, 0.0, &[0.0, 0.0, 0.3])
        .unwrap()
        .is_empty());
    // Both dependents appear; with y = 0, only z's derivative is non-zero.
    assert_eq!(
        holonomic_unknowns(&SPHERE, 0.0, &[0.1, 0.2, 0.3]).unwrap(),
        [1, 2]
    );
    assert_eq!(
        holonomic_unknowns(&SPHERE, 0.0, &[0.1, 0.0, 0.3]).unwrap(),
        [2]
    );
    assert_eq!(
        holonomic_unknowns(&ABSORBED, 0.0, &[0.1, 0.2, 0.3]).unwrap(),
        [1, 2]
    );
    assert!(matches!(
        holonomic_unknowns(&CARTESIAN, 0.0, &[0.3]),
        Err(LinearizeError::Model(ModelError::Length { .. }))
    ));
}

// ---------------------------------------------------------------------------
// (d) The minimal linearization on the constraint manifold.

#[test]
fn cartesian_pendulum_minimal_at_the_bottom() {
    let (g, l) = (CARTESIAN.g, CARTESIAN.l);
    let min = minimal_linearization(&CARTESIAN, 0.0, &[0.0, -l], &[0.0], &[], &[]).unwrap();
    assert_eq!(min.state_names, names(&["x", "x_dot"]));
    assert_eq!(min.b.shape(), (2, 0));
    let exact = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -g / l, 0.0]);
    assert!(max_abs_diff(&min.a, &exact) < 1e-14, "{}", min.a);
    let w = (g / l).sqrt();
    let eig = eigenvalues(&min.a).unwrap();
    assert!(
        eig[0].0.abs() < 1e-14 && (eig[0].1 + w).abs() < 1e-14,
        "{eig:?}"
    );
    assert!(
        eig[1].0.abs() < 1e-14 && (eig[1].1 - w).abs() < 1e-14,
        "{eig:?}"
    );

    // The full reduced state (x, y, ẋ) has the extra zero eigenvalue of y.
    let full = linearize(&CARTESIAN, 0.0, &[0.0, -l, 0.0], &[]).unwrap();
    let eig = eigenvalues(&full.a).unwrap();
    assert_eq!(eig.len(), 3);
    assert!(eig.iter().any(|e| e.0.abs() < 1e-14 && e.1.abs() < 1e-14));
}

/// Central differences of the reduced rhs along the manifold: z = (x, ẋ),
/// y = −√(ℓ(t)² − x²).
fn cartesian_on_manifold(model: &CartesianPendulum, t: f64, z: &[f64]) -> Vec<f64> {
    let (len, _, _) = model.length(t);
    let y = -(len * len - z[0] * z[0]).sqrt();
    let d = rhs_f64(model, t, &[z[0], y, z[1]], &[]);
    vec![d[0], d[2]]
}

#[test]
fn cartesian_pendulum_minimal_off_the_bottom() {
    let (g, l) = (CARTESIAN.g, CARTESIAN.l);
    // At rest at x0, in closed form: ẍ on the circle is −g x √(l² − x²) / l².
    for x0 in [0.2, -0.5, 0.9] {
        let r = (l * l - x0 * x0).sqrt();
        let min = minimal_linearization(&CARTESIAN, 0.0, &[x0, -r], &[0.0], &[], &[]).unwrap();
        let d = -g / (l * l) * (r - x0 * x0 / r);
        let exact = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, d, 0.0]);
        assert!(max_abs_diff(&min.a, &exact) < 1e-13, "{}", min.a);
    }
    // Moving, with a breathing length, against differences along the manifold.
    let mut rng = Rng(9);
    for _ in 0..10 {
        let t = rng.uniform(0.0, 3.0);
        let (len, _, _) = BREATHING.length(t);
        let x0 = rng.uniform(-0.8, 0.8);
        let u0 = rng.uniform(-1.5, 1.5);
        let mut q = [x0, -1.0];
        solve_holonomic(&BREATHING, t, &mut q, &[1], 1e-14, 20).unwrap();
        assert_close(q[1], -(len * len - x0 * x0).sqrt(), 1e-14, "y");
        let min = minimal_linearization(&BREATHING, t, &q, &[u0], &[], &[]).unwrap();
        let fd = central_jacobian(
            |z| cartesian_on_manifold(&BREATHING, t, z),
            &[x0, u0],
            2,
            1e-6,
        );
        assert!(max_abs_diff(&min.a, &fd) < 1e-7, "{}\n{}", min.a, fd);
    }
}

#[test]
fn minimal_linearization_without_holonomic_constraints_is_linearize() {
    let mut rng = Rng(21);
    let state: Vec<f64> = (0..6).map(|_| rng.uniform(-0.7, 0.7)).collect();
    let inputs = [0.1, -0.3, 0.2];
    let full = linearize(&GYRO, 0.5, &state, &inputs).unwrap();
    let min = minimal_linearization(&GYRO, 0.5, &state[..3], &state[3..], &inputs, &[]).unwrap();
    assert_eq!(min, full);
}

#[test]
fn ignorable_coordinates_take_up_constraints() {
    // Absorbed: c = 1 − x² − y² follows; y is not fixed, nothing eliminated.
    let q = [0.3, -0.4, 1.0 - 0.09 - 0.16];
    let full = linearize(&ABSORBED, 0.0, &[0.3, -0.4, 0.7], &[]).unwrap();
    let min = minimal_linearization(&ABSORBED, 0.0, &q, &[0.7], &[], &[]).unwrap();
    assert_eq!(min, full);

    // Shared: x² + y² = 1 fixes y (c = x y takes the second one up).
    let (x, y) = (0.6, -0.8);
    let min = minimal_linearization(&SHARED, 0.0, &[x, y, x * y], &[0.7], &[], &[]).unwrap();
    assert_eq!(min.state_names, names(&["x", "x_dot"]));
    let full = linearize(&SHARED, 0.0, &[x, y, 0.7], &[]).unwrap();
    // z = (x, ẋ) → (x, y, ẋ): dy/dx = −x / y.
    let t = DMatrix::from_row_slice(3, 2, &[1.0, 0.0, -x / y, 0.0, 0.0, 1.0]);
    let expected = full.a.select_rows(&[0, 2]) * t;
    assert!(max_abs_diff(&min.a, &expected) < 1e-15, "{}", min.a);
}

#[test]
fn minimal_linearization_failures_are_typed() {
    let l = CARTESIAN.l;
    // Off the circle.
    assert!(matches!(
        minimal_linearization(&CARTESIAN, 0.0, &[0.1, -1.0], &[0.0], &[], &[]),
        Err(LinearizeError::NotOnManifold { .. })
    ));
    // One constraint cannot fix both y and z.
    let (x, y): (f64, f64) = (0.3, -0.4);
    let z = -(1.0 - x * x - y * y).sqrt();
    assert_eq!(
        minimal_linearization(&SPHERE, 0.0, &[x, y, z], &[0.2], &[], &[]),
        Err(LinearizeError::RankDeficient {
            rank: 1,
            expected: 2
        })
    );
    // At (1, 0) the cusp's constraint fixes x, the independent coordinate.
    assert!(matches!(
        minimal_linearization(&CUSP, 0.0, &[1.0, 0.0], &[0.2], &[], &[]),
        Err(LinearizeError::SingularCoordinates { .. })
    ));
    // Unknown fixed speed; wrong lengths; non-finite values; the model's error.
    assert_eq!(
        minimal_linearization(&CARTESIAN, 0.0, &[0.0, -l], &[0.0], &[], &["y"]),
        Err(LinearizeError::UnknownName("y".to_string()))
    );
    assert!(matches!(
        minimal_linearization(&CARTESIAN, 0.0, &[0.0, -l], &[], &[], &[]),
        Err(LinearizeError::Model(ModelError::Length { .. }))
    ));
    assert!(matches!(
        minimal_linearization(&CARTESIAN, 0.0, &[0.0, -l], &[0.0], &[1.0], &[]),
        Err(LinearizeError::Model(ModelError::Length { .. }))
    ));
    assert!(matches!(
        minimal_linearization(&CARTESIAN, 0.0, &[0.0, -l], &[f64::NAN], &[], &[]),
        Err(LinearizeError::Model(ModelError::NonFinite { .. }))
    ));
    assert!(matches!(
        minimal_linearization(&CARTESIAN, 0.0, &[l, 0.0], &[0.0], &[], &[]),
        Err(LinearizeError::Model(
            ModelError::SingularConstraints { .. }
        ))
    ));
}

// ---------------------------------------------------------------------------
// (e) Fixed speeds.

#[test]
fn a_fixed_speed_is_dropped() {
    // Knife edge, state (φ, ẋ, φ̇): holding ẋ leaves (φ, φ̇).
    let (phi, ux, uphi, tau) = (0.3, 1.2, -0.4, 0.1);
    let full = linearize(&KNIFE, 0.0, &[phi, ux, uphi], &[tau]).unwrap();
    for name in ["x", "x_dot"] {
        let min =
            minimal_linearization(&KNIFE, 0.0, &[0.5, 0.7, phi], &[ux, uphi], &[tau], &[name])
                .unwrap();
        assert_eq!(min.state_names, names(&["phi", "phi_dot"]));
        assert_eq!(min.input_names, names(&["tau"]));
        assert_eq!(min.a, full.a.select_rows(&[0, 2]).select_columns(&[0, 2]));
        assert_eq!(min.b, full.b.select_rows(&[0, 2]));
        assert_eq!(min.a, DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 0.0, 0.0]));
        assert_eq!(min.b, DMatrix::from_row_slice(2, 1, &[0.0, 1.0 / KNIFE.i]));
    }
    // Both speeds fixed (a repeated name is harmless): only φ is left.
    let min = minimal_linearization(
        &KNIFE,
        0.0,
        &[0.5, 0.7, phi],
        &[ux, uphi],
        &[tau],
        &["x", "phi", "x"],
    )
    .unwrap();
    assert_eq!(min.state_names, names(&["phi"]));
    assert_eq!(min.a.shape(), (1, 1));
    // Gyro: hold ψ̇ (a spin rate), keep the rest.
    let state = [0.1, 0.2, -0.3, 0.4, 0.5, -0.6];
    let full = linearize(&GYRO, 0.0, &state, &[0.0; 3]).unwrap();
    let min =
        minimal_linearization(&GYRO, 0.0, &state[..3], &state[3..], &[0.0; 3], &["psi"]).unwrap();
    let keep = [0, 1, 2, 4, 5];
    assert_eq!(min.a, full.a.select_rows(&keep).select_columns(&keep));
    assert_eq!(
        min.state_names,
        names(&["psi", "theta", "phi", "theta_dot", "phi_dot"])
    );
}

/// SpinCart along its manifold with w held: z = (phi, x, ẋ).
fn spin_cart_on_manifold(t: f64, w: f64, z: &[f64]) -> Vec<f64> {
    let l = SPIN_CART.p;
    let y = -(l * l - z[1] * z[1]).sqrt();
    let d = rhs_f64(&SPIN_CART, t, &[z[0], z[1], y, w, z[2]], &[0.3]);
    vec![d[0], d[1], d[4]]
}

#[test]
fn eliminated_coordinate_and_fixed_speed_together() {
    let l = SPIN_CART.p;
    let (phi, x, w, u) = (0.4, 0.35, 1.3, -0.6);
    let mut q = [phi, x, -0.5];
    solve_holonomic(&SPIN_CART, 0.0, &mut q, &[2], 1e-14, 20).unwrap();
    let min = minimal_linearization(&SPIN_CART, 0.0, &q, &[w, u], &[0.3], &["phi"]).unwrap();
    assert_eq!(min.state_names, names(&["phi", "x", "x_dot"]));
    let fd = central_jacobian(|z| spin_cart_on_manifold(0.0, w, z), &[phi, x, u], 3, 1e-6);
    assert!(max_abs_diff(&min.a, &fd) < 1e-7, "{}\n{}", min.a, fd);
    // φ̇ = w is held: the φ row has no dependence on z.
    assert!(min.a.row(0).iter().all(|&v| v == 0.0));
    assert_eq!(min.b, DMatrix::from_row_slice(3, 1, &[0.0, 0.0, 0.0]));

    // Without fixing φ̇: z = (φ, x, φ̇, ẋ), and the torque enters φ̈.
    let min = minimal_linearization(&SPIN_CART, 0.0, &q, &[w, u], &[0.3], &[]).unwrap();
    assert_eq!(min.state_names, names(&["phi", "x", "phi_dot", "x_dot"]));
    assert_eq!(min.b, DMatrix::from_row_slice(4, 1, &[0.0, 0.0, 1.0, 0.0]));
    let y = q[2];
    let full = linearize(&SPIN_CART, 0.0, &[phi, x, y, w, u], &[0.3]).unwrap();
    let mut t = DMatrix::<f64>::zeros(5, 4);
    t[(0, 0)] = 1.0;
    t[(1, 1)] = 1.0;
    t[(2, 1)] = -x / y;
    t[(3, 2)] = 1.0;
    t[(4, 3)] = 1.0;
    let expected = full.a.select_rows(&[0, 1, 3, 4]) * t;
    assert!(max_abs_diff(&min.a, &expected) < 1e-14, "{}", min.a);
    assert!((l * l - x * x - y * y).abs() < 1e-14);
}

// ---------------------------------------------------------------------------
// Dual64 columns against one DualSVec64 pass: same numbers, and the timing.

/// An N-link planar pendulum chain (point masses at the link ends, a damper
/// at every joint, an input torque at the first), optionally with a driven
/// rotor whose speed couples into the first joint (its angle is ignorable):
/// s = 2N (+1) states. The mass matrix is assembled and solved by LDLᵀ, as
/// generated code does for a coupled mass matrix. Unlike generated code, it
/// calls sin and cos 2N² times (generated code computes each once), which
/// favours the vector pass: on derived models the two are much closer (see
/// the `appell_linearize` documentation).
#[derive(Clone, Copy, Debug)]
struct Chain<const N: usize, const ROTOR: bool>;

static CHAIN3_INFO: ModelInfo = ModelInfo {
    name: "Chain3",
    coordinates: &["q1", "q2", "q3"],
    speeds: &["q1", "q2", "q3"],
    retained: &["q1", "q2", "q3"],
    inputs: &["tau"],
    ..BASE_INFO
};

static CHAIN3R_INFO: ModelInfo = ModelInfo {
    name: "Chain3Rotor",
    coordinates: &["q1", "q2", "q3", "r"],
    speeds: &["q1", "q2", "q3", "r"],
    ignorable: &["r"],
    retained: &["q1", "q2", "q3"],
    inputs: &["tau", "tau_r"],
    ..BASE_INFO
};

static CHAIN4_INFO: ModelInfo = ModelInfo {
    name: "Chain4",
    coordinates: &["q1", "q2", "q3", "q4"],
    speeds: &["q1", "q2", "q3", "q4"],
    retained: &["q1", "q2", "q3", "q4"],
    inputs: &["tau"],
    ..BASE_INFO
};

impl<const N: usize, const ROTOR: bool> Model for Chain<N, ROTOR> {
    type Prepared<T: Scalar> = ();

    fn info() -> &'static ModelInfo {
        match (N, ROTOR) {
            (3, false) => &CHAIN3_INFO,
            (3, true) => &CHAIN3R_INFO,
            _ => &CHAIN4_INFO,
        }
    }

    fn parameter_values(&self, out: &mut [f64]) -> Result<(), ModelError> {
        check_len("out", out, 0)
    }

    fn set_parameter(&mut self, _: &str, _: f64) -> bool {
        false
    }

    fn prepare<T: Scalar>(&self) {}

    fn rhs<T: Scalar>(
        &self,
        _: &(),
        _t: T,
        s: &[T],
        inputs: &[T],
        ds: &mut [T],
    ) -> Result<(), ModelError> {
        let info = Self::info();
        check_len("state", s, info.state_len())?;
        check_len("inputs", inputs, info.inputs.len())?;
        check_len("dstate", ds, info.state_len())?;
        let c = T::from_f64;
        let (g, damping) = (9.81, 0.05);
        let len = |i: usize| 0.5 + 0.1 * i as f64;
        // μ_k = Σ_{p ≥ k} m_p with m_p = 1 + 0.2 p.
        let mu = |k: usize| (k..N).map(|p| 1.0 + 0.2 * p as f64).sum::<f64>();
        let mut mass = [[T::zero(); N]; N];
        let mut force = [T::zero(); N];
        for i in 0..N {
            for j in 0..N {
                let k = c(mu(i.max(j)) * len(i) * len(j));
                let d = s[i] - s[j];
                mass[i][j] = k * d.cos();
                force[i] -= k * d.sin() * s[N + j] * s[N + j];
            }
            force[i] -= c(g * mu(i) * len(i)) * s[i].sin() + c(damping) * s[N + i];
        }
        force[0] += inputs[0];
        if ROTOR {
            force[0] += c(0.3) * s[2 * N];
        }
        let acc = ldlt_solve(&mass, &force)?;
        ds[..N].copy_from_slice(&s[N..2 * N]);
        ds[N..2 * N].copy_from_slice(&acc);
        if ROTOR {
            ds[2 * N] = (inputs[1] - c(0.1) * s[2 * N]) / c(0.02) - c(0.3) * s[N];
        }
        Ok(())
    }

    fn constraint_residuals<T: Scalar>(
        &self,
        _: T,
        q: &[T],
        qdot: &[T],
        holonomic: &mut [T],
        velocity: &mut [T],
    ) -> Result<(), ModelError> {
        check_len("q", q, N + ROTOR as usize)?;
        check_len("qdot", qdot, N + ROTOR as usize)?;
        check_len("holonomic", holonomic, 0)?;
        check_len("velocity", velocity, 0)
    }

    unused_methods!();
}

/// A and B in one pass per `W` columns with `DualSVec64<W>` (the alternative
/// to [`linearize`]'s one Dual64 pass per column).
fn linearize_svec<M: Model, const W: usize>(
    model: &M,
    t: f64,
    state: &[f64],
    inputs: &[f64],
) -> (DMatrix<f64>, DMatrix<f64>) {
    let (s, ni) = (state.len(), inputs.len());
    let prepared = model.prepare::<DualSVec64<W>>();
    let mut jac = DMatrix::<f64>::zeros(s, s + ni);
    let mut out = vec![DualSVec64::<W>::from_f64(0.0); s];
    let mut start = 0;
    while start < s + ni {
        let seed = |k: usize, v: f64| {
            let x = DualSVec64::<W>::from_f64(v);
            if k >= start && k < start + W {
                x.derivative(k - start)
            } else {
                x
            }
        };
        let x: Vec<_> = state.iter().enumerate().map(|(k, &v)| seed(k, v)).collect();
        let w: Vec<_> = inputs
            .iter()
            .enumerate()
            .map(|(k, &v)| seed(s + k, v))
            .collect();
        model
            .rhs(&prepared, DualSVec64::from_f64(t), &x, &w, &mut out)
            .unwrap();
        for (i, o) in out.iter().enumerate() {
            if let Some(eps) = &o.eps.0 {
                for k in 0..W.min(s + ni - start) {
                    jac[(i, start + k)] = eps[k];
                }
            }
        }
        start += W;
    }
    (
        jac.columns(0, s).clone_owned(),
        jac.columns(s, ni).clone_owned(),
    )
}

fn check_svec_agrees<M: Model, const W: usize>(model: &M, state: &[f64], inputs: &[f64]) {
    let lin: Linearization = linearize(model, 0.3, state, inputs).unwrap();
    let (a, b) = linearize_svec::<M, W>(model, 0.3, state, inputs);
    assert!(max_abs_diff(&lin.a, &a) < 1e-13, "{}\n{}", lin.a, a);
    assert!(max_abs_diff(&lin.b, &b) < 1e-13, "{}\n{}", lin.b, b);
}

const CHAIN_STATE: [f64; 8] = [0.3, -0.2, 0.5, 0.1, 0.4, -0.7, 0.2, 0.6];

#[test]
fn dualsvec64_gives_the_same_jacobians() {
    check_svec_agrees::<_, 9>(&GYRO, &CHAIN_STATE[..6], &[0.1, 0.2, 0.3]);
    check_svec_agrees::<_, 4>(&GYRO, &CHAIN_STATE[..6], &[0.1, 0.2, 0.3]);
    check_svec_agrees::<_, 7>(&Chain::<3, false>, &CHAIN_STATE[..6], &[0.2]);
    check_svec_agrees::<_, 9>(&Chain::<3, true>, &CHAIN_STATE[..7], &[0.2, 0.1]);
    check_svec_agrees::<_, 9>(&Chain::<4, false>, &CHAIN_STATE, &[0.2]);
    // The chain against central differences, once.
    let model = Chain::<4, false>;
    let lin = linearize(&model, 0.0, &CHAIN_STATE, &[0.2]).unwrap();
    let fd = central_jacobian(|x| rhs_f64(&model, 0.0, x, &[0.2]), &CHAIN_STATE, 8, 1e-6);
    assert!(max_abs_diff(&lin.a, &fd) < 1e-7);
}

/// Median nanoseconds per call of `f` over 7 rounds of `reps` calls.
fn time_ns(reps: usize, mut f: impl FnMut()) -> f64 {
    let mut rounds: Vec<f64> = (0..7)
        .map(|_| {
            let start = std::time::Instant::now();
            for _ in 0..reps {
                f();
            }
            start.elapsed().as_nanos() as f64 / reps as f64
        })
        .collect();
    rounds.sort_by(f64::total_cmp);
    rounds[3]
}

/// One Dual64 pass per column, without building a [`Linearization`] (the
/// bare cost of the columns, to compare with the vector passes).
fn jacobian_dual64<M: Model>(model: &M, t: f64, state: &[f64], inputs: &[f64]) -> DMatrix<f64> {
    use num_dual::Dual64;
    let (s, ni) = (state.len(), inputs.len());
    let prepared = model.prepare::<Dual64>();
    let mut x: Vec<Dual64> = state.iter().map(|&v| Dual64::from_re(v)).collect();
    let mut w: Vec<Dual64> = inputs.iter().map(|&v| Dual64::from_re(v)).collect();
    let mut out = vec![Dual64::from_re(0.0); s];
    let mut jac = DMatrix::<f64>::zeros(s, s + ni);
    for j in 0..s + ni {
        if j < s {
            x[j].eps = 1.0;
        } else {
            w[j - s].eps = 1.0;
        }
        model
            .rhs(&prepared, Dual64::from_re(t), &x, &w, &mut out)
            .unwrap();
        if j < s {
            x[j].eps = 0.0;
        } else {
            w[j - s].eps = 0.0;
        }
        for (i, o) in out.iter().enumerate() {
            jac[(i, j)] = o.eps;
        }
    }
    jac
}

fn report<M: Model, const W: usize>(name: &str, model: &M, state: &[f64], inputs: &[f64]) {
    use std::hint::black_box;
    let reps = 20_000;
    let t = |f: &mut dyn FnMut()| time_ns(reps, f);
    let rhs = time_ns(reps * 10, || {
        black_box(rhs_f64(model, 0.3, black_box(state), black_box(inputs)));
    });
    let full = t(&mut || {
        black_box(linearize(model, 0.3, black_box(state), black_box(inputs)).unwrap());
    });
    let dual = t(&mut || {
        black_box(jacobian_dual64(
            model,
            0.3,
            black_box(state),
            black_box(inputs),
        ));
    });
    macro_rules! svec {
        ($w:expr) => {
            t(&mut || {
                black_box(linearize_svec::<M, $w>(
                    model,
                    0.3,
                    black_box(state),
                    black_box(inputs),
                ));
            })
        };
    }
    let (exact, w4, w8, w16) = (svec!(W), svec!(4), svec!(8), svec!(16));
    println!(
        "{name:>12}: s = {}, inputs = {}: rhs f64 {rhs:.0} ns | linearize {full:.0} ns | \
         Dual64 x{} {dual:.0} ns | DualSVec64<{W}> {exact:.0} ({:.2}x) | <4> {w4:.0} ({:.2}x) | \
         <8> {w8:.0} ({:.2}x) | <16> {w16:.0} ({:.2}x)",
        state.len(),
        inputs.len(),
        state.len() + inputs.len(),
        exact / dual,
        w4 / dual,
        w8 / dual,
        w16 / dual,
    );
}

#[test]
#[ignore = "timing; run with --release -- --ignored --nocapture"]
fn dual64_vs_dualsvec64_timing() {
    report::<_, 9>("Gyro", &GYRO, &CHAIN_STATE[..6], &[0.1, 0.2, 0.3]);
    report::<_, 7>("Chain3", &Chain::<3, false>, &CHAIN_STATE[..6], &[0.2]);
    report::<_, 9>(
        "Chain3Rotor",
        &Chain::<3, true>,
        &CHAIN_STATE[..7],
        &[0.2, 0.1],
    );
    report::<_, 9>("Chain4", &Chain::<4, false>, &CHAIN_STATE, &[0.2]);
}
