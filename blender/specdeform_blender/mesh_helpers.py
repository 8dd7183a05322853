"""Bulk mesh access through numpy (foreach_get / foreach_set), never a loop over vertices."""

import numpy as np

REST = "specdeform_rest"  # the input coordinates of a bound mesh, saved with the .blend


def coordinates(mesh):
    co = np.empty(3 * len(mesh.vertices), np.float32)
    mesh.vertices.foreach_get("co", co)
    return co.reshape(-1, 3)


def set_coordinates(mesh, co):
    mesh.vertices.foreach_set("co", np.ascontiguousarray(co, np.float32).ravel())
    mesh.update()


def triangles(mesh):
    """The mesh's faces triangulated (Blender's loop triangles): vertex indices (f, 3)."""
    mesh.calc_loop_triangles()
    tris = np.empty(3 * len(mesh.loop_triangles), np.int32)
    mesh.loop_triangles.foreach_get("vertices", tris)
    return tris.reshape(-1, 3)


def group_weights(obj, names):
    """{name: (vertex indices, weights)} of the vertex groups `names`, weights above 0 (one loop
    over the vertices, at Bind only: Blender 3.4 has no bulk access to vertex group weights)."""
    index = {obj.vertex_groups[name].index: name for name in names}
    found = {name: ([], []) for name in names}
    for v in obj.data.vertices:
        for g in v.groups:
            if g.group in index and g.weight > 0:
                found[index[g.group]][0].append(v.index)
                found[index[g.group]][1].append(g.weight)
    return {name: (np.array(i, np.int64), np.array(w)) for name, (i, w) in found.items()}


def save_rest(mesh, co):
    attribute = mesh.attributes.get(REST) or mesh.attributes.new(REST, "FLOAT_VECTOR", "POINT")
    attribute.data.foreach_set("vector", np.ascontiguousarray(co, np.float32).ravel())


def saved_rest(mesh):
    attribute = mesh.attributes.get(REST)
    if attribute is None or len(attribute.data) != len(mesh.vertices):
        return None
    co = np.empty(3 * len(mesh.vertices), np.float32)
    attribute.data.foreach_get("vector", co)
    return co.reshape(-1, 3)


def drop_rest(mesh):
    attribute = mesh.attributes.get(REST)
    if attribute is not None:
        mesh.attributes.remove(attribute)
