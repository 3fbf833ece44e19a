"""The models the benchmarks compile: the example models' attributes read
from examples/models/*.rs, the UR5 from its URDF, and the n-link pendulum
on a cart written as PyDy's `pydy.models.n_link_pendulum_on_cart` builds it."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Dict, List, Tuple

REPO = Path(__file__).resolve().parents[2]
UR5_URDF = REPO / "examples/robots/ur5/ur5_robot.urdf"


def rust_model(file: str) -> Tuple[str, Dict[str, float], str]:
    """An example's attributes, its fields with their defaults, its name."""
    text = (REPO / "examples" / "models" / file).read_text()
    lines = text.splitlines()
    start = next(i for i, l in enumerate(lines) if l.startswith("#[appell("))
    end = next(i for i, l in enumerate(lines) if l.startswith("pub struct"))
    name = re.match(r"pub struct (\w+)", lines[end]).group(1)
    fields: List[str] = []
    for l in lines[end + 1 :]:
        if l.startswith("}"):
            break
        m = re.match(r"\s*pub (\w+): f64,", l)
        if m:
            fields.append(m.group(1))
    body = text[text.index(f"impl Default for {name}") :]
    defaults = {f: float(re.search(rf"\b{f}: (-?[0-9.eE+-]+),", body).group(1)) for f in fields}
    return "\n".join(lines[start:end]), defaults, name


def pendulum_on_cart(n: int) -> Tuple[str, List[str]]:
    """PyDy's n-link pendulum on a cart: cart P0 at q0 along N.x with mass
    m0, links of length l_i at absolute angles q_(i+1) from N.x with point
    masses m_(i+1) at their ends, gravity -g N.y, a force F on the cart.
    Returns the model text and the parameter names in PyDy's order."""
    lines = [
        f"coordinates({', '.join(f'q{i}' for i in range(n + 1))}), "
        f"speeds({', '.join(f'q{i}' for i in range(n + 1))})",
        "point(P0 = O + q0 * N.x), particle(P0, mass = m0)",
    ]
    for i in range(n):
        lines.append(
            f"point(P{i + 1} = P{i} + l{i} * cos(q{i + 1}) * N.x + l{i} * sin(q{i + 1}) * N.y), "
            f"particle(P{i + 1}, mass = m{i + 1})"
        )
    lines += ["inputs(F), force(P0, F * N.x)", "gravity(-g * N.y)"]
    params = [f"m{i}" for i in range(n + 1)] + [f"l{i}" for i in range(n)] + ["g"]
    return "\n".join(lines), params
