"""The specdeform Python package, built by CMake (pyproject.toml's setuptools backend runs this).

    pip install .                                    # where PyPI is reachable
    pip install --no-build-isolation .               # with Debian's python3-setuptools and -wheel
    python3 -m build --wheel --no-isolation          # a wheel in dist/ (python3-build)

build_ext configures and builds the extension module alone (the core library, no program, tests
or editor) for the running Python in build/python-<tag>, or in SPECDEFORM_CMAKE_BUILD_DIR (a
build of this checkout for the same Python, which then only relinks what changed), and copies the
native libraries it needs beyond glibc and libstdc++ into specdeform.libs beside the package
(scripts/bundle_libs.py, as auditwheel does), so that the wheel needs no Debian SuiteSparse,
OpenBLAS or tinygltf. The wheel is tagged manylinux_<glibc>_x86_64 for the glibc it was built
against: it installs there and on newer systems.
"""

import os
import platform
import re
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext
from wheel.bdist_wheel import bdist_wheel

root = Path(__file__).resolve().parent


(root / "build" / "setuptools").mkdir(parents=True, exist_ok=True)


def project_version():
    """cmake/version.cmake's rule: CMakeLists.txt's VERSION at a commit tagged v<VERSION>, else
    <VERSION>+g<commit>; an sdist's own (its PKG-INFO), where there is no git."""
    pkg_info = root / "PKG-INFO"
    if pkg_info.exists():
        return re.search(r"^Version: (\S+)$", pkg_info.read_text(), re.M).group(1)
    text = (root / "CMakeLists.txt").read_text()
    version = re.search(r"project\(specdeform VERSION ([0-9.]+)", text).group(1)
    git = ["git", "-C", str(root)]
    try:
        commit = subprocess.run(git + ["rev-parse", "--short=8", "HEAD"], check=True,
                                capture_output=True, text=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return version
    tagged = subprocess.run(git + ["describe", "--tags", "--exact-match", "--match",
                                   f"v{version}", "HEAD"], capture_output=True).returncode == 0
    return version if tagged else f"{version}+g{commit}"


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        tag = sys.implementation.cache_tag
        build_dir = Path(os.environ.get("SPECDEFORM_CMAKE_BUILD_DIR") or
                         root / "build" / f"python-{tag}").resolve()
        if not (build_dir / "CMakeCache.txt").exists():
            self._cmake("-S", root, "-B", build_dir, "-DCMAKE_BUILD_TYPE=Release",
                        f"-DPython_EXECUTABLE={sys.executable}", "-DSPECDEFORM_BUILD_SERVER=OFF",
                        "-DSPECDEFORM_BUILD_CLI=OFF", "-DSPECDEFORM_BUILD_TESTS=OFF",
                        "-DSPECDEFORM_BUILD_BENCHMARKS=OFF", "-DSPECDEFORM_BUILD_PYTHON=ON",
                        f"-DSPECDEFORM_VERSION_FULL={project_version()}")
        self._cmake("--build", build_dir, "--target", "_specdeform", "-j", str(os.cpu_count()),
                    "--", "--no-print-directory")
        suffix = sysconfig.get_config_var("EXT_SUFFIX")
        built = build_dir / "python" / "specdeform" / f"_specdeform{suffix}"
        if not built.exists():
            raise SystemExit(f"setup.py: {build_dir} has no _specdeform{suffix}: it was "
                             f"configured for another Python than {sys.executable}")
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built, target)  # always: the copy is patched below
        subprocess.run([sys.executable, root / "scripts" / "bundle_libs.py", "bundle",
                        target.parent.parent / "specdeform.libs", target], check=True)

    @staticmethod
    def _cmake(*args):
        subprocess.run(["cmake", *map(str, args)], check=True)


class ManylinuxWheel(bdist_wheel):
    def get_tag(self):
        python, abi, plat = super().get_tag()
        libc, version = platform.libc_ver()
        if plat == "linux_x86_64" and libc == "glibc":
            major, minor = version.split(".")[:2]
            plat = f"manylinux_{major}_{minor}_x86_64"
        return python, abi, plat


setup(
    version=project_version(),
    packages=["specdeform"],
    package_dir={"specdeform": "python/specdeform"},
    package_data={"specdeform": ["_specdeform.pyi", "py.typed"]},
    ext_modules=[Extension("specdeform._specdeform", sources=[])],
    cmdclass={"build_ext": CMakeBuild, "bdist_wheel": ManylinuxWheel},
    zip_safe=False,
    # setuptools' own folders (build/lib..., the egg-info) away from the CMake build in build/.
    options={"build": {"build_base": "build/setuptools"},
             "egg_info": {"egg_base": "build/setuptools"}},
)
