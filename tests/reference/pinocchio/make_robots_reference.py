#!/usr/bin/env python3
"""Writes Pinocchio reference data for a set of example-robot-data robots
(tests/robots/, copied there by tests/robots/fetch_robots.py) into robots/
beside this script: one JSON file per robot and base, 20 random states each
within the joint limits, in Pinocchio's own conventions.

For each state: q, v, a, tau, ABA's ddq, RNEA's tau for (q, v, a), CRBA's M
(full, symmetric), the nonlinear effects and the generalized gravity. For
each joint: its name, Pinocchio's type, nq, nv, idx_q and idx_v, so a reader
maps by name; for each continuous joint (nq = 2: cos, sin) each state also
gives the angle.

Fixed bases: pinocchio.buildModelFromUrdf(path). Free bases:
pinocchio.buildModelFromUrdf(path, pinocchio.JointModelFreeFlyer()), the
joint `root_joint` with q = [x, y, z, qx, qy, qz, qw] (position in the world,
unit quaternion of the base's orientation) and v = [v, w], the base's linear
and angular velocity in the base's own axes. Mimic tags are not applied
(Pinocchio's default, mimic=False). The layout is in README.md.

Needs: pip install pin==4.1.0 example-robot-data==6.0.0 numpy
Usage (from anywhere): python3 tests/reference/pinocchio/make_robots_reference.py
"""
import hashlib
import importlib.metadata
import json
import os

import numpy as np
import pinocchio as pin

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", "..", ".."))
ROBOTS_DIR = os.path.join(ROOT, "tests", "robots")
OUT = os.path.join(HERE, "robots")

SEED = 20250301
N_STATES = 20
GRAVITY = [0.0, 0.0, -9.81]
RESIDUAL_TOL = 1e-9

# (name of the file written, URDF under tests/robots/, base, what it is)
ROBOTS = [
    ("z1", "z1/z1.urdf", "fixed", "Unitree Z1 arm with its gripper joint, 7 revolute joints"),
    ("xarm7", "xarm/xarm7.urdf", "fixed", "UFactory xArm 7, 7 revolute joints"),
    ("kinova", "kinova/kinova.urdf", "fixed", "Kinova arm, 6 joints, three of them continuous"),
    ("ur10", "ur/ur10_robot.urdf", "fixed", "Universal Robots UR10"),
    (
        "talos_left_arm",
        "talos/talos_left_arm.urdf",
        "fixed",
        "Talos's left arm with its gripper; the gripper's mimic tags are on fixed joints",
    ),
    ("allegro_right_hand", "allegro_hand/allegro_right_hand.urdf", "fixed", "Allegro right hand, 16 joints"),
    (
        "tiago_no_hand",
        "tiago/tiago_no_hand.urdf",
        "fixed",
        "Tiago mobile manipulator without hand, base fixed as its loader has it; wheels continuous",
    ),
    (
        "double_pendulum_continuous",
        "double_pendulum/double_pendulum_continuous.urdf",
        "fixed",
        "double pendulum on two continuous joints",
    ),
    (
        "hyq_fixed",
        "hyq/hyq_no_sensors.urdf",
        "fixed",
        "HyQ's legs on a fixed trunk; its feet are dummy links of 1e-6 kg fixed to the lower legs",
    ),
    (
        "bolt_fixed",
        "bolt/bolt.urdf",
        "fixed",
        "Bolt biped's legs on a fixed base; its feet have zero mass and an inertia",
    ),
    ("solo12", "solo/solo12.urdf", "free", "Solo12 quadruped"),
    (
        "anymal",
        "anymal_b_simple/anymal.urdf",
        "free",
        "ANYmal B quadruped; its root link is a dummy of 1e-6 kg fixed to base_inertia",
    ),
    ("go1", "go1/go1.urdf", "free", "Unitree Go1 quadruped"),
    ("hyq", "hyq/hyq_no_sensors.urdf", "free", "HyQ quadruped"),
    ("talos_reduced", "talos/talos_reduced.urdf", "free", "Talos humanoid, reduced model (32 joints)"),
    ("g1", "g1/g1_29dof_rev_1_0.urdf", "free", "Unitree G1 humanoid, 29 joints"),
]

REVOLUTE = {"JointModelRX", "JointModelRY", "JointModelRZ", "JointModelRevoluteUnaligned"}
PRISMATIC = {"JointModelPX", "JointModelPY", "JointModelPZ", "JointModelPrismaticUnaligned"}
CONTINUOUS = {"JointModelRUBX", "JointModelRUBY", "JointModelRUBZ", "JointModelRevoluteUnboundedUnaligned"}


def sha256(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def symmetric(m):
    return np.triu(m) + np.triu(m, 1).T


def rel_residual(lhs_terms, rhs):
    res = sum(lhs_terms) - rhs
    scale = max([np.max(np.abs(t)) for t in lhs_terms] + [np.max(np.abs(rhs)), 1e-300])
    return float(np.max(np.abs(res)) / scale)


def random_q(model, rng):
    """A configuration within the joint limits: a revolute or prismatic
    joint uniform between its limits (in [-pi, pi] when they are not both
    finite and distinct), a continuous joint's angle uniform in [-pi, pi],
    the free flyer's position uniform in [-1, 1]^3 and its orientation a
    uniformly random unit quaternion."""
    q = np.zeros(model.nq)
    lo, hi = model.lowerPositionLimit, model.upperPositionLimit
    for j in list(model.joints)[1:]:
        kind, i = j.shortname(), j.idx_q
        if kind in REVOLUTE or kind in PRISMATIC:
            a, b = lo[i], hi[i]
            if not (np.isfinite(a) and np.isfinite(b) and b > a):
                a, b = -np.pi, np.pi
            q[i] = rng.uniform(a, b)
        elif kind in CONTINUOUS:
            t = rng.uniform(-np.pi, np.pi)
            q[i : i + 2] = [np.cos(t), np.sin(t)]
        elif kind == "JointModelFreeFlyer":
            q[i : i + 3] = rng.uniform(-1.0, 1.0, 3)
            quat = rng.normal(size=4)
            q[i + 3 : i + 7] = quat / np.linalg.norm(quat)
        else:
            raise ValueError(f"joint type {kind} not handled")
    return q


def fmt(obj, indent=0):
    """JSON with one state field, one mass-matrix row or one note per line."""
    pad = " " * indent
    flat = json.dumps(obj, allow_nan=False)
    numbers = isinstance(obj, list) and all(isinstance(x, (int, float)) for x in obj)
    if numbers or not isinstance(obj, (list, dict)) or len(flat) <= 100:
        return pad + flat
    if isinstance(obj, dict):
        items = [f"{pad}  {json.dumps(k)}: {fmt(v, indent + 2).lstrip()}" for k, v in obj.items()]
        return pad + "{\n" + ",\n".join(items) + "\n" + pad + "}"
    items = [fmt(x, indent + 2) for x in obj]
    return pad + "[\n" + ",\n".join(items) + "\n" + pad + "]"


def main():
    manifest = json.load(open(os.path.join(ROBOTS_DIR, "MANIFEST.json")))
    by_file = {r["urdf"]: r for r in manifest["robots"]}
    versions = {
        "pinocchio": pin.__version__,
        "example_robot_data": importlib.metadata.version("example-robot-data"),
        "numpy": np.__version__,
    }
    assert versions["example_robot_data"] == manifest["version"], versions
    os.makedirs(OUT, exist_ok=True)
    worst = 0.0
    for index, (name, rel, base, what) in enumerate(ROBOTS):
        path = os.path.join(ROBOTS_DIR, rel)
        entry = by_file[rel]
        assert sha256(path) == entry["sha256"], f"{rel} differs from the manifest"
        if base == "free":
            model = pin.buildModelFromUrdf(path, pin.JointModelFreeFlyer())
        else:
            model = pin.buildModelFromUrdf(path)
        data = model.createData()
        assert np.array_equal(model.gravity.linear, GRAVITY)
        assert np.all(model.armature == 0.0), (name, model.armature)
        joints = []
        for j, jname in zip(list(model.joints)[1:], list(model.names)[1:]):
            kind = j.shortname()
            assert kind in REVOLUTE | PRISMATIC | CONTINUOUS | {"JointModelFreeFlyer"}, (name, kind)
            joints.append(
                {"name": jname, "type": kind, "nq": j.nq, "nv": j.nv, "idx_q": j.idx_q, "idx_v": j.idx_v}
            )
        continuous = [j for j in joints if j["type"] in CONTINUOUS]

        # Damping and friction (read from the URDF into model.damping and
        # model.friction) change none of these algorithms' results.
        bare = model.copy()
        bare.damping[:] = 0.0
        bare.friction[:] = 0.0
        bare_data = bare.createData()

        seed = SEED + index
        rng = np.random.default_rng(seed)
        states, worst_robot = [], 0.0
        for _ in range(N_STATES):
            q = random_q(model, rng)
            v = rng.uniform(-2.0, 2.0, model.nv)
            tau = rng.uniform(-20.0, 20.0, model.nv)
            a = rng.uniform(-3.0, 3.0, model.nv)
            out = []
            for m, d in ((model, data), (bare, bare_data)):
                out.append(
                    (
                        pin.aba(m, d, q, v, tau).copy(),
                        pin.rnea(m, d, q, v, a).copy(),
                        symmetric(pin.crba(m, d, q).copy()),
                        pin.nonLinearEffects(m, d, q, v).copy(),
                        pin.computeGeneralizedGravity(m, d, q).copy(),
                    )
                )
            ddq, rnea, mass, nle, grav = out[0]
            for x, y in zip(out[0], out[1]):
                assert np.array_equal(x, y), f"{name}: damping or friction changes the result"
            assert np.all(np.isfinite(np.concatenate([ddq, rnea, mass.ravel(), nle, grav])))
            assert np.all(np.linalg.eigvalsh(mass) > 0), f"{name}: M not positive definite"
            r = rel_residual([mass @ ddq, nle], tau)
            worst_robot = max(worst_robot, r)
            assert r < RESIDUAL_TOL, (name, r)
            assert rel_residual([mass @ a, nle], rnea) < RESIDUAL_TOL
            zero = np.zeros(model.nv)
            assert rel_residual([grav], pin.rnea(model, data, q, zero, zero)) < RESIDUAL_TOL
            state = {
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
            if continuous:
                state["angles"] = {
                    j["name"]: float(np.arctan2(q[j["idx_q"] + 1], q[j["idx_q"]])) for j in continuous
                }
            states.append(state)

        notes = [what]
        if base == "free":
            notes.append(
                "Free base: buildModelFromUrdf(path, JointModelFreeFlyer()). root_joint's q is "
                "[x, y, z, qx, qy, qz, qw] (position in the world frame, unit quaternion, scalar "
                "last) and its v is [vx, vy, vz, wx, wy, wz], the base's linear and angular velocity "
                "along the base's own axes; its tau is the wrench on the base in the base's axes "
                "(force, then torque)."
            )
        else:
            notes.append(
                "Fixed base: buildModelFromUrdf(path); the root link's inertia is on the universe."
            )
        if continuous:
            notes.append(
                "Continuous joints are JointModelRevoluteUnbounded: nq = 2, q = [cos t, sin t], "
                "nv = 1; each state's `angles` gives t = atan2(sin, cos)."
            )
        notes.append(
            "Fixed joints are frames: Pinocchio merges each link on a fixed joint into the body "
            "of its parent. Mimic tags are not applied (mimic=False, the default)."
        )
        doc = {
            "robot": name,
            "urdf": os.path.relpath(path, ROOT),
            "urdf_sha256": entry["sha256"],
            "base": base,
            "pinocchio_version": versions["pinocchio"],
            "example_robot_data_version": versions["example_robot_data"],
            "numpy_version": versions["numpy"],
            "seed": seed,
            "gravity": GRAVITY,
            "notes": notes,
            "nq": model.nq,
            "nv": model.nv,
            "joints": joints,
            "states": states,
        }
        out = os.path.join(OUT, f"{name}.json")
        with open(out, "w", newline="\n") as f:
            f.write(fmt(doc) + "\n")
        with open(out) as f:
            back = json.load(f)
        assert back["states"] == states and back["joints"] == joints
        worst = max(worst, worst_robot)
        print(f"{name} ({base}): nq {model.nq}, nv {model.nv}; max |M ddq + nle - tau| "
              f"relative {worst_robot:.2e}; wrote {os.path.relpath(out, ROOT)}")
    print(f"pinocchio {versions['pinocchio']}, example-robot-data {versions['example_robot_data']}, "
          f"numpy {versions['numpy']}; max relative residual {worst:.2e}")


if __name__ == "__main__":
    main()
