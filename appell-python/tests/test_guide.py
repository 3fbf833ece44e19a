"""The Python code of docs/guide/python.md and the example script, run as
a user would run them (from the repository root)."""

from __future__ import annotations

import os
import re
import subprocess
import sys

import appell
from conftest import REPO


def test_guide_code_blocks_run(cache, monkeypatch, capsys):
    text = (REPO / "docs/guide/python.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert len(blocks) >= 3
    monkeypatch.chdir(REPO)
    namespace: dict = {}  # one page, one session
    for block in blocks:
        exec(compile(block, "docs/guide/python.md", "exec"), namespace)
    out = capsys.readouterr().out
    assert "['phi', 'phi_dot', 'psi1_dot']" in out
    assert "line 2: unknown name `qq`" in out


def test_example_script_runs(cache):
    env = dict(os.environ, APPELL_CACHE_DIR=str(appell.cache_dir()))
    out = subprocess.run([sys.executable, str(REPO / "appell-python/examples/quickstart.py")],
                         cwd=REPO, env=env, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr[-3000:]
    assert "UR5: gravity compensation" in out.stdout and "upright eigenvalues" in out.stdout
