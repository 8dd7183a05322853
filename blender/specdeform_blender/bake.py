"""Bake: a frame range of the bound mesh to shape keys or to a PC2 point cache played by Blender's
own Mesh Cache modifier, or the current pose to one shape key, so that a Blender without the
add-on, a render farm or an exporter plays it. Baking ends the binding (the mesh back at rest)."""

import bpy
import numpy as np
from bpy.props import EnumProperty, IntProperty, StringProperty

from . import binding, mesh_helpers

CACHE_MODIFIER = "specdeform cache"


def _poses(obj, scene, frames):
    """The mesh's own coordinates at each frame (the handlers deform it, with the full details),
    float32 (f, n, 3)."""
    current = scene.frame_current
    poses = []
    with binding.final_frames():
        for frame in frames:
            scene.frame_set(frame)
            poses.append(mesh_helpers.shown(obj.data))
    scene.frame_set(current)
    return np.array(poses)


def _unbind(obj):
    rest = mesh_helpers.saved_rest(obj.data)
    binding.release(obj)
    mesh_helpers.restore(obj, rest)


def _shape_key(obj, name, co):
    if obj.data.shape_keys is None:
        obj.shape_key_add(name="Basis", from_mix=False)
    key = obj.shape_key_add(name=name, from_mix=False)
    key.data.foreach_set("co", np.ascontiguousarray(co, np.float32).ravel())
    return key


def write_pc2(path, poses, start, rate=1.0):
    """A PC2 file: the header (start frame, sample rate, samples) then float32 positions."""
    header = np.zeros(1, [("magic", "S12"), ("version", "<i4"), ("points", "<i4"),
                          ("start", "<f4"), ("rate", "<f4"), ("samples", "<i4")])
    header[0] = (b"POINTCACHE2\0", 1, poses.shape[1], start, rate, len(poses))
    with open(path, "wb") as f:
        f.write(header.tobytes())
        f.write(np.ascontiguousarray(poses, "<f4").tobytes())


def _play_cache(obj, path, start):
    """Blender's Mesh Cache modifier, first in the stack, playing `path` from frame `start`."""
    mod = obj.modifiers.get(CACHE_MODIFIER) or obj.modifiers.new(CACHE_MODIFIER, "MESH_CACHE")
    mod.cache_format, mod.filepath, mod.frame_start = "PC2", path, start
    if obj.modifiers[0] != mod:
        with bpy.context.temp_override(object=obj):
            bpy.ops.object.modifier_move_to_index(modifier=mod.name, index=0)


def _bound(context):
    obj = context.object
    return obj is not None and obj.type == "MESH" and binding.binding(obj) is not None


class SPECDEFORM_OT_bake(bpy.types.Operator):
    """Bake a frame range of the deformation to shape keys or to a point cache (PC2, played by a
    Mesh Cache modifier) and unbind"""

    bl_idname = "specdeform.bake"
    bl_label = "Bake"
    bl_options = {"REGISTER", "UNDO"}

    frame_start: IntProperty(name="Start", default=1)
    frame_end: IntProperty(name="End", default=250)
    kind: EnumProperty(
        name="Into",
        items=(
            ("POINT_CACHE", "Point cache", "A PC2 file played by a Mesh Cache modifier"),
            ("SHAPE_KEYS", "Shape keys", "One shape key per frame, keyed on at its frame only"),
        ),
        default="POINT_CACHE",
    )
    filepath: StringProperty(
        name="File", subtype="FILE_PATH", default="//specdeform.pc2",
        description="The point cache written (// is the .blend's folder)",
    )

    @classmethod
    def poll(cls, context):
        return _bound(context) and context.mode == "OBJECT"

    def invoke(self, context, _event):
        self.frame_start, self.frame_end = context.scene.frame_start, context.scene.frame_end
        return context.window_manager.invoke_props_dialog(self)

    def execute(self, context):
        if self.frame_end < self.frame_start:
            self.report({"ERROR"}, "the end frame is before the start frame")
            return {"CANCELLED"}
        obj = context.object
        frames = range(self.frame_start, self.frame_end + 1)
        poses = _poses(obj, context.scene, frames)
        if self.kind == "POINT_CACHE":
            path = bpy.path.abspath(self.filepath)
            try:
                write_pc2(path, poses, self.frame_start)
            except OSError as e:
                self.report({"ERROR"}, f"bake: {e}")
                return {"CANCELLED"}
            _unbind(obj)
            _play_cache(obj, self.filepath, self.frame_start)
        else:
            _unbind(obj)
            for frame, co in zip(frames, poses):
                _key_at(_shape_key(obj, f"specdeform {frame}", co), frame, frames)
        self.report({"INFO"}, f"baked {len(frames)} frames; the mesh is unbound")
        return {"FINISHED"}


def _key_at(key, frame, frames):
    """On (1) at its frame, off (0) at the frames beside it within the range."""
    for f, value in ((frame - 1, 0.0), (frame, 1.0), (frame + 1, 0.0)):
        if f in frames:
            key.value = value
            key.keyframe_insert("value", frame=f)


class SPECDEFORM_OT_bake_pose(bpy.types.Operator):
    """Keep the current pose as a shape key (on) over the rest shape, and unbind"""

    bl_idname = "specdeform.bake_pose"
    bl_label = "Bake Pose"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return _bound(context) and context.mode == "OBJECT"

    def execute(self, context):
        obj = context.object
        binding.finish(obj)
        pose = mesh_helpers.shown(obj.data)
        _unbind(obj)
        _shape_key(obj, "specdeform pose", pose).value = 1.0
        return {"FINISHED"}
