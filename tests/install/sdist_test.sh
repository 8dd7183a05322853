#!/usr/bin/env bash
# The source distribution (issue 55): `python3 -m build --sdist --no-isolation` makes it from the
# checkout; it carries what a wheel needs (CMakeLists.txt, cmake, include, src, python, blender,
# scripts/bundle_libs.py), the licence and the changelog, and the program's version; CMake
# configures the module's build from it alone (every file it names is there: what
# `python3 -m build --no-isolation` then compiles).
# Usage: sdist_test.sh BUILD_DIR SOURCE_DIR WORK_DIR
set -euo pipefail
build=$1 source=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*" >&2; exit 1; }

echo "-- python3 -m build --sdist"
/usr/bin/python3 -m build --sdist --no-isolation -o "$work" "$source" >"$work/build.log" 2>&1 ||
  { tail -20 "$work/build.log"; fail "python3 -m build --sdist"; }
sdist=$(ls "$work"/specdeform-*.tar.gz) || fail "no sdist"
version=$("$build"/bin/specdeform --version | cut -d' ' -f2)
[ "$(basename "$sdist")" = "specdeform-$version.tar.gz" ] || fail "$(basename "$sdist") is not $version"
tar xzf "$sdist" -C "$work"
tree="$work/specdeform-$version"
for f in CMakeLists.txt LICENSE CHANGELOG.md README.md setup.py pyproject.toml PKG-INFO \
         cmake/version.cmake cmake/deb/copyright.in include/specdeform/version.h \
         src/version.cpp.in src/mesh/formats/gltf/gltf_rig.cpp python/src/module.cpp \
         python/specdeform/__init__.py blender/specdeform_blender/__init__.py \
         scripts/bundle_libs.py; do
  [ -e "$tree/$f" ] || fail "the sdist lacks $f"
done
grep -qx "Version: $version" "$tree/PKG-INFO" || fail "PKG-INFO's version is not $version"
grep -qx "License: GPL-3.0-or-later" "$tree/PKG-INFO" || fail "PKG-INFO names no licence"

echo "-- CMake configures the module's build from the sdist alone"
cmake -S "$tree" -B "$work/configured" -DSPECDEFORM_BUILD_SERVER=OFF -DSPECDEFORM_BUILD_CLI=OFF \
  -DSPECDEFORM_BUILD_TESTS=OFF -DSPECDEFORM_BUILD_BENCHMARKS=OFF -DSPECDEFORM_BUILD_PYTHON=ON \
  -DSPECDEFORM_VERSION_FULL="$version" -DPython_EXECUTABLE=/usr/bin/python3 \
  >"$work/cmake.log" 2>&1 || { tail -20 "$work/cmake.log"; fail "cmake from the sdist"; }
grep -q "specdeform $version" "$work/cmake.log" || fail "the sdist's build does not say $version"
echo "the sdist $(basename "$sdist") ($(du -k "$sdist" | cut -f1) KiB) configures"
