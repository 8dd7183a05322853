"""Scenes in Blender for the add-on's tests and benchmark: run inside Blender, with the add-on's
folder (SPECDEFORM_BLENDER_DIR) and the compiled module (SPECDEFORM_PYTHON_DIR) on sys.path."""

import os
import sys
import traceback

for var in ("SPECDEFORM_BLENDER_DIR", "SPECDEFORM_PYTHON_DIR"):
    if os.environ.get(var):
        sys.path.insert(0, os.environ[var])

import bpy  # noqa: E402
import numpy as np  # noqa: E402
from mathutils import Matrix  # noqa: E402

import specdeform_blender  # noqa: E402
# For the tests:
from specdeform_blender import binding, editing, library, mesh_helpers  # noqa: E402, F401

SKIP = 77  # CTest's SKIP_RETURN_CODE


def shared_dir():
    path = os.environ.get("SPECDEFORM_SHARED_DIR", "")
    return path if os.path.isdir(os.path.join(path, "meshes")) else None


def fresh_file():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    if not hasattr(bpy.types.Object, "specdeform"):
        specdeform_blender.register()


def add_object(name, V, F, handle, fixed):
    """A mesh object with vertex groups `handle` and `fixed`, and an Empty `target` at the
    origin, set as its target. Returns (object, empty)."""
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(len(V))
    mesh.vertices.foreach_set("co", np.asarray(V, np.float32).ravel())
    mesh.loops.add(F.size)
    mesh.loops.foreach_set("vertex_index", np.asarray(F, np.int32).ravel())
    mesh.polygons.add(len(F))
    mesh.polygons.foreach_set("loop_start", np.arange(0, F.size, F.shape[1], dtype=np.int32))
    mesh.polygons.foreach_set("loop_total", np.full(len(F), F.shape[1], np.int32))
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    empty = bpy.data.objects.new(name + "-target", None)
    for o in (obj, empty):
        bpy.context.scene.collection.objects.link(o)
    for group, members in (("handle", handle), ("fixed", fixed)):
        obj.vertex_groups.new(name=group).add([int(i) for i in members], 1.0, "REPLACE")
    bpy.context.view_layer.objects.active = obj
    s = obj.specdeform
    s.handle_group, s.fixed_group, s.target = "handle", "fixed", empty
    return obj, empty


def bind(obj):
    bpy.context.view_layer.objects.active = obj
    assert bpy.ops.specdeform.bind() == {"FINISHED"}
    assert obj.specdeform.bound


def move(empty, T):
    empty.matrix_world = Matrix(np.asarray(T).tolist())
    bpy.context.view_layer.update()


def evaluated(obj):
    return mesh_helpers.coordinates(obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).data)


def diagonal(V):
    return float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))


def ring_ratios(rest, deformed):
    """specdeform's cross_section_ratios: the vertices sharing a rest coordinate along the longest
    axis, each ring's mean distance to its centroid after over before (rings of 8 or more)."""
    axis = int(np.argmax(rest.max(axis=0) - rest.min(axis=0)))
    _, ring, size = np.unique(rest[:, axis], return_inverse=True, return_counts=True)

    def radii(V):
        centroid = np.array([np.bincount(ring, V[:, k]) for k in range(3)]).T / size[:, None]
        return np.bincount(ring, np.linalg.norm(V - centroid[ring], axis=1)) / size

    before = radii(rest.astype(np.float64))
    keep = (size >= 8) & (before > 0)
    return radii(deformed.astype(np.float64))[keep] / before[keep]


def apply_transform(T, X):
    return X @ T[:3, :3].T + T[:3, 3]


class Layout:
    """Records what a panel's draw() asks for: bpy's UILayout exists only with a window."""

    def __init__(self, labels=None):
        self.labels = [] if labels is None else labels
        self.enabled = True

    def label(self, text="", icon="NONE"):
        self.labels.append(text)

    def row(self, **_):
        return Layout(self.labels)

    column = row

    def prop(self, *_, **__):
        pass

    prop_search = template_list = prop

    def operator(self, *_, **__):
        """The status lines follow the panel's last button: the labels before it are dropped."""
        self.labels.clear()


def panel_lines(obj, width=100000):
    """The status lines the sidebar panel shows for `obj` in a sidebar `width` pixels wide (the
    lines below its buttons)."""
    from specdeform_blender import ui

    panel = type("Panel", (), {"layout": Layout()})()
    region = type("Region", (), {"width": width})()
    context = type("Context", (), {"object": obj, "region": region,
                                   "preferences": bpy.context.preferences})()
    ui.VIEW3D_PT_specdeform.draw(panel, context)
    return panel.layout.labels


def run_in_window(script, first_interval=1.0):
    """Steps the generator `script` from a timer of Blender's window, each `yield s` waiting s
    seconds while the window handles its events; a failure is printed and Blender exits 1."""
    steps = script()

    def drive():
        try:
            return next(steps)
        except StopIteration:
            return None
        except Exception:
            traceback.print_exc()
            os._exit(1)

    bpy.app.timers.register(drive, first_interval=first_interval, persistent=True)
