#!/bin/sh
# Makes .venv here with Pinocchio, MuJoCo and their C++ headers and libraries,
# at the versions of requirements.txt (the ones the README's table was
# measured with). Needs python3 (3.10 or later) with venv, and PyPI.
#
#   pin                    Pinocchio: Python bindings, and under
#                          site-packages/cmeel.prefix its headers and
#                          libpinocchio_*.so (from the libpinocchio wheel),
#                          Boost and urdfdom
#   cmeel-eigen,           headers that Pinocchio's own headers include but
#   cmeel-urdfdom-headers  that `pin` does not install (its "build" extra
#                          would, with scipy and more)
#   cmeel-cppad,           CppAD's and CppADCodeGen's headers, for Pinocchio's
#   cmeel-cppadcodegen     code-generated functions (pinocchio_cg_bench)
#   example-robot-data     where the UR5 and Panda URDFs come from
#   mujoco                 libmujoco.so and its headers
#   numpy                  for pin's bindings
#
# Set PIP_ARGS to pass more arguments to pip; set LATEST=1 to install the
# newest versions instead of requirements.txt's.
set -eu
cd "$(dirname "$0")"
python3 -m venv .venv
.venv/bin/pip install --upgrade --quiet pip
if [ "${LATEST:-0}" = 1 ]; then
    .venv/bin/pip install ${PIP_ARGS:-} pin example-robot-data mujoco numpy cmeel-eigen cmeel-urdfdom-headers cmeel-cppad cmeel-cppadcodegen
else
    .venv/bin/pip install ${PIP_ARGS:-} -r requirements.txt
fi
.venv/bin/python - <<'PY'
import os, cmeel, mujoco, pinocchio
prefix = os.path.join(os.path.dirname(cmeel.__path__[0]), "cmeel.prefix")
print(f"pinocchio {pinocchio.__version__}, mujoco {mujoco.__version__}")
print(f"cmeel prefix: {prefix}")
for f in ("include/pinocchio/algorithm/aba.hpp", "include/eigen3/Eigen/Core",
          "include/urdfdom_headers/urdf_model/model.h", "lib/libpinocchio_default.so",
          "include/cppad/cg.hpp", "include/pinocchio/codegen/cppadcg-algo.hpp"):
    assert os.path.exists(os.path.join(prefix, f)), f"missing {f}"
PY
