"""Files made by real tools, written back whole: Debian's Blender exports the shared models
(tests/files/export_assets.py: glTF with seams, OBJ + MTL with a texture, PLY with colours, quads
and n-gons, a hard-edged part), and the shared glTF samples (a photogrammetry scan, a Blender
export with a node hierarchy). Nothing moved, every file comes back byte for byte; deformed from
the command line with default options, every line, property or byte but the positions and normals
is the input's, the positions are the deformation's, and no seam opens."""

import json
import pathlib
import shutil
import struct
import subprocess
import sys

import numpy as np
import pytest

import specdeform
from conftest import ROOT, SHARED, blender_export

BLENDER_FILES = ["spot.obj", "spot.glb", "spot_colors.ply", "spot_colors.glb", "beast.obj",
                 "beast.glb", "cad_part.obj", "cad_part.glb"]
SHARED_FILES = ["gltf/polycam-scan.glb", "gltf/blender-monkey-display.glb",
                "awkward/quadknot.obj", "awkward/fuze.ply", "awkward/fuze_ascii.ply",
                "awkward/teapot.stl", "models/cow.off"]


@pytest.fixture(scope="session")
def assets(tmp_path_factory) -> pathlib.Path:
    if not (SHARED / "models" / "spot.obj").exists():
        pytest.skip("the shared test meshes are absent")
    return blender_export("export_assets.py", tmp_path_factory.mktemp("blender"),
                          str(SHARED.parent))


def source(name: str, request) -> pathlib.Path:
    """A file Blender exported (made once per session) or a shared one."""
    if name in BLENDER_FILES:
        return request.getfixturevalue("assets") / name
    path = SHARED / name
    if not path.exists():
        pytest.skip(f"shared test mesh {name} absent")
    return path


@pytest.mark.parametrize("name", BLENDER_FILES + SHARED_FILES)
def test_nothing_moved_gives_the_same_file(name, request, tmp_path):
    path = source(name, request)
    V, F, file = specdeform.read_mesh(path, keep=True)
    out = tmp_path / path.name
    file.write(out, V)
    assert out.read_bytes() == path.read_bytes()


# ------------------------------------------------------------------ deformed by the CLI

def scene_for(V, F, info, tmp_path) -> pathlib.Path:
    """A bend as users make one: the vertices around the highest one (along the longest axis)
    moved by a tenth of the diagonal and turned 30 degrees, the lowest tenth fixed; in the file's
    numbering."""
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
             "fixed": {"lowest": 0.1, "axis": "xyz"[axis]},
             "settings": {"modes": 60}}
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(scene))
    return path


def deformed(cli, path, tmp_path, suffix=None):
    """The CLI's deform of `path` by scene_for(); the expected positions by the Python binding
    (file numbering), the output file and the scene."""
    V, F, file = specdeform.read_mesh(path, keep=True)
    scene_path = scene_for(V, F, file.info, tmp_path)
    out = tmp_path / ("out" + (suffix or path.suffix))
    subprocess.run([cli, "deform", str(path), "--scene", str(scene_path), "-o", str(out)],
                   check=True, capture_output=True, timeout=600)
    s = specdeform.read_scene(scene_path, path)
    d = specdeform.SpectralDeformer(s.V, s.F, s.modes, **s.options)
    d.set_selection(s.handles, s.fixed)
    X = d.solve(s.transforms)
    expected = file.info.file_vertices.copy()
    used = file.info.file_to_vertex >= 0
    expected[used] = X[file.info.file_to_vertex[used]]
    return expected, out, s, X


def obj_lines(text):
    return text.split("\n")


@pytest.mark.parametrize("name", ["spot.obj", "beast.obj", "cad_part.obj",
                                  "awkward/quadknot.obj"])
def test_deformed_obj_keeps_every_other_line(name, request, cli, tmp_path):
    path = source(name, request)
    expected, out, _, _ = deformed(cli, path, tmp_path)
    a, b = obj_lines(path.read_text()), obj_lines(out.read_text())
    assert len(a) == len(b)
    positions, normals = [], []
    for line_in, line_out in zip(a, b):
        if line_in.startswith("v "):
            assert line_out.startswith("v ")
            assert line_in.split()[4:] == line_out.split()[4:]  # colours after v kept
            positions.append([float(x) for x in line_out.split()[1:4]])
        elif line_in.startswith("vn "):
            normals.append([float(x) for x in line_out.split()[1:4]])
        else:
            assert line_in == line_out
    positions = np.array(positions)
    diagonal = np.linalg.norm(expected.max(0) - expected.min(0))
    assert np.abs(positions - expected).max() < 1e-6 * diagonal
    if normals:
        # Every vn within 90 degrees of the deformed normal of each face that uses it, where it
        # was at rest (a file may hold faces turned against their normals: the beast has some).
        assert (vn_agreement(b) > 0)[vn_agreement(a) > 0].all()


def vn_agreement(lines):
    """Per face corner that names a vn: the cosine between it and its face's normal (Newell)."""
    P = np.array([[float(x) for x in l.split()[1:4]] for l in lines if l.startswith("v ")])
    N = np.array([[float(x) for x in l.split()[1:4]] for l in lines if l.startswith("vn ")])
    out = []
    for line in lines:
        if not line.startswith("f "):
            continue
        ids = [[int(x) if x else 0 for x in c.split("/")] for c in line.split()[1:]]
        p = P[[i[0] - 1 if i[0] > 0 else len(P) + i[0] for i in ids]]
        n = np.cross(p - p.mean(0), np.roll(p, -1, 0) - p.mean(0)).sum(0)
        n /= max(np.linalg.norm(n), 1e-300)
        for i in ids:
            if len(i) == 3 and i[2] != 0:
                out.append(N[i[2] - 1 if i[2] > 0 else len(N) + i[2]] @ n)
    return np.array(out)


def glb_chunks(path):
    data = pathlib.Path(path).read_bytes()
    length = struct.unpack_from("<I", data, 12)[0]
    bin_length = struct.unpack_from("<I", data, 20 + length)[0]
    return json.loads(data[20:20 + length]), data[28 + length:28 + length + bin_length]


def rewritten_bytes(gltf):
    """The byte ranges of every drawn triangle primitive's POSITION, NORMAL and TANGENT."""
    mask = set()
    for mesh in gltf["meshes"]:
        for p in mesh["primitives"]:
            for key in ("POSITION", "NORMAL", "TANGENT"):
                if key not in p["attributes"]:
                    continue
                a = gltf["accessors"][p["attributes"][key]]
                view = gltf["bufferViews"][a["bufferView"]]
                size = {"VEC3": 12, "VEC4": 16}[a["type"]]
                start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
                stride = view.get("byteStride", size)
                for i in range(a["count"]):
                    mask.update(range(start + i * stride, start + i * stride + size))
    return mask


@pytest.mark.parametrize("name", ["spot.glb", "spot_colors.glb", "beast.glb", "cad_part.glb",
                                  "gltf/polycam-scan.glb", "gltf/blender-monkey-display.glb"])
def test_deformed_gltf_rewrites_positions_normals_tangents_only(name, request, cli, tmp_path):
    path = source(name, request)
    expected, out, scene, X = deformed(cli, path, tmp_path)
    json_in, bin_in = glb_chunks(path)
    json_out, bin_out = glb_chunks(out)
    for gltf in (json_in, json_out):
        for a in gltf["accessors"]:
            a.pop("min", None)
            a.pop("max", None)
    assert json_in == json_out
    assert len(bin_in) == len(bin_out)
    mask = rewritten_bytes(json_in)
    outside = np.frombuffer(bin_in, np.uint8) != np.frombuffer(bin_out, np.uint8)
    outside[list(mask)] = False
    assert not outside.any()
    # The positions are the deformation's; copies of a vertex share theirs (no seam opens).
    _, _, back = specdeform.read_mesh(out, keep=True)
    W = back.info.file_vertices
    diagonal = np.linalg.norm(expected.max(0) - expected.min(0))
    assert np.abs(W - expected).max() < 1e-5 * diagonal
    rest = specdeform.read_mesh(path, keep=True)[2].info
    groups = {}
    for v, m in enumerate(rest.file_to_vertex):
        groups.setdefault(int(m), []).append(v)
    spread = max(np.abs(W[g] - W[g[0]]).max() for g in groups.values() if len(g) > 1)
    assert spread < 1e-6 * diagonal
    # The handle reached its target (the smooth base's miss is reported separately).
    T = scene.transforms[0]
    handle = scene.handles[0]
    target = scene.V[handle] @ T[:3, :3].T + T[:3, 3]
    assert np.abs(X[handle] - target).max() < 0.02 * diagonal


def ply_header(data: bytes) -> bytes:
    return data[:data.index(b"end_header\n") + 11]


@pytest.mark.parametrize("name", ["spot_colors.ply", "awkward/fuze.ply", "awkward/fuze_ascii.ply"])
def test_deformed_ply_keeps_every_other_property(name, request, cli, tmp_path):
    path = source(name, request)
    expected, out, _, _ = deformed(cli, path, tmp_path)
    data_in, data_out = path.read_bytes(), out.read_bytes()
    header = ply_header(data_in)
    assert ply_header(data_out) == header
    _, _, before = specdeform.read_mesh(path, keep=True)
    _, _, after = specdeform.read_mesh(out, keep=True)
    np.testing.assert_array_equal(before.colours, after.colours)
    np.testing.assert_array_equal(before.uv, after.uv)
    diagonal = np.linalg.norm(expected.max(0) - expected.min(0))
    assert np.abs(after.info.file_vertices - expected).max() < 1e-6 * diagonal
    if b"binary" in header:
        # Vertex records are fixed-size here: only their x y z (and normals) differ.
        lines = header.decode().split("\n")
        vertices = int(next(line for line in lines if line.startswith("element vertex")).split()[2])
        sizes = {"float": 4, "double": 8, "uchar": 1, "int": 4, "uint": 4, "short": 2}
        props = [line.split() for line in lines[lines.index(next(
            line for line in lines if line.startswith("element vertex"))) + 1:]]
        props = props[:next(i for i, p in enumerate(props) if p[0] != "property")]
        record = sum(sizes[p[1]] for p in props)
        rewritten = np.zeros(record, bool)
        at = 0
        for p in props:
            if p[2] in ("x", "y", "z", "nx", "ny", "nz"):
                rewritten[at:at + sizes[p[1]]] = True
            at += sizes[p[1]]
        a = np.frombuffer(data_in[len(header):], np.uint8)
        b = np.frombuffer(data_out[len(header):], np.uint8)
        differs = a != b
        differs[:vertices * record] &= ~np.tile(rewritten, vertices)
        assert not differs.any()


# ------------------------------------------------------------------ real glTF scenes

def gltf_transform() -> pathlib.Path:
    tool = ROOT / "web" / "node_modules" / ".bin" / "gltf-transform"
    if not tool.exists():
        pytest.skip("gltf-transform is not installed (scripts/setup.sh: npm ci in web/)")
    return tool


@pytest.fixture(scope="session")
def scenes(assets, tmp_path_factory) -> pathlib.Path:
    """Blender's scene (one mesh drawn by three nodes, a textured clear-coated material) as .glb
    and as .gltf with its buffer and texture beside it, and what glTF-Transform, the tool real
    pipelines run, makes of it: Draco (.glb and .gltf), meshopt with quantisation,
    EXT_mesh_gpu_instancing; and Blender's spot quantised. One folder a file."""
    tool = gltf_transform()
    out = tmp_path_factory.mktemp("scenes")
    for name, files in {"fleet-glb": ["fleet.glb"], "spot-glb": ["spot.glb"],
                        "fleet-gltf": ["fleet.gltf", "fleet.bin", "fleet_texture.png"]}.items():
        (out / name).mkdir()
        for f in files:
            shutil.copy(assets / f, out / name / f)
    for command, source_file, target, extra in [
            ("draco", "fleet-glb/fleet.glb", "draco-glb/fleet.glb", []),
            ("draco", "fleet-gltf/fleet.gltf", "draco-gltf/fleet.gltf", []),
            ("meshopt", "fleet-glb/fleet.glb", "meshopt/fleet.glb", []),
            ("instance", "fleet-glb/fleet.glb", "instanced/fleet.glb", ["--min", "2"]),
            ("quantize", "spot-glb/spot.glb", "quantized/spot.glb", [])]:
        (out / target).parent.mkdir(exist_ok=True)
        subprocess.run([str(tool), command, str(out / source_file), str(out / target), *extra],
                       check=True, capture_output=True, timeout=300)
    return out


SCENES = ["fleet-glb/fleet.glb", "fleet-gltf/fleet.gltf", "draco-glb/fleet.glb",
          "draco-gltf/fleet.gltf", "meshopt/fleet.glb", "instanced/fleet.glb", "quantized/spot.glb"]


@pytest.mark.parametrize("name", SCENES)
def test_scene_comes_back_whole_and_valid(name, scenes, cli, tmp_path):
    """scripts/try_assets.py's checks: info and a bend exit 0; every file the output names is
    beside it; no seam opens; no Khronos validator code the input lacks; nothing moved gives the
    same bytes; the other container keeps the document; two outputs in one folder stay apart."""
    sys.path.insert(0, str(ROOT / "scripts"))
    import try_assets
    result = try_assets.try_file(cli, scenes / name, tmp_path)
    assert result["problems"] == []


def test_scene_drawings_get_their_own_accessors(scenes, cli, tmp_path):
    """The three cows share one mesh; bent, each gets its own POSITION, NORMAL and TANGENT in a
    mesh of its own where it came out different, while indices, texture coordinates and the
    material stay shared; the instanced file keeps its nodes' instancing only where it could."""
    path = scenes / "fleet-glb" / "fleet.glb"
    V, F, file = specdeform.read_mesh(path, keep=True)
    assert file.summary()["drawings"] == 3
    out = tmp_path / "out.glb"
    scene = scene_for(V, F, file.info, tmp_path)
    run = subprocess.run([cli, "deform", str(path), "--scene", str(scene), "-o", str(out)],
                         check=True, capture_output=True, text=True, timeout=600)
    assert "meshes copied for the nodes that draw them" in run.stderr
    before, _ = glb_chunks(path)
    after, _ = glb_chunks(out)
    meshes = [n["mesh"] for n in after["nodes"] if "mesh" in n]
    assert len(set(meshes)) > 1
    attributes = [after["meshes"][m]["primitives"][0] for m in meshes]
    assert len({a["attributes"]["POSITION"] for a in attributes}) == len(set(meshes))
    assert len({a["attributes"]["TEXCOORD_0"] for a in attributes}) == 1
    assert len({a["indices"] for a in attributes}) == 1
    assert after["materials"] == before["materials"]
    # Instanced: the bend moves the instances apart, so the node draws them as children.
    path = scenes / "instanced" / "fleet.glb"
    out = tmp_path / "instanced.glb"
    run = subprocess.run([cli, "deform", str(path), "--scene", str(scene), "-o", str(out)],
                         check=True, capture_output=True, text=True, timeout=600)
    assert "EXT_mesh_gpu_instancing" in glb_chunks(path)[0]["extensionsUsed"]
    assert "one child node per instance" in run.stderr
