"""Bulk mesh access through numpy (foreach_get / foreach_set), never a loop over vertices."""

import numpy as np

REST = "specdeform_rest"  # the input coordinates of a bound mesh, saved with the .blend
# Which vertices REST holds the rest of (a boolean point attribute, all true when saved): Join
# adds vertices whose attributes Blender fills with zeros (false), which Redo gives back as a
# bound mesh; Separate carries both attributes with its vertices.
REST_SET = "specdeform_rest_set"


def coordinates(mesh):
    co = np.empty(3 * len(mesh.vertices), np.float32)
    mesh.vertices.foreach_get("co", co)
    return co.reshape(-1, 3)


def set_coordinates(mesh, co):
    mesh.vertices.foreach_set("co", np.ascontiguousarray(co, np.float32).ravel())
    mesh.update()


# On a mesh with shape keys the pose lives in a key of its own, relative to the basis, which
# holds the rest: the other keys still add their offsets on top of the pose.
POSE_KEY = "specdeform"


def pose_key(mesh):
    """The add-on's shape key, where the mesh has shape keys and it was made (Bind), or None."""
    keys = mesh.shape_keys
    return keys.key_blocks.get(POSE_KEY) if keys is not None else None


def add_pose_key(obj):
    """Bind on a mesh with shape keys: the add-on's key, a copy of the basis at value 1; the
    basis stays the active key (Edit Mode edits the rest)."""
    mesh = obj.data
    if mesh.shape_keys is None or pose_key(mesh) is not None:
        return
    active = obj.active_shape_key_index
    key = obj.shape_key_add(name=POSE_KEY, from_mix=False)
    key.relative_key = mesh.shape_keys.reference_key
    key.value = 1.0
    obj.active_shape_key_index = active


def key_names(mesh):
    """The names of the mesh's shape keys, in order (none without keys)."""
    keys = mesh.shape_keys
    return tuple(k.name for k in keys.key_blocks) if keys is not None else ()


def key_coordinates(key):
    co = np.empty(3 * len(key.data), np.float32)
    key.data.foreach_get("co", co)
    return co.reshape(-1, 3)


def relative_mix(obj):
    """The shape Blender mixes from the mesh's relative shape keys, as New Shape from Mix takes
    it: the basis plus each unmuted key's value times its offset from its relative key; None
    where Blender mixes otherwise (absolute keys, a key limited to a vertex group, a key shown
    alone)."""
    keys = obj.data.shape_keys
    blocks = list(keys.key_blocks)
    if not keys.use_relative or obj.show_only_shape_key or any(k.vertex_group for k in blocks):
        return None
    co = {k.name: key_coordinates(k) for k in blocks}
    mix = co[keys.reference_key.name].copy()
    for k in blocks[1:]:
        if not k.mute and k.value != 0:
            mix += np.float32(k.value) * (co[k.name] - co[k.relative_key.name])
    return mix


def rest_coordinates(mesh):
    """The shape the deformation starts from: the basis key's, or the mesh's own coordinates."""
    keys = mesh.shape_keys
    return coordinates(mesh) if keys is None else key_coordinates(keys.reference_key)


def shown(mesh):
    """The pose as the add-on wrote it: its key's coordinates, or the mesh's own."""
    key = pose_key(mesh)
    return coordinates(mesh) if key is None else key_coordinates(key)


def show(mesh, co):
    """Writes the pose: into the add-on's key, or the mesh's own coordinates."""
    key = pose_key(mesh)
    if key is None:
        return set_coordinates(mesh, co)
    key.data.foreach_set("co", np.ascontiguousarray(co, np.float32).ravel())
    mesh.update()


def restore(obj, rest):
    """Unbind: the add-on's key removed (the basis is the rest), or the rest written back."""
    key = pose_key(obj.data)
    if key is not None:
        obj.shape_key_remove(key)
        obj.data.update()
    else:
        set_coordinates(obj.data, rest)


def polygons(mesh):
    """The mesh's faces: the corners of each (int32 (p,)) and their vertices, face after face
    (int32 (sum,)); triangulation.triangulate makes triangles of them."""
    sizes = np.empty(len(mesh.polygons), np.int32)
    mesh.polygons.foreach_get("loop_total", sizes)
    starts = np.empty(len(mesh.polygons), np.int32)
    mesh.polygons.foreach_get("loop_start", starts)
    loops = np.empty(len(mesh.loops), np.int32)
    mesh.loops.foreach_get("vertex_index", loops)
    within = np.arange(sizes.sum()) - np.repeat(np.cumsum(sizes) - sizes, sizes)
    return sizes, loops[np.repeat(starts, sizes) + within]


def add_group_weights(vertices, index, found):
    """The weights above 0 of the vertex groups `index` maps (group index -> name) over `vertices`
    (a slice of the mesh's: Bind reads a chunk at a time), added to found[name] = (indices,
    weights). A loop over the vertices: Blender 3.4 has no bulk access to vertex group weights."""
    for v in vertices:
        for g in v.groups:
            if g.group in index and g.weight > 0:
                found[index[g.group]][0].append(v.index)
                found[index[g.group]][1].append(g.weight)


def save_rest(mesh, co):
    attribute = mesh.attributes.get(REST) or mesh.attributes.new(REST, "FLOAT_VECTOR", "POINT")
    attribute.data.foreach_set("vector", np.ascontiguousarray(co, np.float32).ravel())
    flags = mesh.attributes.get(REST_SET) or mesh.attributes.new(REST_SET, "BOOLEAN", "POINT")
    flags.data.foreach_set("value", np.ones(len(co), bool))


def rest_covers(mesh):
    """Whether the saved rest holds every vertex's (false: vertices joined since it was saved)."""
    flags = mesh.attributes.get(REST_SET)
    if flags is None:  # saved before the flags were
        return True
    values = np.empty(len(flags.data), bool)
    flags.data.foreach_get("value", values)
    return bool(values.all())


def saved_rest(mesh):
    attribute = mesh.attributes.get(REST)
    if attribute is None or len(attribute.data) != len(mesh.vertices):
        return None
    co = np.empty(3 * len(mesh.vertices), np.float32)
    attribute.data.foreach_get("vector", co)
    return co.reshape(-1, 3)


def drop_rest(mesh):
    for name in (REST, REST_SET):
        attribute = mesh.attributes.get(name)
        if attribute is not None:
            mesh.attributes.remove(attribute)
