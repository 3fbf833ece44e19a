#!/usr/bin/env python3
"""Builds the drivers and times appell's generated dynamics against
Pinocchio's (and MuJoCo's mj_forward) on the same random states, then prints
markdown tables. See README.md beside this script.

    ./setup.sh        # once: .venv with pin, example-robot-data, mujoco, ...
    ./run.py          # build everything, check, time, print the tables

Steps:
1. `make -j1` (the C++ and C drivers) and `cargo build --release` of rust/,
   once for the default x86-64 target and once with -C target-cpu=native,
   into $CARGO_TARGET_DIR/{generic,native} (default build/target/...),
   with CARGO_BUILD_JOBS=1 unless it is set; `make cg` (pinocchio_cg_bench,
   Pinocchio's code-generated functions) unless --no-cg, whose generated
   libraries are made once per run in build/cg.
2. URDFs of the chains without one in examples/robots (n = 24, 48, 64; appell
   times 64 too when the Rust driver is built with --features large-models,
   run.py's default) are written into build/urdf/ with make_urdf.py's
   chain_urdf; MuJoCo's
   copies (no <visual>/<collision>, the Panda's fingers fixed) go to
   build/mujoco/.
3. Correctness: both Pinocchio builds evaluate the states of
   tests/reference/pinocchio/*.json and, on a free flyer, of
   tests/reference/pinocchio/robots/ for the floating-base robots (computed
   by Pinocchio's Python bindings) and must agree with them to 1e-9
   relative.
4. Timing: ROUNDS rounds; in each, every model is timed by every
   implementation, one process each, TRIES times over (the order of the
   implementations reversed from one round to the next). Each process
   times each function over BATCH states REPS times and reports the median
   per-call time; of a round's TRIES processes the fastest median is kept
   (the shared machine switches between a fast and a slow state from one
   process to the next).
5. Tables: for each model and function, the median over the rounds of the
   kept medians, and in parentheses their range (min-max over the rounds);
   ratios are taken within each round, then the median (range).
   Checksums of paired functions (appell's rhs and Pinocchio's ABA and
   MuJoCo's qacc; M and f against CRBA and NLE) are compared too.
6. Forward-dynamics derivatives (fixed bases whose appell model has a
   generated Jacobian, or a jacobian(on) twin in rust/src/jacobian.rs):
   appell's rhs_jacobian and rhs_jacobian_dual (dual numbers, one rhs per
   column) against Pinocchio's computeABADerivatives (aba_derivatives),
   timed as the rest; before the timing, both drivers print the
   derivatives of DERIVATIVE_STATES states (--dump-jacobian,
   --dump-derivatives) and they are compared entry by entry.

Raw JSON lines go to build/results.jsonl, the tables to build/results.md.
"""
import argparse
import importlib.util
import json
import os
import platform
import statistics
import subprocess
import sys
import time
import xml.etree.ElementTree as ET

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
BUILD = os.path.join(HERE, "build")
VENV_PYTHON = os.path.join(HERE, ".venv", "bin", "python")
ROBOTS = os.path.join(ROOT, "examples", "robots")
REFERENCE = os.path.join(ROOT, "tests", "reference", "pinocchio")

PANDA_WELD = ["panda_finger_joint1", "panda_finger_joint2"]

# (name, URDF, joints welded at 0, timed by appell too). Whether appell
# times a model is finally decided by the Rust build's `appell_bench list`
# (spatial_chain_64 needs --features large-models, which run.py passes).
MODELS = [
    ("ur5", os.path.join(ROBOTS, "ur5", "ur5_robot.urdf"), [], True),
    # The same file, appell reading its right angles as exact
    # (`right_angles = 1e-10`, rust/src/arms.rs); Pinocchio reads it as written.
    ("ur5_right_angles", os.path.join(ROBOTS, "ur5", "ur5_robot.urdf"), [], True),
    ("panda", os.path.join(ROBOTS, "panda", "panda.urdf"), PANDA_WELD, True),
] + [
    (f"spatial_chain_{n}", os.path.join(ROBOTS, "spatial_chain", f"spatial_chain_{n}.urdf"), [], True)
    for n in (2, 4, 8, 16, 32)
]
# Floating-base robots: example-robot-data 6.0.0's URDFs as the repository
# holds them (tests/robots/, unchanged; tests/robots/MANIFEST.json), loaded
# on a free joint `root_joint` by every driver (pinocchio_bench --free:
# JointModelFreeFlyer; appell: `urdf(..., base = free)`, rust/src/floating.rs).
# The last entry names the reference file in tests/reference/pinocchio/robots
# (Pinocchio's Python bindings, free flyer) that the Pinocchio builds are
# checked against. MuJoCo does not time them.
TEST_ROBOTS = os.path.join(ROOT, "tests", "robots")
FREE_MODELS = [
    ("solo12", os.path.join(TEST_ROBOTS, "solo", "solo12.urdf"), [], True),
    ("anymal_b", os.path.join(TEST_ROBOTS, "anymal_b_simple", "anymal.urdf"), [], True),
    ("go1", os.path.join(TEST_ROBOTS, "go1", "go1.urdf"), [], True),
    ("hyq", os.path.join(TEST_ROBOTS, "hyq", "hyq_no_sensors.urdf"), [], True),
    # The same file, appell reading its right angles as exact
    # (`right_angles = 1e-10`); Pinocchio reads it as written.
    ("hyq_right_angles", os.path.join(TEST_ROBOTS, "hyq", "hyq_no_sensors.urdf"), [], True),
    ("g1", os.path.join(TEST_ROBOTS, "g1", "g1_29dof_rev_1_0.urdf"), [], True),
]
FREE_REFERENCE = {"solo12": "solo12", "anymal_b": "anymal", "go1": "go1", "hyq": "hyq", "hyq_right_angles": "hyq", "g1": "g1"}
FREE = {name for name, _, _, _ in FREE_MODELS}
# Models read from another's file with other options: its reference.
SAME_FILE = {"ur5_right_angles": "ur5"}

# Chains without a URDF in examples/robots, written into build/urdf by
# make_urdf.py's chain_urdf; (n, timed by appell too).
LARGE_CHAINS = ((24, False), (48, False), (64, True))

# appell function -> the Pinocchio function computing the same thing. A
# function the Rust driver gains (rust/src/main.rs) is paired here.
PAIRS = [
    ("rhs", "aba"),
    ("mass_matrix_and_forcing", "crba_nle"),
    ("inverse_dynamics", "rnea"),
    ("mass_matrix", "crba_sym"),
    ("gravity", "gravity"),
    # The forward-dynamics derivatives: appell's generated Jacobian of the
    # reduced rhs (A = d rhs/d state, B = d rhs/d inputs) against
    # computeABADerivatives (ddq_dq, ddq_dv, Minv). The checksums sum the
    # same numbers: appell the rows of A and B that are the accelerations'
    # (all columns: the retained coordinates, the speeds, the inputs),
    # Pinocchio ddq_dq + ddq_dv + Minv (the symmetric matrix's sum from its
    # upper triangle, the part it is documented to fill). Pinocchio's
    # ddq_dq has a column for the coordinate appell's reduced state leaves
    # out (the first joint, about the vertical), zero up to rounding.
    ("rhs_jacobian", "aba_derivatives"),
    # The same derivatives by dual numbers (the baseline appell's
    # linearize used before rhs_jacobian), checked against the same sum.
    ("rhs_jacobian_dual", "aba_derivatives"),
]
# Functions of PAIRS shown in their own table (the derivatives), not in
# the per-pair tables.
DERIVATIVES = ("rhs_jacobian", "rhs_jacobian_dual")
# States whose derivatives are compared entry by entry before the timing.
DERIVATIVE_STATES = 20
# appell function -> Pinocchio's code-generated counterpart
# (pinocchio_cg_bench, impl "pinocchio_cg").
PAIRS_CG = {"rhs": "aba", "inverse_dynamics": "rnea", "mass_matrix": "crba_sym", "gravity": "gravity",
            "rhs_jacobian": "aba_derivatives"}
# The Rust driver's conversions between the conventions (free bases only).
CONVERSIONS = ["map_in", "map_out"]
# Pinocchio functions shown in the second table, in order.
PINOCCHIO_FUNCTIONS = ["aba", "rnea", "crba", "crba_sym", "nle", "gravity", "crba_nle", "aba_derivatives"]


def appell_revision():
    """The commit the Rust driver was built from, and whether the tree had
    changes outside this directory (read-only git queries); outside a git
    checkout (a `git archive` snapshot), $APPELL_REVISION."""
    try:
        head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT,
                              capture_output=True, text=True, check=True).stdout.strip()
        status = subprocess.run(["git", "status", "--porcelain", "--", ".", ":!comparisons/pinocchio"],
                                cwd=ROOT, capture_output=True, text=True, check=True).stdout
        return head + (" with uncommitted changes" if status.strip() else "")
    except (OSError, subprocess.CalledProcessError):
        return os.environ.get("APPELL_REVISION", "unknown (not a git checkout; set APPELL_REVISION)")


def cpu_name():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def log(msg):
    print(msg, file=sys.stderr, flush=True)


def run(cmd, **kw):
    log("+ " + " ".join(cmd))
    subprocess.run(cmd, check=True, **kw)


# --------------------------------------------------------------- building


def build_cxx():
    run(["make", "-j1", f"PYTHON={VENV_PYTHON}"], cwd=HERE)


def build_cg():
    """pinocchio_cg_bench, or None (with the reason logged) if it cannot be
    built (no CppAD / CppADCodeGen headers: run ./setup.sh again)."""
    try:
        run(["make", "-j1", "cg", f"PYTHON={VENV_PYTHON}"], cwd=HERE)
    except subprocess.CalledProcessError as e:
        log(f"  pinocchio_cg_bench not built ({e}); timing without Pinocchio's code generation")
        return None
    return os.path.join(BUILD, "pinocchio_cg_bench")


def rust_target_dir(variant):
    base = os.environ.get("CARGO_TARGET_DIR") or os.path.join(BUILD, "target")
    return os.path.join(base, variant)


def build_rust(variant, features):
    env = dict(os.environ)
    env.setdefault("CARGO_BUILD_JOBS", "1")
    env["CARGO_TARGET_DIR"] = rust_target_dir(variant)
    flags = env.get("RUSTFLAGS", "")
    if variant == "native":
        flags = (flags + " -C target-cpu=native").strip()
    env["RUSTFLAGS"] = flags
    manifest = os.path.join(HERE, "rust", "Cargo.toml")
    start = time.time()
    cmd = ["cargo", "build", "--release", "--manifest-path", manifest]
    if features:
        cmd += ["--features", features]
    run(cmd, env=env)
    log(f"  rust ({variant}) built in {time.time() - start:.0f} s")
    return os.path.join(env["CARGO_TARGET_DIR"], "release", "appell_bench")


def write_chain_urdfs():
    """The larger chains, by make_urdf.py's own writer, into build/urdf."""
    spec = importlib.util.spec_from_file_location(
        "make_urdf", os.path.join(ROBOTS, "spatial_chain", "make_urdf.py")
    )
    make_urdf = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(make_urdf)
    out = os.path.join(BUILD, "urdf")
    os.makedirs(out, exist_ok=True)
    paths = []
    for n, with_appell in LARGE_CHAINS:
        path = os.path.join(out, f"spatial_chain_{n}.urdf")
        with open(path, "w", newline="\n") as f:
            f.write(make_urdf.chain_urdf(n))
        paths.append((f"spatial_chain_{n}", path, [], with_appell))
    return paths


def mujoco_urdf(name, urdf, weld):
    """A copy MuJoCo can load: no meshes, welded joints fixed, no mimic."""
    tree = ET.parse(urdf)
    robot = tree.getroot()
    for link in robot.findall("link"):
        for tag in ("visual", "collision"):
            for e in link.findall(tag):
                link.remove(e)
    for joint in robot.findall("joint"):
        if joint.get("name") in weld:
            joint.set("type", "fixed")
            for tag in ("mimic", "limit", "axis", "dynamics"):
                for e in joint.findall(tag):
                    joint.remove(e)
    out = os.path.join(BUILD, "mujoco")
    os.makedirs(out, exist_ok=True)
    path = os.path.join(out, f"{name}.urdf")
    tree.write(path)
    return path


# ------------------------------------------------------------- correctness


def check_against_reference(binary):
    """Largest relative difference of `binary --check` from the reference
    files, over every quantity and robot."""
    worst = 0.0
    files = [(name, urdf, weld, os.path.join(REFERENCE, f"{SAME_FILE.get(name, name)}.json"), [])
             for name, urdf, weld, _ in MODELS]
    files += [(name, urdf, weld, os.path.join(REFERENCE, "robots", f"{FREE_REFERENCE[name]}.json"), ["--free"])
              for name, urdf, weld, _ in FREE_MODELS]
    for name, urdf, weld, path, free in files:
        with open(path) as f:
            ref = json.load(f)
        lines = []
        for s in ref["states"]:
            lines.append(" ".join(repr(x) for x in s["q"] + s["v"] + s["tau"] + s["a"]))
        cmd = [binary, urdf, "--check"] + (["--weld", ",".join(weld)] if weld else []) + free
        out = subprocess.run(cmd, input="\n".join(lines) + "\n", capture_output=True, text=True, check=True)
        got = [json.loads(line) for line in out.stdout.splitlines()]
        assert len(got) == len(ref["states"]), (name, len(got))
        for s, g in zip(ref["states"], got):
            for key in ("ddq", "rnea", "mass_matrix", "nle", "gravity_torque"):
                want = s[key]
                if key == "mass_matrix":
                    want = [x for row in want for x in row]
                scale = 1.0 + max(abs(x) for x in want)
                diff = max(abs(a - b) for a, b in zip(g[key], want)) / scale
                worst = max(worst, diff)
    return worst


def check_derivatives(pin_bin, rust_bin, name, urdf, weld, joints, seed):
    """Entry-by-entry comparison of appell's generated Jacobian
    (`appell_bench --dump-jacobian`, in Pinocchio's joint order) with
    computeABADerivatives (`pinocchio_bench --dump-derivatives`) on the
    first DERIVATIVE_STATES states of the batch; None if the appell model
    has no generated Jacobian. Per block, the largest absolute difference
    and the largest relative to 1 + the block's largest entry."""
    batch = ["--batch", str(DERIVATIVE_STATES), "--seed", str(seed)]
    wl = ["--weld", ",".join(weld)] if weld else []
    pin = [x for x in run_driver([pin_bin, urdf, "--name", name, "--dump-derivatives"] + wl + batch) if "ddq_dq" in x]
    app = [x for x in run_driver([rust_bin, name, "--joints", ",".join(joints), "--dump-jacobian"] + batch)
           if "ddq_dq" in x]
    if not app:
        return None
    # A model with a `jacobian(on)` twin (rust/src/jacobian.rs) dumps both
    # under its name: compare the first, the model as the examples write it.
    app = [x for x in app if x.get("type") == app[0].get("type")]
    assert len(app) == len(pin), (name, len(app), len(pin))
    out = {"states": len(app), "type": app[0]["type"]}
    for key in ("ddq", "ddq_dq", "ddq_dv", "ddq_dtau"):
        worst_abs = worst_rel = 0.0
        left_out = 0.0  # Pinocchio's entries where appell has none (the cyclic coordinate)
        for a, p in zip(app, pin):
            av = [x for row in a[key] for x in row] if key != "ddq" else a[key]
            pv = [x for row in p[key] for x in row] if key != "ddq" else p[key]
            assert len(av) == len(pv), (name, key, len(av), len(pv))
            scale = 1.0 + max(abs(x) for x in pv)
            for x, y in zip(av, pv):
                if x is None:
                    left_out = max(left_out, abs(y))
                    continue
                worst_abs = max(worst_abs, abs(x - y))
                worst_rel = max(worst_rel, abs(x - y) / scale)
        out[key] = {"max_abs": worst_abs, "max_rel": worst_rel}
        if key == "ddq_dq":
            out[key]["left_out_max_abs"] = left_out
    out["dual_max_diff"] = max(a["dual_max_diff"] for a in app)
    return out


# ----------------------------------------------------------------- timing


def run_driver(cmd, cwd=None):
    out = subprocess.run(cmd, capture_output=True, text=True, cwd=cwd)
    if out.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{out.stderr}")
    return [json.loads(line) for line in out.stdout.splitlines() if line.strip()]


def fmt_ns(x):
    """Nanoseconds to 3 significant digits, with thousands separators."""
    digits = max(0, 2 - len(str(int(x))) + 1) if x < 100 else 0
    return f"{round(x, digits) if digits else int(float(f'{x:.3g}')):,}"


def fmt_range(values, unit=None):
    unit = unit or fmt_ns
    if not values:
        return "–"
    med = statistics.median(values)
    lo, hi = min(values), max(values)
    return f"{unit(med)} ({unit(lo)}–{unit(hi)})"


def fmt_ratio(x):
    return f"{x:.2f}"


def measure(args):
    """Builds, checks and times; writes every driver line to
    build/results.jsonl after one line of metadata; returns its path."""
    if not os.path.exists(VENV_PYTHON):
        sys.exit("no .venv here: run ./setup.sh first")
    os.makedirs(BUILD, exist_ok=True)
    started = time.time()
    variants = [v for v in args.rust.split(",") if v]

    pin_bin = os.path.join(BUILD, "pinocchio_bench")
    pin_lib_bin = os.path.join(BUILD, "pinocchio_bench_lib")
    mj_bin = os.path.join(BUILD, "mujoco_bench")
    cg_bin = None if args.no_cg else os.path.join(BUILD, "pinocchio_cg_bench")
    cg_dir = os.path.join(BUILD, "cg")
    rust_bins = {}
    if args.no_build:
        for v in variants:
            rust_bins[v] = os.path.join(rust_target_dir(v), "release", "appell_bench")
        if cg_bin and not os.path.exists(cg_bin):
            cg_bin = None
    else:
        t0 = time.time()
        build_cxx()
        log(f"  C++ drivers built in {time.time() - t0:.0f} s")
        if cg_bin:
            t0 = time.time()
            cg_bin = build_cg()
            log(f"  code-generation driver built in {time.time() - t0:.0f} s")
            # The generated libraries are made again (the URDFs or flags may
            # have changed).
            if os.path.isdir(cg_dir):
                for f in os.listdir(cg_dir):
                    if f.endswith(".so"):
                        os.remove(os.path.join(cg_dir, f))
        for v in variants:
            rust_bins[v] = build_rust(v, args.features)

    models = MODELS + FREE_MODELS + ([] if args.no_large else write_chain_urdfs())
    # The robots, then the chains by size.
    models.sort(key=lambda m: (m[0].startswith("spatial_chain_"), int(m[0].rsplit("_", 1)[1]) if m[0].startswith("spatial_chain_") else 0))
    if args.models:
        keep = set(args.models.split(","))
        models = [m for m in models if m[0] in keep]
    # The models each Rust build has (spatial_chain_64 only with the
    # large-models feature).
    rust_models = {}
    for v in variants:
        listed = subprocess.run([rust_bins[v], "list"], capture_output=True, text=True, check=True).stdout.split()
        rust_models[v] = set(listed)
        missing = [name for name, _, _, with_appell in models if with_appell and name not in listed]
        if missing:
            log(f"  appell_{v} lacks {', '.join(missing)} (build it with --features large-models)")
    models = [(name, urdf, weld, with_appell and any(name in rust_models[v] for v in variants))
              for name, urdf, weld, with_appell in models]

    # Correctness of the C++ builds against the Python bindings' data.
    checks = {}
    for label, binary in (("header-only", pin_bin), ("library", pin_lib_bin)):
        checks[label] = check_against_reference(binary)
        log(f"  pinocchio_bench ({label}) against tests/reference/pinocchio: max rel. diff {checks[label]:.1e}")
        assert checks[label] < 1e-9, checks[label]

    common = ["--batch", str(args.batch), "--reps", str(args.reps), "--seed", str(args.seed)]
    # Joint order: Pinocchio's, from one untimed call.
    joints = {}
    for name, urdf, weld, _ in models:
        wl = ["--weld", ",".join(weld)] if weld else []
        fl = ["--free"] if name in FREE else []
        head = run_driver([pin_bin, urdf, "--name", name, "--batch", "1", "--reps", "1", "--only", "gravity"] + wl + fl)[0]
        joints[name] = head["joints"]
    # The derivatives, entry by entry (fixed bases with a Jacobian in the
    # first Rust build).
    derivative_checks = {}
    if variants:
        for name, urdf, weld, with_appell in models:
            if with_appell and name not in FREE and name in rust_models[variants[0]]:
                c = check_derivatives(pin_bin, rust_bins[variants[0]], name, urdf, weld, joints[name], args.seed)
                if c:
                    derivative_checks[name] = c
                    log(f"  derivatives of {name} ({c['type']}) against computeABADerivatives: "
                        + ", ".join(f"{k} {c[k]['max_abs']:.1e}" for k in ("ddq", "ddq_dq", "ddq_dv", "ddq_dtau"))
                        + f"; dual numbers {c['dual_max_diff']:.1e}")
    mj_urdf = {} if args.no_mujoco else {
        name: mujoco_urdf(name, urdf, weld) for name, urdf, weld, _ in models if name not in FREE
    }

    # Pinocchio's code generation: record, generate and compile each
    # function once per model (untimed; the libraries stay in build/cg).
    cg_prepare = {}
    meta_cg_compiled = {}
    if cg_bin:
        os.makedirs(cg_dir, exist_ok=True)
        for name, urdf, weld, _ in models:
            wl = ["--weld", ",".join(weld)] if weld else []
            fl = ["--free"] if name in FREE else []
            t0 = time.time()
            lines = run_driver([cg_bin, urdf, "--name", name, "--batch", "1", "--reps", "1"] + wl + fl, cwd=cg_dir)
            cg_prepare[name] = {x["prepare"]: x["seconds"] for x in lines if "prepare" in x}
            cg_prepare[name]["total"] = round(time.time() - t0, 1)
            compiled = [x["compiled"] for x in lines if "prepare" in x]
            meta_cg_compiled[name] = all(compiled) if compiled else False
            log(f"  code generation for {name}: {cg_prepare[name]}")

    path = os.path.join(BUILD, "results.jsonl")
    raw = open(path, "w")
    meta = {
        "date": time.strftime("%Y-%m-%d %H:%M"),
        "cpu": cpu_name(),
        "cores": os.cpu_count(),
        "revision": appell_revision(),
        "rounds": args.rounds,
        "tries": args.tries,
        "reps": args.reps,
        "batch": args.batch,
        "seed": args.seed,
        "rust": variants,
        "rust_features": args.features,
        "models": [[name, with_appell] for name, _, _, with_appell in models],
        "free": sorted(FREE & {name for name, _, _, _ in models}),
        "checks": checks,
        "cg_prepare": cg_prepare,
        "cg_compiled": meta_cg_compiled,
        "derivative_checks": derivative_checks,
    }
    raw.write(json.dumps({"meta": meta}) + "\n")
    for r in range(args.rounds):
        log(f"round {r + 1}/{args.rounds}")
        for name, urdf, weld, with_appell in models:
            wl = ["--weld", ",".join(weld)] if weld else []
            fl = ["--free"] if name in FREE else []
            jl = ["--joints", ",".join(joints[name])]
            jobs = [
                ("pinocchio", [pin_bin, urdf, "--name", name] + wl + fl + common, None),
                ("pinocchio_lib", [pin_lib_bin, urdf, "--name", name] + wl + fl + common, None),
            ]
            if cg_bin:
                jobs.append(("pinocchio_cg", [cg_bin, urdf, "--name", name] + wl + fl + common, cg_dir))
            if with_appell:
                for v in [v for v in variants if name in rust_models[v]]:
                    jobs.append((f"appell_{v}", [rust_bins[v], name] + jl + common, None))
            if not args.no_mujoco and name in mj_urdf:
                jobs.append(("mujoco", [mj_bin, mj_urdf[name], "--name", name] + jl + common, None))
            if r % 2:
                jobs.reverse()
            for t in range(args.tries):
                for key, cmd, cwd in jobs:
                    for line in run_driver(cmd, cwd):
                        if "prepare" in line:
                            continue
                        line["round"], line["try"], line["impl_key"] = r, t, key
                        raw.write(json.dumps(line) + "\n")
            raw.flush()
    elapsed = time.time() - started
    raw.write(json.dumps({"meta_end": {"seconds": round(elapsed)}}) + "\n")
    raw.close()
    return path


def report(path):
    """The markdown tables of a results.jsonl file."""
    meta, timed, heads, seconds = None, [], [], None
    with open(path) as f:
        for text in f:
            line = json.loads(text)
            if "meta" in line:
                meta = line["meta"]
            elif "meta_end" in line:
                seconds = line["meta_end"]["seconds"]
            elif "fn" in line:
                timed.append(line)
            else:
                heads.append(line)
    variants = meta["rust"]
    appell_keys = [f"appell_{v}" for v in variants]
    models = meta["models"]
    small = [name for name, with_appell in models if with_appell]
    has_mujoco = any(x["impl_key"] == "mujoco" for x in timed)
    has_cg = any(x["impl_key"] == "pinocchio_cg" for x in timed)
    free = set(meta.get("free", []))

    # Of each round's tries, the fastest median.
    best = {}
    for x in timed:
        k = (x["impl_key"], x["model"], x["fn"], x["round"])
        if k not in best or x["median_ns"] < best[k]["median_ns"]:
            best[k] = x

    def per_round(key, model, fn):
        return {r: x["median_ns"] for (k, m, f, r), x in best.items() if (k, m, f) == (key, model, fn)}

    def medians(key, model, fn):
        return list(per_round(key, model, fn).values())

    def ratios(key_a, fn_a, key_b, fn_b, model):
        a, b = per_round(key_a, model, fn_a), per_round(key_b, model, fn_b)
        return [a[r] / b[r] for r in a if r in b]

    def checksum(key, model, fn):
        for x in timed:
            if (x["impl_key"], x["model"], x["fn"]) == (key, model, fn):
                return x["checksum"]
        return None

    def head(key, model=None):
        for x in heads:
            if x["impl_key"] == key and (model is None or x["model"] == model):
                return x
        return {}

    def table(cols, rows):
        lines = ["| " + " | ".join(cols) + " |", "| " + " | ".join(["---"] + ["---:"] * (len(cols) - 1)) + " |"]
        lines += ["| " + " | ".join(row) + " |" for row in rows]
        return lines + [""]

    out = [
        f"Pinocchio {head('pinocchio').get('version', '?')}; {meta['date']}; {meta['cpu']}, {meta['cores']} cores; "
        f"appell at commit {meta['revision']}. {meta['rounds']} rounds; in each, {meta['tries']} processes per "
        f"implementation and model, each timing {meta['reps']} passes over {meta['batch']} states and reporting its "
        f"median pass, the faster of the {meta['tries']} kept. Cells: median over the rounds (min–max over the "
        f"rounds), ns per call; ratios taken within each round.",
        "",
    ]

    # Table 1: forward dynamics.
    cols = ["model", "dof", "appell rhs ops"] + [f"appell rhs ({v}), ns" for v in variants]
    cols += ["Pinocchio ABA, ns"] + [f"ABA / appell ({v})" for v in variants]
    if has_cg:
        cols += ["Pinocchio codegen ABA, ns"] + [f"codegen ABA / appell ({v})" for v in variants]
    cols += ["Pinocchio ABA (library), ns"] + (["MuJoCo mj_forward, ns"] if has_mujoco else [])
    rows = []
    for name in small:
        h = head(appell_keys[0], name) if appell_keys else {}
        label = name + (" (free base)" if name in free else "")
        row = [label, str(h.get("nv", head("pinocchio", name).get("nv", "?"))), f"{h.get('rhs_ops', 0):,}"]
        row += [fmt_range(medians(k, name, "rhs")) for k in appell_keys]
        row += [fmt_range(medians("pinocchio", name, "aba"))]
        row += [fmt_range(ratios("pinocchio", "aba", k, "rhs", name), fmt_ratio) for k in appell_keys]
        if has_cg:
            row += [fmt_range(medians("pinocchio_cg", name, "aba"))]
            row += [fmt_range(ratios("pinocchio_cg", "aba", k, "rhs", name), fmt_ratio) for k in appell_keys]
        row += [fmt_range(medians("pinocchio_lib", name, "aba"))]
        if has_mujoco:
            row += [fmt_range(medians("mujoco", name, "mj_forward"))]
        rows.append(row)
    out += table(cols, rows)

    # Table 2: the other appell functions against their counterparts.
    for fa, fp in PAIRS[1:]:
        if fa in DERIVATIVES:
            continue  # their own table below
        if not appell_keys or not any(medians(appell_keys[0], m, fa) for m in small):
            continue  # a function the Rust driver does not time (yet)
        cg = PAIRS_CG.get(fa) if has_cg else None
        cols = ["model"] + [f"appell {fa} ({v}), ns" for v in variants] + [f"Pinocchio {fp}, ns"]
        cols += [f"{fp} / appell ({v})" for v in variants]
        if cg:
            cols += [f"Pinocchio codegen {cg}, ns"] + [f"codegen / appell ({v})" for v in variants]
        rows = []
        for name in small:
            row = [name] + [fmt_range(medians(k, name, fa)) for k in appell_keys]
            row += [fmt_range(medians("pinocchio", name, fp))]
            row += [fmt_range(ratios("pinocchio", fp, k, fa, name), fmt_ratio) for k in appell_keys]
            if cg:
                row += [fmt_range(medians("pinocchio_cg", name, cg))]
                row += [fmt_range(ratios("pinocchio_cg", cg, k, fa, name), fmt_ratio) for k in appell_keys]
            rows.append(row)
        out += table(cols, rows)

    # The forward-dynamics derivatives: appell's generated Jacobian and the
    # dual-number one against computeABADerivatives (and ABA itself).
    derived = [name for name in small if appell_keys and medians(appell_keys[0], name, "rhs_jacobian")]
    if derived:
        def jacobian_ops(name):
            for x in heads:
                if x.get("model") == name and x.get("jacobian_ops"):
                    return f"{x['jacobian_ops']:,}" + (" (twin)" if "jacobian_type" in x else "")
            return "?"
        cols = ["model", "dof", "appell rhs_jacobian ops"]
        for v in variants:
            cols += [f"appell rhs_jacobian ({v}), ns", f"appell dual ({v}), ns"]
        cols += ["Pinocchio aba_derivatives, ns", "Pinocchio ABA, ns"]
        cols += [f"aba_derivatives / rhs_jacobian ({v})" for v in variants]
        if has_cg:
            cols += ["Pinocchio codegen aba_derivatives, ns"]
            cols += [f"codegen aba_derivatives / rhs_jacobian ({v})" for v in variants]
        cols += [f"dual / rhs_jacobian ({v})" for v in variants]
        cols += [f"rhs_jacobian / rhs ({v})" for v in variants] + ["aba_derivatives / ABA"]
        rows = []
        for name in derived:
            h = head(appell_keys[0], name)
            row = [name, str(h.get("nv", "?")), jacobian_ops(name)]
            for k in appell_keys:
                row += [fmt_range(medians(k, name, "rhs_jacobian")), fmt_range(medians(k, name, "rhs_jacobian_dual"))]
            row += [fmt_range(medians("pinocchio", name, "aba_derivatives")), fmt_range(medians("pinocchio", name, "aba"))]
            row += [fmt_range(ratios("pinocchio", "aba_derivatives", k, "rhs_jacobian", name), fmt_ratio) for k in appell_keys]
            if has_cg:
                row += [fmt_range(medians("pinocchio_cg", name, "aba_derivatives"))]
                row += [fmt_range(ratios("pinocchio_cg", "aba_derivatives", k, "rhs_jacobian", name), fmt_ratio)
                        for k in appell_keys]
            row += [fmt_range(ratios(k, "rhs_jacobian_dual", k, "rhs_jacobian", name), fmt_ratio) for k in appell_keys]
            row += [fmt_range(ratios(k, "rhs_jacobian", k, "rhs", name), fmt_ratio) for k in appell_keys]
            row += [fmt_range(ratios("pinocchio", "aba_derivatives", "pinocchio", "aba", name), fmt_ratio)]
            rows.append(row)
        out += ["Forward-dynamics derivatives: appell's `rhs_jacobian` (the generated rhs, A = ∂rhs/∂state and "
                "B = ∂rhs/∂inputs in one call; \"(twin)\": from the same robot derived with `jacobian(on)`, "
                "rust/src/jacobian.rs), the same three outputs by dual numbers (one `Dual64` rhs per column of A "
                "and B), Pinocchio's `computeABADerivatives` (ddq_dq, ddq_dv, Minv) and its `aba`"
                + (", and the same recorded and compiled by CppADCodeGen (`CodeGenABADerivatives`)" if has_cg else "")
                + ".", ""]
        out += table(cols, rows)
        checks = meta.get("derivative_checks", {})
        if checks:
            out += [f"Derivatives entry by entry, appell's generated Jacobian (rows and columns placed by joint "
                    f"name) against computeABADerivatives on the first {DERIVATIVE_STATES} states, largest "
                    f"absolute difference (relative to 1 + the block's largest entry):", ""]
            for name, c in checks.items():
                parts = [f"{label} {c[k]['max_abs']:.1e} ({c[k]['max_rel']:.1e})"
                         for k, label in (("ddq", "q̈"), ("ddq_dq", "∂q̈/∂q"), ("ddq_dv", "∂q̈/∂v"),
                                          ("ddq_dtau", "∂q̈/∂τ"))]
                out.append(f"- {name} ({c['type']}): " + ", ".join(parts)
                           + f"; Pinocchio's ∂q̈/∂q in the column appell leaves out (cyclic): at most "
                           f"{c['ddq_dq']['left_out_max_abs']:.1e}; generated against dual numbers: "
                           f"{c['dual_max_diff']:.1e}")
            out.append("")

    # The conversions between Pinocchio's conventions and appell's (free
    # bases), beside the rhs they feed.
    converted = [name for name in small if name in free and appell_keys and medians(appell_keys[0], name, "map_in")]
    if converted:
        cols = ["model"]
        for v in variants:
            cols += [f"map_in ({v}), ns", f"map_out ({v}), ns", f"rhs ({v}), ns"]
        rows = []
        for name in converted:
            row = [name]
            for k in appell_keys:
                row += [fmt_range(medians(k, name, f)) for f in CONVERSIONS + ["rhs"]]
            rows.append(row)
        out += ["Converting a state (untimed in the tables above): `map_in` is Pinocchio's q and v to appell's "
                "reduced state (`q_from_pinocchio`, `v_from_pinocchio`, the retained coordinates picked), "
                "`map_out` appell's accelerations to Pinocchio's a (`a_to_pinocchio`).", ""]
        out += table(cols, rows)

    # Table 3: every Pinocchio function, every model.
    cols = ["model", "dof"] + [f"{f}, ns" for f in PINOCCHIO_FUNCTIONS]
    cols += ["MuJoCo mj_forward, ns"] if has_mujoco else []
    rows = []
    for name, _ in models:
        row = [name, str(head("pinocchio", name).get("nv", "?"))]
        row += [fmt_range(medians("pinocchio", name, f)) for f in PINOCCHIO_FUNCTIONS]
        if has_mujoco:
            row += [fmt_range(medians("mujoco", name, "mj_forward"))]
        rows.append(row)
    out += table(cols, rows)

    # Table 4: the library build beside the header-only one.
    fns = ("aba", "rnea", "crba", "gravity")
    cols = ["model"] + [f"{f}: header-only / library, ns" for f in fns]
    rows = []
    for name, _ in models:
        row = [name]
        for f in fns:
            a, b = medians("pinocchio", name, f), medians("pinocchio_lib", name, f)
            row.append(f"{fmt_ns(statistics.median(a))} / {fmt_ns(statistics.median(b))}" if a and b else "–")
        rows.append(row)
    out += table(cols, rows)

    # Agreement of the checksums (sum of all outputs over the batch).
    out += ["Checksums (sum of every output over the batch), largest relative difference from Pinocchio's "
            "over the models:", ""]
    worst = {}
    pairs = [(k, fa, fp) for k in appell_keys for fa, fp in PAIRS]
    pairs += [("mujoco", "mj_forward", "aba"), ("pinocchio_lib", "aba", "aba"), ("pinocchio_lib", "crba_nle", "crba_nle")]
    pairs += [("pinocchio_cg", f, f) for f in PAIRS_CG.values()]
    where, floating = {}, {}
    for name, _ in models:
        for k, fa, fp in pairs:
            if name in free and fa in DERIVATIVES:
                # A free base's A and B are by the quaternion's components,
                # Pinocchio's along its tangent: not the same numbers.
                continue
            a, b = checksum(k, name, fa), checksum("pinocchio", name, fp)
            if a is not None and b is not None:
                label = f"{k} {fa} vs {fp}"
                d = abs(a - b) / max(abs(b), 1.0)
                if d >= worst.get(label, 0.0):
                    worst[label], where[label] = d, name
                if name in free:
                    floating[label] = max(floating.get(label, 0.0), d)
    out += [f"- {label}: {d:.1e} ({where[label]}){'  **above 1e-9**' if d > 1e-9 else ''}"
            for label, d in worst.items()] + [""]
    if floating:
        out += ["The same over the floating-base robots alone (appell's outputs converted to Pinocchio's "
                "conventions by `PinocchioMap` before summing):", ""]
        out += [f"- {label}: {d:.1e}" for label, d in floating.items()] + [""]
    if meta.get("cg_prepare"):
        compiled = meta.get("cg_compiled", {})
        what = ("seconds to record, generate and compile each function"
                if all(compiled.get(name, True) for name in meta["cg_prepare"])
                else "seconds to record each function and load its library (the libraries were already "
                     "in build/cg, as with --no-build: not compiled again)")
        out.append(f"Pinocchio's code generation, {what} (once per run, before the timing): "
                   + "; ".join(f"{name} " + ", ".join(f"{f} {t:g}" for f, t in times.items())
                               for name, times in meta["cg_prepare"].items())
                   + ".")
        out.append("")
    out.append(
        "pinocchio_bench against tests/reference/pinocchio (Python bindings' values): "
        + ", ".join(f"{k} {v:.1e}" for k, v in meta["checks"].items())
        + "."
    )
    mj = head("mujoco")
    if mj:
        out.append(f"MuJoCo {mj.get('version', '?')}.")
    if seconds is not None:
        out.append(f"Run time (build, check and timing): {seconds} s.")
    return "\n".join(out) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--reps", type=int, default=21, help="timed passes per process")
    ap.add_argument("--batch", type=int, default=1000, help="states per pass")
    ap.add_argument("--seed", type=int, default=20240917)
    ap.add_argument("--tries", type=int, default=2,
                    help="processes per implementation, model and round; each function keeps its fastest median")
    ap.add_argument("--rust", default="native,generic", help="Rust builds to time: native, generic or both")
    ap.add_argument("--features", default="large-models",
                    help="cargo features of the Rust driver (large-models: the 64-link chain; '' for none)")
    ap.add_argument("--no-build", action="store_true", help="use the binaries already built")
    ap.add_argument("--no-mujoco", action="store_true")
    ap.add_argument("--no-cg", action="store_true", help="leave out Pinocchio's code-generated functions (pinocchio_cg_bench)")
    ap.add_argument("--no-large", action="store_true", help="skip the chains n = 24, 48, 64 (written into build/urdf)")
    ap.add_argument("--models", default=None, help="comma-separated subset of the models")
    ap.add_argument("--report", metavar="RESULTS_JSONL", default=None,
                    help="only print the tables of an earlier run's build/results.jsonl")
    args = ap.parse_args()
    path = args.report or measure(args)
    text = report(path)
    if not args.report:
        with open(os.path.join(BUILD, "results.md"), "w") as f:
            f.write(text)
    print(text)


if __name__ == "__main__":
    main()
