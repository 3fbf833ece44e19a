#!/usr/bin/env python3
"""Writes Pinocchio's analytical derivatives of the dynamics (derivatives/
beside this script) at the states of the reference files make_reference.py
wrote (ur5, panda, spatial_chain_8) and make_robots_reference.py wrote
(solo12, on a free flyer; its first 8 states, the base's wrench in tau
set to zero): for each state, computeRNEADerivatives at
(q, v, a) and computeABADerivatives at (q, v, tau), in Pinocchio's joint
order as those files have it. On a free flyer the derivatives by q are
along Pinocchio's tangent: d f(integrate(q, dq)) / d dq at dq = 0, with
the base's part a twist in the base's axes (linear, then angular).

Each file has, per state (the state itself is the one in ../<robot>.json,
matched by index; q, v, a and tau are repeated here so that the file can be
read alone):

    dtau_dq, dtau_dv, dtau_da   d rnea(q, v, a) / d q, v, a (dtau_da = M)
    ddq_dq, ddq_dv, ddq_dtau    d aba(q, v, tau) / d q, v, tau (ddq_dtau = M^-1)

each a list of rows. Pinocchio fills only the upper triangle of dtau_da and
ddq_dtau; both are written whole (the upper triangle mirrored).

The script checks Pinocchio's answer before writing it: every matrix against
central differences of pin.rnea / pin.aba (step 1e-6, 1e-4 on a free
flyer, to 1e-6 relative; q moved by pin.integrate), dtau_da against CRBA,
ddq_dtau M = I, and ddq_dq = -M^-1 dtau_dq at a = aba(q, v, tau) (the two
algorithms differentiate the same equations).

Needs: pip install pin==4.1.0 numpy
Usage (from anywhere): python3 tests/reference/pinocchio/make_derivatives_reference.py
"""
import json
import os

import numpy as np
import pinocchio as pin

from make_reference import ROBOTS, fmt, load, symmetric

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", "..", ".."))
OUT = os.path.join(HERE, "derivatives")

NAMES = ["ur5", "panda", "spatial_chain_8"]
# Floating-base robots: (name, the states' file in robots/).
FREE_NAMES = [("solo12", "solo12")]
STEP = 1e-6
# Solo12's accelerations reach 1e4: a step of 1e-6 loses 1e-7 to rounding.
FREE_STEP = 1e-4
# A free flyer's file keeps its first states only (each is 18 x 18 x 6).
FREE_STATES = 8
DIFF_TOL = 1e-6
TOL = 1e-9


def rel(a, b):
    """max |a - b| over 1 + max |b|."""
    return float(np.max(np.abs(a - b)) / (1.0 + np.max(np.abs(b))))


def central(f, x, step):
    """Central differences of f at x, one column per component."""
    cols = []
    for j in range(len(x)):
        e = np.zeros(len(x))
        e[j] = step
        cols.append((f(x + e) - f(x - e)) / (2 * step))
    return np.array(cols).T


def derivatives(model, data, q, v, a, tau):
    dtau_dq, dtau_dv, dtau_da = (m.copy() for m in pin.computeRNEADerivatives(model, data, q, v, a))
    ddq_dq, ddq_dv, ddq_dtau = (m.copy() for m in pin.computeABADerivatives(model, data, q, v, tau))
    return {
        "dtau_dq": dtau_dq,
        "dtau_dv": dtau_dv,
        "dtau_da": symmetric(dtau_da),
        "ddq_dq": ddq_dq,
        "ddq_dv": ddq_dv,
        "ddq_dtau": symmetric(ddq_dtau),
    }


def check(model, data, q, v, a, tau, d, step):
    """The checks of the module's docstring; returns the worst difference
    from central differences."""
    rnea = lambda q_, v_, a_: pin.rnea(model, data, q_, v_, a_).copy()
    aba = lambda q_, v_, t_: pin.aba(model, data, q_, v_, t_).copy()
    moved = lambda dq: pin.integrate(model, q, dq)
    zero = np.zeros(model.nv)
    numeric = {
        "dtau_dq": central(lambda x: rnea(moved(x), v, a), zero, step),
        "dtau_dv": central(lambda x: rnea(q, x, a), v, step),
        "dtau_da": central(lambda x: rnea(q, v, x), a, step),
        "ddq_dq": central(lambda x: aba(moved(x), v, tau), zero, step),
        "ddq_dv": central(lambda x: aba(q, x, tau), v, step),
        "ddq_dtau": central(lambda x: aba(q, v, x), tau, step),
    }
    worst = 0.0
    for key, value in numeric.items():
        r = rel(d[key], value)
        assert r < DIFF_TOL, (key, r)
        worst = max(worst, r)
    mass = symmetric(pin.crba(model, data, q).copy())
    assert rel(d["dtau_da"], mass) < TOL
    n = model.nv
    assert rel(d["ddq_dtau"] @ mass, np.eye(n)) < TOL
    ddq = aba(q, v, tau)
    at_ddq = pin.computeRNEADerivatives(model, data, q, v, ddq)[0].copy()
    assert rel(d["ddq_dq"], -np.linalg.solve(mass, at_ddq)) < TOL
    return worst


def joint_names(base):
    """The joints of a reference file: names (make_reference.py) or
    entries with a name (make_robots_reference.py)."""
    return [j["name"] if isinstance(j, dict) else j for j in base["joints"]]


def main():
    os.makedirs(OUT, exist_ok=True)
    robots = {name: (rel_, welded) for name, rel_, _, welded in ROBOTS}
    jobs = [(name, robots[name][0], robots[name][1], f"{name}.json", False) for name in NAMES]
    jobs += [(name, None, [], os.path.join("robots", f"{states}.json"), True) for name, states in FREE_NAMES]
    for name, rel_, welded, states_file, free in jobs:
        with open(os.path.join(HERE, states_file)) as f:
            base = json.load(f)
        if free:
            rel_ = base["urdf"]
            model = pin.buildModelFromUrdf(os.path.join(ROOT, rel_), pin.JointModelFreeFlyer())
        else:
            model = load(os.path.join(ROOT, rel_), welded)
        data = model.createData()
        assert list(model.names)[1:] == joint_names(base), name
        states, worst = [], 0.0
        for s in base["states"][:FREE_STATES] if free else base["states"]:
            q, v, a, tau = (np.array(s[k]) for k in ("q", "v", "a", "tau"))
            if free:
                # A free base is not actuated: the joints' torques only.
                tau[:6] = 0.0
            d = derivatives(model, data, q, v, a, tau)
            worst = max(worst, check(model, data, q, v, a, tau, d, FREE_STEP if free else STEP))
            entry = {k: s[k] for k in ("q", "v", "a")}
            entry["tau"] = tau.tolist()
            entry.update({k: m.tolist() for k, m in d.items()})
            states.append(entry)
        doc = {
            "robot": name,
            "urdf": rel_,
            "pinocchio_version": pin.__version__,
            "numpy_version": np.__version__,
            "states_from": f"tests/reference/pinocchio/{states_file}",
            "base": "free" if free else "fixed",
            "gravity": base["gravity"],
            "joints": joint_names(base),
            "states": states,
        }
        out = os.path.join(OUT, f"{name}.json")
        with open(out, "w", newline="\n") as f:
            f.write(fmt(doc) + "\n")
        with open(out) as f:
            assert json.load(f)["states"] == states
        print(f"{name}: {len(states)} states; worst against central differences {worst:.1e}; wrote {out}")


if __name__ == "__main__":
    main()
