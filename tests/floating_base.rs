//! `urdf(..., base = free)` and `base = planar`: the root link on a joint
//! of its own, `root_joint`, as Pinocchio's `JointModelFreeFlyer` puts it.

mod common;

use appell::{Appell, Model};
use common::Rng;

/// The arm on a free base from the URDF's option.
#[derive(Appell, Clone)]
#[appell(urdf("tests/data/floating_arm.urdf", base = free), gravity(-9.81 * N.z))]
struct FreeArm;

/// The same written by hand: a free joint, then the URDF fixed in its frame.
#[derive(Appell, Clone)]
#[appell(joint(root_joint, free, parent = N, child = Base))]
#[appell(urdf("tests/data/floating_arm.urdf", parent = Base), gravity(-9.81 * N.z))]
struct FreeArmByHand;

/// On a planar base (x, y and the heading about N.z).
#[derive(Appell, Clone)]
#[appell(urdf("tests/data/floating_arm.urdf", base = planar), gravity(-9.81 * N.x))]
struct PlanarArm;

/// A state with a unit quaternion where the coordinates are named `*_qw`...
fn random_q<M: Model>(rng: &mut Rng) -> Vec<f64> {
    let info = M::info();
    let mut q: Vec<f64> = info
        .coordinates
        .iter()
        .map(|_| rng.uniform(-1.0, 1.0))
        .collect();
    if let Some(k) = info.coordinate_index("root_joint_qw") {
        let norm = q[k..k + 4].iter().map(|x| x * x).sum::<f64>().sqrt();
        q[k..k + 4].iter_mut().for_each(|x| *x /= norm);
    }
    q
}

/// The largest relative difference of the rhs to the oracle's.
fn against_the_oracle<M: Model>(model: &M, rng: &mut Rng) -> f64 {
    let info = M::info();
    let mut worst: f64 = 0.0;
    for _ in 0..200 {
        let q = random_q::<M>(rng);
        let u: Vec<f64> = info.speeds.iter().map(|_| rng.uniform(-2.0, 2.0)).collect();
        let mut x: Vec<f64> = info
            .retained
            .iter()
            .map(|c| q[info.coordinate_index(c).unwrap()])
            .collect();
        x.extend(&u);
        let inputs: Vec<f64> = info.inputs.iter().map(|_| rng.uniform(-1.0, 1.0)).collect();
        let mut d = vec![0.0; x.len()];
        model
            .rhs(&model.prepare::<f64>(), 0.0, &x, &inputs, &mut d)
            .unwrap();
        let o = appell::oracle::reduced_rhs(model, 0.0, &q, &u, &inputs).unwrap();
        for (a, b) in d.iter().zip(&o) {
            worst = worst.max((a - b).abs() / (1.0 + a.abs().max(b.abs())));
        }
    }
    worst
}

#[test]
fn a_free_base_from_the_option_is_the_free_joint_written_by_hand() {
    let info = FreeArm::info();
    assert_eq!(info.coordinates, FreeArmByHand::info().coordinates);
    assert_eq!(info.speeds, FreeArmByHand::info().speeds);
    assert_eq!(
        info.coordinates,
        [
            "root_joint_qw",
            "root_joint_qx",
            "root_joint_qy",
            "root_joint_qz",
            "root_joint_x",
            "root_joint_y",
            "root_joint_z",
            "hip"
        ]
    );
    let mut rng = Rng(36);
    for _ in 0..100 {
        let q = random_q::<FreeArm>(&mut rng);
        let mut x: Vec<f64> = info
            .retained
            .iter()
            .map(|c| q[info.coordinate_index(c).unwrap()])
            .collect();
        x.extend((0..info.speeds.len()).map(|_| rng.uniform(-2.0, 2.0)));
        let tau = [rng.uniform(-1.0, 1.0)];
        let (mut a, mut b) = (vec![0.0; x.len()], vec![0.0; x.len()]);
        FreeArm
            .rhs(&FreeArm.prepare::<f64>(), 0.0, &x, &tau, &mut a)
            .unwrap();
        FreeArmByHand
            .rhs(&FreeArmByHand.prepare::<f64>(), 0.0, &x, &tau, &mut b)
            .unwrap();
        for (p, r) in a.iter().zip(&b) {
            assert!((p - r).abs() <= 1e-12 * (1.0 + r.abs()), "{a:?} {b:?}");
        }
    }
}

#[test]
fn floating_bases_agree_with_the_oracle() {
    // The base's centre of mass is off its origin: the case the random
    // mechanisms found wrong before the quaternion remainder was mended.
    let free = against_the_oracle(&FreeArm, &mut Rng(1));
    let planar = against_the_oracle(&PlanarArm, &mut Rng(2));
    println!("free base {free:.1e}, planar base {planar:.1e}");
    assert!(free < 1e-10 && planar < 1e-10, "{free:e} {planar:e}");
    assert_eq!(
        PlanarArm::info().coordinates,
        ["root_joint_x", "root_joint_y", "root_joint_angle", "hip"]
    );
}
