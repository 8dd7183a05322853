"""Mesh files and mesh arrays: reading, writing, and the rejection of bad arrays."""

import errno

import numpy as np
import pytest

import specdeform
from conftest import shared_file


@pytest.mark.parametrize("extension", [".obj", ".off", ".ply", ".stl"])
def test_write_then_read_gives_the_mesh_back(tmp_path, bar, extension):
    V, F = bar
    path = tmp_path / f"bar{extension}"
    specdeform.write_mesh(path, V, F)
    V2, F2 = specdeform.read_mesh(path)
    assert F2.dtype == np.int32 and F2.shape == F.shape
    # STL stores float32 and welds the corners back into vertices in the order it meets them.
    tolerance = 1e-6 if extension == ".stl" else 0.0
    np.testing.assert_allclose(V2[F2], V[F], atol=tolerance, rtol=0)


def test_read_mesh_maps_back_to_the_file(tmp_path):
    # Vertex 1 is used by no face: dropped, and written back in its place with info.
    path = tmp_path / "t.off"
    path.write_text("OFF\n5 2 0\n0 0 0\n9 9 9\n1 0 0\n0 1 0\n1 1 0\n3 0 2 3\n3 2 4 3\n")
    V, F, info = specdeform.read_mesh(path, return_info=True)
    assert len(V) == 4 and info.unused_vertices == 1 and info.file_faces == 2
    np.testing.assert_array_equal(info.vertex_to_file, [0, 2, 3, 4])
    np.testing.assert_array_equal(info.file_vertices[1], [9, 9, 9])
    out = tmp_path / "out.off"
    specdeform.write_mesh(out, V + 1, F, info=info)
    V2, F2, info2 = specdeform.read_mesh(out, return_info=True)
    np.testing.assert_array_equal(info2.file_vertices[[0, 2, 3, 4]], V + 1)
    np.testing.assert_array_equal(info2.file_vertices[1], [9, 9, 9])


def test_kept_file_comes_back_with_new_positions(tmp_path):
    # A quad with texture coordinates, a normal, a material and a comment: written back with
    # V moved, every other line as it was; its polygons and attributes readable.
    text = ("# quad\nmtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 1\n"
            "vn 0 0 1\nusemtl red\nf 1/1/1 2/2/1 3/2/1 4/1/1\n")
    path = tmp_path / "quad.obj"
    path.write_text(text)
    V, F, file = specdeform.read_mesh(path, keep=True)
    assert F.shape == (2, 3) and file.format == "OBJ"
    np.testing.assert_array_equal(file.offsets, [0, 4])
    np.testing.assert_array_equal(file.corner_uv, [0, 1, 1, 0])
    assert file.summary()["polygons_by_corners"] == {4: 1}
    assert file.summary()["materials"] == ["red"]
    out = tmp_path / "out.obj"
    assert file.write(out, V) == []
    assert out.read_text() == text
    turn = np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]])  # a quarter turn about z
    file.write(out, V @ turn.T, normals="recompute")
    lines = out.read_text().split("\n")
    assert [l for l in lines if not l.startswith("v ")] == [
        l for l in text.split("\n") if not l.startswith("v ")]
    V2, F2, back = specdeform.read_mesh(out, keep=True)
    np.testing.assert_allclose(V2, V @ turn.T, atol=1e-7)
    np.testing.assert_allclose(back.normals, [[0, 0, 1]])
    # Another format: what it cannot hold is said.
    notes = file.write(tmp_path / "out.stl", V)
    assert "texture coordinates" in notes[0] and "materials" in notes[0]
    with pytest.raises(specdeform.InputError, match="rows"):
        file.write(out, V[:3])
    with pytest.raises(specdeform.InputError, match="normals"):
        file.write(out, V, normals="sideways")


def test_shared_mesh_reads(tmp_path):
    V, F = specdeform.read_mesh(shared_file("models/cow.off"))
    assert V.shape == (2762, 3) and F.shape == (5520, 3)


def test_generated_meshes_have_their_documented_sizes():
    assert specdeform.icosphere(2)[0].shape == (162, 3)
    V, F = specdeform.torus(major_segments=12, minor_segments=6)
    assert V.shape == (72, 3) and F.shape == (144, 3)
    V, F = specdeform.bumpy_plane(resolution=4, bump_height=0)
    assert V.shape == (25, 3) and np.all(V[:, 2] == 0)


def test_missing_file_is_an_os_error(tmp_path):
    with pytest.raises(FileNotFoundError) as e:
        specdeform.read_mesh(tmp_path / "missing.off")
    assert e.value.errno == errno.ENOENT and e.value.filename.endswith("missing.off")
    with pytest.raises(IsADirectoryError):
        specdeform.read_mesh(tmp_path)


def test_unwritable_place_is_an_os_error(tmp_path, bar):
    with pytest.raises(FileNotFoundError):
        specdeform.write_mesh(tmp_path / "missing" / "bar.off", *bar)
    (tmp_path / "file").write_text("")
    with pytest.raises(NotADirectoryError):
        specdeform.write_mesh(tmp_path / "file" / "bar.off", *bar)
    with pytest.raises(specdeform.InputError, match="unknown mesh format '.abc'"):
        specdeform.write_mesh(tmp_path / "bar.abc", *bar)


def test_malformed_file_is_an_input_error(tmp_path):
    path = tmp_path / "trunc.off"
    path.write_text("OFF\n3 1 0\n0 0 0\n1 0 0\n")
    with pytest.raises(specdeform.InputError, match="trunc.off"):
        specdeform.read_mesh(path)
    assert issubclass(specdeform.InputError, ValueError)
    assert issubclass(specdeform.InputError, specdeform.Error)
    assert issubclass(specdeform.SolverError, RuntimeError)


def test_float_faces_are_refused_not_truncated(bar):
    V, F = bar
    with pytest.raises(specdeform.InputError, match="integer"):
        specdeform.cotan_stiffness(V, F.astype(float))
    with pytest.raises(specdeform.InputError, match="integer"):
        specdeform.cotan_stiffness(V, F + 0.5)


@pytest.mark.parametrize(
    "change, message",
    [
        (lambda V, F: (V[:, :2], F), r"V: expected an \(n, 3\) array, got shape \(2594, 2\)"),
        (lambda V, F: (V, F[:, :2]), r"F: expected an \(f, 3\)"),
        (lambda V, F: (V.ravel(), F), r"shape \(7782,\)"),
        (lambda V, F: (V.astype(complex), F), "real numbers"),
        (lambda V, F: (np.where(V == V.max(), np.nan, V), F), "not finite"),
        (lambda V, F: (V, np.where(F == 0, len(V), F)), "index 2594 out of range"),
        (lambda V, F: (V, np.where(F == 0, -1, F)), "index -1 out of range"),
        (lambda V, F: (V, np.where(F == 0, 2**40, F)), "index 1099511627776 out of range"),
        (lambda V, F: (V, np.where(F == 0, np.uint64(2**64 - 1), F.astype(np.uint64))), "range"),
        (lambda V, F: (V, F[:0]), "no faces"),
        (lambda V, F: ([[0, 0, 0], [1, 0]], F), "not convertible"),
        (lambda V, F: ("V", F), "V: expected an"),
    ],
)
def test_bad_arrays_are_refused_with_a_clear_message(bar, change, message):
    V, F = change(*bar)
    with pytest.raises(specdeform.InputError, match=message):
        specdeform.mass_matrix(V, F)


def test_any_layout_and_integer_type_is_read_in_place_or_converted(bar):
    V, F = bar
    K = specdeform.cotan_stiffness(V, F)
    wide = np.zeros((len(V), 6))
    wide[:, ::2] = V
    for V2, F2 in [
        (np.ascontiguousarray(V), F.astype(np.int64)),
        (np.asfortranarray(V), F.astype(np.uint16)),
        (wide[:, ::2], np.asfortranarray(F)),  # strided
        (V.astype(np.float32).astype(np.float64), F.tolist()),  # lists
    ]:
        assert abs(specdeform.cotan_stiffness(V2, F2) - specdeform.cotan_stiffness(V2, F)).max() == 0
    # Negative strides: the mesh numbered backwards.
    n = len(V)
    reversed_K = specdeform.cotan_stiffness(V[::-1], n - 1 - F)
    assert abs(reversed_K[::-1, ::-1] - K).max() == 0
