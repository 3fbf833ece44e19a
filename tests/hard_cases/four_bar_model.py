"""Writes the IFToMM A02 N-four-bar as a `#[derive(Appell)]` model for a
given N (the attribute lists are long and regular): N+1 cranks pinned at
(i, 0) with absolute angles t0..tN, N couplers with angles f1..fN joining
the crank tips, uniform rods of length a and mass m, loops closed by
holonomic constraints, t0 privileged.

Usage: python3 tests/hard_cases/four_bar_model.py 40 > tests/hard_cases/four_bar_40.rs
"""
import sys

n = int(sys.argv[1])
name = f"FourBar{n}"
lines = []
lines.append(f"//! IFToMM A02 with N = {n}, written by `four_bar_model.py {n}` (do not edit).")
lines.append("")
lines.append("use appell::Appell;")
lines.append("")
lines.append(f"/// IFToMM A02, N = {n}: see `four_bar_model.py`.")
lines.append("#[derive(Appell, Clone, Debug)]")
coords = [f"t{i}" for i in range(n + 1)] + [f"f{i}" for i in range(1, n + 1)]
lines.append(f"#[appell(coordinates({', '.join(coords)}), speeds(t0))]")
inertia = "inertia = principal(0, m * a * a / 12, m * a * a / 12)"
# One attribute per link (its frame, points, body and loop constraints):
# the derive's helper attributes count towards the compiler's recursion
# limit, so fewer, fuller attributes keep large N within it.
for i in range(n + 1):
    lines.append(
        f"#[appell(frame(C{i} = N.rotate_z(t{i})), point(A{i} = O + {i} * a * N.x), "
        f"point(B{i} = A{i} + a * C{i}.x), point(G{i} = A{i} + a / 2 * C{i}.x), "
        f"body(crank{i}, center = G{i}, frame = C{i}, mass = m, {inertia}))]"
    )
for i in range(1, n + 1):
    lines.append(
        f"#[appell(frame(K{i} = N.rotate_z(f{i})), point(H{i} = B{i-1} + a / 2 * K{i}.x), "
        f"body(coupler{i}, center = H{i}, frame = K{i}, mass = m, {inertia}), "
        f"holonomic(dot(B{i-1} + a * K{i}.x - B{i}, N.x) == 0), holonomic(dot(B{i-1} + a * K{i}.x - B{i}, N.y) == 0))]"
    )
lines.append("#[appell(gravity(-g * N.y))]")
lines.append(f"pub struct {name} {{")
lines.append("    /// Link length [m].")
lines.append("    pub a: f64,")
lines.append("    /// Link mass [kg].")
lines.append("    pub m: f64,")
lines.append("    /// Gravity [m/s²].")
lines.append("    pub g: f64,")
lines.append("}")
print("\n".join(lines))
