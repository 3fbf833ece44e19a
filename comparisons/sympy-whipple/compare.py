#!/usr/bin/env python3
"""Time SymPy's generated C rhs (at -O2 and -O3) and appell's generated Rust
rhs alternately, so that all see the same machine load.

Usage: python3 compare.py [rounds] [path/to/whipple_bicycle] [path/to/native/whipple_bicycle]
The ratio reported is SymPy's ns per call over appell's (below 1: SymPy's C
is faster). The optional third path is the same example built with
RUSTFLAGS="-C target-cpu=native"; it is timed in the same rounds, and the
native C variants are then also compared with it (ratio_native_*).

Each round runs appell's `bench`, then the harness built three ways (-O2
and -O3 with -march=native, -O2 for the generic x86-64 target), then
appell's `bench` again and the three harnesses in reverse order; each
program keeps the faster of its two runs in the round, and the ratio of
the round is SymPy's time over appell's. Every harness run reports the median over 15 batches of
at least 2 ms each (the same method as appell's `bench`). Prints a table
and writes build/compare.json.
"""
import json
import os
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
BUILD = os.path.join(HERE, "build")
ROUNDS = int(sys.argv[1]) if len(sys.argv) > 1 else 9
APPELL = sys.argv[2] if len(sys.argv) > 2 else os.path.join(
    HERE, "..", "..", "target", "release", "examples", "whipple_bicycle")
APPELL_NATIVE = sys.argv[3] if len(sys.argv) > 3 else None

# name -> compiler flags; "O2" and "O3" are with -march=native, "O2-generic"
# targets the default x86-64 baseline (as the Rust build does without
# target-cpu=native).
VARIANTS = {"O2": ["-O2", "-march=native"], "O3": ["-O3", "-march=native"],
            "O2-generic": ["-O2"]}
bins = {}
for name, flags in VARIANTS.items():
    exe = os.path.join(BUILD, f"harness-{name}")
    # The rhs and the harness are separate translation units (no LTO), so the
    # call cannot be inlined or hoisted out of the timing loop.
    subprocess.run(["cc", *flags, "-o", exe, os.path.join(HERE, "harness.c"),
                    os.path.join(BUILD, "whipple_sympy_rhs.c"), "-lm"], check=True)
    bins[name] = exe


def appell_bench(exe=APPELL):
    r = json.loads(subprocess.run([exe, "bench"], capture_output=True, text=True,
                                  check=True).stdout)
    return r["rhs_ns"], r["ops"]


def sympy_bench(opt):
    r = json.loads(subprocess.run([bins[opt], "bench", "1"], capture_output=True, text=True,
                                  check=True).stdout)
    return r["rhs_ns"]


rounds = []
appell_ops = None
for k in range(ROUNDS):
    # appell, SymPy variants, appell, SymPy variants in reverse order: every
    # program is timed twice per round and keeps the faster of its two runs
    # (a run that overlaps a burst of other load is then discarded).
    times = {"appell": [], "appell_native": []}
    for name in VARIANTS:
        times[name] = []
    for order in (list(VARIANTS), list(reversed(VARIANTS))):
        ns, appell_ops = appell_bench()
        times["appell"].append(ns)
        if APPELL_NATIVE:
            times["appell_native"].append(appell_bench(APPELL_NATIVE)[0])
        for name in order:
            times[name].append(sympy_bench(name))
    a = min(times["appell"])
    r = {"appell_ns": a, "appell_ns_runs": times["appell"]}
    if APPELL_NATIVE:
        r["appell_native_ns"] = min(times["appell_native"])
        r["appell_native_ns_runs"] = times["appell_native"]
    for name in VARIANTS:
        ns = min(times[name])
        r[f"sympy_{name}_ns"] = ns
        r[f"sympy_{name}_ns_runs"] = times[name]
        r[f"ratio_{name}"] = ns / a
        if APPELL_NATIVE and "march=native" in " ".join(VARIANTS[name]):
            r[f"ratio_native_{name}"] = ns / r["appell_native_ns"]
    rounds.append(r)
    native = f" (native {r['appell_native_ns']:6.1f} ns)" if APPELL_NATIVE else ""
    print(f"round {k + 1}: appell {a:6.1f} ns{native}; sympy "
          + ", ".join(f"{name} {r[f'sympy_{name}_ns']:6.1f} ns ({r[f'ratio_{name}']:4.2f}x)"
                      for name in VARIANTS), flush=True)

keys = ["appell_ns"] + [f"sympy_{n}_ns" for n in VARIANTS] + [f"ratio_{n}" for n in VARIANTS]
if APPELL_NATIVE:
    keys += ["appell_native_ns"] + [k for k in rounds[0] if k.startswith("ratio_native_")]
med = {key: statistics.median(r[key] for r in rounds) for key in keys}
derive = json.load(open(os.path.join(BUILD, "derive.json")))
summary = {"rounds_n": ROUNDS, "medians": med, "appell_ops": appell_ops,
           "sympy_ops": derive["ops_total"], "rounds": rounds}
with open(os.path.join(BUILD, "compare.json"), "w") as fh:
    json.dump(summary, fh, indent=1)
print(json.dumps({"medians": med, "appell_ops": appell_ops,
                  "sympy_ops": derive["ops_total"]}, indent=1))
