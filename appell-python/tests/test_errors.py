"""Bad input raises a clear Python exception; compile errors carry the
derive's message and the line of the model text; the cache reloads a
model without compiling it."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import appell
from conftest import PENDULUM

def test_shapes_names_and_values(wheel_axle):
    m = wheel_axle
    with pytest.raises(ValueError, match=r"expected \(3,\) or \(N, 3\)"):
        m.rhs(np.zeros(4), [0.0])
    with pytest.raises(ValueError, match="shape"):
        m.rhs(np.zeros((2, 2, 3)), [0.0])
    with pytest.raises(ValueError, match="rows"):
        m.rhs(np.zeros((5, 3)), np.zeros((4, 1)))
    with pytest.raises(appell.ModelError, match="non-finite"):
        m.rhs([np.nan, 0.0, 0.0], [0.0])
    with pytest.raises(appell.ModelError, match="row 2"):
        m.rhs(np.array([[0, 0, 0], [0, 0, 0], [0, np.inf, 0.0]]), [0.0])
    with pytest.raises(KeyError, match="did you mean 'phi_dot'"):
        m.rhs({"phi": 0.0, "phi_dt": 0.0, "psi1_dot": 0.0}, [0.0])
    with pytest.raises(KeyError, match="misses"):
        m.rhs({"phi": 0.0}, [0.0])
    with pytest.raises(KeyError, match="unknown parameter 'alpa'"):
        m.rhs([0, 0, 0.0], [0.0], params={"alpa": 1.0})
    with pytest.raises(appell.ModelError, match="positive"):
        m.rhs([0, 0, 0.0], [0.0], params={"a": 0.0})
    with pytest.raises(TypeError):
        m.rhs(["a", "b", "c"], [0.0])
    with pytest.raises(ValueError, match="required"):
        m.inverse_dynamics(np.zeros(7), np.zeros(2), None)
    with pytest.raises(ValueError, match="method"):
        m.simulate([0, 0, 0.0], [0, 1], u=[0.0], method="euler")
    with pytest.raises(appell.ModelError, match="t_eval"):
        m.simulate([0, 0, 0.0], [0, 1, 0.5], u=[0.0])
    with pytest.raises(appell.ModelError, match="h_max"):
        m.simulate([0, 0, 0.0], [0, 1], u=[0.0], method="rk4")


def test_a_feedback_law_that_fails(wheel_axle, pendulum):
    m, x0, t = wheel_axle, [0.3, 0.1, 0.0], [0.0, 1.0]

    def raises(t, x):
        raise ZeroDivisionError("the controller divided by zero")
    with pytest.raises(ZeroDivisionError, match="controller"):
        m.simulate(x0, t, u=raises)
    with pytest.raises(ZeroDivisionError):
        m.simulate(x0, t, u=raises, method="radau5")
    with pytest.raises(ZeroDivisionError):
        m.simulate(x0, t, u=raises, event=lambda t, x: x[2] - 1.0)
    with pytest.raises(ValueError, match=r"expected \(1,\)"):
        m.simulate(x0, t, u=lambda t, x: [0.0, 1.0])
    with pytest.raises(KeyError, match="did you mean 'tau'"):
        m.simulate(x0, t, u=lambda t, x: {"tua": 0.0})
    with pytest.raises(appell.ModelError, match=r"u\(t, x\) returned NaN for input 0 at t = "):
        m.simulate(x0, t, u=lambda t, x: [np.nan], method="rk4", h_max=0.1)
    with pytest.raises(appell.ModelError, match=r"row 1: u\(t, x\) returned inf"):
        m.simulate(np.array([x0, [5.0, 0.1, 0.0]]), t, u=lambda t, x: [np.inf] if x[0] > 4.0 else [0.0])
    with pytest.raises(ValueError, match="no inputs"):
        pendulum.simulate([0.1, 0.0], t, u=lambda t, x: [])


def test_functions_a_model_lacks(pendulum):
    assert not pendulum.has_jacobian or pendulum.rhs_jacobian([0.1, 0.0])[0].shape == (2,)
    A, B = pendulum.linearize([0.0, 0.0])
    np.testing.assert_allclose(A, [[0, 1], [-9.81 / 0.5, 0]], rtol=1e-14)
    assert B.shape == (2, 0)


def test_the_pendulums_derivatives(pendulum):
    # Q = m l² a + m g l sin q: ∂Q/∂q = m g l cos q, ∂Q/∂v = 0, M = m l².
    q, v, a = np.array([0.3]), np.array([-0.7]), np.array([0.2])
    tau, dq, dv, m = pendulum.inverse_dynamics_derivatives(q, v, a)
    np.testing.assert_allclose(tau, [0.25 * 0.2 + 9.81 * 0.5 * np.sin(0.3)], rtol=1e-14)
    np.testing.assert_allclose(dq, [[9.81 * 0.5 * np.cos(0.3)]], rtol=1e-14)
    np.testing.assert_allclose(dv, [[0.0]], atol=1e-15)
    np.testing.assert_allclose(m, [[0.25]], rtol=1e-14)
    if pendulum.has_jacobian:
        accel, fq, fv, fu = pendulum.forward_dynamics_derivatives(q, v)
        np.testing.assert_allclose(fq, [[-9.81 / 0.5 * np.cos(0.3)]], rtol=1e-14)
        assert fu.shape == (1, 0)
    else:
        with pytest.raises(appell.ModelError, match="forward_dynamics_derivatives"):
            pendulum.forward_dynamics_derivatives(q, v)
    with pytest.raises(ValueError, match="shape"):
        pendulum.inverse_dynamics_derivatives(np.zeros(2), v, a)


def test_compile_error_names_the_line(cache):
    text = textwrap.dedent("""\
        coordinates(q), speeds(q), positive(m, l)
        point(P = O + l * sin(qq) * N.x - l * cos(q) * N.y)
        particle(P, mass = m)
    """)
    with pytest.raises(appell.CompileError) as info:
        appell.from_model(text, parameters={"m": 1.0, "l": 1.0}, name="Broken", progress=False)
    err = info.value
    first = err.diagnostics[0]
    assert first.line == 2
    assert "unknown name `qq`" in first.message and "did you mean `q`?" in first.message
    assert first.source_line == "point(P = O + l * sin(qq) * N.x - l * cos(q) * N.y)"
    assert "line 2" in str(err)


def test_bad_names_and_missing_files(cache, tmp_path):
    with pytest.raises(FileNotFoundError):
        appell.from_urdf(tmp_path / "nothing.urdf")
    with pytest.raises(FileNotFoundError):
        appell.from_model('urdf("no/such/robot.urdf")')
    with pytest.raises(ValueError, match="base"):
        appell.from_urdf(__file__, base="floating")
    with pytest.raises(ValueError, match="not a valid identifier"):
        appell.from_model(PENDULUM, parameters={"m": 1.0, "l": 1.0, "g": 9.81}, name="my model")
    with pytest.raises(ValueError, match="not a valid identifier"):
        appell.from_model(PENDULUM, parameters={"m-1": 1.0})


def test_bad_urdf_is_a_compile_error(cache, tmp_path):
    urdf = tmp_path / "bad.urdf"
    urdf.write_text('<robot name="bad"><link name="a"/><joint name="j" type="revolute">'
                    '<parent link="a"/><child link="missing"/></joint></robot>')
    with pytest.raises(appell.CompileError) as info:
        appell.from_urdf(urdf, progress=False)
    assert info.value.diagnostics and "missing" in str(info.value)


def test_missing_cargo_is_a_clear_error(cache, monkeypatch, tmp_path):
    monkeypatch.setenv("PATH", str(tmp_path))
    monkeypatch.delenv("CARGO", raising=False)
    monkeypatch.setenv("HOME", str(tmp_path))
    with pytest.raises(appell.ToolchainError, match="rustup"):
        appell.from_model(PENDULUM + "\n// a model not in the cache\n",
                          parameters={"m": 1.0, "l": 1.0, "g": 9.81}, name="NoCargo", progress=False)


def test_cached_model_reloads_without_compiling(pendulum, cache):
    again = appell.from_model(PENDULUM, parameters={"m": 1.0, "l": 0.5, "g": 9.81}, name="Pendulum")
    assert np.array_equal(again.rhs([0.2, 0.0]), pendulum.rhs([0.2, 0.0]))
    # A new interpreter: the module comes from the cache, cargo never runs.
    script = textwrap.dedent(f"""
        import appell, json
        appell.set_cache_dir({str(cache)!r})
        m = appell.from_model({PENDULUM!r}, parameters={{"m": 1.0, "l": 0.5, "g": 9.81}}, name="Pendulum")
        print(json.dumps([appell.cache_info(), list(m.rhs([0.2, 0.0]))]))
    """)
    env = dict(os.environ, PATH="/nonexistent")  # no cargo to run
    env.pop("CARGO", None)
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env)
    assert out.returncode == 0, out.stderr
    import json
    stats, rates = json.loads(out.stdout)
    assert stats["compilations"] == 0 and stats["loads"] == 1
    assert rates == list(pendulum.rhs([0.2, 0.0]))


def test_parameters_without_values_refuse_to_run(pendulum):
    named = appell.from_model(PENDULUM, parameters=["m", "l", "g"], name="Pendulum", progress=False)
    with pytest.raises(ValueError, match=r"\['g', 'l', 'm'\] have no value"):
        named.rhs([0.2, 0.0])
    with pytest.raises(ValueError, match="no value"):
        named.simulate([0.2, 0.0], [0.0, 1.0])
    # a call's own values are enough
    assert np.array_equal(named.rhs([0.2, 0.0], params={"m": 1.0, "l": 0.5, "g": 9.81}),
                          pendulum.rhs([0.2, 0.0]))
    named.parameters = {"m": 1.0, "l": 0.5}
    with pytest.raises(ValueError, match=r"\['g'\]"):
        named.rhs([0.2, 0.0])
    named.parameters = {"g": 9.81}
    assert np.array_equal(named.rhs([0.2, 0.0]), pendulum.rhs([0.2, 0.0]))
