"""``appell.Model``: a compiled model's functions on NumPy arrays."""

from __future__ import annotations

import difflib
import os
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union, overload

import numpy as np

from ._pinocchio import PinocchioMap, base_coordinates, detect_base, model_name

#: What ``simulate`` returns with an event: the times reached, the states
#: there, and the event's (t, x) or None.
EventRun = Tuple[np.ndarray, np.ndarray, Optional[Tuple[float, np.ndarray]]]

from .errors import ModelError

ArrayLike = Union[np.ndarray, Sequence[float], Sequence[Sequence[float]], Mapping[str, Any]]

_threads = max(1, os.cpu_count() or 1)
_min_rows = 64


def set_num_threads(n: int) -> None:
    """The most threads a batched call splits its rows over (default: the
    number of CPUs). Threads are used from 64 rows per thread up."""
    global _threads
    if int(n) < 1:
        raise ValueError("the number of threads must be at least 1")
    _threads = int(n)


def get_num_threads() -> int:
    """See :func:`set_num_threads`."""
    return _threads


def _hint(name: str, names: Sequence[str]) -> str:
    close = difflib.get_close_matches(name, list(names), n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""


class Model:
    """A model compiled by :func:`appell.from_model` or
    :func:`appell.from_urdf` (or one of its scenes, :meth:`scene`).

    Every function takes NumPy arrays (any float dtype and memory layout
    are converted to C-contiguous float64) or, for one row, a dict keyed by
    the names in :attr:`info`. A leading axis makes a batch: N states at
    once, split over threads with the GIL released; the result gains the
    same leading axis. ``params`` (a dict of names or an array in
    :attr:`parameter_names` order) applies to that call only; set
    :attr:`parameters` to change them for good.

    Layouts (as in the Rust ``appell::Model``): the reduced state ``x`` is
    the retained coordinates then the speeds (:attr:`state_names`); ``q``
    all coordinates, ``v`` the speeds, ``u`` the inputs (None: all zero).
    """

    def __init__(self, native: Any, name: str, parameter_values: Mapping[str, float],
                 scene: Optional[int] = None, source: str = "", unset: Optional[set] = None):
        self._native = native
        self._scene = scene
        self._source = source
        info = native.info(scene)
        self._info = info
        self.name: str = name if scene is None else info["name"].split("::")[-1]
        self.parameter_names: List[str] = list(info["parameters"])
        self.state_names: List[str] = list(info["state"])
        self.coordinate_names: List[str] = list(info["coordinates"])
        self.speed_names: List[str] = list(info["speeds"])
        self.input_names: List[str] = list(info["inputs"])
        self._s = info["state_len"]
        self._n = len(self.coordinate_names)
        self._l = len(self.speed_names)
        self._ni = len(self.input_names)
        self._m = info["constraints"]
        self._no_inputs = np.zeros(0)
        scene_infos = native.scene_names()
        model_name = native.info(None)["name"]
        self._scene_names = [s.split("::")[-1] for s in scene_infos]
        self._scene_types = list(scene_infos)
        # Parameters declared by name only, without a value yet: calls
        # refuse to run until they have one (never a silent zero).
        self._unset = set(unset) if unset is not None and scene is None else (unset or set())
        if scene is None and parameter_values:
            self.parameters = dict(parameter_values)

    # ----- description -------------------------------------------------

    @property
    def info(self) -> Dict[str, Any]:
        """Names, the state's layout, the form of the equations, operation
        counts, the equations as text, the scenes and the parameters."""
        d = dict(self._info)
        d["scenes"] = list(self._scene_names)
        d["parameter_values"] = self.parameters
        return d

    @property
    def scenes(self) -> List[str]:
        """The scenes' names as declared in ``scene(name, ...)``."""
        return list(self._scene_names)

    def scene(self, name: str) -> "Model":
        """Scene ``name`` (as declared in ``scene(name, ...)``) as a model
        of its own, sharing this model's parameters."""
        for k, (short, typ) in enumerate(zip(self._scene_names, self._scene_types)):
            if name in (short, typ):
                return Model(self._native, typ, {}, scene=k, source=self._source, unset=self._unset)
        raise KeyError(f"no scene {name!r}; the scenes are {self._scene_names}{_hint(name, self._scene_names)}")

    @property
    def parameters(self) -> Dict[str, float]:
        """The parameter values by name; assign a dict (all or some names)
        to change them. Checked as the Rust ``validate`` checks them."""
        values = self._native.parameter_values()
        return dict(zip(self.parameter_names, values))

    @parameters.setter
    def parameters(self, values: Union[Mapping[str, float], Sequence[float], np.ndarray]) -> None:
        self._native.set_parameters(self._parameter_array(values))
        if isinstance(values, Mapping):
            self._unset.difference_update(str(k) for k in values)
        else:
            self._unset.clear()

    def _check_set(self, params: Any) -> None:
        missing = set(self._unset)
        if isinstance(params, Mapping):
            missing.difference_update(str(k) for k in params)
        elif params is not None:
            missing.clear()
        if missing:
            raise ValueError(
                f"parameters {sorted(missing)} have no value: set model.parameters = {{...}} "
                "or pass params= to the call"
            )

    def _parameter_array(self, values: Any) -> List[float]:
        if isinstance(values, Mapping):
            current = dict(zip(self.parameter_names, self._native.parameter_values()))
            for key, value in values.items():
                key = str(key)
                if key not in current:
                    raise KeyError(
                        f"unknown parameter {key!r}; the parameters are {self.parameter_names}"
                        f"{_hint(key, self.parameter_names)}"
                    )
                current[key] = float(value)
            return [current[p] for p in self.parameter_names]
        arr = np.asarray(values, dtype=np.float64).ravel()
        if arr.shape != (len(self.parameter_names),):
            raise ValueError(
                f"params has {arr.size} values; the model has {len(self.parameter_names)} "
                f"parameters {self.parameter_names}"
            )
        return [float(v) for v in arr]

    # ----- argument handling -------------------------------------------

    def _array(self, what: str, value: Any, names: Sequence[str], allow_none: bool = False) -> np.ndarray:
        width = len(names)
        if value is None:
            if allow_none or width == 0 or what == "u":
                return np.zeros(width)
            raise ValueError(f"`{what}` is required: {width} values {list(names)}")
        if isinstance(value, Mapping):
            row = np.empty(width)
            seen = set()
            for key, v in value.items():
                key = str(key)
                if key not in names:
                    raise KeyError(f"`{what}` has no entry {key!r}; its names are {list(names)}{_hint(key, names)}")
                row[list(names).index(key)] = float(v)
                seen.add(key)
            missing = [n for n in names if n not in seen]
            if missing:
                raise KeyError(f"`{what}` misses {missing} (its names are {list(names)})")
            return row
        if type(value) is np.ndarray and value.dtype == np.float64 and value.flags.c_contiguous:
            arr = value
        else:
            try:
                arr = np.ascontiguousarray(value, dtype=np.float64)
            except (TypeError, ValueError) as e:
                raise TypeError(f"`{what}` must be an array of numbers or a dict of names: {e}") from None
        if arr.ndim not in (1, 2) or arr.shape[-1] != width:
            raise ValueError(
                f"`{what}` has shape {arr.shape}; expected ({width},) or (N, {width}) for {list(names)}"
            )
        return arr

    def _call(self, op: str, args: List[np.ndarray], t: float, params: Any) -> np.ndarray:
        if self._unset:
            self._check_set(params)
        p = None if params is None else self._parameter_array(params)
        return self._native.call(op, args, float(t), self._scene, p, _threads, _min_rows)

    def pinocchio_map(self, joints: Optional[Sequence[str]] = None,
                      base: Optional[str] = None) -> "PinocchioMap":
        """Conversions between this model's q, v, accelerations, forces and
        M and Pinocchio's (see :class:`appell.PinocchioMap`). ``joints``:
        the moving joints in Pinocchio's order (``pin_model.names[2:]`` on
        a free base, ``[1:]`` on a fixed one; URDF names are written as the
        model writes them, ``-`` as ``_``). By default the model's own
        order: depth first from the root, children in the URDF file's
        order, where Pinocchio's parser takes a link's children by joint
        name; where the two differ, pass Pinocchio's. ``base``: the free or
        planar joint's name, found from the coordinates' names by default
        (``root_joint`` for ``from_urdf``)."""
        full = self._native.info(None)
        if list(full["speeds"]) != self.speed_names or list(full["coordinates"]) != self.coordinate_names:
            raise ValueError(f"the scene {self.name} has other coordinates or speeds than the model: "
                             "Pinocchio's q and v map to the model's, so take the model's pinocchio_map()")
        kind, found = detect_base(self.coordinate_names)
        if base is not None:
            if found != base:
                raise KeyError(f"no free or planar joint {base!r} among the coordinates "
                               f"{self.coordinate_names}")
        taken = base_coordinates(kind, found)
        if joints is None:
            joints = [c for c in self.coordinate_names if c not in taken]
        native = self._native.pinocchio_map(kind, found or "", [model_name(str(j)) for j in joints])
        return PinocchioMap(native, kind, found, joints)

    def reduced_state(self, q: ArrayLike, v: ArrayLike) -> np.ndarray:
        """The reduced state x (retained coordinates, then the speeds) from
        all coordinates ``q`` and the speeds ``v`` (the model's: from
        Pinocchio's, :meth:`pinocchio_map` converts them); batched like
        every function."""
        qa = self._array("q", q, self.coordinate_names)
        va = self._array("v", v, self.speed_names)
        keep = [self.coordinate_names.index(r) for r in self._info["retained"]]
        if qa.ndim == 2 or va.ndim == 2:
            rows = qa.shape[0] if qa.ndim == 2 else va.shape[0]
            qa = np.broadcast_to(qa, (rows, qa.shape[-1]))
            va = np.broadcast_to(va, (rows, va.shape[-1]))
        return np.concatenate([qa[..., keep], va], axis=-1)

    # ----- the functions -------------------------------------------------

    def rhs(self, x: ArrayLike, u: Optional[ArrayLike] = None, t: float = 0.0,
            params: Any = None) -> np.ndarray:
        """The reduced equations of motion: ẋ = f(t, x, u); shape of ``x``."""
        if params is None and self._scene is None and not self._unset:
            fast = self._native.rhs_fast(x, u, t)
            if fast is not None:
                return fast
        xa = self._array("x", x, self.state_names)
        ua = self._array("u", u, self.input_names)
        return self._call("rhs", [xa, ua], t, params)

    def coordinate_rates(self, q: ArrayLike, v: ArrayLike, u: Optional[ArrayLike] = None,
                         t: float = 0.0, params: Any = None) -> np.ndarray:
        """All coordinates' rates q̇ (the dependent and ignorable ones too)."""
        args = [self._array("q", q, self.coordinate_names), self._array("v", v, self.speed_names),
                self._array("u", u, self.input_names)]
        return self._call("coordinate_rates", args, t, params)

    def mass_matrix(self, q: ArrayLike, t: float = 0.0, params: Any = None) -> np.ndarray:
        """M(q), (l, l) or (N, l, l) (Pinocchio's ``crba``)."""
        out = self._call("mass_matrix", [self._array("q", q, self.coordinate_names)], t, params)
        return out.reshape(out.shape[:-1] + (self._l, self._l))

    def mass_matrix_and_forcing(self, q: ArrayLike, v: ArrayLike, u: Optional[ArrayLike] = None,
                                t: float = 0.0, params: Any = None) -> Tuple[np.ndarray, np.ndarray]:
        """Appell's equations M ÿ = f: (M, f)."""
        args = [self._array("q", q, self.coordinate_names), self._array("v", v, self.speed_names),
                self._array("u", u, self.input_names)]
        out = self._call("mass_matrix_and_forcing", args, t, params)
        l = self._l
        return out[..., : l * l].reshape(out.shape[:-1] + (l, l)), out[..., l * l :]

    def inverse_dynamics(self, q: ArrayLike, v: ArrayLike, a: ArrayLike, t: float = 0.0,
                         params: Any = None) -> np.ndarray:
        """The generalized forces for accelerations ``a`` (``rnea``)."""
        args = [self._array("q", q, self.coordinate_names), self._array("v", v, self.speed_names),
                self._array("a", a, self.speed_names)]
        return self._call("inverse_dynamics", args, t, params)

    def gravity_forces(self, q: ArrayLike, t: float = 0.0, params: Any = None) -> np.ndarray:
        """The forces that hold the mechanism still (``computeGeneralizedGravity``)."""
        return self._call("gravity_forces", [self._array("q", q, self.coordinate_names)], t, params)

    def bias_forces(self, q: ArrayLike, v: ArrayLike, t: float = 0.0, params: Any = None) -> np.ndarray:
        """h(q, v) with M ÿ + h = Q (``nonLinearEffects``)."""
        args = [self._array("q", q, self.coordinate_names), self._array("v", v, self.speed_names)]
        return self._call("bias_forces", args, t, params)

    def energies(self, q: ArrayLike, v: ArrayLike, u: Optional[ArrayLike] = None, t: float = 0.0,
                 params: Any = None) -> Dict[str, np.ndarray]:
        """Kinetic and potential energy, the total's rate and the inputs' power."""
        args = [self._array("q", q, self.coordinate_names), self._array("v", v, self.speed_names),
                self._array("u", u, self.input_names)]
        out = self._call("energies", args, t, params)
        return {k: out[..., i] for i, k in enumerate(("kinetic", "potential", "rate", "input_power"))}

    def constraint_forces(self, q: ArrayLike, v: ArrayLike, u: Optional[ArrayLike] = None,
                          t: float = 0.0, params: Any = None) -> Tuple[np.ndarray, np.ndarray]:
        """The constraints' multipliers λ (one per velocity constraint row)
        and all coordinates' accelerations q̈, from the independent KKT solve."""
        args = [self._array("q", q, self.coordinate_names), self._array("v", v, self.speed_names),
                self._array("u", u, self.input_names)]
        out = self._call("constraint_forces", args, t, params)
        return out[..., : self._m], out[..., self._m :]

    def foot_forces(self, q: ArrayLike, v: ArrayLike, u: Optional[ArrayLike] = None,
                    t: float = 0.0, params: Any = None) -> Dict[str, Dict[str, Optional[np.ndarray]]]:
        """The ground's reaction on each foot the model or scene holds
        (``contact(link, point | flat)`` in a scene that names it; the
        feet are ``info["feet"]``), keyed by the foot's link: ``position``
        (the link's origin), ``force`` (on the link at its origin) and
        ``moment`` (a flat foot's, about the origin; None for a point
        foot), each in N's axes, with the batch's leading axis. The friction
        a foot needs is ``hypot(force[0], force[1]) / force[2]`` where
        ``force[2] > 0``."""
        args = [self._array("q", q, self.coordinate_names), self._array("v", v, self.speed_names),
                self._array("u", u, self.input_names)]
        feet = self._info["feet"]
        out = self._call("foot_forces", args, t, params)
        out = out.reshape(out.shape[:-1] + (len(feet), 9))
        return {foot["link"]: {"position": out[..., k, 0:3], "force": out[..., k, 3:6],
                               "moment": out[..., k, 6:9] if foot["flat"] else None}
                for k, foot in enumerate(feet)}

    @property
    def has_jacobian(self) -> bool:
        """Whether the derive generated the rhs's Jacobian (``rhs_jacobian``)."""
        return self._info["jacobian"] is not None

    def rhs_jacobian(self, x: ArrayLike, u: Optional[ArrayLike] = None, t: float = 0.0,
                     params: Any = None) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The generated Jacobian: (ẋ, A = ∂ẋ/∂x, B = ∂ẋ/∂u). Models without
        one raise ModelError; :meth:`linearize` works for every model."""
        if not self.has_jacobian:
            raise ModelError(
                f"model {self.name} has no generated Jacobian (info['jacobian'] is None); "
                "use linearize(), which differentiates by dual numbers"
            )
        xa, ua = self._array("x", x, self.state_names), self._array("u", u, self.input_names)
        out = self._call("rhs_jacobian", [xa, ua], t, params)
        s, ni = self._s, self._ni
        lead = out.shape[:-1]
        return (out[..., :s], out[..., s : s + s * s].reshape(lead + (s, s)),
                out[..., s + s * s :].reshape(lead + (s, ni)))

    def linearize(self, x: ArrayLike, u: Optional[ArrayLike] = None, t: float = 0.0,
                  params: Any = None) -> Tuple[np.ndarray, np.ndarray]:
        """A = ∂ẋ/∂x and B = ∂ẋ/∂u at (x, u): exact, from the generated
        Jacobian or by dual numbers."""
        xa, ua = self._array("x", x, self.state_names), self._array("u", u, self.input_names)
        out = self._call("linearize", [xa, ua], t, params)
        s, ni = self._s, self._ni
        lead = out.shape[:-1]
        return out[..., : s * s].reshape(lead + (s, s)), out[..., s * s :].reshape(lead + (s, ni))

    _STEP_METHODS = {"rk4": "step_jacobian_rk4",
                     "semi_implicit_euler": "step_jacobian_semi_implicit_euler"}

    def step_jacobian(self, x: ArrayLike, u: Optional[ArrayLike] = None, *, h: float,
                      method: str = "rk4", t: float = 0.0,
                      params: Any = None) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
        """One fixed step of size ``h`` from time ``t`` of the integrator a
        controller loop runs, the inputs ``u`` held over it, and its
        Jacobians in one call: (x⁺, A = ∂x⁺/∂x of shape (s, s),
        B = ∂x⁺/∂u of shape (s, inputs)), what a discrete-time MPC or DDP
        solver linearizes at every knot. ``method``: ``"rk4"`` (the
        classical Runge–Kutta step) or ``"semi_implicit_euler"`` (the
        speeds first, v⁺ = v + h v̇, then the retained coordinates at the
        new speeds). Exact to rounding: the chain rule through the stages
        of the generated Jacobian (``has_jacobian``), else the step in dual
        numbers. Batched over rows of ``x`` and ``u``; one ``h``.

        ``x`` is the reduced state (:meth:`reduced_state`): a free base's
        quaternion is four of its components and is not renormalised by
        the step, so A is not Crocoddyl's tangent-space Jacobian. An
        unknown ``method`` is ValueError; a non-finite ``h``, ``x`` or
        ``u``, or a failed step, ModelError. ``params``: parameter values
        for this call only."""
        op = self._STEP_METHODS.get(method)
        if op is None:
            raise ValueError(f"unknown method {method!r}; the fixed steps are {sorted(self._STEP_METHODS)}"
                             f"{_hint(str(method), list(self._STEP_METHODS))}")
        xa, ua = self._array("x", x, self.state_names), self._array("u", u, self.input_names)
        out = self._call(op, [xa, ua, np.array([float(h)])], t, params)
        s, ni = self._s, self._ni
        lead = out.shape[:-1]
        return (out[..., :s], out[..., s : s + s * s].reshape(lead + (s, s)),
                out[..., s + s * s :].reshape(lead + (s, ni)))

    def inverse_dynamics_derivatives(
            self, q: ArrayLike, v: ArrayLike, a: ArrayLike, t: float = 0.0, params: Any = None
    ) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Inverse dynamics and its derivatives in one call (Pinocchio's
        ``computeRNEADerivatives``): (Q, ∂Q/∂q of shape (l, n), ∂Q/∂v of
        shape (l, l), M). One column per coordinate: a quaternion's four
        components are four columns, where Pinocchio differentiates along
        its tangent. A model derived with ``jacobian(off)``, or one that is
        not a tree, raises ModelError."""
        args = [self._array("q", q, self.coordinate_names), self._array("v", v, self.speed_names),
                self._array("a", a, self.speed_names)]
        out = self._call("inverse_dynamics_derivatives", args, t, params)
        l, n = self._l, len(self.coordinate_names)
        lead = out.shape[:-1]
        at = l + l * n
        return (out[..., :l], out[..., l:at].reshape(lead + (l, n)),
                out[..., at : at + l * l].reshape(lead + (l, l)), out[..., at + l * l :].reshape(lead + (l, l)))

    def forward_dynamics_derivatives(
            self, q: ArrayLike, v: ArrayLike, u: Optional[ArrayLike] = None, t: float = 0.0,
            params: Any = None
    ) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The accelerations and their derivatives in all coordinates, in one
        call (Pinocchio's ``computeABADerivatives``): (ÿ, ∂ÿ/∂q of shape
        (l, n), ∂ÿ/∂v of shape (l, l), ∂ÿ/∂u of shape (l, inputs)), zero
        columns for the coordinates the equations do not read. For a robot
        whose joints are all driven, ∂ÿ/∂u is M⁻¹ (Pinocchio's
        ``ddq_dtau``). Models without a generated Jacobian raise
        ModelError."""
        args = [self._array("q", q, self.coordinate_names), self._array("v", v, self.speed_names),
                self._array("u", u, self.input_names)]
        out = self._call("forward_dynamics_derivatives", args, t, params)
        l, n = self._l, len(self.coordinate_names)
        lead = out.shape[:-1]
        at = l + l * n
        return (out[..., :l], out[..., l:at].reshape(lead + (l, n)),
                out[..., at : at + l * l].reshape(lead + (l, l)), out[..., at + l * l :].reshape(lead + (l, self._ni)))

    @overload
    def simulate(self, x0: ArrayLike, t_eval: ArrayLike, u: Any = None,
                 method: str = "dop853", rtol: float = 1e-8, atol: float = 1e-10,
                 t0: Optional[float] = None, h_max: Optional[float] = None,
                 max_steps: int = 1_000_000, params: Any = None,
                 event: None = None) -> np.ndarray: ...

    @overload
    def simulate(self, x0: ArrayLike, t_eval: ArrayLike, u: Any = None,
                 method: str = "dop853", rtol: float = 1e-8, atol: float = 1e-10,
                 t0: Optional[float] = None, h_max: Optional[float] = None,
                 max_steps: int = 1_000_000, params: Any = None, *,
                 event: Callable[[float, np.ndarray], float]) -> EventRun: ...

    def simulate(self, x0: ArrayLike, t_eval: ArrayLike, u: Any = None,
                 method: str = "dop853", rtol: float = 1e-8, atol: float = 1e-10,
                 t0: Optional[float] = None, h_max: Optional[float] = None,
                 max_steps: int = 1_000_000, params: Any = None,
                 event: Optional[Callable[[float, np.ndarray], float]] = None
                 ) -> Union[np.ndarray, EventRun]:
        """Integrates from ``x0`` at ``t0`` (default ``t_eval[0]``) and
        returns the states at ``t_eval``: (len(t_eval), s), or
        (N, len(t_eval), s) for N initial states (split over threads).
        ``method``: "dop853" (adaptive, explicit), "radau5" (implicit, for
        stiff models) or "rk4" (fixed steps of at most ``h_max``).

        Inputs ``u``: held constant (an array or a dict of names), or a
        function ``u(t, x)`` of the time and the reduced state that returns
        them (array or dict), called at every evaluation of the rhs: a
        feedback controller (Radau5 also calls it where it evaluates its
        Jacobian). With a function, the rows of a batch run one after
        another, and Radau5's Newton iteration uses the model's Jacobian
        with the inputs held at their current values (the law's own
        derivative is not known), which may slow its convergence but does
        not change its solution.

        With ``event`` (a function g(t, x); one initial state; DOP853), the
        run stops where g changes sign, and the result is a tuple
        (times reached, states there, (t_event, x_event) or None)."""
        xa = self._array("x0", x0, self.state_names)
        feedback = None
        if callable(u):
            if not self.input_names:
                raise ValueError(f"`u` is a function, but the model {self.name} has no inputs")
            feedback = self._feedback(u)
            ua = np.zeros(len(self.input_names))
        else:
            ua = self._array("u", u, self.input_names)
            if ua.ndim != 1:
                raise ValueError("`u` must be one row of inputs, or a function u(t, x)")
        times = np.ascontiguousarray(t_eval, dtype=np.float64)
        if times.ndim != 1 or times.size == 0:
            raise ValueError(f"`t_eval` must be a non-empty 1-D array, got shape {times.shape}")
        start = float(times[0]) if t0 is None else float(t0)
        if self._unset:
            self._check_set(params)
        p = None if params is None else self._parameter_array(params)
        return self._native.simulate(xa, ua, start, times, method, float(rtol), float(atol),
                                     None if h_max is None else float(h_max), int(max_steps),
                                     self._scene, p, _threads, event, feedback)

    def _feedback(self, law: Callable[..., Any]) -> Callable[[float, np.ndarray], np.ndarray]:
        """``law(t, x)`` checked and returned as one float64 row of inputs."""
        names = self.input_names

        def inputs(t: float, x: np.ndarray) -> np.ndarray:
            row = self._array("u", law(t, x), names)
            if row.ndim != 1:
                raise ValueError(f"u(t, x) must return one row of inputs {list(names)}, "
                                 f"got shape {row.shape}")
            return row
        return inputs

    def ode_function(self, u: Optional[ArrayLike] = None, params: Any = None,
                     form: str = "solve_ivp") -> Callable[..., np.ndarray]:
        """The rhs as a plain function. ``form="solve_ivp"``: ``f(t, x)``
        for ``scipy.integrate.solve_ivp`` (``vectorized=True`` works: x of
        shape (s, k)). ``form="odeint"``: the signature of PyDy's generated
        rhs, for ``scipy.integrate.odeint``: ``f(x, t, r=None, p=None)``,
        or ``f(x, t, p=None)`` for a model without inputs (as PyDy drops
        ``r`` for a system without specifieds); ``r`` the inputs (array,
        dict, or a function ``r(x, t)``), ``p`` the parameters (array or
        dict). ``u`` and ``params`` are the defaults."""
        fixed_u = self._array("u", u, self.input_names)
        fixed_p = None if params is None else self._parameter_array(params)
        rhs = self.rhs

        if form == "solve_ivp":
            def f(t: float, x: np.ndarray) -> np.ndarray:
                x = np.asarray(x, dtype=np.float64)
                if x.ndim == 2:
                    return rhs(np.ascontiguousarray(x.T), fixed_u, t, fixed_p).T
                return rhs(x, fixed_u, t, fixed_p)
            return f
        if form == "odeint" and not self.input_names:
            def h(x: np.ndarray, t: float, p: Any = None) -> np.ndarray:
                return rhs(x, fixed_u, t, fixed_p if p is None else p)
            return h
        if form == "odeint":
            def g(x: np.ndarray, t: float, r: Any = None, p: Any = None) -> np.ndarray:
                if r is None:
                    inputs = fixed_u
                elif callable(r):
                    inputs = r(x, t)
                else:
                    inputs = r
                return rhs(x, inputs, t, fixed_p if p is None else p)
            return g
        raise ValueError(f"form must be \"solve_ivp\" or \"odeint\", not {form!r}")

    def __repr__(self) -> str:
        return (f"<appell.Model {self.name}: state {self.state_names}, inputs {self.input_names}, "
                f"parameters {self.parameter_names}>")
