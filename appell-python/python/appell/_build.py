"""Compiling a model into a native module, and the cache that keeps it.

The cache directory (``appell.cache_dir()``; set it with
``appell.set_cache_dir(path)`` or the environment variable
``APPELL_CACHE_DIR``; by default ``$XDG_CACHE_HOME/appell`` or
``~/.cache/appell``) holds:

- ``src/appell-<hash>/`` and ``src/glue-<hash>-<hash>/``: the source of the
  appell crates and of the glue this package carries (written once per
  package build from ``appell._native``);
- ``target/``: one cargo target directory shared by every model, so that
  the derive, the runtime, PyO3 and NumPy's bindings are compiled once;
- ``models/<key>/``: one small crate per model and the module built from
  it. ``key`` hashes the crate's text (the model text, the parameter
  names), the contents of the files the model reads (URDF), the package
  version, the carried source, the Rust flags and the platform.

A model whose module is in the cache loads without calling cargo.
"""

from __future__ import annotations

import hashlib
import importlib.machinery
import importlib.util
import json
import os
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import threading
import time
from pathlib import Path
from types import ModuleType
from typing import Dict, List, Optional, Sequence, Tuple

from . import _native
from .errors import CompileError, Diagnostic, ToolchainError

ABI = 1
_cache_dir: Optional[Path] = None
_loaded: Dict[str, ModuleType] = {}
_lock = threading.Lock()
stats = {"compilations": 0, "loads": 0, "hits": 0}

PROFILE = """
[profile.release]
opt-level = 3
debug = false
incremental = false
codegen-units = 16

# The derive optimised: it runs while the model compiles.
[profile.release.build-override]
opt-level = 3
"""


def cache_dir() -> Path:
    """The cache directory (see the module documentation)."""
    if _cache_dir is not None:
        return _cache_dir
    env = os.environ.get("APPELL_CACHE_DIR")
    if env:
        return Path(env).expanduser().resolve()
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base).resolve() / "appell"


def set_cache_dir(path: Optional[os.PathLike]) -> None:
    """Uses ``path`` as the cache directory (None: back to the default)."""
    global _cache_dir
    _cache_dir = None if path is None else Path(path).expanduser().resolve()


def _cargo() -> str:
    cargo = os.environ.get("CARGO") or shutil.which("cargo")
    if cargo is None:
        home = Path.home() / ".cargo" / "bin" / ("cargo.exe" if os.name == "nt" else "cargo")
        if home.exists():
            cargo = str(home)
    if cargo is None:
        raise ToolchainError(
            "appell compiles each model with Rust, and no `cargo` was found on PATH "
            "(or in $CARGO, or ~/.cargo/bin). Install a Rust toolchain (1.89 or newer) from "
            "https://rustup.rs and try again."
        )
    return cargo


def _unpack(tree: Path, files: List[Tuple[str, bytes]], fix=None) -> Path:
    """Writes ``files`` into ``tree`` once (atomically: other processes see
    the whole tree or none)."""
    if (tree / ".complete").exists():
        return tree
    tree.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=".unpack-", dir=tree.parent))
    for rel, data in files:
        if fix is not None:
            data = fix(rel, data)
        path = tmp / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)
    (tmp / ".complete").write_text(_native.VERSION)
    try:
        os.replace(tmp, tree)
    except OSError:
        # Another process unpacked it first.
        shutil.rmtree(tmp, ignore_errors=True)
    return tree


def _source_trees(root: Path) -> Tuple[Path, Path]:
    """The carried appell crates and the glue, each in a directory named by
    its hash (a new glue alone leaves the compiled appell crates valid)."""
    glue_prefix = "appell-python/glue/"
    files = _native.sources()
    appell_tree = _unpack(root / "src" / f"appell-{_native.APPELL_HASH}",
                          [(r, d) for r, d in files if not r.startswith(glue_prefix)])

    def fix(rel: str, data: bytes) -> bytes:
        if rel == "Cargo.toml":
            # The glue's `appell = { path = "../.." }` points at the tree.
            return data.replace(b'path = "../.."', b"path = " + json.dumps(str(appell_tree)).encode())
        return data

    # The glue's manifest names the appell tree: one glue tree per pair.
    glue_tree = _unpack(root / "src" / f"glue-{_native.GLUE_HASH}-{_native.APPELL_HASH}",
                        [(r[len(glue_prefix):], d) for r, d in files if r.startswith(glue_prefix)], fix)
    return appell_tree, glue_tree


def _suffix() -> str:
    if os.name == "nt":
        return ".pyd"
    return ".abi3.so"


def model_key(lib_rs: str, files: Sequence[Path], rustflags: str) -> str:
    h = hashlib.sha256()
    for part in (
        lib_rs,
        PROFILE,
        _native.VERSION,
        _native.SOURCE_HASH,
        rustflags,
        sysconfig.get_platform(),
        str(ABI),
    ):
        h.update(part.encode())
        h.update(b"\0")
    for f in files:
        h.update(str(f).encode() + b"\0")
        h.update(Path(f).read_bytes())
    return h.hexdigest()[:20]


def _load(module_name: str, path: Path) -> ModuleType:
    loader = importlib.machinery.ExtensionFileLoader(module_name, str(path))
    spec = importlib.util.spec_from_file_location(module_name, str(path), loader=loader)
    assert spec is not None
    module = importlib.util.module_from_spec(spec)
    loader.exec_module(module)
    if getattr(module, "abi", None) != ABI:
        raise CompileError(
            f"the cached module {path} was built for another version of appell; "
            "delete it (or the cache) and try again",
            [],
        )
    return module


def _diagnostics(messages: List[dict], lib_rs: Path, model_lines: List[str], first: int) -> List[Diagnostic]:
    found: List[Diagnostic] = []
    for msg in messages:
        if msg.get("level") not in ("error", "error: internal compiler error"):
            continue
        text = msg.get("message", "")
        children = [
            c.get("message", "") for c in msg.get("children", []) if c.get("message")
        ]
        if children:
            text += "\n" + "\n".join(f"  = {c}" for c in children)
        line = column = source = None
        for span in msg.get("spans", []):
            if not span.get("is_primary"):
                continue
            if Path(span.get("file_name", "")).name == lib_rs.name:
                k = span["line_start"] - first + 1
                if 1 <= k <= len(model_lines):
                    line, column, source = k, span["column_start"], model_lines[k - 1]
            break
        if text.startswith("aborting due to") or text.startswith("could not compile"):
            continue
        found.append(Diagnostic(text, line, column, source))
    return found


def compile_crate(
    name: str,
    lib_rs_text: str,
    first_line: int,
    model_text: str,
    files: Sequence[Path],
    rustflags: Optional[str],
    progress: bool,
    module_name_of,
) -> ModuleType:
    """Loads the model's module from the cache, compiling it if needed."""
    flags = os.environ.get("APPELL_RUSTFLAGS", "") if rustflags is None else rustflags
    # The module name is part of the text: hash a placeholder.
    key = model_key(lib_rs_text, files, flags)
    module_name = module_name_of(key)
    lib_rs_text = lib_rs_text.replace("__APPELL_MODULE__", module_name)
    with _lock:
        if key in _loaded:
            stats["hits"] += 1
            return _loaded[key]
        root = cache_dir()
        crate = root / "models" / key
        artifact = crate / (module_name + _suffix())
        if artifact.exists():
            module = _load(module_name, artifact)
            stats["loads"] += 1
            _loaded[key] = module
            return module
        cargo = _cargo()
        appell_tree, glue_tree = _source_trees(root)
        crate.mkdir(parents=True, exist_ok=True)
        manifest = (
            "[package]\n"
            f'name = "{module_name.replace("_", "-")}"\n'
            'version = "0.0.0"\nedition = "2021"\npublish = false\n\n'
            "[lib]\n"
            f'name = "{module_name}"\ncrate-type = ["cdylib"]\npath = "lib.rs"\n\n'
            "[dependencies]\n"
            f"appell = {{ path = {json.dumps(str(appell_tree))} }}\n"
            f"appell-python-glue = {{ path = {json.dumps(str(glue_tree))} }}\n"
            'pyo3 = { version = "0.25", features = ["abi3-py39", "extension-module"] }\n'
            + PROFILE
            + "\n[workspace]\n"
        )
        (crate / "Cargo.toml").write_text(manifest)
        (crate / "lib.rs").write_text(lib_rs_text)
        (crate / "model.txt").write_text(model_text)
        lock = glue_tree / "model.Cargo.lock"
        if not (crate / "Cargo.lock").exists() and lock.exists():
            shutil.copyfile(lock, crate / "Cargo.lock")
        env = dict(os.environ)
        env["CARGO_TARGET_DIR"] = str(
            Path(os.environ["APPELL_CARGO_TARGET_DIR"]).resolve()
            if os.environ.get("APPELL_CARGO_TARGET_DIR")
            else root / "target"
        )
        if os.name == "nt":
            env["PYO3_PYTHON"] = sys.executable
        else:
            # abi3: the module needs no particular interpreter to build, so
            # every venv shares the compiled PyO3.
            env.pop("PYO3_PYTHON", None)
            env["PYO3_NO_PYTHON"] = "1"
        env["RUSTFLAGS"] = flags
        env.pop("CARGO_BUILD_TARGET", None)
        cmd = [cargo, "build", "--release", "--lib", "--message-format=json"]
        started = time.perf_counter()
        if progress:
            print(
                f"appell: compiling model {name} in {crate} "
                "(the first model also compiles appell's crates once, a few minutes)",
                file=sys.stderr,
                flush=True,
            )
        proc = subprocess.Popen(
            cmd,
            cwd=crate,
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            encoding="utf-8",
            errors="replace",
        )
        log: List[str] = []

        def pump() -> None:
            assert proc.stderr is not None
            for line in proc.stderr:
                log.append(line)
                if progress and line.strip().startswith(("Compiling", "Finished", "Downloaded", "Updating")):
                    print("appell:   " + line.strip(), file=sys.stderr, flush=True)

        reader = threading.Thread(target=pump, daemon=True)
        reader.start()
        messages: List[dict] = []
        built: Optional[str] = None
        assert proc.stdout is not None
        for line in proc.stdout:
            try:
                msg = json.loads(line)
            except ValueError:
                continue
            if msg.get("reason") == "compiler-message":
                messages.append(msg.get("message", {}))
            elif msg.get("reason") == "compiler-artifact" and msg.get("target", {}).get("name") == module_name:
                for f in msg.get("filenames", []):
                    if f.endswith((".so", ".dylib", ".dll")):
                        built = f
        code = proc.wait()
        reader.join()
        stats["compilations"] += 1
        if code != 0 or built is None:
            model_lines = model_text.splitlines()
            diags = _diagnostics(messages, crate / "lib.rs", model_lines, first_line)
            if diags:
                summary = "\n".join(str(d) for d in diags)
                raise CompileError(
                    f"model {name} does not compile:\n{summary}", diags, "".join(log)
                )
            tail = "".join(log[-30:])
            raise CompileError(f"cargo failed to build model {name}:\n{tail}", [], "".join(log))
        tmp = artifact.with_suffix(".tmp")
        shutil.copyfile(built, tmp)
        os.replace(tmp, artifact)
        if progress:
            print(
                f"appell: model {name} compiled in {time.perf_counter() - started:.1f} s",
                file=sys.stderr,
                flush=True,
            )
        module = _load(module_name, artifact)
        _loaded[key] = module
        return module
