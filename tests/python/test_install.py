"""`cmake --install` (the README's system-wide install) gives a package that imports and works
without the build folder (the Blender add-on installs its own copy beside it)."""

import os
import subprocess
import sys

import pytest


def test_installed_package_imports(tmp_path):
    build, cmake = os.environ.get("SPECDEFORM_BUILD_DIR"), os.environ.get("SPECDEFORM_CMAKE")
    if not build or not cmake:
        pytest.skip("not run by ctest (SPECDEFORM_BUILD_DIR, SPECDEFORM_CMAKE)")
    subprocess.run([cmake, "--install", build], env={**os.environ, "DESTDIR": str(tmp_path)},
                   check=True, capture_output=True)
    found = list(tmp_path.rglob("specdeform/__init__.py"))
    (package,) = [p for p in found if "specdeform_blender" not in p.parts]
    site = package.parent.parent
    assert sorted(p.name for p in package.parent.iterdir() if not p.name.endswith(".so")) == [
        "__init__.py", "_scene.py", "_specdeform.pyi", "py.typed"]
    check = ("import specdeform; V, F = specdeform.icosphere(2); "
             "print(specdeform.__file__, specdeform.manifold_harmonics(V, F, 4)[0].round(3))")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    out = subprocess.run([sys.executable, "-c", check], env={**env, "PYTHONPATH": str(site)},
                         cwd=tmp_path, capture_output=True, text=True, check=True).stdout
    assert out.startswith(str(package)) and "[0. 2. 2. 2.]" in out.replace("  ", " ")
