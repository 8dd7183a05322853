"""Messy geometry as real tools write it (issue 52): Debian's Blender builds a scan with holes,
T-junctions, zero-area vertices and a zero-length edge (PLY, OBJ), a six-part CAD assembly (binary
STL), shells wound inside out with a fin and a pinch (OBJ) and a room of 245 pieces with collapsed
props (glTF) (tests/files/export_messy.py), beside the shared awkward files. Each goes through
what a user does: `info --basis` says whether deform works, an identity scene writes the input
byte for byte (the command line and Python), and a bend exits 0 with its handle at its target."""

import json
import pathlib
import subprocess

import numpy as np
import pytest

import specdeform
from conftest import SHARED, blender_export

MADE = ["scan.ply", "scan.obj", "cad.stl", "shells.obj", "room.glb"]
SHARED_AWKWARD = ["awkward/wallhole.obj", "awkward/multibody.stl", "awkward/soup.stl",
                  "awkward/busted.STL", "awkward/featuretype.STL", "awkward/jacked.obj"]


@pytest.fixture(scope="session")
def made(tmp_path_factory) -> pathlib.Path:
    return blender_export("export_messy.py", tmp_path_factory.mktemp("messy"))


def source(name: str, request) -> pathlib.Path:
    if name in MADE:
        return request.getfixturevalue("made") / name
    path = SHARED / name
    if not path.exists():
        pytest.skip(f"shared test mesh {name} absent")
    return path


def scene(path, tmp_path, transform):
    """The vertices within 0.15 diagonals of the highest one (along the longest axis) moved by
    `transform`, the lowest tenth fixed; in the file's numbering. Returns the scene's path, the
    mesh's vertices and the handle's mesh vertices."""
    V, F, info = specdeform.read_mesh(path, return_info=True)
    extent = V.max(axis=0) - V.min(axis=0)
    axis = int(np.argmax(extent))
    top = int(np.argmax(V[:, axis]))
    spec = {"handles": [{"around": {"vertex": int(info.vertex_to_file[top]), "radius": 0.15},
                         "transform": transform}],
            "fixed": {"lowest": 0.1, "axis": "xyz"[axis]}}
    out = tmp_path / "scene.json"
    out.write_text(json.dumps(spec))
    diagonal = float(np.linalg.norm(extent))
    handle = np.flatnonzero(np.linalg.norm(V - V[top], axis=1) <= 0.15 * diagonal)
    return out, V, info, handle, diagonal


def bend(diagonal):
    return {"translate": [0.1 * diagonal, 0.05 * diagonal, 0.0],
            "rotate": {"axis": [0, 0, 1], "degrees": 30}}


@pytest.mark.parametrize("name", MADE + SHARED_AWKWARD)
def test_info_agrees_with_deform(name, request, cli, tmp_path):
    path = source(name, request)
    info = subprocess.run([cli, "info", str(path), "--json", "--basis"], capture_output=True,
                          text=True, check=True, timeout=600)
    verdict = json.loads(info.stdout)["deform"]
    assert verdict["ok"], verdict
    V, F = specdeform.read_mesh(path)
    diagonal = float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))
    scene_path, *_ = scene(path, tmp_path, bend(diagonal))
    run = subprocess.run([cli, "deform", str(path), "--scene", str(scene_path), "-o",
                          str(tmp_path / ("out" + path.suffix))], capture_output=True, text=True,
                         timeout=600)
    assert run.returncode == 0, run.stderr


@pytest.mark.parametrize("options", [[], ["--solver", "spatial"], ["--energy", "linear"],
                                     ["--detail", "frames"],
                                     ["--laplacian", "intrinsic-delaunay"]])
@pytest.mark.parametrize("name", MADE + SHARED_AWKWARD)
def test_identity_scene_writes_the_input(name, options, request, cli, tmp_path):
    path = source(name, request)
    scene_path, *_ = scene(path, tmp_path, {"translate": [0, 0, 0]})
    out = tmp_path / ("out" + path.suffix)
    subprocess.run([cli, "deform", str(path), "--scene", str(scene_path), "-o", str(out)]
                   + options, check=True, capture_output=True, timeout=600)
    assert out.read_bytes() == path.read_bytes()


@pytest.mark.parametrize("name", MADE + SHARED_AWKWARD)
def test_python_rest_is_exact_and_a_bend_reaches_its_handle(name, request, cli, tmp_path):
    path = source(name, request)
    _, V, info, handle, diagonal = scene(path, tmp_path, {})
    d = specdeform.SpectralDeformer(*specdeform.read_mesh(path), min(60, len(V) - 1))
    fixed = np.argsort(V[:, int(np.argmax(V.max(axis=0) - V.min(axis=0)))])[:len(V) // 10]
    fixed = np.setdiff1d(fixed, handle)
    d.set_selection([handle], fixed)
    assert np.array_equal(d.solve([np.eye(4)]), V)
    scene_path, *_ = scene(path, tmp_path, bend(diagonal))
    out = tmp_path / ("out" + path.suffix)
    subprocess.run([cli, "deform", str(path), "--scene", str(scene_path), "-o", str(out)],
                   check=True, capture_output=True, timeout=600)
    s = specdeform.read_scene(scene_path, path)
    W, _ = specdeform.read_mesh(out)
    T = s.transforms[0]
    target = V[handle] @ T[:3, :3].T + T[:3, 3]
    assert np.abs(W[handle] - target).max() <= 0.01 * diagonal
