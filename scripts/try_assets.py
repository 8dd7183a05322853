"""Tries the command line on a folder of mesh files as a new user would, and checks what comes
back (docs/files.md). Run with Debian's python3 and the bindings on PYTHONPATH:

    PYTHONPATH=build/python /usr/bin/python3 scripts/try_assets.py DIR [--cli build/bin/specdeform]

For every mesh file under DIR (.obj .off .ply .stl .gltf .glb): `info --json` exits 0; `deform`
with a bend (the vertices around the highest one along the longest axis moved by a tenth of the
diagonal and turned 30 degrees, the lowest tenth fixed; default options) exits 0; every file the
output names is beside it; copies of a welded position stay together (no seam opens); a glTF
output has no Khronos glTF Validator issue code of severity error or warning that its input
lacks; the output moved nothing where nothing was asked to move (identity: same bytes). Prints
one line per file and a summary; exits 1 if any check failed."""

import argparse
import json
import pathlib
import re
import subprocess
import sys
import tempfile

import numpy as np

import specdeform

ROOT = pathlib.Path(__file__).resolve().parents[1]
EXTENSIONS = {".obj", ".off", ".ply", ".stl", ".gltf", ".glb"}


def bend_scene(V, info, path):
    extent = V.max(axis=0) - V.min(axis=0)
    axis = int(np.argmax(extent))
    top = int(np.argmax(V[:, axis]))
    move = [0.0, 0.0, 0.0]
    move[(axis + 1) % 3] = 0.1 * float(np.linalg.norm(extent))
    turn = [0.0, 0.0, 0.0]
    turn[(axis + 2) % 3] = 1.0
    scene = {"handles": [{"around": {"vertex": int(info.vertex_to_file[top]), "radius": 0.1},
                          "transform": {"translate": move,
                                        "rotate": {"axis": turn, "degrees": 30}}}],
             "fixed": {"lowest": 0.1, "axis": "xyz"[axis]}}
    path.write_text(json.dumps(scene))


def validator_codes(files):
    """Per file: the set of error and warning codes, or None where it could not be validated."""
    out = subprocess.run(["node", str(ROOT / "web" / "tools" / "validate-gltf.mjs"), *map(str, files)],
                         capture_output=True, text=True, check=True, cwd=ROOT / "web").stdout
    codes = {}
    for line in out.splitlines():
        r = json.loads(line)
        codes[r["file"]] = (None if "error" in r else
                            (set(r["errors"]) | set(r["warnings"]), r["unresolved"]))
    return codes


def named_files(path):
    """The files a mesh file names beside it (relative names)."""
    suffix = path.suffix.lower()
    names = []
    if suffix == ".gltf":
        doc = json.loads(path.read_text())
        for key in ("buffers", "images"):
            for item in doc.get(key, []):
                uri = item.get("uri", "")
                if uri and not uri.startswith("data:"):
                    names.append(re.sub(r"%([0-9A-Fa-f]{2})", lambda m: chr(int(m[1], 16)), uri))
    elif suffix == ".obj":
        for line in path.read_text(errors="replace").splitlines():
            if line.startswith("mtllib "):
                mtl = line[7:].strip()
                names.append(mtl)
                mtl_path = path.parent / mtl
                if mtl_path.exists():
                    for l in mtl_path.read_text(errors="replace").splitlines():
                        words = l.strip().split()
                        if words and (words[0].startswith("map_") or words[0] in ("bump", "disp", "decal", "refl", "norm")):
                            names.append(texture_name(l.strip()))
    return names


def texture_name(line):
    """The file of an MTL texture line: the rest of the line after the options."""
    takes = {"-blendu": 1, "-blendv": 1, "-bm": 1, "-boost": 1, "-cc": 1, "-clamp": 1,
             "-imfchan": 1, "-mm": 2, "-o": 3, "-s": 3, "-t": 3, "-texres": 1, "-type": 1}
    words = line.split(" ")[1:]
    i = 0
    while i < len(words):
        w = words[i]
        if w == "":
            i += 1
            continue
        if w in takes:
            i += 1
            n = 0
            while n < takes[w] and i < len(words):
                if words[i] != "":
                    try:
                        float(words[i])
                    except ValueError:
                        if w not in ("-blendu", "-blendv", "-cc", "-clamp", "-imfchan", "-type"):
                            break
                    n += 1
                i += 1
            continue
        return " ".join(words[i:]).strip()
    return ""


def seam_spread(out, rest_info, split):
    """How far apart copies of a welded vertex came (a fraction of the diagonal): by the file's
    numbering where the output keeps it, else infinite where the output welds fewer vertices."""
    _, _, back = specdeform.read_mesh(out, keep=True)
    W = back.info.file_vertices
    if split or len(W) != len(rest_info.file_to_vertex):
        return 0.0 if back.info.welded_vertices >= rest_info.welded_vertices else float("inf")
    diagonal = float(np.linalg.norm(W.max(0) - W.min(0)))
    groups = {}
    for v, m in enumerate(rest_info.file_to_vertex):
        if m >= 0:
            groups.setdefault(int(m), []).append(v)
    spread = max((np.abs(W[g] - W[g[0]]).max() for g in groups.values() if len(g) > 1), default=0.0)
    return spread / diagonal


def gltf_json(path):
    data = path.read_bytes()
    if path.suffix.lower() == ".gltf":
        return json.loads(data)
    length = int.from_bytes(data[12:16], "little")
    return json.loads(data[20:20 + length])


def container_and_twin_checks(cli, path, scene, out, out_dir):
    """The other container keeps the document (materials, extensions, node names), validates no
    worse; a second output into the same folder leaves the first as it was."""
    problems = []
    other = out_dir / ("other" + (".gltf" if path.suffix.lower() == ".glb" else ".glb"))
    run = subprocess.run([cli, "deform", str(path), "--scene", str(scene), "-o", str(other)],
                         capture_output=True, text=True)
    if run.returncode != 0:
        return ["to the other container: " + run.stderr.strip()]
    a, b = gltf_json(out), gltf_json(other)  # the same deformation in the two containers
    for key in ("materials", "extensionsUsed", "skins", "animations", "textures", "samplers"):
        if a.get(key) != b.get(key):
            problems.append(f"the other container changed {key}")
    names = lambda d: [n.get("name") for n in d.get("nodes", [])]
    if names(b)[:len(names(a))] != names(a):
        problems.append("the other container changed the nodes")
    for name in named_files(other):
        if not (other.parent / name).exists():
            problems.append(f"the other container names {name}, which is not beside it")
    codes = validator_codes([out, other])
    if codes[str(other)] and codes[str(out)] and codes[str(other)][0] - codes[str(out)][0]:
        problems.append("the other container has new validator codes: " +
                        ", ".join(sorted(codes[str(other)][0] - codes[str(out)][0])))
    before = specdeform.read_mesh(out, keep=True)[2].info.file_vertices.copy()
    twin = out_dir / ("twin" + path.suffix)
    spec = json.loads(scene.read_text())
    spec["handles"][0]["transform"]["translate"] = [-x for x in spec["handles"][0]["transform"]["translate"]]
    scene2 = out_dir / "bend2.json"
    scene2.write_text(json.dumps(spec))
    subprocess.run([cli, "deform", str(path), "--scene", str(scene2), "-o", str(twin)],
                   capture_output=True, check=False)
    after = specdeform.read_mesh(out, keep=True)[2].info.file_vertices
    if not np.array_equal(before, after):
        problems.append("a second output into the folder changed the first")
    return problems


def try_file(cli, path, work):
    result = {"file": str(path), "problems": []}
    p = result["problems"]
    info = subprocess.run([cli, "info", "--json", str(path)], capture_output=True, text=True)
    if info.returncode != 0:
        p.append("info: " + info.stderr.strip().splitlines()[-1])
        return result
    try:
        V, F, file = specdeform.read_mesh(path, keep=True)
    except Exception as e:  # noqa: BLE001 - any refusal is reported
        p.append("read: " + str(e))
        return result
    result["vertices"] = len(V)
    out_dir = work / path.stem
    out_dir.mkdir(parents=True, exist_ok=True)
    scene = out_dir / "bend.json"
    bend_scene(V, file.info, scene)
    out = out_dir / ("out" + path.suffix)
    run = subprocess.run([cli, "deform", str(path), "--scene", str(scene), "-o", str(out)],
                         capture_output=True, text=True)
    if run.returncode != 0:
        p.append("deform: " + (run.stderr.strip().splitlines() or ["?"])[-1])
        return result
    result["notes"] = [l for l in run.stderr.splitlines() if "note" in l]
    for name in named_files(out):
        if not (out.parent / name).exists() and (path.parent / name).exists():
            p.append(f"names {name}, which is not beside it")
    split = any("meshes copied" in n or "child node" in n for n in run.stderr.splitlines())
    spread = seam_spread(out, file.info, split)
    if spread > 1e-6:
        p.append(f"a seam opened: {spread:.2e} of the diagonal")
    same = out_dir / ("same" + path.suffix)
    file.write(same, V)
    if same.read_bytes() != path.read_bytes() and path.suffix.lower() != ".gltf":
        p.append("nothing moved, yet the file came back different")
    elif path.suffix.lower() == ".gltf" and same.read_text() != path.read_text():
        p.append("nothing moved, yet the .gltf's JSON came back different")
    if path.suffix.lower() in (".gltf", ".glb"):
        p.extend(container_and_twin_checks(cli, path, scene, out, out_dir))
        codes = validator_codes([path, out])
        before, after = codes[str(path)], codes[str(out)]
        if after is None:
            p.append("the validator could not read the output")
        elif before is not None:
            new = after[0] - before[0]
            if new:
                p.append("new validator codes: " + ", ".join(sorted(new)))
            if after[1]:
                p.append("the validator could not read " + ", ".join(after[1]))
    return result


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folder", type=pathlib.Path)
    parser.add_argument("--cli", default=str(ROOT / "build" / "bin" / "specdeform"))
    parser.add_argument("--work", type=pathlib.Path, default=None,
                        help="where outputs go (default: a temporary folder)")
    args = parser.parse_args()
    files = sorted(f for f in args.folder.rglob("*") if f.suffix.lower() in EXTENSIONS)
    work = args.work or pathlib.Path(tempfile.mkdtemp(prefix="try-assets-"))
    failed = 0
    for f in files:
        r = try_file(args.cli, f, work)
        status = "ok" if not r["problems"] else "FAIL"
        failed += bool(r["problems"])
        print(f"{status:4} {f.relative_to(args.folder)} ({r.get('vertices', '?')} vertices)"
              + "".join("\n       " + x for x in r["problems"]))
    print(f"{len(files) - failed} of {len(files)} files passed; outputs in {work}")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
