//! Assembly of the full-coordinate equations M_full q̈ + h = Q + Dᵀ λ,
//! D q̈ + Ḋ q̇ + ḋ = 0 from the model's kinematic description, by dual
//! numbers.

use super::error::OracleError;
use super::layout::{finite_all, Geometry, Layout};
use super::vec3::{cross, dot, map3, mat_vec, mul, mul_bt, vee};
use appell_core::dynamic::DynModel;
use appell_core::Scalar;
use appell_core::{check_len, Model, ModelInfo};
use num_dual::{Dual2_64, Dual64};

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

pub(super) fn full_dynamics_with<K: DynModel + ?Sized>(
    model: &K,
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

    let info = model.dyn_info();
    let mut masses = vec![0.0; lay.bodies];
    let mut inertias = vec![[0.0; 9]; lay.bodies];
    model.dyn_mass_properties(&mut masses, &mut inertias)?;
    finite_all(masses.iter().copied(), "a body mass")?;
    finite_all(inertias.iter().flatten().copied(), "a body inertia")?;

    // Values at (q, t).
    let g0 = Geometry::<f64>::eval(model, lay, t, q)?;
    finite_all(g0.positions.iter().flatten().copied(), "a body position")?;
    finite_all(g0.rotations.iter().flatten().copied(), "a body rotation")?;
    finite_all(g0.points.iter().flatten().copied(), "a force point")?;
    finite_all(g0.frames.iter().flatten().copied(), "a torque frame")?;

    let jac = Jacobians::eval(model, lay, t, q, &g0)?;

    // Velocities and acceleration remainders along (q + s q̇, t + s).
    let q2: Vec<Dual2_64> = q
        .iter()
        .zip(qdot)
        .map(|(&x, &v)| Dual2_64::new(x, v, 0.0))
        .collect();
    let mut pos2 = vec![[Dual2_64::zero(); 3]; lay.bodies];
    let mut rot2 = vec![[Dual2_64::zero(); 9]; lay.bodies];
    model.dyn_body_poses_dual2(Dual2_64::new(t, 1.0, 0.0), &q2, &mut pos2, &mut rot2)?;

    // Constraint rows, their rate along the motion, and load point velocities.
    let q1: Vec<Dual64> = q
        .iter()
        .zip(qdot)
        .map(|(&x, &v)| Dual64::new(x, v))
        .collect();
    let t1 = Dual64::new(t, 1.0);
    let mut dmat = vec![Dual64::zero(); m * n];
    let mut doff = vec![Dual64::zero(); m];
    let inputs1 = input_duals(info, inputs);
    model.dyn_driven_constraint_rows_dual(t1, &q1, &inputs1, &mut dmat, &mut doff)?;
    let g1 = Geometry::<Dual64>::eval(model, lay, t1, &q1)?;

    let mut forces = vec![[0.0; 3]; lay.points];
    let mut torques = vec![[0.0; 3]; lay.frames];
    model.dyn_load_values(t, q, qdot, inputs, &mut forces, &mut torques)?;
    finite_all(forces.iter().flatten().copied(), "a force")?;
    finite_all(torques.iter().flatten().copied(), "a torque")?;

    let bodies = Bodies {
        masses: &masses,
        inertias: &inertias,
        positions: &pos2,
        rotations: &rot2,
    };
    let (mass, bias, kinetic_energy) = inertia_terms(info, lay, &bodies, &g0, &jac);
    let (gen_forces, power) = generalized_forces(lay, &jac, &g0, &g1, &forces, &torques);

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

/// The Jacobians at `(q, t)`, indexed `[body or load][coordinate]`: of the
/// mass centres (J_j), of the bodies' angular velocities (G_j), of the
/// force points (J_P) and of the torque frames' angular velocities (G_F).
struct Jacobians {
    body: Vec<[f64; 3]>,
    ang_body: Vec<[f64; 3]>,
    point: Vec<[f64; 3]>,
    ang_frame: Vec<[f64; 3]>,
}

impl Jacobians {
    /// Evaluates the geometry with a [`Dual64`] seed on one coordinate at a
    /// time; `g0` is the geometry at `(q, t)` (the angular columns are
    /// vee((∂R/∂q_r) Rᵀ)).
    fn eval<K: DynModel + ?Sized>(
        model: &K,
        lay: &Layout,
        t: f64,
        q: &[f64],
        g0: &Geometry<f64>,
    ) -> Result<Self, OracleError> {
        let n = lay.n;
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
        Ok(Jacobians {
            body: jac_body,
            ang_body,
            point: jac_point,
            ang_frame,
        })
    }
}

/// The bodies' mass properties and their poses along (q + s q̇, t + s)
/// (first derivatives: velocities, second: acceleration remainders).
struct Bodies<'a> {
    masses: &'a [f64],
    inertias: &'a [[f64; 9]],
    positions: &'a [[Dual2_64; 3]],
    rotations: &'a [[Dual2_64; 9]],
}

/// M_full (n×n row-major), h and the kinetic energy, summed over the
/// bodies: the translational part of every body, the rotational part of
/// the rigid ones.
fn inertia_terms(
    info: &ModelInfo,
    lay: &Layout,
    bodies: &Bodies<'_>,
    g0: &Geometry<f64>,
    jac: &Jacobians,
) -> (Vec<f64>, Vec<f64>, f64) {
    let n = lay.n;
    let mut mass = vec![0.0; n * n];
    let mut bias = vec![0.0; n];
    let mut kinetic_energy = 0.0;
    for j in 0..lay.bodies {
        let mj = bodies.masses[j];
        let v = map3(&bodies.positions[j], |x| x.v1);
        let a = map3(&bodies.positions[j], |x| x.v2);
        kinetic_energy += 0.5 * mj * dot(&v, &v);
        let jac_j = &jac.body[j * n..(j + 1) * n];
        for r in 0..n {
            for c in 0..n {
                mass[r * n + c] += mj * dot(&jac_j[r], &jac_j[c]);
            }
            bias[r] += mj * dot(&jac_j[r], &a);
        }
        if !info.bodies[j].rigid {
            continue;
        }
        let rot = &g0.rotations[j];
        let inertia_n = mul_bt(&mul(rot, &bodies.inertias[j]), rot);
        let rdot = map3(&bodies.rotations[j], |x| x.v1);
        let rddot = map3(&bodies.rotations[j], |x| x.v2);
        let w = vee(&mul_bt(&rdot, rot));
        let alpha = vee(&mul_bt(&rddot, rot));
        let iw = mat_vec(&inertia_n, &w);
        kinetic_energy += 0.5 * dot(&w, &iw);
        let ia = mat_vec(&inertia_n, &alpha);
        let gyro = cross(&w, &iw);
        let rot_bias = [ia[0] + gyro[0], ia[1] + gyro[1], ia[2] + gyro[2]];
        let ang = &jac.ang_body[j * n..(j + 1) * n];
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
    (mass, bias, kinetic_energy)
}

/// Q and the power of the loads: `forces` at the force points and
/// `torques` on the torque frames, with `g1` the geometry along
/// (q + ε q̇, t + ε) for the load velocities.
#[allow(clippy::needless_range_loop)] // one index into several parallel arrays
fn generalized_forces(
    lay: &Layout,
    jac: &Jacobians,
    g0: &Geometry<f64>,
    g1: &Geometry<Dual64>,
    forces: &[[f64; 3]],
    torques: &[[f64; 3]],
) -> (Vec<f64>, f64) {
    let n = lay.n;
    let mut gen_forces = vec![0.0; n];
    let mut power = 0.0;
    for p in 0..lay.points {
        for r in 0..n {
            gen_forces[r] += dot(&jac.point[p * n + r], &forces[p]);
        }
        power += dot(&map3(&g1.points[p], |x| x.eps), &forces[p]);
    }
    for f in 0..lay.frames {
        for r in 0..n {
            gen_forces[r] += dot(&jac.ang_frame[f * n + r], &torques[f]);
        }
        let fdot = map3(&g1.frames[f], |x| x.eps);
        power += dot(&vee(&mul_bt(&fdot, &g0.frames[f])), &torques[f]);
    }
    (gen_forces, power)
}

/// The inputs as dual numbers along the motion, for constraints that read
/// them (driven coordinates): an input `x` whose companion `x_rate` is an
/// input too moves at it, and `x_rate` at `x_accel` when that is one;
/// every other input is held (rate 0).
fn input_duals(info: &appell_core::ModelInfo, inputs: &[f64]) -> Vec<Dual64> {
    let index = |name: &str| info.inputs.iter().position(|i| *i == name);
    info.inputs
        .iter()
        .zip(inputs)
        .map(|(name, &x)| {
            let accel = name
                .strip_suffix("_rate")
                .and_then(|base| index(&format!("{base}_accel")));
            let rate = accel.or_else(|| index(&format!("{name}_rate")));
            Dual64::new(x, rate.map_or(0.0, |k| inputs[k]))
        })
        .collect()
}
