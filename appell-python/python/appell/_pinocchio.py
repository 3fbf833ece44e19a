"""A robot's state in Pinocchio's conventions, and back (the Rust
``appell::pinocchio::PinocchioMap``): see :meth:`appell.Model.pinocchio_map`."""

from __future__ import annotations

import re
from typing import Any, List, Optional, Sequence, Tuple

import numpy as np

# Rust's keywords: a URDF name that is one gets a `_` after it.
_KEYWORDS = set("""as async await break const continue crate dyn else enum extern false fn for if impl
in let loop match mod move mut pub ref return self Self static struct super trait true type unsafe use
where while abstract become box do final gen macro override priv try typeof unsized virtual yield""".split())


def model_name(urdf: str) -> str:
    """A URDF joint's name as the model writes it: each character that
    cannot stand in a Rust name becomes ``_``, a leading digit gets a ``_``
    before it, a keyword a ``_`` after it."""
    s = re.sub(r"[^A-Za-z0-9_]", "_", urdf)
    if not s or s[0].isdigit():
        s = "_" + s
    if s in _KEYWORDS or s == "_":
        s += "_"
    return s


def _rows(value: Any) -> np.ndarray:
    return np.ascontiguousarray(value, dtype=np.float64)


class PinocchioMap:
    """Conversions between a model's arrays and Pinocchio's, made by
    :meth:`appell.Model.pinocchio_map`. A free base: Pinocchio's
    ``q = [x, y, z, qx, qy, qz, qw, joints]`` and ``v = [v, ω, joints]``
    with v and ω in the base's axes, where the model has the quaternion
    scalar first, the position, ω in the base's axes and ṗ in N's axes
    (and its forces dual to those speeds). Every conversion is exact.

    ``q`` below is always the model's coordinates (``model.coordinate_names``
    order), ``v`` the model's speeds; the ``_pin`` arrays are Pinocchio's.
    Each takes one row or N rows (a leading axis), as the model's functions
    do."""

    def __init__(self, native: Any, kind: str, base: Optional[str], joints: Sequence[str]):
        self._native = native
        self.base_kind: str = kind
        self.base: Optional[str] = base
        self.joints: List[str] = list(joints)
        self.nq: int = native.nq
        self.nv: int = native.nv

    def _convert(self, what: str, *args: Any) -> np.ndarray:
        return self._native.convert(what, [_rows(a) for a in args])

    def q_from(self, q_pin: Any) -> np.ndarray:
        """The model's coordinates from Pinocchio's ``q``."""
        return self._convert("q_from", q_pin)

    def q_to(self, q: Any) -> np.ndarray:
        """Pinocchio's ``q`` from the model's coordinates."""
        return self._convert("q_to", q)

    def v_from(self, q: Any, v_pin: Any) -> np.ndarray:
        """The model's speeds at ``q`` from Pinocchio's ``v``."""
        return self._convert("v_from", q, v_pin)

    def v_to(self, q: Any, v: Any) -> np.ndarray:
        """Pinocchio's ``v`` at ``q`` from the model's speeds."""
        return self._convert("v_to", q, v)

    def state_from(self, q_pin: Any, v_pin: Any) -> Tuple[np.ndarray, np.ndarray]:
        """(q, v), the model's, from Pinocchio's ``q`` and ``v``."""
        q = self.q_from(q_pin)
        return q, self.v_from(q, v_pin)

    def a_from(self, q: Any, v_pin: Any, a_pin: Any) -> np.ndarray:
        """The model's accelerations (rates of its speeds) at ``q`` from
        Pinocchio's ``v`` and ``a``."""
        return self._convert("a_from", q, v_pin, a_pin)

    def a_to(self, q: Any, v: Any, v_dot: Any) -> np.ndarray:
        """Pinocchio's ``a`` (the rates of its ``v``) at ``q`` and the
        model's speeds ``v``, from the model's accelerations."""
        return self._convert("a_to", q, v, v_dot)

    def tau_from(self, q: Any, tau_pin: Any) -> np.ndarray:
        """The model's generalized forces at ``q`` from Pinocchio's."""
        return self._convert("tau_from", q, tau_pin)

    def tau_to(self, q: Any, tau: Any) -> np.ndarray:
        """Pinocchio's generalized forces (dual to its ``v``) at ``q`` from
        the model's (dual to its speeds)."""
        return self._convert("tau_to", q, tau)

    def mass_to(self, q: Any, mass: Any) -> np.ndarray:
        """Pinocchio's mass matrix (nv, nv) at ``q`` from the model's."""
        m = _rows(mass)
        if m.ndim not in (2, 3) or m.shape[-1] != m.shape[-2]:
            raise ValueError(f"`mass` must be (l, l) or (N, l, l), got shape {m.shape}")
        rows = m.shape[:-2]
        flat = self._convert("mass_to", q, m.reshape(rows + (m.shape[-1] * m.shape[-2],)))
        return flat.reshape(flat.shape[:-1] + (self.nv, self.nv))

    def __repr__(self) -> str:
        return (f"<appell.PinocchioMap: {self.base_kind} base {self.base!r}, nq {self.nq}, nv {self.nv}, "
                f"{len(self.joints)} joints>")


def detect_base(coordinates: Sequence[str]) -> Tuple[str, Optional[str]]:
    """The base a model's coordinate names show: a free joint ``b``
    (``b_qw, b_qx, b_qy, b_qz, b_x, b_y, b_z``), a planar one (``b_x, b_y,
    b_angle``), or none."""
    names = set(coordinates)
    for c in coordinates:
        if c.endswith("_qw"):
            b = c[:-3]
            if all(f"{b}_{s}" in names for s in ("qx", "qy", "qz", "x", "y", "z")):
                return "free", b
    for c in coordinates:
        if c.endswith("_angle"):
            b = c[:-6]
            if f"{b}_x" in names and f"{b}_y" in names:
                return "planar", b
    return "fixed", None


def base_coordinates(kind: str, base: Optional[str]) -> List[str]:
    """The coordinates a base of ``kind`` on joint ``base`` takes."""
    if kind == "free":
        return [f"{base}_{s}" for s in ("qw", "qx", "qy", "qz", "x", "y", "z")]
    if kind == "planar":
        return [f"{base}_{s}" for s in ("x", "y", "angle")]
    return []
