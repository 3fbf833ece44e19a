#!/usr/bin/env python3
"""Writes the spatial test chains spatial_chain_{2,4,8,16,32}.urdf beside this
script. They are synthetic serial chains of revolute joints with asymmetric,
offset inertias, used as reference robots for the Pinocchio data in
tests/reference/pinocchio/.

The chain with n links:

- links `base_link` (no inertial), then `link_1` ... `link_n`;
- joint `j_k` (k = 1..n), revolute, parent `base_link` for k = 1 and
  `link_{k-1}` otherwise, child `link_k`; origin xyz "0 0 0" for k = 1 and
  "0 0 0.5" (in the parent link's frame) otherwise, rpy "0 0 0"; axis "0 0 1"
  for odd k and "0 1 0" for even k; limits +-3.15 rad (not used by the
  dynamics);
- link_k: centre of mass at "0.05 0.02 0.25" in the link frame (rpy "0 0 0"),
  mass 1 + 0.1 k, inertia about the centre of mass in the link frame
  ixx = 0.02 + 0.001 k, iyy = 0.03 + 0.001 k, izz = 0.01 + 0.001 k,
  ixy = 0.001, ixz = -0.002, iyz = 0.0015 (the entries of the inertia
  matrix, as URDF and Pinocchio read them).

Numbers are written with Python's repr of the float, which round-trips
exactly (so 1 + 0.1 * 3 is written 1.3000000000000003: that is the value).

Usage (from anywhere): python3 examples/robots/spatial_chain/make_urdf.py
"""
import os

SIZES = (2, 4, 8, 16, 32)
HERE = os.path.dirname(os.path.abspath(__file__))


def num(x):
    """A float as the shortest string that reads back to the same double."""
    return repr(float(x))


def chain_urdf(n):
    out = []
    out.append('<?xml version="1.0"?>')
    out.append(f"<!-- Written by make_urdf.py ({n} links); do not edit. -->")
    out.append(f'<robot name="spatial_chain_{n}">')
    out.append('  <link name="base_link"/>')
    for k in range(1, n + 1):
        parent = "base_link" if k == 1 else f"link_{k - 1}"
        xyz = "0 0 0" if k == 1 else "0 0 0.5"
        axis = "0 0 1" if k % 2 == 1 else "0 1 0"
        mass = 1 + 0.1 * k
        ixx = 0.02 + 0.001 * k
        iyy = 0.03 + 0.001 * k
        izz = 0.01 + 0.001 * k
        ixy, ixz, iyz = 0.001, -0.002, 0.0015
        out.append(f'  <joint name="j_{k}" type="revolute">')
        out.append(f'    <parent link="{parent}"/>')
        out.append(f'    <child link="link_{k}"/>')
        out.append(f'    <origin xyz="{xyz}" rpy="0 0 0"/>')
        out.append(f'    <axis xyz="{axis}"/>')
        out.append('    <limit lower="-3.15" upper="3.15" effort="100" velocity="10"/>')
        out.append("  </joint>")
        out.append(f'  <link name="link_{k}">')
        out.append("    <inertial>")
        out.append('      <origin xyz="0.05 0.02 0.25" rpy="0 0 0"/>')
        out.append(f'      <mass value="{num(mass)}"/>')
        out.append(
            f'      <inertia ixx="{num(ixx)}" ixy="{num(ixy)}" ixz="{num(ixz)}" '
            f'iyy="{num(iyy)}" iyz="{num(iyz)}" izz="{num(izz)}"/>'
        )
        out.append("    </inertial>")
        out.append("  </link>")
    out.append("</robot>")
    return "\n".join(out) + "\n"


def main():
    for n in SIZES:
        path = os.path.join(HERE, f"spatial_chain_{n}.urdf")
        with open(path, "w", newline="\n") as f:
            f.write(chain_urdf(n))
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
