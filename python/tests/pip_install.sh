#!/bin/sh
# pip install of the package from the source tree, offline, into a fresh directory: the extension comes from the
# CMake build BUILD (PD_BUILD_DIR), then the installed package runs a scene.
#   pip_install.sh PYTHON SOURCE_DIR BUILD TARGET
set -eu
python=$1 source=$2 build=$3 target=$4
rm -rf "$target"
PD_BUILD_DIR=$build "$python" -m pip install --quiet --no-build-isolation --no-index --no-deps --no-warn-script-location \
  --target "$target" "$source/python"
cd "$target"
PYTHONPATH=$target "$python" - <<'PY'
import os, sys, polydyn
assert os.path.dirname(polydyn.__file__) == os.path.join(os.getcwd(), "polydyn"), polydyn.__file__
r = polydyn.run(polydyn.Scene.from_string("tend 0.3\ncube floor grey 1 1 0.1\nfixed\nloc 0 0 -0.05\n"
                                          "cube box red 0.1 0.1 0.1\nloc 0 0 0.2\n"))
# free fall from 0.2 m: z = 0.2 − g t²/2 until the box touches the floor at t = √(2·0.15/g) = 0.175 s
assert abs(r.x[10, 0, 2] - (0.2 - 9.81 * 0.1 ** 2 / 2)) < 1e-9, r.x[10, 0, 2]
print("pip install: ok,", polydyn.__version__)
PY
