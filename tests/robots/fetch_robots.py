#!/usr/bin/env python3
"""Copies the robot URDFs of the installed example-robot-data package into
this directory, one folder per description package, and writes MANIFEST.json:
the package's version, and for each URDF its source path, sha256, licence,
and the base its usual Pinocchio model has (fixed or free).

Only URDF text is copied (no meshes, no SRDF). A description package's
LICENSE file and its README.md (which states the licence, the upstream
source and the modifications example-robot-data made) are copied beside its
URDFs.

Descriptions whose licence forbids derivatives or commercial use (CC-BY-NC-ND:
alex_description) are not copied unless --restricted is given; they are
listed in the manifest under "skipped" with the reason. cassie_description
has SDF files only and is listed there too.

Needs: pip install example-robot-data==6.0.0
Usage (from anywhere): python3 tests/robots/fetch_robots.py [--restricted]
"""
import argparse
import hashlib
import importlib.metadata
import json
import os
import re
import shutil
import sys

HERE = os.path.dirname(os.path.abspath(__file__))

# Robots whose usual Pinocchio model has a floating base: the loaders of
# example-robot-data-loaders 5.0.0 build them with JointModelFreeFlyer
# (free_flyer = True). Keyed by the URDF's path inside robots/. Everything
# else is fixed (arms, hands, pendulums; the mobile bases Tiago and Tiago
# Pro, whose loaders are fixed too).
FREE = {
    "a1_description/urdf/a1.urdf",
    "alexander_description/urdf/alexander_v1.lowerBodyOnly.urdf",
    "anymal_b_simple_description/robots/anymal.urdf",
    "anymal_b_simple_description/robots/anymal-kinova.urdf",
    "anymal_c_simple_description/urdf/anymal.urdf",
    "b1_description/urdf/b1.urdf",
    "b1_description/urdf/b1-z1.urdf",
    "bolt_description/robots/bolt.urdf",
    "borinot_description/urdf/borinot_flying_arm_2.urdf",
    "centauro_description/urdf/centauro.urdf",
    "g1_description/urdf/g1_29dof_rev_1_0.urdf",
    "g1_description/urdf/g1_29dof_with_hand_rev_1_0.urdf",
    "go1_description/urdf/go1.urdf",
    "go2_description/urdf/go2.urdf",
    "hector_description/robots/quadrotor_base.urdf",
    "hextilt_description/urdf/hextilt_flying_arm_5.urdf",
    "human_description/robots/human.urdf",
    "hyq_description/robots/hyq_no_sensors.urdf",
    "icub_description/robots/icub.urdf",
    "icub_description/robots/icub_reduced.urdf",
    "iris_description/robots/iris.urdf",
    "iris_description/robots/iris_simple.urdf",
    "laikago_description/urdf/laikago.urdf",
    "pr2_description/urdf/pr2.urdf",
    "quadruped_description/urdf/quadruped.urdf",
    "romeo_description/urdf/romeo.urdf",
    "romeo_description/urdf/romeo_small.urdf",
    "romeo_description/urdf/romeo_laas_small.urdf",
    "simple_humanoid_description/urdf/simple_humanoid.urdf",
    "simple_humanoid_description/urdf/simple_humanoid_classical.urdf",
    "solo_description/robots/solo.urdf",
    "solo_description/robots/solo12.urdf",
    "talos_data/robots/talos_reduced.urdf",
    "talos_data/robots/talos_reduced_box.urdf",
    "talos_data/robots/talos_reduced_corrected.urdf",
    "talos_data/robots/talos_full_v2.urdf",
    "talos_data/robots/talos_full_v2_box.urdf",
}

# Licences that do not allow redistributing the file in this repository.
RESTRICTED = ("NC", "ND")


def robots_dir():
    """example-robot-data's robots/ folder in the cmeel prefix."""
    for entry in sys.path:
        d = os.path.join(entry, "cmeel.prefix", "share", "example-robot-data", "robots")
        if os.path.isdir(d):
            return d
    sys.exit("example-robot-data is not installed (pip install example-robot-data==6.0.0)")


def sha256(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def licence(package_dir):
    """The licence a description's README.md states (`license: X`)."""
    readme = os.path.join(package_dir, "README.md")
    if not os.path.isfile(readme):
        return None
    with open(readme, encoding="utf-8") as f:
        for line in f:
            m = re.match(r"\s*licen[sc]e\s*:\s*(.+?)\s*$", line, re.IGNORECASE)
            if m:
                return m.group(1)
    return None


def short(package):
    """The folder name here: the package's name without `_description`."""
    return re.sub(r"_(description|data)$", "", package)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--restricted",
        action="store_true",
        help="copy the descriptions with NC/ND licences too (not for committing)",
    )
    args = parser.parse_args()
    src = robots_dir()
    version = importlib.metadata.version("example-robot-data")
    robots, skipped, licences = [], [], {}
    for package in sorted(os.listdir(src)):
        pdir = os.path.join(src, package)
        if not os.path.isdir(pdir):
            continue
        lic = licence(pdir)
        urdfs = sorted(
            os.path.relpath(os.path.join(root, name), src)
            for root, _, files in os.walk(pdir)
            for name in files
            if name.endswith(".urdf")
        )
        if not urdfs:
            skipped.append({"package": package, "reason": "no URDF (SDF files only)"})
            continue
        restricted = lic is not None and any(r in lic.split("-") for r in RESTRICTED)
        if restricted and not args.restricted:
            for rel in urdfs:
                skipped.append(
                    {
                        "package": package,
                        "source": rel,
                        "sha256": sha256(os.path.join(src, rel)),
                        "licence": lic,
                        "reason": "its licence forbids derivatives or commercial use; "
                        "fetch_robots.py --restricted copies it for a local survey",
                    }
                )
            continue
        folder = short(package)
        out_dir = os.path.join(HERE, folder)
        os.makedirs(out_dir, exist_ok=True)
        kept = []
        for extra in ("LICENSE", "README.md"):
            if os.path.isfile(os.path.join(pdir, extra)):
                shutil.copyfile(os.path.join(pdir, extra), os.path.join(out_dir, extra))
                kept.append(extra)
        licences[folder] = {"package": package, "licence": lic, "files": kept}
        names = [os.path.basename(rel) for rel in urdfs]
        assert len(set(names)) == len(names), f"{package}: two URDFs share a name"
        for rel in urdfs:
            dest = os.path.join(out_dir, os.path.basename(rel))
            shutil.copyfile(os.path.join(src, rel), dest)
            robots.append(
                {
                    "urdf": os.path.relpath(dest, HERE),
                    "source": rel,
                    "sha256": sha256(dest),
                    "bytes": os.path.getsize(dest),
                    "licence": lic,
                    "base": "free" if rel in FREE else "fixed",
                }
            )
    unknown = FREE - {r["source"] for r in robots} - {s.get("source") for s in skipped}
    assert not unknown, f"free-base robots not found: {sorted(unknown)}"
    manifest = {
        "package": "example-robot-data",
        "version": version,
        "script": "tests/robots/fetch_robots.py",
        "note": "URDF text copied unchanged from the package's robots/ folder; meshes are not "
        "copied. `base` is the base of the robot's usual Pinocchio model (the free_flyer flag of "
        "example-robot-data-loaders 5.0.0's loader for it; fixed where no loader says free).",
        "licences": licences,
        "robots": robots,
        "skipped": skipped,
    }
    with open(os.path.join(HERE, "MANIFEST.json"), "w", newline="\n") as f:
        json.dump(manifest, f, indent=2)
        f.write("\n")
    total = sum(r["bytes"] for r in robots)
    print(f"example-robot-data {version}: {len(robots)} URDFs ({total / 1e6:.1f} MB) into {HERE}")
    for s in skipped:
        print(f"skipped {s.get('source', s['package'])}: {s['reason']}")


if __name__ == "__main__":
    main()
