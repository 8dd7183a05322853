#!/usr/bin/env python3
"""Makes compiled modules self-contained, as auditwheel does for manylinux wheels.

bundle LIBS_DIR ELF...   copies every shared library the ELF files need beyond the system's base
    (glibc, libstdc++, libgcc_s) into LIBS_DIR under a name unique to its content
    (libcholmod.so.3 -> libcholmod-1a2b3c4d.so.3, so that a host which loaded its own copy, such as
    Blender, keeps it), renames the copies' sonames and every NEEDED entry to match, and points
    each file's RUNPATH at LIBS_DIR through $ORIGIN. Each copy's licence goes beside it, as its
    Debian package states it: LIBS_DIR/LICENSES/<copy>.copyright (/usr/share/doc/<package>/
    copyright, the package found by dpkg -S). Needs ldd, patchelf and dpkg.
check DIR                lists each NEEDED entry of an ELF file under DIR that is neither in the
    system's base nor a file under DIR found through the file's RUNPATH, and each bundled copy
    (a library in a *.libs folder) without its licence; exit status 1 if any.
hidden ELF...            prints the system paths of the libraries `bundle` would copy (a test
    hides them to show that the bundled module loads without them).

Usage: bundle_libs.py bundle LIBS_DIR ELF... | check DIR | hidden ELF...
"""

import hashlib
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

# glibc's libraries, the dynamic loader, and the C++ and GCC runtimes: what manylinux wheels and
# Blender's Python modules may take from the system.
BASE = {
    "linux-vdso.so.1", "ld-linux-x86-64.so.2", "libc.so.6", "libm.so.6", "libmvec.so.1",
    "libpthread.so.0", "libdl.so.2", "librt.so.1", "libutil.so.1", "libresolv.so.2",
    "libstdc++.so.6", "libgcc_s.so.1",
}


def _patchelf(*args):
    patchelf = os.environ.get("PATCHELF", "patchelf")
    return subprocess.run([patchelf, *map(str, args)], check=True, capture_output=True,
                          text=True).stdout


def _needed(elf):
    return _patchelf("--print-needed", elf).split()


def _dependencies(elfs):
    """Soname -> system path of every library the files need, directly or not, beyond BASE."""
    found = {}
    for elf in elfs:
        out = subprocess.run(["ldd", str(elf)], check=True, capture_output=True, text=True).stdout
        for line in out.splitlines():
            match = re.match(r"\s*(\S+) => (\S+)", line)
            if not match or match.group(1) in BASE:
                continue
            soname, path = match.groups()
            if path == "not":
                raise SystemExit(f"bundle_libs: {elf} needs {soname}, which is not installed")
            found[soname] = Path(path)
    return found


def _unique_name(soname, path):
    digest = hashlib.sha256(path.read_bytes()).hexdigest()[:8]
    stem, so, version = soname.partition(".so")
    return f"{stem}-{digest}{so}{version}"


def bundle(libs_dir, elfs):
    libs_dir = Path(libs_dir)
    elfs = [Path(e) for e in elfs]
    dependencies = _dependencies(elfs)
    shutil.rmtree(libs_dir, ignore_errors=True)
    libs_dir.mkdir(parents=True)
    renamed = {soname: _unique_name(soname, path) for soname, path in dependencies.items()}
    copies = []
    for soname, path in dependencies.items():
        copy = libs_dir / renamed[soname]
        shutil.copyfile(path.resolve(), copy)
        copy.chmod(0o755)
        _patchelf("--set-soname", copy.name, copy)
        copies.append(copy)
    licences = libs_dir / "LICENSES"
    licences.mkdir()
    for soname, path in dependencies.items():
        shutil.copyfile(_copyright(path), licences / f"{renamed[soname]}.copyright")
    for elf in elfs + copies:
        replacements = []
        for name in _needed(elf):
            if name in renamed:
                replacements += ["--replace-needed", name, renamed[name]]
        if replacements:
            _patchelf(*replacements, elf)
        origin = os.path.relpath(libs_dir, elf.parent)
        _patchelf("--set-rpath", "$ORIGIN" if origin == "." else f"$ORIGIN/{origin}", elf)


def _copyright(path):
    """The copyright file of the Debian package that installed `path`."""
    for candidate in (path, path.resolve(), Path(str(path.resolve()).replace("/usr/lib/", "/lib/"))):
        out = subprocess.run(["dpkg", "-S", str(candidate)], capture_output=True, text=True)
        if out.returncode == 0:
            package = out.stdout.split(":")[0]
            copyright = Path("/usr/share/doc") / package / "copyright"
            if copyright.is_file():
                return copyright
    raise SystemExit(f"bundle_libs: no Debian copyright file found for {path}")


def _is_elf(path):
    with open(path, "rb") as f:
        return f.read(4) == b"\x7fELF"


def check(root):
    root = Path(root).resolve()
    problems = []
    for path in sorted(root.rglob("*")):
        if not path.is_file() or path.is_symlink() or not _is_elf(path):
            continue
        runpath = _patchelf("--print-rpath", path).strip()
        dirs = [Path(d.replace("$ORIGIN", str(path.parent))).resolve()
                for d in runpath.split(":") if d]
        for name in _needed(path):
            if name in BASE:
                continue
            inside = [d / name for d in dirs if d.is_relative_to(root)]
            if not any(candidate.is_file() for candidate in inside):
                problems.append(f"{path.relative_to(root)} needs {name}, not bundled")
        if path.parent.name.endswith(".libs") and \
                not (path.parent / "LICENSES" / f"{path.name}.copyright").is_file():
            problems.append(f"{path.relative_to(root)} has no licence in LICENSES/")
    for problem in problems:
        print(problem)
    return 1 if problems else 0


def main(argv):
    if len(argv) >= 3 and argv[0] == "bundle":
        bundle(argv[1], argv[2:])
        return 0
    if len(argv) == 2 and argv[0] == "check":
        return check(argv[1])
    if len(argv) >= 2 and argv[0] == "hidden":
        for path in sorted({p.resolve() for p in _dependencies(argv[1:]).values()}):
            print(path)
        return 0
    print(__doc__.strip().splitlines()[-1], file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
