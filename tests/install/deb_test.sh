#!/usr/bin/env bash
# The Debian packages (issues 45, 55): `cpack -G DEB` makes specdeform and specdeform-dev from the
# build; their dependencies name Debian's packages (dpkg-shlibdeps; the -dev packages the CMake
# package finds); each carries a machine-readable copyright and a changelog, its version is the
# program's, and lintian finds no error; unpacked (dpkg-deb -x, as apt would lay them out under
# /), the program runs `demo` from another folder, Debian's python3 imports its module, and
# Debian's Blender lists its add-on, which loads that module.
# Usage: deb_test.sh BUILD_DIR WORK_DIR [BLENDER]
set -euo pipefail
build=$1 work=$2 blender=${3:-}
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*" >&2; exit 1; }

echo "-- cpack"
(cd "$build" && cpack -G DEB -B "$work" >/dev/null) || fail "cpack"
deb=$(ls "$work"/specdeform_*_amd64.deb) || fail "no .deb"
dev=$(ls "$work"/specdeform-dev_*_amd64.deb) || fail "no -dev .deb"
depends=$(dpkg-deb -f "$deb" Depends)
echo "Depends: $depends"
for package in libcholmod3 libopenblas0 libtinygltf2d libzip4 python3-numpy; do
  [[ $depends == *"$package"* ]] || fail "Depends lacks $package"
done
dev_depends=$(dpkg-deb -f "$dev" Depends)
for package in libeigen3-dev libcgal-dev libsuitesparse-dev libtinygltf-dev; do
  [[ $dev_depends == *"$package"* ]] || fail "specdeform-dev's Depends lacks $package"
done
version=$("$build"/bin/specdeform --version | cut -d' ' -f2)
for d in "$deb" "$dev"; do
  [ "$(dpkg-deb -f "$d" Version)" = "$version" ] || fail "$d's version is not $version"
  [[ $(dpkg-deb -f "$d" Maintainer) == *"<"*@*">" ]] || fail "$d's Maintainer has no address"
done
if command -v lintian >/dev/null; then
  errors=$(lintian "$deb" "$dev" 2>/dev/null | grep '^E:' || true)
  [ -z "$errors" ] || fail "lintian: $errors"
  echo "lintian: no error"
fi

echo "-- unpacked"
root="$work/root"
dpkg-deb -x "$deb" "$root"
dpkg-deb -x "$dev" "$root"
for f in usr/bin/specdeform usr/share/specdeform/web/index.html usr/lib/libspecdeform.a \
         usr/lib/cmake/specdeform/specdeformConfig.cmake \
         usr/share/blender/scripts/addons/specdeform_blender/__init__.py \
         usr/share/doc/specdeform/changelog.gz usr/share/doc/specdeform-dev/changelog.gz; do
  [ -e "$root/$f" ] || fail "$f is not in the packages"
done
for p in specdeform specdeform-dev; do
  head -1 "$root/usr/share/doc/$p/copyright" | grep -q copyright-format/1.0 ||
    fail "$p's copyright is not machine-readable"
done
dpkg-deb -c "$deb" | grep -q 'usr/lib/libspecdeform.a' && fail "the library is in the program's package"
[ ! -e "$root/usr/share/blender/scripts/addons/specdeform_blender/lib" ] ||
  fail "the package's add-on carries its own module"
mkdir -p "$work/elsewhere"
cd "$work/elsewhere"
"$root/usr/bin/specdeform" demo -o demo >/dev/null || fail "demo"
[ -s demo/4_deformed.obj ] || fail "demo wrote no result"
site="$root/usr/lib/python3/dist-packages"
PYTHONPATH="$site" /usr/bin/python3 -c "
import specdeform, sys
assert specdeform.__file__.startswith(sys.argv[1]), specdeform.__file__
V, F = specdeform.bumpy_bar()
print('python3 imports', specdeform.__file__)" "$site" || fail "import specdeform"

if [ -n "$blender" ]; then
  # Debian's Blender reads its system add-ons from /usr/share/blender/scripts/addons only: the
  # unpacked folder is shown to it as a user scripts folder.
  mkdir -p "$work/user_scripts"
  ln -s "$root/usr/share/blender/scripts/addons" "$work/user_scripts/addons"
  PYTHONPATH="$site" BLENDER_USER_SCRIPTS="$work/user_scripts" \
  "$blender" -b --factory-startup --python-exit-code 1 --python-expr "
import addon_utils, sys
addon_utils.enable('specdeform_blender', default_set=True, handle_error=None)
library = sys.modules['specdeform_blender.library']
assert library.specdeform is not None, library.problem
assert library.specdeform.__file__.startswith('$site'), library.specdeform.__file__
print('blender loads the add-on with', library.specdeform.__file__)
" 2>&1 | grep -E "blender loads|Error|error" || fail "the add-on in Blender"
fi
