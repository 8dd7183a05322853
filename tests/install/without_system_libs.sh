#!/usr/bin/env bash
# Runs COMMAND with the system's copies of the libraries MODULE needs hidden (bind-mounted
# /dev/null in a user and mount namespace), except those that Debian's numpy or the programs
# COMMAND names load themselves (Debian's Blender links OpenBLAS): a bundled copy of MODULE that
# still loads shows that it needs none of the others.
# Usage: tests/install/without_system_libs.sh MODULE COMMAND...
set -euo pipefail
module=$1
shift
here=$(cd "$(dirname "$0")" && pwd)
numpy=$(/usr/bin/python3 -c 'import numpy, os; print(os.path.dirname(numpy.__file__))')
programs=$(command -v "$1")
for arg in "${@:2}"; do
  [ -f "$arg" ] && [ -x "$arg" ] && programs+=" $arg"  # cmake -E env ... blender
done
kept=$( (find "$numpy" -name '*.so' -exec ldd {} \; ; for p in $programs; do ldd "$p" || true; done) |
       awk '/=>/ {print $3}' | xargs -r readlink -f | sort -u)
hidden=$(/usr/bin/python3 "$here/../../scripts/bundle_libs.py" hidden "$module" | grep -vxF "$kept")
[ -n "$hidden" ] || { echo "without_system_libs: nothing to hide for $module" >&2; exit 1; }
if ! unshare --map-root-user --mount true 2>/dev/null; then
  echo "without_system_libs: no user namespaces here: the system's libraries stay visible" >&2
  exec "$@"
fi
exec unshare --map-root-user --mount bash -c \
  'for f in $1; do mount --bind /dev/null "$f"; done; shift; exec "$@"' _ "$hidden" "$@"
