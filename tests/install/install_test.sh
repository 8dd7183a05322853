#!/usr/bin/env bash
# `cmake --install` as a packager and a user run it (issue 45):
#  - staged (DESTDIR, prefix /opt/specdeform): every file lands under the prefix;
#  - into a prefix P: P/bin/specdeform runs `demo` from another folder and `edit` serves the
#    installed page; a consumer project (tests/install/consumer) finds specdeform::core with
#    find_package, builds and runs, and the same through pkg-config; Debian's python3 imports
#    the installed package;
#  - into ~/.local (the README's prefix): Debian's python3 imports it with no PYTHONPATH.
# Usage: install_test.sh CMAKE BUILD_DIR SOURCE_DIR WORK_DIR
set -euo pipefail
cmake=$1 build=$2 source=$3 work=$4
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*" >&2; exit 1; }

echo "-- staged install"
DESTDIR="$work/stage" "$cmake" --install "$build" --prefix /opt/specdeform >/dev/null
outside=$(cd "$work/stage" && find . -type f -not -path './opt/specdeform/*')
[ -z "$outside" ] || fail "files outside the prefix: $outside"

echo "-- install into a prefix"
prefix="$work/prefix"
"$cmake" --install "$build" --prefix "$prefix" >/dev/null
for f in bin/specdeform lib/libspecdeform.a include/specdeform/deform/spectral_deformer.h \
         lib/cmake/specdeform/specdeformConfig.cmake lib/pkgconfig/specdeform.pc \
         share/specdeform/web/index.html; do
  [ -e "$prefix/$f" ] || fail "$f is not installed"
done

echo "-- the program from another folder"
mkdir -p "$work/elsewhere"
(cd "$work/elsewhere" && "$prefix/bin/specdeform" demo -o demo >/dev/null) || fail "demo"
ls "$work/elsewhere/demo" | grep -q . || fail "demo wrote nothing"

echo "-- edit serves the installed page (marked, to tell it from the source tree's)"
echo "<!-- installed -->" >>"$prefix/share/specdeform/web/index.html"
"$prefix/bin/specdeform" edit --port 0 --no-cache >"$work/edit.log" 2>&1 &
edit=$!
trap 'kill $edit 2>/dev/null || true' EXIT
url=
for _ in $(seq 100); do
  url=$(grep -o 'http://[^ ]*' "$work/edit.log" | head -1 || true)
  [ -n "$url" ] && break
  sleep 0.1
done
[ -n "$url" ] || fail "edit printed no address: $(cat "$work/edit.log")"
page=$(/usr/bin/python3 -c 'import sys, urllib.request; print(urllib.request.urlopen(sys.argv[1]).read().decode())' "$url")
[ "$page" = "$(cat "$prefix/share/specdeform/web/index.html")" ] || fail "edit served another page"
kill $edit

echo "-- a consumer project through find_package"
"$cmake" -S "$source/tests/install/consumer" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_BUILD_TYPE=Release >/dev/null
"$cmake" --build "$work/consumer" >/dev/null
"$work/consumer/consumer"

echo "-- the same through pkg-config"
flags=$(PKG_CONFIG_PATH="$prefix/lib/pkgconfig" pkg-config --cflags --libs specdeform)
# shellcheck disable=SC2086
c++ -std=c++20 -O1 "$source/tests/install/consumer/main.cpp" -o "$work/pkg-consumer" $flags
"$work/pkg-consumer"

echo "-- Python"
site=$(find "$prefix" -path '*site-packages/specdeform/__init__.py' -not -path '*blender*')
[ -n "$site" ] || fail "no Python package under the prefix"
(cd "$work/elsewhere" && env -u PYTHONPATH PYTHONPATH="$(dirname "$(dirname "$site")")" /usr/bin/python3 -c \
  'import specdeform; V, F = specdeform.icosphere(2); print(specdeform.manifold_harmonics(V, F, 4)[0].round(3))') \
  | grep -q "0. 2. 2. 2." || fail "the installed Python package"
[ -f "$prefix/share/specdeform/blender/specdeform_blender/__init__.py" ] || fail "no add-on"

echo "-- the README's prefix ~/.local: Debian's python3 finds the module with no PYTHONPATH"
home="$work/home"
HOME="$home" "$cmake" --install "$build" --prefix "$home/.local" --component python >/dev/null
(cd "$work/elsewhere" && env -u PYTHONPATH HOME="$home" /usr/bin/python3 -c \
  'import specdeform; print(specdeform.__file__)') | grep -q "^$home/.local/lib/python3" ||
  fail "Debian's python3 does not find the module installed under ~/.local"
echo "install: ok"
