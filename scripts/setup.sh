#!/usr/bin/env bash
# Installs what specdeform needs on Debian 12 (idempotent), then configures and builds it: the
# C++ library, program, tests and benchmarks, the Python bindings (build/python), the Blender
# add-on (build/blender; Debian's blender runs its tests) and the browser editor (web/dist, Vite).
# Usage: scripts/setup.sh [build-dir]      (default: build)
#        scripts/setup.sh --packages        (the Debian packages only: for pip install .)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}

packages=(build-essential cmake pkg-config libeigen3-dev libsuitesparse-dev libopenblas-dev
          libspectra-dev libcli11-dev nlohmann-json3-dev libgtest-dev libbenchmark-dev libboost-dev
          libcgal-dev libtinygltf-dev libdraco-dev libmeshoptimizer-dev libzip-dev python3-dev pybind11-dev python3-numpy python3-scipy python3-pytest
          python3-matplotlib python3-pip python3-venv python3-build patchelf lintian blender xvfb)
command -v npm >/dev/null || packages+=(nodejs npm)
scripts/apt_install.sh "${packages[@]}"
[ "$build" = --packages ] && exit 0

# The editor's npm packages, pinned by web/package-lock.json; reinstalled when the lock changes.
# Vite 8 needs Node.js 20.19 or later.
if ! node -e 'const [a, b] = process.versions.node.split(".").map(Number);
              process.exit(a > 20 || (a === 20 && b >= 19) ? 0 : 1)'; then
  echo "setup: Node.js $(node --version) is too old for the editor's build (20.19 or later)" >&2
  exit 1
fi
if [ ! web/node_modules/.package-lock.json -nt web/package-lock.json ]; then
  (cd web && npm ci --no-audit --no-fund --loglevel=error)
fi
(cd web && npm run --silent build >/dev/null)

# The Python bindings for Debian's python3, which sees Debian's numpy and scipy.
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DPython_EXECUTABLE=/usr/bin/python3 >/dev/null
cmake --build "$build" -j "$(nproc)"
