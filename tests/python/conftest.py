"""Shared fixtures of the Python binding tests (run by ctest: see CMakeLists.txt here)."""

import os
import pathlib
import shutil
import subprocess

import numpy as np
import pytest

import specdeform

ROOT = pathlib.Path(__file__).resolve().parents[2]
# The shared test meshes beside the checkout; the tests that need them skip when absent.
SHARED = pathlib.Path(os.environ.get("SPECDEFORM_SHARED_DIR", ROOT.parent / "shared")) / "meshes"


@pytest.fixture(scope="session")
def cli() -> str:
    """The specdeform program built beside the bindings."""
    path = os.environ.get("SPECDEFORM_CLI")
    if not path:
        pytest.skip("the specdeform program is not built (SPECDEFORM_CLI)")
    return path


def shared_file(relative: str) -> pathlib.Path:
    path = SHARED / relative
    if not path.exists():
        pytest.skip(f"shared test mesh {relative} absent")
    return path


@pytest.fixture(scope="session")
def lumpy_sphere():
    """An icosphere (642 vertices) with seeded random bumps: no symmetry, so every eigenvalue is
    simple and eigenvectors compare one by one."""
    V, F = specdeform.icosphere(3)
    rng = np.random.default_rng(7)
    return V * (1 + 0.05 * rng.standard_normal((len(V), 1))), F


@pytest.fixture(scope="session")
def bar():
    """The demo model at a coarse resolution (2594 vertices)."""
    return specdeform.bumpy_bar(cells_per_unit=12)


def blender_export(script: str, out: pathlib.Path, *args: str) -> pathlib.Path:
    """Runs tests/files/`script` in Debian's Blender (`blender -b --factory-startup`), writing its
    files to `out`; skips where Blender is not installed."""
    blender = shutil.which("blender")
    if blender is None:
        pytest.skip("blender is not installed (scripts/setup.sh installs it)")
    subprocess.run([blender, "-b", "--factory-startup", "--python-exit-code", "1", "--python",
                    str(ROOT / "tests" / "files" / script), "--", str(out), *args],
                   check=True, capture_output=True, timeout=600)
    return out
