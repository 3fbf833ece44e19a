#!/usr/bin/env python3
"""Derive the Whipple bicycle (Moore's 2012 geometry) with SymPy's KanesMethod,
reduce it to the three independent speeds (roll, rear wheel, steer rates), and
write C code for the right-hand side after common subexpression elimination.

Output (in ./build/ by default):
  whipple_sympy_rhs.c  the generated rhs (M and f with CSE, then a 3x3 solve)
  derive.json          timings of each stage and the operation counts

The model follows appell's examples/models/whipple_bicycle.rs: coordinates
q1..q8 (rear contact x, y; yaw; roll; pitch; rear wheel; steer; front wheel),
z down, gravity +g N.z, pitch q5 dependent through (Q - P).A.z = 0, a steer
torque T acting on E about C.z and back on C.
"""
import json
import os
from collections import Counter
import sys
import time

import sympy as sm
import sympy.physics.mechanics as me

OUT = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "build")
os.makedirs(OUT, exist_ok=True)

timings = {}
t_start = time.perf_counter()


def stamp(name, t0):
    dt = time.perf_counter() - t0
    timings[name] = round(dt, 3)
    print(f"[{time.perf_counter() - t_start:8.2f} s] {name}: {dt:.2f} s", flush=True)


# ----------------------------------------------------------------------------
# Model
# ----------------------------------------------------------------------------
t0 = time.perf_counter()
q = me.dynamicsymbols("q1:9")
qd = [qi.diff() for qi in q]
u = me.dynamicsymbols("u1:9")
q1, q2, q3, q4, q5, q6, q7, q8 = q
u1, u2, u3, u4, u5, u6, u7, u8 = u

PARAMS = sm.symbols(
    "rf rr d1 d2 d3 l1 l2 l3 l4 mc md me mf ic11 ic22 ic33 ic31 id11 id22 "
    "ie11 ie22 ie33 ie31 if11 if22 g"
)
(rf, rr, d1, d2, d3, l1, l2, l3, l4, mc, md, m_e, mf, ic11, ic22, ic33, ic31,
 id11, id22, ie11, ie22, ie33, ie31, if11, if22, g) = PARAMS
T = sm.Symbol("T")  # steer torque input

N = me.ReferenceFrame("N")
A = N.orientnew("A", "Axis", (q3, N.z))  # yaw
B = A.orientnew("B", "Axis", (q4, A.x))  # roll
C = B.orientnew("C", "Axis", (q5, B.y))  # pitch (rear frame)
D = C.orientnew("D", "Axis", (q6, C.y))  # rear wheel
E = C.orientnew("E", "Axis", (q7, C.z))  # steer (front frame)
F = E.orientnew("F", "Axis", (q8, E.y))  # front wheel

# Speeds: u_i = q_i' for i = 3..8; the rear contact velocity is expressed in
# the yaw frame A (u1 along A.x, u2 along A.y), which keeps the cyclic yaw out
# of the constraint equations.
kd = [qd[0] - (u1 * sm.cos(q3) - u2 * sm.sin(q3)),
      qd[1] - (u1 * sm.sin(q3) + u2 * sm.cos(q3))]
kd += [qd[i] - u[i] for i in range(2, 8)]

O = me.Point("O")
O.set_vel(N, 0)
P = O.locatenew("P", q1 * N.x + q2 * N.y)
P.set_vel(N, u1 * A.x + u2 * A.y)
Do = P.locatenew("Do", -rr * B.z)
Do.set_vel(N, P.vel(N) + Do.pos_from(P).dt(N))
Co = Do.locatenew("Co", l1 * C.x + l2 * C.z)
Co.v2pt_theory(Do, N, C)
Fo = Do.locatenew("Fo", d1 * C.x + d2 * E.z + d3 * E.x)
Fo.set_vel(N, Do.vel(N) + Fo.pos_from(Do).dt(N))
Eo = Fo.locatenew("Eo", l3 * E.x + l4 * E.z)
Eo.v2pt_theory(Fo, N, E)
# Front contact: the point of the rim nearest the ground, in the wheel plane.
Q = Fo.locatenew("Q", rf * me.cross(me.cross(E.y, A.z), E.y).normalize())

# Holonomic constraint: the front contact touches the ground.
holonomic = Q.pos_from(P).dot(A.z)

# Velocities of the wheels' material points at the contacts.
v_rear = Do.vel(N) + me.cross(D.ang_vel_in(N), P.pos_from(Do))
v_front = Fo.vel(N) + me.cross(F.ang_vel_in(N), Q.pos_from(Fo))
vel_constraints = [v_rear.dot(A.x), v_rear.dot(A.y),
                   v_front.dot(A.x), v_front.dot(A.y), v_front.dot(A.z)]

bodies = [
    me.RigidBody("rear_frame", Co, C, mc, (me.inertia(C, ic11, ic22, ic33, 0, 0, ic31), Co)),
    # The wheels' central inertias are symmetric about their axles, so they
    # are written in the frames the axles are fixed in (C and E); written in
    # D and F the same dyadics would leave cos(q6)**2 + sin(q6)**2 factors
    # (and q8 likewise) unsimplified in the equations.
    me.RigidBody("rear_wheel", Do, D, md, (me.inertia(C, id11, id22, id11), Do)),
    me.RigidBody("front_frame", Eo, E, m_e, (me.inertia(E, ie11, ie22, ie33, 0, 0, ie31), Eo)),
    me.RigidBody("front_wheel", Fo, F, mf, (me.inertia(E, if11, if22, if11), Fo)),
]
loads = [(Co, mc * g * N.z), (Do, md * g * N.z), (Eo, m_e * g * N.z), (Fo, mf * g * N.z),
         (E, T * C.z), (C, -T * C.z)]

u_ind = [u4, u6, u7]
# Dependent speeds in the order of the velocity constraints they dominate
# near upright running (rear A.x: u1, rear A.y: u2, front A.x: front wheel
# rate u8, front A.y: yaw rate u3, front A.z: pitch rate u5), so that the
# pivots of SymPy's LU solve (taken on the diagonal) do not vanish there.
u_dep = [u1, u2, u8, u3, u5]
stamp("model", t0)

t0 = time.perf_counter()
kane = me.KanesMethod(
    N,
    q_ind=[q1, q2, q3, q4, q6, q7, q8],
    u_ind=u_ind,
    kd_eqs=kd,
    q_dependent=[q5],
    configuration_constraints=[holonomic],
    u_dependent=u_dep,
    velocity_constraints=vel_constraints,
)
stamp("KanesMethod (constraints, Ars)", t0)

t0 = time.perf_counter()
kane.kanes_equations(bodies, loads)
stamp("kanes_equations (Fr, Fr*)", t0)

# ----------------------------------------------------------------------------
# Reduction to the independent speeds
# ----------------------------------------------------------------------------
# KanesMethod gives mass_matrix * udot = forcing, 8x8 in all udots: the first three
# rows are the reduced dynamics k_d udot = f_d (which still contain the
# dependent speeds and accelerations), the last five are the time derivatives
# of the velocity constraints. Eliminating the dependent accelerations:
#   udot_dep = Ars udot_ind + c,   c = B_dep^-1 forcing[3:],
# gives M3 udot_ind = f3 with M3 = K_ind + K_dep Ars, f3 = f_d - K_dep c,
# and the dependent speeds are then replaced by u_dep = Ars u_ind.
t0 = time.perf_counter()
p = len(u_ind)
# Plain symbols for the code printer (replaced before the products below,
# which share subexpressions and would be slow to walk as trees).
qs = sm.symbols("q1:9")
us = sm.symbols("u1:9")
plain = dict(zip(q, qs))
plain.update(dict(zip(u, us)))
MM = kane.mass_matrix.xreplace(plain)
FF = kane.forcing.xreplace(plain)
Ars = kane._Ars.xreplace(plain)  # -B_dep^-1 B_ind, computed by KanesMethod (LU)
u_ind_s = [plain[x] for x in u_ind]
u_dep_s = [plain[x] for x in u_dep]
for m in (MM, FF, Ars):
    bad = m.atoms(sm.Derivative) | m.atoms(sm.core.function.AppliedUndef)
    assert not bad, f"time functions left: {bad}"
u_dep_expr = Ars * sm.Matrix(u_ind_s)
FF = FF.xreplace(dict(zip(u_dep_s, u_dep_expr)))
K_ind, K_dep = MM[:p, :p], MM[:p, p:]
B_dep = MM[p:, p:]
c = B_dep.LUsolve(FF[p:, :])
M3 = K_ind + K_dep * Ars
f3 = FF[:p, :] - K_dep * c
q5dot = u_dep_expr[u_dep.index(u5)]
exprs = [q5dot] + [M3[i, j] for i in range(3) for j in range(3)] + list(f3)
stamp("reduction to 3x3", t0)

# ----------------------------------------------------------------------------
# CSE and C code
# ----------------------------------------------------------------------------
t0 = time.perf_counter()
def dag_size(roots):
    seen = set()
    stack = list(roots)
    while stack:
        e = stack.pop()
        if e in seen:
            continue
        seen.add(e)
        stack.extend(e.args)
    return len(seen)


dag_nodes = dag_size(exprs)
print("distinct subexpressions before cse:", dag_nodes, flush=True)
stamp("dag size", t0)
t0 = time.perf_counter()
CSE_ORDER = os.environ.get("CSE_ORDER", "none")
repl, reduced = sm.cse(exprs, order=CSE_ORDER)
stamp("cse", t0)
free = set()
for _, e in repl:
    free |= e.free_symbols
for e in reduced:
    free |= e.free_symbols
free -= {s_ for s_, _ in repl}
allowed = set(PARAMS) | {T, qs[3], qs[4], qs[6], us[3], us[5], us[6]}
assert free <= allowed, f"unexpected symbols {free - allowed}"


def count_ops(e):
    """Binary operations as a straight-line program would compute them:
    an n-term sum is n-1 additions/subtractions (a negative term is a
    subtraction), an n-factor product n-1 multiplications (a factor with a
    negative exponent a division instead, a numeric coefficient one
    multiplication, -1 a negation when not absorbed by a subtraction),
    x**k for integer k a chain of multiplications (binary powering, like
    appell), sqrt and the trigonometric functions one call each."""
    cnt = Counter()

    def powchain(k):
        # multiplications for x**k by binary powering (as appell lowers it)
        if k <= 1:
            return 0
        return powchain(k // 2) + 1 + (k % 2)

    def visit(x, in_add=False):
        if x.is_Atom:
            return
        if x.is_Add:
            terms = x.args
            negs = 0
            for a in terms:
                c, rest = a.as_coeff_Mul()
                if c.is_negative:
                    negs += 1
                visit(a, in_add=True)
            cnt["add"] += len(terms) - 1
            if negs == len(terms):
                cnt["neg"] += 1
            return
        if x.is_Mul:
            c, rest = x.as_coeff_Mul()
            factors = list(sm.Mul.make_args(rest))
            num = [f for f in factors if not (f.is_Pow and f.exp.is_negative)]
            den = [f for f in factors if f.is_Pow and f.exp.is_negative]
            for f in num:
                visit(f)
            for f in den:
                visit(sm.Pow(f.base, -f.exp))
            k = len(num)
            if c != 1 and c != -1:
                k += 1  # numeric coefficient multiplies
            cnt["mul"] += max(k - 1, 0)
            if not num and c in (1, -1):
                k = 1  # 1/x
            cnt["div"] += len(den)
            if c == -1 and not in_add:
                cnt["neg"] += 1
            return
        if x.is_Pow:
            b, ex = x.base, x.exp
            visit(b)
            if ex == sm.S.Half:
                cnt["calls"] += 1
            elif ex == -sm.S.Half:
                cnt["calls"] += 1
                cnt["div"] += 1
            elif ex.is_Integer and ex > 0:
                cnt["mul"] += powchain(int(ex))
            elif ex.is_Integer and ex < 0:
                cnt["mul"] += powchain(int(-ex))
                cnt["div"] += 1
            elif ex.is_Rational and ex.q == 2:
                # x**(k/2) = sqrt(x) * x**((k-1)/2)
                k = abs(int(ex.p))
                cnt["calls"] += 1
                cnt["mul"] += powchain((k - 1) // 2) + (1 if k > 1 else 0)
                if ex < 0:
                    cnt["div"] += 1
            else:
                cnt["calls"] += 1  # pow()
            return
        if isinstance(x, sm.Function):
            cnt["calls"] += 1
            for a in x.args:
                visit(a)
            return
        raise NotImplementedError(type(x))

    visit(e)
    return cnt


ops = Counter()
for _, e in repl:
    ops += count_ops(e)
for e in reduced:
    ops += count_ops(e)
ops_exprs = dict(ops)
# Operations that depend on the parameters only (appell computes such work
# once, in `prepare`; SymPy's code recomputes it at every call).
param_only_syms = set()
ops_param = Counter()
for s_, e in repl:
    if e.free_symbols <= set(PARAMS) | param_only_syms:
        param_only_syms.add(s_)
        ops_param += count_ops(e)
print("ops on parameters only:", dict(ops_param), sum(ops_param.values()))
# The 3x3 solve appended in C (SOLVE below), counted by hand: reciprocals
# i0, i1 and y2 (3 div); multipliers e1 e2 e3 (3 mul); eight row updates
# (8 mul, 8 sub); back substitution y1, y0 (5 mul, 3 sub).
SOLVE_OPS = {"add": 11, "mul": 16, "div": 3}
ops_total = Counter(ops_exprs) + Counter(SOLVE_OPS)
ops_total_n = sum(ops_total.values())
print("ops (cse'd expressions):", dict(ops_exprs), sum(ops_exprs.values()))
print("ops (with 3x3 solve):", dict(ops_total), ops_total_n)

t0 = time.perf_counter()
from sympy.printing.c import C99CodePrinter
printer = C99CodePrinter()
lines = []
lines.append("/* Generated by derive.py (SymPy %s KanesMethod + cse + C99CodePrinter). */" % sm.__version__)
lines.append("#include <math.h>")
lines.append("")
lines.append("/* p: the 26 parameters in the order")
lines.append(" *    " + " ".join(str(s) for s in PARAMS))
lines.append(" * x: state (q4, q5, q7, u4, u6, u7), r: input (steer torque T)")
lines.append(" * dx: (q4', q5', q7', u4', u6', u7') */")
lines.append("void sympy_whipple_rhs(const double *restrict p, const double *restrict x,")
lines.append("                       const double *restrict r, double *restrict dx)")
lines.append("{")
for i, s in enumerate(PARAMS):
    lines.append(f"    const double {s} = p[{i}];")
for i, s in enumerate([qs[3], qs[4], qs[6], us[3], us[5], us[6]]):
    lines.append(f"    const double {s} = x[{i}];")
lines.append("    const double T = r[0];")
for s, e in repl:
    lines.append(f"    const double {s} = {printer.doprint(e)};")
names = ["q5d"] + [f"m{i}{j}" for i in range(3) for j in range(3)] + ["f0", "f1", "f2"]
for n_, e in zip(names, reduced):
    lines.append(f"    double {n_} = {printer.doprint(e)};")
# SOLVE: M3 y = f3 by Gaussian elimination without pivoting (M3 is the
# reduced mass matrix, symmetric positive definite).
lines.append("""    /* 3x3 solve, Gaussian elimination without pivoting */
    const double i0 = 1.0 / m00;
    const double e1 = m10 * i0, e2 = m20 * i0;
    m11 -= e1 * m01; m12 -= e1 * m02; f1 -= e1 * f0;
    m21 -= e2 * m01; m22 -= e2 * m02; f2 -= e2 * f0;
    const double i1 = 1.0 / m11;
    const double e3 = m21 * i1;
    m22 -= e3 * m12; f2 -= e3 * f1;
    const double y2 = f2 / m22;
    const double y1 = (f1 - m12 * y2) * i1;
    const double y0 = (f0 - m01 * y1 - m02 * y2) * i0;
    dx[0] = u4;
    dx[1] = q5d;
    dx[2] = u7;
    dx[3] = y0;
    dx[4] = y1;
    dx[5] = y2;
}""")
code = "\n".join(lines) + "\n"
with open(os.path.join(OUT, "whipple_sympy_rhs.c"), "w") as fh:
    fh.write(code)
stamp("C code printing", t0)

timings["total"] = round(time.perf_counter() - t_start, 3)
with open(os.path.join(OUT, "derive.json"), "w") as fh:
    json.dump({
        "sympy": sm.__version__,
        "timings_s": timings,
        "cse_order": CSE_ORDER,
        "distinct_subexpressions_before_cse": dag_nodes,
        "cse_temporaries": len(repl),
        "ops_expressions": dict(ops_exprs),
        "ops_solve": SOLVE_OPS,
        "ops_parameter_only": sum(ops_param.values()),
        "ops_total": ops_total_n,
        "ops_total_by_kind": dict(ops_total),
        "c_bytes": len(code),
    }, fh, indent=1)
print(json.dumps(timings))
