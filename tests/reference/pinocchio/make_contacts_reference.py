#!/usr/bin/env python3
"""Writes Pinocchio reference data for legged robots standing on their feet
(contacts/ beside this script): for each robot and contact set, 20 random
states within the joint limits, each with the accelerations and the contact
forces of Pinocchio's constrained forward dynamics.

A point contact holds a foot frame's origin still: its rows are the frame's
linear velocity in the world's axes (LOCAL_WORLD_ALIGNED), J v = 0, and the
accelerations keep it, J ddq + gamma = 0 with gamma the frame's classical
acceleration at ddq = 0. A flat contact holds the whole frame: three more
rows, its angular velocity in the world's axes (the frame Jacobian's six
rows), and its lambda is the ground's force and then its moment about the
frame's origin. Pinocchio's `forwardDynamics(model, data, q, v,
tau, J, gamma)` solves

    M ddq + nle = tau + J^T lambda,    J ddq = -gamma,

so lambda is the force the ground exerts on each foot, in world axes. The
script checks its answer three ways before writing it: against the KKT
system assembled here from CRBA, nle and the Jacobians (numpy), by the
feet's classical accelerations at (q, v, ddq) (zero), and by the residual
of the equations of motion; each to 1e-9 relative.

States: q uniform within the joint limits (the base's position in [-1, 1]^3,
its orientation a uniform random unit quaternion), drawn again while a
stance leg is within reach of a singular configuration (the condition
number of the foot's Jacobian in its leg's joints above 1e3: a knee
nearly stretched, where both computations lose about cond^2 of their
digits and the comparison would measure that), v random and then
projected onto the null space of J (a state that keeps the feet still), tau
random on the joints (zero on the base: a robot has no motor there).

Conventions are Pinocchio's (free flyer: q = [x, y, z, qx, qy, qz, qw, ...],
v = [v, w] in the base's axes), as in ../robots/; the layout is in README.md.

Needs: pip install pin==4.1.0 numpy
Usage (from anywhere): python3 tests/reference/pinocchio/make_contacts_reference.py
"""
import importlib.metadata
import json
import os

import numpy as np
import pinocchio as pin

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", "..", ".."))
OUT = os.path.join(HERE, "contacts")

SEED = 20261206
N_STATES = 20
TOL = 1e-9
MAX_LEG_CONDITION = 1e3

# (file written, URDF under tests/, feet frames held, their kind, what it is)
SETS = [
    (
        "solo12_four_feet",
        "tests/robots/solo/solo12.urdf",
        ["FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"],
        "point",
        "Solo12 standing on four point feet",
    ),
    (
        "solo12_trot_fl_hr",
        "tests/robots/solo/solo12.urdf",
        ["FL_FOOT", "HR_FOOT"],
        "point",
        "Solo12 trotting: front-left and hind-right feet down",
    ),
    (
        "g1_double_support",
        "tests/robots/g1/g1_29dof_rev_1_0.urdf",
        ["left_ankle_roll_link", "right_ankle_roll_link"],
        "flat",
        "G1 (29 joints) in double support: both feet flat on the ground",
    ),
    (
        "g1_left_support",
        "tests/robots/g1/g1_29dof_rev_1_0.urdf",
        ["left_ankle_roll_link"],
        "flat",
        "G1 (29 joints) in single support: the left foot flat on the ground",
    ),
]


def rows_of(kind):
    """The frame Jacobian's rows a contact holds: the linear three, or all
    six for a flat foot."""
    return {"point": 3, "flat": 6}[kind]


def random_state(model, rng):
    q = np.zeros(model.nq)
    for j in range(1, model.njoints):
        joint = model.joints[j]
        iq, nq = joint.idx_q, joint.nq
        if nq == 7:
            q[iq : iq + 3] = rng.uniform(-1.0, 1.0, 3)
            quat = rng.normal(size=4)
            q[iq + 3 : iq + 7] = quat / np.linalg.norm(quat)
        else:
            lo = model.lowerPositionLimit[iq : iq + nq]
            hi = model.upperPositionLimit[iq : iq + nq]
            lo = np.where(np.isfinite(lo), lo, -np.pi)
            hi = np.where(np.isfinite(hi), hi, np.pi)
            q[iq : iq + nq] = rng.uniform(lo, hi)
    return q


def contact_terms(model, data, frames, kind, q, v):
    """J (3 or 6 rows a foot, world axes) and gamma (the feet's classical
    accelerations at ddq = 0)."""
    pin.forwardKinematics(model, data, q, v, np.zeros(model.nv))
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    rows, drift = [], []
    for f in frames:
        fid = model.getFrameId(f)
        jac = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
        rows.append(jac[: rows_of(kind), :])
        acc = pin.getFrameClassicalAcceleration(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
        drift.append(acc.vector[: rows_of(kind)])
    return np.vstack(rows), np.concatenate(drift)


def feet_accelerations(model, data, frames, kind, q, v, a):
    pin.forwardKinematics(model, data, q, v, a)
    pin.updateFramePlacements(model, data)
    return np.concatenate(
        [
            pin.getFrameClassicalAcceleration(
                model, data, model.getFrameId(f), pin.LOCAL_WORLD_ALIGNED
            ).vector[: rows_of(kind)]
            for f in frames
        ]
    )


def leg_condition(model, data, frames, kind, q):
    """The largest condition number of a foot's Jacobian in the joints of
    its leg (the columns after the base's that move it)."""
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    worst = 0.0
    for f in frames:
        frame = model.getFrameId(f)
        jac = pin.getFrameJacobian(model, data, frame, pin.LOCAL_WORLD_ALIGNED)[: rows_of(kind)]
        cols = [c for c in range(6, model.nv) if np.abs(jac[:, c]).max() > 0]
        worst = max(worst, np.linalg.cond(jac[:, cols]))
    return worst


def one_state(model, data, frames, kind, rng):
    q = random_state(model, rng)
    while leg_condition(model, data, frames, kind, q) > MAX_LEG_CONDITION:
        q = random_state(model, rng)
    jac, _ = contact_terms(model, data, frames, kind, q, np.zeros(model.nv))
    v = rng.uniform(-1.0, 1.0, model.nv)
    v = v - np.linalg.pinv(jac) @ (jac @ v)
    jac, gamma = contact_terms(model, data, frames, kind, q, v)
    assert np.abs(jac @ v).max() < 1e-12
    tau = np.concatenate([np.zeros(6), rng.uniform(-1.0, 1.0, model.nv - 6)])
    ddq = pin.forwardDynamics(model, data, q, v, tau, jac, gamma).copy()
    lam = data.lambda_c.copy()
    # The same from a KKT system assembled here.
    mass = pin.crba(model, data, q)
    mass = np.triu(mass) + np.triu(mass, 1).T
    nle = pin.nonLinearEffects(model, data, q, v)
    k = jac.shape[0]
    kkt = np.block([[mass, jac.T], [jac, np.zeros((k, k))]])
    sol = np.linalg.solve(kkt, np.concatenate([tau - nle, -gamma]))
    scale = max(1.0, np.abs(ddq).max(), np.abs(lam).max())
    assert np.abs(sol[: model.nv] - ddq).max() < TOL * scale, "ddq differs from the KKT solve"
    assert np.abs(-sol[model.nv :] - lam).max() < TOL * scale or np.abs(
        sol[model.nv :] - lam
    ).max() < TOL * scale, "lambda differs from the KKT solve"
    # Sign: M ddq + nle = tau + J^T lambda.
    residual = mass @ ddq + nle - tau - jac.T @ lam
    assert np.abs(residual).max() < TOL * scale, f"lambda's sign: residual {np.abs(residual).max()}"
    feet = feet_accelerations(model, data, frames, kind, q, v, ddq)
    assert np.abs(feet).max() < TOL * scale, f"feet accelerate: {np.abs(feet).max()}"
    return {
        "q": q.tolist(),
        "v": v.tolist(),
        "tau": tau.tolist(),
        "ddq": ddq.tolist(),
        "lambda": lam.tolist(),
    }


def main():
    os.makedirs(OUT, exist_ok=True)
    rng = np.random.default_rng(SEED)
    for name, urdf, frames, kind, what in SETS:
        model = pin.buildModelFromUrdf(os.path.join(ROOT, urdf), pin.JointModelFreeFlyer())
        data = model.createData()
        assert np.allclose(model.gravity.linear, [0.0, 0.0, -9.81])
        joints = [
            {
                "name": model.names[j],
                "nq": model.joints[j].nq,
                "nv": model.joints[j].nv,
                "idx_q": model.joints[j].idx_q,
                "idx_v": model.joints[j].idx_v,
            }
            for j in range(1, model.njoints)
        ]
        states = [one_state(model, data, frames, kind, rng) for _ in range(N_STATES)]
        doc = {
            "robot": name,
            "what": what,
            "urdf": urdf,
            "base": "free",
            "contacts": [{"frame": f, "kind": kind} for f in frames],
            "pinocchio": pin.__version__,
            "numpy": importlib.metadata.version("numpy"),
            "seed": SEED,
            "joints": joints,
            "states": states,
        }
        path = os.path.join(OUT, f"{name}.json")
        with open(path, "w") as fh:
            json.dump(doc, fh, indent=1)
            fh.write("\n")
        print(f"{path}: {len(states)} states, {len(frames)} feet")


if __name__ == "__main__":
    main()
