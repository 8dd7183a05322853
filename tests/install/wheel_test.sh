#!/usr/bin/env bash
# The Python wheel as a Python user gets it (issues 45, 55): `pip wheel` builds it from the checkout
# (reusing BUILD_DIR's CMake build, so only the module is relinked when changed); every compiled
# file in it needs only what it carries or glibc and libstdc++, each library it carries has its
# licence beside it, its metadata has the LICENSE, the licence and the program's version, and
# scipy only as an extra; it installs into a fresh venv
# (--system-site-packages, for Debian's numpy) and deforms a mesh there, run from another folder
# with the system's copies of the libraries it bundles hidden.
# Usage: wheel_test.sh BUILD_DIR SOURCE_DIR WORK_DIR
set -euo pipefail
build=$1 source=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*" >&2; exit 1; }
python=/usr/bin/python3

echo "-- pip wheel"
(cd "$source" && SPECDEFORM_CMAKE_BUILD_DIR="$build" $python -m pip wheel --no-build-isolation \
   --no-deps --no-index -q -w "$work/dist" .) || fail "pip wheel"
wheel=$(ls "$work"/dist/specdeform-*-cp3*-manylinux_2_*_x86_64.whl) || fail "no manylinux wheel"
echo "$(basename "$wheel"): $(du -k "$wheel" | cut -f1) KiB"

echo "-- what the wheel carries"
$python -m zipfile -e "$wheel" "$work/unpacked"
$python "$source/scripts/bundle_libs.py" check "$work/unpacked" ||
  fail "unbundled libraries, or bundled ones without their licence"
grep -q "GNU GENERAL PUBLIC LICENSE" "$work"/unpacked/specdeform-*.dist-info/LICENSE ||
  fail "no LICENSE in the wheel's metadata"
grep -q "^License: GPL-3.0-or-later" "$work"/unpacked/specdeform-*.dist-info/METADATA ||
  fail "the wheel's metadata names no licence"
version=$("$build"/bin/specdeform --version | cut -d' ' -f2)
grep -qx "Version: $version" "$work"/unpacked/specdeform-*.dist-info/METADATA ||
  fail "the wheel's version is not the program's $version"
if grep "^Requires-Dist: scipy" "$work"/unpacked/specdeform-*.dist-info/METADATA | grep -vq "extra =="; then
  fail "the wheel requires scipy (optional: the extra 'scipy')"
fi

echo "-- a fresh venv, the build tree and the system's libraries out of sight"
$python -m venv --system-site-packages "$work/venv"
"$work/venv/bin/pip" install --no-index -q "$wheel" || fail "pip install"
mkdir -p "$work/elsewhere"
cd "$work/elsewhere"
"$source/tests/install/without_system_libs.sh" "$build"/python/specdeform/_specdeform*.so \
  env -u PYTHONPATH "$work/venv/bin/python" - "$work/venv" <<'PY' || fail "deform in the venv"
import sys

import numpy as np
import specdeform

assert specdeform.__file__.startswith(sys.argv[1]), specdeform.__file__
V, F = specdeform.bumpy_bar()
x = V[:, 0]
top, bottom = np.flatnonzero(x > x.max() - 0.05), np.flatnonzero(x < x.min() + 0.05)
d = specdeform.SpectralDeformer(V, F, modes=40)
d.set_selection(handles=[top], fixed=bottom)
T = np.eye(4)
T[2, 3] = 0.3
X = d.solve([T])
moved = X[top, 2] - V[top, 2]
assert np.abs(moved - 0.3).max() < 0.01 * np.ptp(V, axis=0).max(), moved
assert np.abs(X[bottom] - V[bottom]).max() < 1e-9
specdeform.write_mesh("bent.off", X, F)
assert np.allclose(specdeform.read_mesh("bent.off")[0], X, atol=1e-6)
print("deformed", len(V), "vertices with", specdeform.__file__)
PY
