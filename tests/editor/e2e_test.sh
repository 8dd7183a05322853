#!/usr/bin/env bash
# Runs the browser editor's end-to-end test (web/e2e/editor.e2e.mjs) in Debian's Chromium.
# Usage: e2e_test.sh SPECDEFORM_BINARY WEB_DIR OUTPUT_DIR [MESH [SUBDIVIDE] [-- E2E_ARGS...]]
# MESH: a file, tried as given; SUBDIVIDE: refine it that many times first (into OUTPUT_DIR).
# E2E_SCRIPT: another script of web/e2e taking the same options (default editor.e2e.mjs).
# Exit 77 (skipped) without Chromium, Node.js >= 20, the editor's npm packages, or the mesh
# (the shared test meshes are not in every checkout).
set -u
bin=$1 web=$2 out=$3
shift 3
mesh=${1:-}
[ $# -gt 0 ] && shift
levels=0
if [ $# -gt 0 ] && [ "$1" != "--" ]; then levels=$1; shift; fi
[ "${1:-}" = "--" ] && shift
chromium=${CHROMIUM:-/usr/bin/chromium}
if [ ! -x "$chromium" ]; then echo "SKIP: no $chromium (apt-get install chromium)"; exit 77; fi
if ! node -e 'process.exit(Number(process.versions.node.split(".")[0]) >= 20 ? 0 : 1)'; then
  echo "SKIP: Node.js >= 20 needed by playwright-core"; exit 77
fi
if [ ! -d "$web/node_modules/playwright-core" ]; then
  echo "SKIP: run scripts/setup.sh first (web/node_modules)"; exit 77
fi
mkdir -p "$out"
mesh_args=()
if [ -n "$mesh" ]; then
  if [ ! -f "$mesh" ]; then echo "SKIP: no $mesh (the shared test meshes)"; exit 77; fi
  if [ "$levels" -gt 0 ]; then
    refined="$out/$(basename "${mesh%.*}")-l$levels.obj"
    "$bin" subdivide "$mesh" -o "$refined" -l "$levels" >/dev/null || exit 1
    mesh=$refined
  fi
  mesh_args=(--mesh "$mesh")
fi
exec node "$web/e2e/${E2E_SCRIPT:-editor.e2e.mjs}" --binary "$bin" --chromium "$chromium" --out "$out" \
  "${mesh_args[@]}" "$@"
