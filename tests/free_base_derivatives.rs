//! The derivatives of a floating-base robot's dynamics against
//! Pinocchio's analytical ones (`computeABADerivatives`,
//! `computeRNEADerivatives`; `tests/reference/pinocchio/derivatives/
//! solo12.json`, written by `make_derivatives_reference.py`): Solo12 on a
//! free base, with the generated Jacobian of the world-frame form.
//!
//! The model's derivatives are by its own coordinates (the base's
//! quaternion, scalar first, and its position in N) and speeds (the
//! base's angular velocity in its axes, ṗ in N's); Pinocchio's are along
//! its tangent (`integrate(q, δ)`: a twist in the base's axes) and by its
//! `v` (the base's twist in its axes). Each of Pinocchio's columns is the
//! model's derivatives carried along the same path by the chain rule: the
//! path's q and u in dual numbers through `appell::pinocchio::PinocchioMap`
//! (exact and generic over the scalar), the accelerations' (forces')
//! first-order change from the generated matrices, and the result mapped
//! back to Pinocchio's `a` (`tau`) in dual numbers.

use appell::num_dual::Dual64;
use appell::pinocchio::PinocchioMap;
use appell::{Appell, Model};
use serde_json::Value;

/// Solo12 on a free base with its Jacobian generated (`jacobian(on)`:
/// the world-frame form with the free root).
#[derive(Appell, Clone, Debug, Default)]
#[appell(urdf("tests/robots/solo/solo12.urdf", base = free), gravity(-9.81 * N.z), jacobian(on))]
struct Solo12;

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("a list")
        .iter()
        .map(|x| x.as_f64().expect("a number"))
        .collect()
}

/// |a − b| / (1 + max |b|).
fn relative(a: &[f64], b: &[f64]) -> f64 {
    let scale = 1.0 + b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs() / scale))
}

fn dual(re: f64, eps: f64) -> Dual64 {
    Dual64::new(re, eps)
}

fn eps(x: &[Dual64]) -> Vec<f64> {
    x.iter().map(|d| d.eps).collect()
}

/// y + ε J dx for a row-major `rows` × dx.len() matrix `j`.
fn moved(y: &[f64], j: &[f64], dx: &[f64]) -> Vec<Dual64> {
    let cols = dx.len();
    y.iter()
        .enumerate()
        .map(|(r, &v)| {
            let d: f64 = (0..cols).map(|c| j[r * cols + c] * dx[c]).sum();
            dual(v, d)
        })
        .collect()
}

/// Pinocchio's `q ⊕ ε δ` to first order: a free flyer moves by the twist
/// δ[..6] in the base's axes (position p + ε R δ_v, quaternion
/// e ⊗ (1, ε δ_ω / 2), scalar last), each joint by δ.
fn integrate(q: &[f64], delta: &[f64]) -> Vec<Dual64> {
    let (x, y, z, w) = (q[3], q[4], q[5], q[6]);
    let r = [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ];
    let mut out: Vec<Dual64> = q.iter().map(|&v| dual(v, 0.0)).collect();
    for i in 0..3 {
        out[i].eps = (0..3).map(|k| r[i][k] * delta[k]).sum();
    }
    let d = [delta[3] / 2.0, delta[4] / 2.0, delta[5] / 2.0];
    // (x, y, z, w) ⊗ (d, 0): the vector part w d + v × d, the scalar −v·d.
    out[3].eps = w * d[0] + y * d[2] - z * d[1];
    out[4].eps = w * d[1] + z * d[0] - x * d[2];
    out[5].eps = w * d[2] + x * d[1] - y * d[0];
    out[6].eps = -(x * d[0] + y * d[1] + z * d[2]);
    for k in 7..q.len() {
        out[k].eps = delta[k - 1];
    }
    out
}

/// One reference state and the model's derivatives there.
struct At {
    map: PinocchioMap,
    q_pin: Vec<f64>,
    v_pin: Vec<f64>,
    a_pin: Vec<f64>,
    q: Vec<f64>,
    u: Vec<f64>,
    /// ABA's: ÿ and ∂ÿ/∂q, ∂ÿ/∂u, ∂ÿ/∂inputs.
    accel: Vec<f64>,
    fq: Vec<f64>,
    fu: Vec<f64>,
    ft: Vec<f64>,
    /// RNEA's at the state's u̇ (from Pinocchio's a): Q and ∂Q/∂q,
    /// ∂Q/∂u, M.
    u_dot: Vec<f64>,
    forces: Vec<f64>,
    dq: Vec<f64>,
    du: Vec<f64>,
    mass: Vec<f64>,
}

impl At {
    /// Pinocchio's columns of ∂a/∂q, ∂a/∂v, ∂τ/∂q, ∂τ/∂v along the path
    /// `q_pin(ε)` (duals) with `v_pin + ε dv`.
    fn columns(&self, q_path: &[Dual64], dv: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let m = &self.map;
        let mut q = vec![dual(0.0, 0.0); self.q.len()];
        m.q_from_pinocchio(q_path, &mut q).unwrap();
        let v: Vec<Dual64> = self
            .v_pin
            .iter()
            .zip(dv)
            .map(|(&x, &d)| dual(x, d))
            .collect();
        let a: Vec<Dual64> = self.a_pin.iter().map(|&x| dual(x, 0.0)).collect();
        let mut u = vec![dual(0.0, 0.0); self.u.len()];
        m.v_from_pinocchio(&q, &v, &mut u).unwrap();
        let (dq, du) = (eps(&q), eps(&u));
        let delta: Vec<f64> = dq.iter().chain(&du).copied().collect();
        let fqu: Vec<f64> = self.fq_fu();
        // ABA: ÿ moved along the path, then Pinocchio's a.
        let accel = moved(&self.accel, &fqu, &delta);
        let mut a_pin = vec![dual(0.0, 0.0); self.map.nv()];
        m.a_to_pinocchio(&q, &u, &accel, &mut a_pin).unwrap();
        // RNEA: u̇ from Pinocchio's a along the path, Q moved, then τ.
        let mut u_dot = vec![dual(0.0, 0.0); self.u.len()];
        m.a_from_pinocchio(&q, &v, &a, &mut u_dot).unwrap();
        let ddelta: Vec<f64> = delta.iter().copied().chain(eps(&u_dot)).collect();
        let forces = moved(&self.forces, &self.rnea_matrix(), &ddelta);
        let mut tau = vec![dual(0.0, 0.0); self.map.nv()];
        m.tau_to_pinocchio(&q, &forces, &mut tau).unwrap();
        (eps(&a_pin), eps(&tau))
    }

    /// [∂ÿ/∂q ∂ÿ/∂u], row-major.
    fn fq_fu(&self) -> Vec<f64> {
        side_by_side(&[(&self.fq, self.q.len()), (&self.fu, self.u.len())])
    }

    /// [∂Q/∂q ∂Q/∂u M], row-major.
    fn rnea_matrix(&self) -> Vec<f64> {
        let l = self.u.len();
        side_by_side(&[(&self.dq, self.q.len()), (&self.du, l), (&self.mass, l)])
    }
}

/// Row-major matrices of the same rows, side by side.
fn side_by_side(blocks: &[(&Vec<f64>, usize)]) -> Vec<f64> {
    let rows = blocks[0].0.len() / blocks[0].1;
    (0..rows)
        .flat_map(|r| {
            blocks
                .iter()
                .flat_map(move |(m, c)| m[r * c..(r + 1) * c].iter().copied())
        })
        .collect()
}

#[test]
fn solo12s_derivatives_agree_with_pinocchio() {
    let path = format!(
        "{}/tests/reference/pinocchio/derivatives/solo12.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let data: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    assert_eq!(data["base"], "free");
    let names: Vec<&str> = data["joints"].as_array().unwrap()[1..]
        .iter()
        .map(|j| j.as_str().unwrap())
        .collect();
    let info = Solo12::info();
    assert!(
        info.jacobian.unwrap().form.contains("world"),
        "{}",
        info.jacobian.unwrap().form
    );
    let (n, l, ni) = (info.coordinates.len(), info.speeds.len(), info.inputs.len());
    let model = Solo12;
    let keys = [
        "ddq_dq", "ddq_dv", "ddq_dtau", "dtau_dq", "dtau_dv", "dtau_da",
    ];
    let mut worst = [0.0f64; 6];
    let states = data["states"].as_array().unwrap();
    for s in states {
        let rows =
            |k: &str| -> Vec<Vec<f64>> { s[k].as_array().unwrap().iter().map(numbers).collect() };
        let map = PinocchioMap::free("root_joint", info.coordinates, info.speeds, &names).unwrap();
        let nv = map.nv();
        let (q_pin, v_pin, a_pin, tau_pin) = (
            numbers(&s["q"]),
            numbers(&s["v"]),
            numbers(&s["a"]),
            numbers(&s["tau"]),
        );
        assert!(
            tau_pin[..6].iter().all(|&x| x == 0.0),
            "a free base is not actuated"
        );
        let mut q = vec![0.0; n];
        map.q_from_pinocchio(&q_pin, &mut q).unwrap();
        let mut u = vec![0.0; l];
        map.v_from_pinocchio(&q, &v_pin, &mut u).unwrap();
        let inputs: Vec<f64> = info
            .inputs
            .iter()
            .map(|i| {
                tau_pin[6 + names
                    .iter()
                    .position(|j| Some(*j) == i.strip_prefix("tau_"))
                    .unwrap()]
            })
            .collect();
        let mut u_dot = vec![0.0; l];
        map.a_from_pinocchio(&q, &v_pin, &a_pin, &mut u_dot)
            .unwrap();
        let mut at = At {
            map,
            q_pin: q_pin.clone(),
            v_pin: v_pin.clone(),
            a_pin,
            q: q.clone(),
            u: u.clone(),
            accel: vec![0.0; l],
            fq: vec![0.0; l * n],
            fu: vec![0.0; l * l],
            ft: vec![0.0; l * ni],
            u_dot: u_dot.clone(),
            forces: vec![0.0; l],
            dq: vec![0.0; l * n],
            du: vec![0.0; l * l],
            mass: vec![0.0; l * l],
        };
        model
            .forward_dynamics_derivatives(
                0.0,
                &q,
                &u,
                &inputs,
                &mut at.accel,
                &mut at.fq,
                &mut at.fu,
                &mut at.ft,
            )
            .unwrap();
        model
            .inverse_dynamics_derivatives(
                0.0,
                &q,
                &u,
                &at.u_dot,
                &mut at.forces,
                &mut at.dq,
                &mut at.du,
                &mut at.mass,
            )
            .unwrap();
        // Column by column along Pinocchio's tangent and v.
        let mut ours: [Vec<Vec<f64>>; 6] = Default::default();
        for j in 0..nv {
            let mut e = vec![0.0; nv];
            e[j] = 1.0;
            let (da, dtau) = at.columns(&integrate(&at.q_pin, &e), &vec![0.0; nv]);
            ours[0].push(da);
            ours[3].push(dtau);
            let still: Vec<Dual64> = at.q_pin.iter().map(|&x| dual(x, 0.0)).collect();
            let (da, dtau) = at.columns(&still, &e);
            ours[1].push(da);
            ours[4].push(dtau);
        }
        // By the joints' torques: ÿ moves by ∂ÿ/∂inputs, then a_to.
        for k in 6..nv {
            let name = format!("tau_{}", names[k - 6]);
            let i = info.inputs.iter().position(|x| *x == name).unwrap();
            let accel: Vec<Dual64> = (0..l)
                .map(|r| dual(at.accel[r], at.ft[r * ni + i]))
                .collect();
            let (q_d, u_d): (Vec<Dual64>, Vec<Dual64>) = (
                q.iter().map(|&x| dual(x, 0.0)).collect(),
                u.iter().map(|&x| dual(x, 0.0)).collect(),
            );
            let mut a = vec![dual(0.0, 0.0); nv];
            at.map.a_to_pinocchio(&q_d, &u_d, &accel, &mut a).unwrap();
            ours[2].push(eps(&a));
        }
        // M in Pinocchio's v.
        let mut mass = vec![0.0; nv * nv];
        at.map.mass_to_pinocchio(&q, &at.mass, &mut mass).unwrap();
        ours[5] = mass.chunks(nv).map(<[f64]>::to_vec).collect();
        for (k, key) in keys.iter().enumerate() {
            let theirs = rows(key);
            // Our columns were pushed as rows: compare transposed, but M
            // and the torque columns (6.. only) as they are.
            let (flat_ours, flat_theirs): (Vec<f64>, Vec<f64>) = match k {
                2 => (
                    ours[2].iter().flatten().copied().collect(),
                    (6..nv)
                        .flat_map(|c| theirs.iter().map(move |row| row[c]))
                        .collect::<Vec<_>>(),
                ),
                5 => (
                    ours[5].iter().flatten().copied().collect(),
                    theirs.iter().flatten().copied().collect(),
                ),
                _ => (
                    ours[k].iter().flatten().copied().collect(),
                    (0..nv)
                        .flat_map(|c| theirs.iter().map(move |row| row[c]))
                        .collect::<Vec<_>>(),
                ),
            };
            worst[k] = worst[k].max(relative(&flat_ours, &flat_theirs));
        }
    }
    println!(
        "Solo12 on a free base, {} states: {}",
        states.len(),
        keys.iter()
            .zip(worst)
            .map(|(k, w)| format!("{k} {w:.1e}"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    for (k, w) in keys.iter().zip(worst) {
        assert!(w <= 1e-9, "{k} differs from Pinocchio's by {w:.2e}");
    }
}
