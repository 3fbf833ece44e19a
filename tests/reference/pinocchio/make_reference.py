#!/usr/bin/env python3
"""Writes the Pinocchio reference data in this directory: one JSON file per
robot (ur5, panda, spatial_chain_{2,4,8,16,32}) with 20 random states each,
and for each state the forward dynamics (ABA), the inverse dynamics (RNEA),
the joint-space mass matrix (CRBA), the nonlinear effects and the generalized
gravity. The layout is described in README.md beside this script.

The URDFs are read from the repository's copies in examples/robots/. Every
model has a fixed base. The Panda's two finger joints are welded at 0.

Needs: pip install pin example-robot-data numpy
(example-robot-data is used only to record its version and to check that the
copied UR5 and Panda URDFs are unchanged).

Usage (from anywhere): python3 tests/reference/pinocchio/make_reference.py
"""
import hashlib
import importlib.metadata
import json
import os
import sys

import numpy as np
import pinocchio as pin

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", "..", ".."))

SEED = 20240917
N_STATES = 20
GRAVITY = [0.0, 0.0, -9.81]
RESIDUAL_TOL = 1e-9

# (name, URDF path relative to ROOT, path inside example-robot-data's robots/
# folder or None, joints welded at 0)
ROBOTS = [
    ("ur5", "examples/robots/ur5/ur5_robot.urdf", "ur_description/urdf/ur5_robot.urdf", []),
    (
        "panda",
        "examples/robots/panda/panda.urdf",
        "panda_description/urdf/panda.urdf",
        ["panda_finger_joint1", "panda_finger_joint2"],
    ),
] + [
    (f"spatial_chain_{n}", f"examples/robots/spatial_chain/spatial_chain_{n}.urdf", None, [])
    for n in (2, 4, 8, 16, 32)
]

NOTES = {
    "ur5": [
        "Fixed base: the URDF's root link 'world' is attached to Pinocchio's universe by the "
        "fixed 'world_joint'. The inertia of base_link is on the universe and takes no part in "
        "the dynamics. The fixed joints 'base_link-base_fixed_joint', 'ee_fixed_joint' and "
        "'wrist_3_link-tool0_fixed_joint' become frames, and their child links are massless.",
        "Angles written 1.57079632679 and 3.14159265359 in the URDF (pi/2 and pi rounded to 11 "
        "decimals) are used as written. They are not the exact pi/2 and pi (differences "
        "4.9e-12 and 2.1e-13 rad).",
        "Every joint has <dynamics damping=\"0.0\" friction=\"0.0\">. model.damping, "
        "model.friction and model.armature are all zero. pinocchio.aba ignores damping and "
        "friction anyway (checked here: the results are unchanged when they are zeroed).",
    ],
    "panda": [
        "Fixed base at panda_link0, whose inertia is on the universe and takes no part in the "
        "dynamics.",
        "panda_finger_joint1 and panda_finger_joint2 (prismatic) are welded at 0 with "
        "pinocchio.buildReducedModel. Pinocchio merges the link8 (massless), panda_hand and "
        "both finger inertias rigidly into panda_link7's body: panda_joint8 translates 0.107 "
        "along z, panda_hand_joint rotates -pi/4 about z, and each finger origin is at 0.0584 "
        "along the hand's z axis.",
        "panda_finger_joint2 has <mimic joint=\"panda_finger_joint1\"/>. It is loaded with "
        "mimic=False (the default), which makes it an independent joint, and is then welded.",
        "The URDF has <dynamics damping=\"0.003\" friction=\"0.0\"> on the arm joints (plus "
        "non-URDF attributes D, K, mu_coulomb, mu_viscous, which the parser ignores) and "
        "damping=\"0.3\" on the fingers. Pinocchio reads damping and friction into "
        "model.damping and model.friction. pinocchio.aba, rnea, crba, nonLinearEffects and "
        "computeGeneralizedGravity do not use them (checked here: the results are unchanged "
        "when they are zeroed). So the data has no joint damping or friction.",
        "URDF has no rotor inertia or armature. model.armature is zero (asserted), and "
        "model.rotorInertia is zero.",
    ],
}
CHAIN_NOTES = [
    "Synthetic chain written by examples/robots/spatial_chain/make_urdf.py. Revolute joints, "
    "axes alternating z (odd k) and y (even k). No damping, friction or armature.",
]


def version(dist):
    try:
        return importlib.metadata.version(dist)
    except importlib.metadata.PackageNotFoundError:
        return None


def erd_robots_dir():
    """example-robot-data's robots/ folder in the cmeel prefix, or None."""
    for entry in sys.path:
        d = os.path.join(entry, "cmeel.prefix", "share", "example-robot-data", "robots")
        if os.path.isdir(d):
            return d
    return None


def sha256(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def load(urdf, welded):
    model = pin.buildModelFromUrdf(urdf)
    if welded:
        ids = [model.getJointId(name) for name in welded]
        assert all(0 < i < model.njoints for i in ids), welded
        q_ref = pin.neutral(model)
        for i in ids:
            jm = model.joints[i]
            assert jm.nq == 1
            q_ref[jm.idx_q] = 0.0
        model = pin.buildReducedModel(model, ids, q_ref)
    return model


def symmetric(m):
    upper = np.triu(m)
    return upper + np.triu(m, 1).T


def dynamics(model, data, q, v, tau, a):
    ddq = pin.aba(model, data, q, v, tau).copy()
    rnea = pin.rnea(model, data, q, v, a).copy()
    mass = symmetric(pin.crba(model, data, q).copy())
    nle = pin.nonLinearEffects(model, data, q, v).copy()
    grav = pin.computeGeneralizedGravity(model, data, q).copy()
    return ddq, rnea, mass, nle, grav


def rel_residual(lhs_terms, rhs):
    """max |sum(lhs_terms) - rhs| over the scale of the largest term."""
    res = sum(lhs_terms) - rhs
    scale = max([np.max(np.abs(t)) for t in lhs_terms] + [np.max(np.abs(rhs)), 1e-300])
    return float(np.max(np.abs(res)) / scale)


def fmt(obj, indent=0):
    """JSON with one state field, one mass-matrix row or one note per line.
    Floats are written by json.dumps, which uses repr (the shortest form that
    reads back to the same double)."""
    pad = " " * indent
    flat = json.dumps(obj, allow_nan=False)
    numbers = isinstance(obj, list) and all(isinstance(x, (int, float)) for x in obj)
    if numbers or not isinstance(obj, (list, dict)) or len(flat) <= 100:
        return pad + flat
    if isinstance(obj, dict):
        items = [f'{pad}  {json.dumps(k)}: {fmt(v, indent + 2).lstrip()}' for k, v in obj.items()]
        return pad + "{\n" + ",\n".join(items) + "\n" + pad + "}"
    items = [fmt(x, indent + 2) for x in obj]
    return pad + "[\n" + ",\n".join(items) + "\n" + pad + "]"


def main():
    versions = {
        "pinocchio": pin.__version__,
        "example_robot_data": version("example-robot-data"),
        "numpy": np.__version__,
    }
    erd_dir = erd_robots_dir()
    worst = 0.0
    for index, (name, rel, erd_rel, welded) in enumerate(ROBOTS):
        urdf = os.path.join(ROOT, rel)
        if erd_rel is not None:
            assert erd_dir is not None, "example-robot-data is not installed"
            original = os.path.join(erd_dir, erd_rel)
            assert sha256(urdf) == sha256(original), f"{rel} differs from {original}"

        model = load(urdf, welded)
        data = model.createData()
        assert np.array_equal(model.gravity.linear, GRAVITY), model.gravity
        assert np.array_equal(model.gravity.angular, [0.0, 0.0, 0.0])
        assert model.nq == model.nv, (name, model.nq, model.nv)
        revolute = {"JointModelRX", "JointModelRY", "JointModelRZ", "JointModelRevoluteUnaligned"}
        kinds = [j.shortname() for j in list(model.joints)[1:]]
        assert all(k in revolute for k in kinds), (name, kinds)
        assert np.all(model.armature == 0.0), (name, model.armature)
        assert np.all(model.rotorInertia == 0.0), (name, model.rotorInertia)
        joints = list(model.names)[1:]
        assert list(model.names)[0] == "universe"
        for w in welded:
            assert w not in joints
        n = model.nv

        # The same model without damping and friction: every quantity must be
        # identical, which shows that the algorithms do not use them.
        bare = model.copy()
        bare.damping[:] = 0.0
        bare.friction[:] = 0.0
        bare_data = bare.createData()

        # One seed per robot, written in the file: SEED + the robot's index.
        seed = SEED + index
        rng = np.random.default_rng(seed)
        states = []
        worst_robot = 0.0
        for _ in range(N_STATES):
            q = rng.uniform(-np.pi, np.pi, n)
            v = rng.uniform(-2.0, 2.0, n)
            tau = rng.uniform(-20.0, 20.0, n)
            a = rng.uniform(-3.0, 3.0, n)
            ddq, rnea, mass, nle, grav = dynamics(model, data, q, v, tau, a)

            for x, y in zip((ddq, rnea, mass, nle, grav), dynamics(bare, bare_data, q, v, tau, a)):
                assert np.array_equal(x, y), f"{name}: damping or friction changes the result"
            assert np.all(np.isfinite(np.concatenate([ddq, rnea, mass.ravel(), nle, grav])))
            assert np.all(np.linalg.eigvalsh(mass) > 0), f"{name}: mass matrix not positive definite"

            # M ddq + nle = tau (ABA against CRBA and RNEA).
            r = rel_residual([mass @ ddq, nle], tau)
            worst_robot = max(worst_robot, r)
            assert r < RESIDUAL_TOL, (name, r)
            # Further consistency: rnea(q, v, a) = M a + nle, and the
            # generalized gravity is rnea(q, 0, 0).
            assert rel_residual([mass @ a, nle], rnea) < RESIDUAL_TOL
            zero = np.zeros(n)
            assert rel_residual([grav], pin.rnea(model, data, q, zero, zero)) < RESIDUAL_TOL

            states.append(
                {
                    "q": q.tolist(),
                    "v": v.tolist(),
                    "tau": tau.tolist(),
                    "ddq": ddq.tolist(),
                    "a": a.tolist(),
                    "rnea": rnea.tolist(),
                    "mass_matrix": mass.tolist(),
                    "nle": nle.tolist(),
                    "gravity_torque": grav.tolist(),
                }
            )

        doc = {"robot": name, "urdf": rel, "pinocchio_version": versions["pinocchio"]}
        if erd_rel is not None:
            doc["example_robot_data_version"] = versions["example_robot_data"]
        doc.update(
            {
                "numpy_version": versions["numpy"],
                "seed": seed,
                "gravity": GRAVITY,
                "welded": [{"joint": w, "value": 0.0} for w in welded],
                "notes": NOTES.get(name, CHAIN_NOTES),
                "dof": n,
                "joints": joints,
                "states": states,
            }
        )
        out = os.path.join(HERE, f"{name}.json")
        with open(out, "w", newline="\n") as f:
            f.write(fmt(doc) + "\n")
        # The file reads back to exactly the values computed.
        with open(out) as f:
            back = json.load(f)
        assert back["states"] == states and back["joints"] == joints
        worst = max(worst, worst_robot)
        print(f"{name}: {n} dof, joints {joints}")
        print(f"  max relative residual |M ddq + nle - tau| = {worst_robot:.3e}; wrote {out}")
    print(f"pinocchio {versions['pinocchio']}, example-robot-data {versions['example_robot_data']}, "
          f"numpy {versions['numpy']}")
    print(f"max relative residual over all robots: {worst:.3e}")


if __name__ == "__main__":
    main()
