#!/usr/bin/env python3
"""Check SymPy's generated rhs (build/whipple_sympy_rhs.c) two ways:

1. against appell's rhs (`whipple_bicycle eval`) at random states that
   satisfy the holonomic constraint (pitch q5 solved by Newton for the given
   roll q4 and steer q7);
2. against the benchmark: eigenvalues of the lean/steer linearization at
   5 m/s and the weave and capsize speeds (central differences of the
   compiled rhs, pitch re-solved at every perturbed configuration).

Usage: python3 check.py [path/to/whipple_bicycle]
Writes build/check.json. Needs only SymPy (mpmath) and a C compiler.
"""
import ctypes
import json
import math
import os
import random
import subprocess
import sys

import mpmath
import sympy as sm
import sympy.physics.mechanics as me

HERE = os.path.dirname(os.path.abspath(__file__))
BUILD = os.path.join(HERE, "build")
APPELL = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
    HERE, "..", "..", "target", "release", "examples", "whipple_bicycle")

PARAMS = [0.35, 0.3, 0.9534570696121849, 0.2676445084476887, 0.03207142672761929,
          0.4707271515135145, -0.47792881146460797, -0.00597083392418685,
          -0.3699518200282974, 85.0, 2.0, 4.0, 3.0, 7.178169776497895, 11.0,
          4.821830223502103, 3.8225535938357873, 0.0603, 0.12, 0.05841337700152972,
          0.06, 0.007586622998470264, 0.009119225261946298, 0.1405, 0.28, 9.81]
rf, rr, d1, d2, d3 = PARAMS[:5]

# ---- the compiled rhs through ctypes --------------------------------------
lib_path = os.path.join(BUILD, "libwhipple_sympy.so")
subprocess.run(["cc", "-O2", "-shared", "-fPIC", "-o", lib_path,
                os.path.join(BUILD, "whipple_sympy_rhs.c"), "-lm"], check=True)
lib = ctypes.CDLL(lib_path)
D6 = ctypes.c_double * 6
P26 = (ctypes.c_double * 26)(*PARAMS)


def sympy_rhs(x, torque=0.0):
    dx = D6()
    lib.sympy_whipple_rhs(P26, D6(*x), (ctypes.c_double * 1)(torque), dx)
    return list(dx)


# ---- the holonomic constraint (front contact height), built here ----------
q3, q4, q5, q7 = sm.symbols("q3 q4 q5 q7")
N = me.ReferenceFrame("N")
A = N.orientnew("A", "Axis", (q3, N.z))
B = A.orientnew("B", "Axis", (q4, A.x))
C = B.orientnew("C", "Axis", (q5, B.y))
E = C.orientnew("E", "Axis", (q7, C.z))
r_PQ = (-rr * B.z + d1 * C.x + d2 * E.z + d3 * E.x
        + rf * me.cross(me.cross(E.y, A.z), E.y).normalize())
hol = sm.simplify(r_PQ.dot(A.z))
hol_f = sm.lambdify((q4, q5, q7), hol, "math")
dhol_f = sm.lambdify((q4, q5, q7), hol.diff(q5), "math")


def pitch(q4v, q7v, guess=math.pi / 10):
    x = guess
    for _ in range(50):
        step = hol_f(q4v, x, q7v) / dhol_f(q4v, x, q7v)
        x -= step
        if abs(step) < 1e-15:
            break
    return x


# ---- 1. against appell ------------------------------------------------------
rng = random.Random(20240601)
states = []
for _ in range(20):
    q4v = rng.uniform(-0.5, 0.5)
    q7v = rng.uniform(-0.8, 0.8)
    q5v = pitch(q4v, q7v)
    u4, u6, u7 = rng.uniform(-2, 2), rng.uniform(-20, 0), rng.uniform(-2, 2)
    torque = rng.uniform(-1, 1)
    others = [rng.uniform(-3, 3) for _ in range(5)]  # q1 q2 q3 q6 q8: ignorable
    states.append((q4v, q5v, q7v, u4, u6, u7, torque, others))

lines = []
for (q4v, q5v, q7v, u4, u6, u7, torque, o) in states:
    lines.append(json.dumps({
        "q": {"q1": o[0], "q2": o[1], "q3": o[2], "q4": q4v, "q5": q5v, "q6": o[3],
              "q7": q7v, "q8": o[4]},
        "u": {"q4": u4, "q6": u6, "q7": u7}, "inputs": {"steer_torque": torque}}))
out = subprocess.run([APPELL, "eval"], input="\n".join(lines) + "\n", capture_output=True,
                     text=True, check=True).stdout.strip().splitlines()
max_rel = 0.0
max_abs = 0.0
rows = []
for s, line in zip(states, out):
    a = json.loads(line)
    appell = [a["qdot"]["q4"], a["qdot"]["q5"], a["qdot"]["q7"],
              a["udot"]["q4"], a["udot"]["q6"], a["udot"]["q7"]]
    sy = sympy_rhs(s[:6], s[6])
    # relative to the larger magnitude, floored at 1e-6 so that components
    # that vanish (round-off on both sides) do not count as relative errors
    for x, y in zip(appell, sy):
        d = abs(x - y)
        max_abs = max(max_abs, d)
        max_rel = max(max_rel, d / max(abs(x), abs(y), 1e-6))
    rows.append({"state": list(s[:7]), "appell": appell, "sympy": sy})
print(f"against appell at {len(states)} states: max |diff| {max_abs:.3e}, "
      f"max relative diff {max_rel:.3e}")

# ---- 2. benchmark linearization ---------------------------------------------


def lean_steer_rates(z, v):
    q4v, q7v, u4, u7 = z
    q5v = pitch(q4v, q7v)
    d = sympy_rhs([q4v, q5v, q7v, u4, -v / rr, u7])
    return [d[0], d[2], d[3], d[5]]


def jacobian(v, h=1e-6):
    J = mpmath.matrix(4, 4)
    for j in range(4):
        zp = [0.0] * 4
        zm = [0.0] * 4
        zp[j] += h
        zm[j] -= h
        fp, fm = lean_steer_rates(zp, v), lean_steer_rates(zm, v)
        for i in range(4):
            J[i, j] = (fp[i] - fm[i]) / (2 * h)
    return J


def eigs(v):
    ev = mpmath.eig(jacobian(v), left=False, right=False)
    return sorted(((float(mpmath.re(e)), float(mpmath.im(e))) for e in ev),
                  key=lambda e: (e[0], e[1]))


def weave(v):
    return max(e[0] for e in eigs(v) if abs(e[1]) > 1e-9)


def capsize(v):
    return max(e[0] for e in eigs(v) if abs(e[1]) <= 1e-9)


def bisect(f, lo, hi, tol=1e-10):
    flo = f(lo)
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        if (f(mid) > 0) == (flo > 0):
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


pitch0 = pitch(0.0, 0.0)
ev5 = eigs(5.0)
vw = bisect(weave, 3.0, 5.0)
vc = bisect(capsize, 5.0, 8.0)
print(f"upright pitch {pitch0!r} (pi/10 = {math.pi / 10!r})")
print("eigenvalues at 5 m/s:", ev5)
print(f"weave speed {vw:.10f} (benchmark 4.29238253634111), "
      f"capsize speed {vc:.10f} (benchmark 6.02426201538837)")
with open(os.path.join(BUILD, "check.json"), "w") as fh:
    json.dump({"appell_states": len(states), "max_abs_diff": max_abs,
               "max_rel_diff": max_rel, "upright_pitch": pitch0,
               "eigenvalues_5mps": ev5, "weave_speed": vw, "capsize_speed": vc,
               "rows": rows}, fh, indent=1)
