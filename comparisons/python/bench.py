"""Benchmarks of the appell Python package (see README.md here).

    python bench.py overhead     per-call cost of one rhs from Python
    python bench.py throughput   batched rhs on 2 threads against Pinocchio's
                                 Python bindings looping aba (UR5) and PyDy's
                                 Cython rhs (n-link pendulum on a cart)
    python bench.py compile      text to importable module: cold and cached,
                                 for the wheel-axle, the bicycle and the UR5
    python bench.py all
    python bench.py throughput-native   throughput with the models compiled
                                 with -C target-cpu=native (their own cache:
                                 set APPELL_CACHE_DIR to another directory)

Each writes results/<name>.json and prints a table. Timings are the best of
several repetitions (the machine is shared), taken side by side in one run.
"""

from __future__ import annotations

import json
import os
import platform
import subprocess
import sys
import time
import uuid
from pathlib import Path

import numpy as np

import appell
from models import REPO, UR5_URDF, pendulum_on_cart, rust_model

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"


def best(f, number: int, repeats: int = 7) -> float:
    """Seconds per call: the best of `repeats` runs of `number` calls."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        for _ in range(number):
            f()
        times.append((time.perf_counter() - start) / number)
    return min(times)


def save(name: str, data: dict) -> None:
    RESULTS.mkdir(exist_ok=True)
    data["machine"] = {"cpus": os.cpu_count(), "python": platform.python_version(),
                       "numpy": np.__version__, "appell": appell.__version__,
                       "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())}
    (RESULTS / f"{name}.json").write_text(json.dumps(data, indent=1) + "\n")


def load_models():
    wa, wd, wn = rust_model("wheel_axle.rs")
    bi, bd, bn = rust_model("whipple_bicycle.rs")
    return {
        "wheel_axle": appell.from_model(wa, parameters=wd, name=wn),
        "whipple_bicycle": appell.from_model(bi, parameters=bd, name=bn),
        "ur5": appell.from_urdf(UR5_URDF),
    }


def overhead() -> dict:
    rng = np.random.default_rng(1)
    rows = []
    appell.set_num_threads(1)
    for name, m in load_models().items():
        s, ni = len(m.state_names), len(m.input_names)
        x, u = rng.uniform(-0.5, 0.5, s), rng.uniform(-0.5, 0.5, ni)
        if name == "whipple_bicycle":
            x[1] = 0.3  # near the pitch the rolling contacts hold
        n = 200_000
        X, U = np.tile(x, (n, 1)), np.tile(u, (n, 1))
        single = best(lambda: m.rhs(x, u), 100_000)
        batch = best(lambda: m.rhs(X, U), 1) / n
        empty = best(lambda: np.empty(s), 100_000)
        rows.append({"model": name, "state": s, "single_call_ns": single * 1e9,
                     "batched_per_state_ns": batch * 1e9, "overhead_ns": (single - batch) * 1e9,
                     "numpy_empty_ns": empty * 1e9})
    print(f"{'model':18} {'one call':>10} {'per state in a batch':>22} {'overhead':>10} {'np.empty':>10}")
    for r in rows:
        print(f"{r['model']:18} {r['single_call_ns']:8.0f}ns {r['batched_per_state_ns']:20.0f}ns "
              f"{r['overhead_ns']:8.0f}ns {r['numpy_empty_ns']:8.0f}ns")
    data = {"rows": rows, "note": "single: Model.rhs on one 1-D state; batched: one call on 200,000 "
            "states on one thread, divided by 200,000 (the Rust time and a few checks per state)"}
    save("overhead", data)
    return data


def throughput(rustflags=None, name="throughput") -> dict:
    import pinocchio as pin

    rng = np.random.default_rng(2)
    appell.set_num_threads(2)
    out = {}
    # --- UR5: appell's batched forward dynamics against pinocchio.aba in a loop
    ur5 = appell.from_urdf(UR5_URDF, rustflags=rustflags)
    model = pin.buildModelFromUrdf(str(UR5_URDF))
    data = model.createData()
    n_app, n_pin = 400_000, 40_000
    q = rng.uniform(-np.pi, np.pi, (n_app, 6))
    v = rng.uniform(-1, 1, (n_app, 6))
    tau = rng.uniform(-10, 10, (n_app, 6))
    x = ur5.reduced_state(q, v)
    mine = ur5.rhs(x[:100], tau[:100])[:, 5:]
    theirs = np.array([pin.aba(model, data, q[k], v[k], tau[k]).copy() for k in range(100)])
    agree = float(np.max(np.abs(mine - theirs) / np.maximum(1.0, np.abs(theirs))))

    def pin_loop():
        for k in range(n_pin):
            pin.aba(model, data, q[k], v[k], tau[k])

    app = best(lambda: ur5.rhs(x, tau), 1, 5) / n_app
    pin_t = best(pin_loop, 1, 5) / n_pin
    appell.set_num_threads(1)
    app1 = best(lambda: ur5.rhs(x, tau), 1, 5) / n_app
    appell.set_num_threads(2)
    out["ur5"] = {"appell_states_per_s": 1 / app, "pinocchio_states_per_s": 1 / pin_t,
                  "ratio": pin_t / app, "appell_1_thread_states_per_s": 1 / app1,
                  "ratio_1_thread": pin_t / app1, "max_relative_difference": agree,
                  "pinocchio": pin.__version__, "threads": 2}
    # --- n-link pendulum on a cart: appell against PyDy's Cython rhs
    from pydy.models import n_link_pendulum_on_cart

    for links in (4,):
        start = time.perf_counter()
        system = n_link_pendulum_on_cart(n=links, cart_force=True, joint_torques=False)
        values = {**{f"m{i}": 1.0 + 0.1 * i for i in range(links + 1)},
                  **{f"l{i}": 1.0 - 0.05 * i for i in range(links)}, "g": 9.81}
        rhs = system.generate_ode_function(generator="cython", constants_arg_type="array",
                                           specifieds_arg_type="array")
        # The generated function takes the constants in the order of the
        # system's set of them as generation left it.
        consts = np.array([values[str(c)] for c in system.constants_symbols])
        pydy_generation = time.perf_counter() - start
        coords = [str(c).replace("(t)", "") for c in system.coordinates]
        speeds = [str(c).replace("(t)", "") for c in system.speeds]
        text, params = pendulum_on_cart(links)
        start = time.perf_counter()
        mine_model = appell.from_model(text, parameters={p: values[p] for p in params},
                                       name=f"PendulumOnCart{links}", rustflags=rustflags)
        appell_load = time.perf_counter() - start
        n_app, n_py = 400_000, 40_000
        X = rng.uniform(-1, 1, (n_app, 2 * links + 2))  # PyDy's layout: q0..qn, u0..un
        F = rng.uniform(-1, 1, (n_app, 1))
        # appell's reduced state leaves out the cart's position q0 (cyclic).
        Xa = np.ascontiguousarray(X[:, 1:])
        assert mine_model.state_names == coords[1:] + [f"q{i}_dot" for i in range(links + 1)], \
            (mine_model.state_names, coords, speeds)
        mine = mine_model.rhs(Xa[:100], F[:100])
        # (the generated function may hand back one buffer each call: copy)
        theirs = np.array([rhs(X[k], 0.0, F[k], consts).copy() for k in range(100)])[:, 1:]
        agree = float(np.max(np.abs(mine - theirs) / np.maximum(1.0, np.abs(theirs))))

        def pydy_loop():
            for k in range(n_py):
                rhs(X[k], 0.0, F[k], consts)

        app = best(lambda: mine_model.rhs(Xa, F), 1, 5) / n_app
        py_t = best(pydy_loop, 1, 5) / n_py
        appell.set_num_threads(1)
        app1 = best(lambda: mine_model.rhs(Xa, F), 1, 5) / n_app
        appell.set_num_threads(2)
        out[f"pendulum_on_cart_{links}"] = {
            "appell_states_per_s": 1 / app, "pydy_states_per_s": 1 / py_t, "ratio": py_t / app,
            "appell_1_thread_states_per_s": 1 / app1, "ratio_1_thread": py_t / app1,
            "max_relative_difference": agree, "pydy_generation_s": pydy_generation,
            "appell_load_s": appell_load, "threads": 2,
        }
    for k, r in out.items():
        if not isinstance(r, dict):
            continue
        other = "pinocchio_states_per_s" if "pinocchio_states_per_s" in r else "pydy_states_per_s"
        print(f"{k:22} appell {r['appell_states_per_s']:12.0f}/s  {other.split('_')[0]} "
              f"{r[other]:10.0f}/s  ratio {r['ratio']:6.1f}x (1 thread {r['ratio_1_thread']:5.1f}x)  "
              f"(max rel. diff {r['max_relative_difference']:.1e})")
    out["rustflags"] = rustflags or ""
    save(name, out)
    return out


LOAD = r"""
import sys, time, json
sys.path.insert(0, {here!r})
import appell
from models import rust_model, UR5_URDF
which, tag = sys.argv[1], sys.argv[2]
start = time.perf_counter()
if which == "ur5":
    m = appell.from_urdf(UR5_URDF, extra=tag, progress=False)
else:
    a, d, n = rust_model(which + ".rs")
    m = appell.from_model(a + "\n" + tag, parameters=d, name=n, progress=False)
elapsed = time.perf_counter() - start
print(json.dumps({{"seconds": elapsed, **appell.cache_info()}}))
"""


def compile_times() -> dict:
    script = LOAD.format(here=str(HERE))
    rows = []
    for which in ("wheel_axle", "whipple_bicycle", "ur5"):
        tag = f"// benchmark {uuid.uuid4().hex}"  # a text not in the cache
        runs = []
        for _ in range(4):  # the first compiles, the others load the cache
            out = subprocess.run([sys.executable, "-c", script, which, tag],
                                 capture_output=True, text=True, check=True)
            runs.append(json.loads(out.stdout.strip().splitlines()[-1]))
        assert runs[0]["compilations"] == 1 and all(r["compilations"] == 0 for r in runs[1:])
        rows.append({"model": which, "cold_s": runs[0]["seconds"],
                     "cached_ms": min(r["seconds"] for r in runs[1:]) * 1e3})
    for r in rows:
        print(f"{r['model']:18} cold {r['cold_s']:6.1f} s   cached {r['cached_ms']:6.1f} ms")
    data = {"rows": rows, "note": "cold: a model text not in the cache, with the appell crates, "
            "PyO3 and numpy already compiled in the cache's target directory; cached: a new "
            "interpreter loading the same model (best of 3); both inside one from_model call"}
    save("compile", data)
    return data


if __name__ == "__main__":
    what = sys.argv[1] if len(sys.argv) > 1 else "all"
    if what in ("overhead", "all"):
        overhead()
    if what in ("throughput", "all"):
        throughput()
    if what in ("compile", "all"):
        compile_times()
    if what == "throughput-native":
        throughput("-C target-cpu=native", "throughput_native")
