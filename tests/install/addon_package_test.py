"""The add-on's two zips as an artist gets them (issues 45, 55, 57): the add-on for Blender 3.4-4.1
(its folder specdeform_blender at the top) and the extension for Blender 4.2+ (one folder named
for its id, blender_manifest.toml in it: Blender 4.2 takes one folder holding the manifest), each
named for its Blenders, carry the same files; every compiled file in them needs only what they
carry or glibc, libstdc++, libgcc and libm, and each library they carry has its licence beside
it, the project's LICENSE at the top; the manifest holds to Blender's documented schema (version
1.0.0, as Blender's own `extension validate` checks it); the add-on imports its own modules
relatively, as an extension must (it is loaded as bl_ext.<repository>.specdeform).

    /usr/bin/python3 addon_package_test.py ADDON_ZIP EXTENSION_ZIP BUNDLE_LIBS_PY VERSION
"""

import ast
import re
import subprocess
import sys
import tempfile
import tomllib
import zipfile
from pathlib import Path

addon_zip, extension_zip, bundle_libs, version = sys.argv[1:5]
work = Path(tempfile.mkdtemp())
zipfile.ZipFile(addon_zip).extractall(work / "addon")
zipfile.ZipFile(extension_zip).extractall(work / "extension")
addon = work / "addon" / "specdeform_blender"

assert Path(addon_zip).name == f"specdeform_blender-{version}-blender-3.4-to-4.1.zip"
assert Path(extension_zip).name == f"specdeform-{version}-blender-4.2-and-later-linux_x64.zip"
assert [p.name for p in (work / "addon").iterdir()] == ["specdeform_blender"]
assert [p.name for p in (work / "extension").iterdir()] == ["specdeform"]
extension = work / "extension" / "specdeform"
files = sorted(str(p.relative_to(addon)) for p in addon.rglob("*") if p.is_file())
assert files == sorted(str(p.relative_to(extension)) for p in extension.rglob("*") if p.is_file())
assert "blender_manifest.toml" in files and "__init__.py" in files, files
modules = [f for f in files if f.startswith("lib/specdeform/_specdeform.cpython-311")]
assert modules, "no module for Python 3.11 (Blender 3.4 and 4.2-4.5) in the add-on"

# Every bundled library with its licence (bundle_libs.py check), the project's at the top.
for root in (addon, extension):
    assert subprocess.run([sys.executable, bundle_libs, "check", root]).returncode == 0, root
assert "GNU GENERAL PUBLIC LICENSE" in (addon / "LICENSE").read_text()

# The manifest, by the rules of Blender's extension schema 1.0.0.
manifest = tomllib.loads((extension / "blender_manifest.toml").read_text())
required = {"schema_version": str, "id": str, "version": str, "name": str, "tagline": str,
            "maintainer": str, "type": str, "blender_version_min": str, "license": list}
optional = {"blender_version_max": str, "website": str, "copyright": list, "tags": list,
            "platforms": list, "wheels": list, "permissions": dict, "build": dict}
for key, kind in required.items():
    assert isinstance(manifest.get(key), kind), f"manifest: {key} missing or not a {kind}"
for key, value in manifest.items():
    assert key in required or key in optional, f"manifest: unknown field {key}"
    assert isinstance(value, (required | optional)[key]), f"manifest: {key} is a {type(value)}"
assert manifest["schema_version"] == "1.0.0"
assert manifest["id"].isidentifier() and not manifest["id"].startswith("_"), manifest["id"]
assert manifest["id"] == extension.name, "the folder is named for the id (__init__.py's check)"
assert manifest["version"] == version, (manifest["version"], version)


def release(text):
    assert re.fullmatch(r"\d+\.\d+\.\d+", text), f"not X.Y.Z: {text}"
    return tuple(map(int, text.split(".")))


def terse(text, what):
    assert text and text == text.strip() and len(text) <= 64, f"{what}: {text!r}"
    assert text[-1].isalnum() or text[-1] in ")]}", f"{what} ends with punctuation: {text!r}"


release(manifest["version"])
terse(manifest["tagline"], "tagline")
assert manifest["type"] in {"add-on", "theme"}
assert release(manifest["blender_version_min"]) >= (4, 2, 0)
if "blender_version_max" in manifest:
    assert release(manifest["blender_version_max"]) > release(manifest["blender_version_min"])
assert manifest["license"] and all(x.startswith("SPDX:") for x in manifest["license"])
assert set(manifest.get("platforms", [])) <= {"windows-x64", "windows-arm64", "macos-x64",
                                               "macos-arm64", "linux-x64"}
assert manifest.get("platforms") == ["linux-x64"], "the module is built for x86-64 Linux only"
for key, reason in manifest.get("permissions", {}).items():
    assert key in {"files", "network", "clipboard", "camera", "microphone"}, key
    terse(reason, f"permission {key}")

# bl_info (Blender before 4.2) says the same version.
init = ast.parse((addon / "__init__.py").read_text())
bl_info = next(ast.literal_eval(n.value) for n in init.body
               if isinstance(n, ast.Assign) and n.targets[0].id == "bl_info")
assert ".".join(map(str, bl_info["version"])) == version, bl_info["version"]

# Relative imports of the add-on's own modules only.
for path in addon.glob("*.py"):
    for node in ast.walk(ast.parse(path.read_text())):
        names = [a.name for a in node.names] if isinstance(node, ast.Import) else []
        if isinstance(node, ast.ImportFrom) and node.level == 0:
            names.append(node.module)
        assert not any(n.split(".")[0] == "specdeform_blender" for n in names), path.name
print(f"passed: {len(files)} files, manifest {manifest['id']} {manifest['version']}")
