"""appell from Python: a model written in appell's model language, or a
robot read from a URDF file, compiled by the Rust derive into a native
module, cached, and called on NumPy arrays.

    import appell
    model = appell.from_model('''
        coordinates(x, theta), speeds(x, theta), positive(m_cart, m_bob, l)
        point(C = O + x * N.x)
        point(P = C + l * sin(theta) * N.x - l * cos(theta) * N.y)
        particle(C, mass = m_cart), particle(P, mass = m_bob)
        gravity(-g * N.y)
    ''', parameters={"m_cart": 2.0, "m_bob": 0.5, "l": 1.0, "g": 9.81})
    model.rhs([0.3, 0.0, 0.0])

Compiling needs a Rust toolchain (``cargo``). See docs/guide/python.md.
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any, Dict, Mapping, Optional, Sequence, Tuple, Union

from . import _build, _native
from ._build import cache_dir, set_cache_dir
from ._model import Model, get_num_threads, set_num_threads
from ._pinocchio import PinocchioMap
from ._text import check_identifier, crate_source
from .errors import AppellError, CompileError, Diagnostic, ModelError, ToolchainError

__version__ = _native.VERSION

__all__ = [
    "from_model",
    "from_urdf",
    "Model",
    "PinocchioMap",
    "cache_dir",
    "set_cache_dir",
    "cache_info",
    "set_num_threads",
    "get_num_threads",
    "AppellError",
    "CompileError",
    "Diagnostic",
    "ModelError",
    "ToolchainError",
]


def _module_name(key: str) -> str:
    return f"appell_model_{key}"


def _compile(name: str, text: str, parameters: Sequence[str], files: Sequence[Path],
             rustflags: Optional[str], progress: bool) -> Any:
    lib_rs, first = crate_source(name, text, list(parameters), "__APPELL_MODULE__")
    module = _build.compile_crate(name, lib_rs, first, text, files, rustflags, progress, _module_name)
    # Each Model its own parameters, even when two share a module.
    return module.model.copy()


def from_model(source: str, parameters: Union[Mapping[str, float], Sequence[str], None] = None,
               name: str = "Model", rustflags: Optional[str] = None,
               progress: bool = True) -> Model:
    """Compiles a model written in appell's model language.

    ``source`` is the content of the ``#[appell(...)]`` attributes of the
    Rust struct: the items one after another (a line break separates two
    items as a comma does), or the attributes themselves (``#[appell(...)]``
    lines pasted from a Rust file).

    ``parameters`` are the struct's fields: every name the model text uses
    that is not a coordinate, an input, a frame or a point. Give a dict
    (name → default value, in the order of the fields) or a list of names
    (then set :attr:`Model.parameters` before calling). ``name`` is the
    struct's name (scenes are named after it).

    ``rustflags`` (default: the environment's ``APPELL_RUSTFLAGS``, else
    none) are passed to rustc, e.g. ``"-C target-cpu=native"``; they are
    part of the cache key. The module is cached (see :func:`cache_dir`):
    the same text, parameters and flags load without compiling.

    Raises :class:`CompileError` (each error with its line of ``source``),
    :class:`ToolchainError` (no cargo), ``ValueError`` (bad names).
    """
    if not isinstance(source, str):
        raise TypeError("the model source must be a string (the #[appell(...)] items)")
    if parameters is None:
        names: list = []
        defaults: Dict[str, float] = {}
    elif isinstance(parameters, Mapping):
        names = [str(k) for k in parameters]
        defaults = {str(k): float(v) for k, v in parameters.items()}
    else:
        if isinstance(parameters, str):
            raise TypeError("parameters: give a dict of defaults or a list of names, not a string")
        names = [str(k) for k in parameters]
        defaults = {}
    # Files the model reads are found from the current directory; the
    # derive gets them as absolute paths (the text's lines are unchanged).
    files = []

    def absolute(m: "re.Match[str]") -> str:
        f = Path(m.group(2)).expanduser().resolve()
        if not f.is_file():
            raise FileNotFoundError(f"the model reads {m.group(2)!r} ({f}), which does not exist")
        files.append(f)
        return m.group(1) + '"' + f.as_posix() + '"'

    source = re.sub(r'(urdf\(\s*)"([^"]+)"', absolute, source)
    native = _compile(name, source, names, files, rustflags, progress)
    return Model(native, name, defaults, source=source, unset=set(names) - set(defaults))


def _camel(stem: str) -> str:
    parts = re.split(r"[^A-Za-z0-9]+", stem)
    name = "".join(p[:1].upper() + p[1:] for p in parts if p)
    if not name or not name[0].isalpha():
        name = "Robot" + name
    return name


def _number(x: float) -> str:
    text = repr(float(x))
    if "e" not in text and "." not in text and "inf" not in text and "nan" not in text:
        text += ".0"
    return text


def from_urdf(path: Union[str, os.PathLike], base: str = "fixed",
              gravity: Optional[Sequence[float]] = (0.0, 0.0, -9.81), name: Optional[str] = None,
              options: str = "", extra: str = "", rustflags: Optional[str] = None,
              progress: bool = True) -> Model:
    """Compiles a robot read from a URDF file (``urdf("path", ...)`` of the
    model language, see docs/guide/joints-and-urdf.md).

    ``base``: "fixed" (the root link welded to the world) or "free" (a
    floating base, Pinocchio's free flyer). ``gravity``: the acceleration
    of gravity in the world frame (None: none). ``options``: more options of
    the ``urdf(...)`` item, as text (e.g. ``'weld(finger_joint1)'``);
    ``extra``: more items (contacts, scenes). ``name``: the struct's name
    (default: from the file's name). The file's contents are part of the
    cache key.

    Raises FileNotFoundError for a missing file, :class:`CompileError` for
    a file the derive refuses (with its message).
    """
    file = Path(path).expanduser().resolve()
    if not file.is_file():
        raise FileNotFoundError(f"no URDF file at {file}")
    if base not in ("fixed", "free"):
        raise ValueError(f'base must be "fixed" or "free", not {base!r}')
    args = [f'"{file.as_posix()}"']
    if base == "free":
        args.append("base = free")
    if options.strip():
        args.append(options.strip())
    items = [f"urdf({', '.join(args)})"]
    if gravity is not None:
        g = [float(c) for c in gravity]
        if len(g) != 3:
            raise ValueError(f"gravity must have 3 components, got {len(g)}")
        terms = [f"{_number(c)} * N.{axis}" for c, axis in zip(g, "xyz") if c != 0.0]
        if terms:
            items.append(f"gravity({' + '.join(terms)})")
    text = ", ".join(items)
    if extra.strip():
        text += "\n" + extra
    model_name = name or _camel(file.stem)
    check_identifier("model name", model_name)
    native = _compile(model_name, text, [], [file], rustflags, progress)
    return Model(native, model_name, {}, source=text)


def cache_info() -> Dict[str, Any]:
    """The cache directory and what this process did with it: models
    ``compilations`` (cargo ran), ``loads`` (a cached module loaded without
    compiling) and ``hits`` (a model already loaded in this process)."""
    return {"cache_dir": str(cache_dir()), **_build.stats}
