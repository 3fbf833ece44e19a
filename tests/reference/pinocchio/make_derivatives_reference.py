#!/usr/bin/env python3
"""Writes Pinocchio's analytical derivatives of the dynamics (derivatives/
beside this script) at the states of the reference files make_reference.py
wrote (ur5, panda, spatial_chain_8): for each state, computeRNEADerivatives
at (q, v, a) and computeABADerivatives at (q, v, tau), in Pinocchio's joint
order as those files have it.

Each file has, per state (the state itself is the one in ../<robot>.json,
matched by index; q, v, a and tau are repeated here so that the file can be
read alone):

    dtau_dq, dtau_dv, dtau_da   d rnea(q, v, a) / d q, v, a (dtau_da = M)
    ddq_dq, ddq_dv, ddq_dtau    d aba(q, v, tau) / d q, v, tau (ddq_dtau = M^-1)

each a list of rows. Pinocchio fills only the upper triangle of dtau_da and
ddq_dtau; both are written whole (the upper triangle mirrored).

The script checks Pinocchio's answer before writing it: every matrix against
central differences of pin.rnea / pin.aba (step 1e-6, to 1e-6 relative;
every joint is revolute, so q + h e_j is a plain sum), dtau_da against CRBA,
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
STEP = 1e-6
DIFF_TOL = 1e-6
TOL = 1e-9


def rel(a, b):
    """max |a - b| over 1 + max |b|."""
    return float(np.max(np.abs(a - b)) / (1.0 + np.max(np.abs(b))))


def central(f, x):
    """Central differences of f at x, one column per component."""
    cols = []
    for j in range(len(x)):
        e = np.zeros(len(x))
        e[j] = STEP
        cols.append((f(x + e) - f(x - e)) / (2 * STEP))
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


def check(model, data, q, v, a, tau, d):
    """The checks of the module's docstring; returns the worst difference
    from central differences."""
    rnea = lambda q_, v_, a_: pin.rnea(model, data, q_, v_, a_).copy()
    aba = lambda q_, v_, t_: pin.aba(model, data, q_, v_, t_).copy()
    numeric = {
        "dtau_dq": central(lambda x: rnea(x, v, a), q),
        "dtau_dv": central(lambda x: rnea(q, x, a), v),
        "dtau_da": central(lambda x: rnea(q, v, x), a),
        "ddq_dq": central(lambda x: aba(x, v, tau), q),
        "ddq_dv": central(lambda x: aba(q, x, tau), v),
        "ddq_dtau": central(lambda x: aba(q, v, x), tau),
    }
    worst = 0.0
    for key, value in numeric.items():
        r = rel(d[key], value)
        assert r < DIFF_TOL, (key, r)
        worst = max(worst, r)
    mass = symmetric(pin.crba(model, data, q).copy())
    assert rel(d["dtau_da"], mass) < TOL
    n = len(q)
    assert rel(d["ddq_dtau"] @ mass, np.eye(n)) < TOL
    ddq = aba(q, v, tau)
    at_ddq = pin.computeRNEADerivatives(model, data, q, v, ddq)[0].copy()
    assert rel(d["ddq_dq"], -np.linalg.solve(mass, at_ddq)) < TOL
    return worst


def main():
    os.makedirs(OUT, exist_ok=True)
    robots = {name: (rel_, welded) for name, rel_, _, welded in ROBOTS}
    for name in NAMES:
        rel_, welded = robots[name]
        model = load(os.path.join(ROOT, rel_), welded)
        data = model.createData()
        with open(os.path.join(HERE, f"{name}.json")) as f:
            base = json.load(f)
        assert list(model.names)[1:] == base["joints"], name
        states, worst = [], 0.0
        for s in base["states"]:
            q, v, a, tau = (np.array(s[k]) for k in ("q", "v", "a", "tau"))
            d = derivatives(model, data, q, v, a, tau)
            worst = max(worst, check(model, data, q, v, a, tau, d))
            entry = {k: s[k] for k in ("q", "v", "a", "tau")}
            entry.update({k: m.tolist() for k, m in d.items()})
            states.append(entry)
        doc = {
            "robot": name,
            "urdf": rel_,
            "pinocchio_version": pin.__version__,
            "numpy_version": np.__version__,
            "states_from": f"tests/reference/pinocchio/{name}.json",
            "gravity": base["gravity"],
            "joints": base["joints"],
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
