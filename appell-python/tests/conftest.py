"""Shared fixtures: the repository, the models compiled once per session
(in the cache of ``APPELL_CACHE_DIR``, or a fresh one under pytest's
temporary directory), and the Rust examples the results are compared with.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
from pathlib import Path
from typing import Dict, List, Tuple

import numpy as np
import pytest

import appell

REPO = Path(os.environ.get("APPELL_REPO", Path(__file__).resolve().parents[2]))


def rust_model(file: str) -> Tuple[str, Dict[str, float], str]:
    """The ``#[appell(...)]`` attributes of an example model (as written,
    comments and ``#[allow]`` included), its fields with the values of its
    ``Default``, and the struct's name."""
    text = (REPO / "examples" / "models" / file).read_text()
    lines = text.splitlines()
    start = next(i for i, l in enumerate(lines) if l.startswith("#[appell("))
    end = next(i for i, l in enumerate(lines) if l.startswith("pub struct"))
    attributes = "\n".join(lines[start:end])
    name = re.match(r"pub struct (\w+)", lines[end]).group(1)
    fields: List[str] = []
    for l in lines[end + 1 :]:
        if l.startswith("}"):
            break
        m = re.match(r"\s*pub (\w+): f64,", l)
        if m:
            fields.append(m.group(1))
    defaults: Dict[str, float] = {}
    body = text[text.index(f"impl Default for {name}") :]
    for f in fields:
        m = re.search(rf"\b{f}: (-?[0-9.eE+-]+),", body)
        defaults[f] = float(m.group(1))
    return attributes, defaults, name


@pytest.fixture(scope="session", autouse=True)
def cache(tmp_path_factory):
    if not os.environ.get("APPELL_CACHE_DIR"):
        appell.set_cache_dir(tmp_path_factory.mktemp("appell-cache"))
    return appell.cache_dir()


@pytest.fixture(scope="session")
def wheel_axle(cache):
    attributes, defaults, name = rust_model("wheel_axle.rs")
    return appell.from_model(attributes, parameters=defaults, name=name)


PENDULUM = """
coordinates(q), speeds(q), positive(m, l)
point(P = O + l * sin(q) * N.x - l * cos(q) * N.y), particle(P, mass = m)
gravity(-g * N.y)
"""


@pytest.fixture(scope="session")
def pendulum(cache):
    """A model without inputs."""
    return appell.from_model(PENDULUM, parameters={"m": 1.0, "l": 0.5, "g": 9.81}, name="Pendulum")


@pytest.fixture(scope="session")
def bicycle(cache):
    attributes, defaults, name = rust_model("whipple_bicycle.rs")
    return appell.from_model(attributes, parameters=defaults, name=name)


@pytest.fixture(scope="session")
def ur5(cache):
    return appell.from_urdf(REPO / "examples/robots/ur5/ur5_robot.urdf", gravity=(0, 0, -9.81))


_examples: Dict[str, Path] = {}


def rust_example(name: str) -> Path:
    """The example program ``name``, built with cargo (test profile, the
    environment's target directory, features as the whole workspace: after ``cargo test --workspace`` it is
    already built)."""
    if name not in _examples:
        out = subprocess.run(
            ["cargo", "build", "--profile", "test", "--workspace", "--example", name, "--message-format=json"],
            cwd=REPO, capture_output=True, text=True,
        )
        assert out.returncode == 0, out.stderr[-3000:]
        for line in out.stdout.splitlines():
            msg = json.loads(line)
            if msg.get("reason") == "compiler-artifact" and msg.get("executable") and msg["target"]["name"] == name:
                _examples[name] = Path(msg["executable"])
        assert name in _examples, f"no executable for example {name}"
    return _examples[name]


def rust_answers(example: str, lines: List[dict], action: str = "eval", scene: str = "") -> List[dict]:
    """The example's command line run on JSON lines."""
    args = [str(rust_example(example)), action] + (["--scene", scene] if scene else [])
    out = subprocess.run(args, input="\n".join(json.dumps(l) for l in lines) + "\n",
                         capture_output=True, text=True, check=True)
    answers = [json.loads(l) for l in out.stdout.splitlines() if l.strip()]
    assert len(answers) == len(lines), out.stdout[-2000:]
    for a in answers:
        assert "error" not in a, a
    return answers


@pytest.fixture
def rng():
    return np.random.default_rng(20261206)
