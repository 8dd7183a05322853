"""Bind, Unbind, Apply, and the handle list's Add and Remove."""

import bpy

from . import binding, library, mesh_helpers, preparing, tasks


def _poll_mesh(context):
    obj = context.object
    return library.specdeform is not None and obj is not None and obj.type == "MESH"


class SPECDEFORM_OT_bind(tasks.Watcher, bpy.types.Operator):
    """Compute (or load from the cache) the mesh's harmonics and follow the target"""

    bl_idname = "specdeform.bind"
    bl_label = "Bind"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        obj = context.object
        ready = _poll_mesh(context) and context.mode == "OBJECT" and tasks.running(obj) is None
        return ready and binding.binding(obj) is None  # greyed out while bound

    def execute(self, context):
        return self._said(preparing.bind_now(context.object))

    def invoke(self, context, _event):
        """From the panel: a task (the window stays free), its progress in the panel, Esc to
        cancel; the operator ends with the bind (one undo step)."""
        if not tasks.in_window():
            return self.execute(context)
        self.task = tasks.start(context.object, lambda _obj, _error: None)
        return self._said(self.task.error) if self.task.finished else self.watch(context)

    def ended(self):
        return self.task.finished

    def end(self):
        return self._said(self.task.error)

    def _said(self, error):
        if error:
            self.report({"ERROR"}, error)
            return {"CANCELLED"}
        return {"FINISHED"}


class SPECDEFORM_OT_unbind(bpy.types.Operator):
    """Stop following the target and restore the input mesh"""

    bl_idname = "specdeform.unbind"
    bl_label = "Unbind"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return _poll_mesh(context) and context.object.specdeform.bound

    def execute(self, context):
        obj = context.object
        tasks.cancel(obj)
        rest = mesh_helpers.saved_rest(obj.data)
        if rest is None:
            self.report({"ERROR"}, "the input coordinates are gone (the mesh was edited)")
            return {"CANCELLED"}
        binding.release(obj)
        mesh_helpers.restore(obj, rest)
        return {"FINISHED"}


class SPECDEFORM_OT_apply(bpy.types.Operator):
    """Keep the deformed mesh as the mesh's own coordinates and stop following the target"""

    bl_idname = "specdeform.apply"
    bl_label = "Apply"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return _poll_mesh(context) and context.object.specdeform.bound

    def execute(self, context):
        obj = context.object
        tasks.finish(obj)
        binding.finish(obj)
        binding.release(obj)
        key = mesh_helpers.pose_key(obj.data)
        if key is not None:  # with shape keys the pose stays a key of its own, at value 1
            key.name = "specdeform pose"
        return {"FINISHED"}


class SPECDEFORM_OT_handle_add(bpy.types.Operator):
    """Add a handle: a vertex group and the object that moves it"""

    bl_idname = "specdeform.handle_add"
    bl_label = "Add Handle"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return _poll_mesh(context) and not context.object.specdeform.bound

    def execute(self, context):
        s = context.object.specdeform
        s.handles.add()
        s.handle_index = len(s.handles) - 1
        return {"FINISHED"}


class SPECDEFORM_OT_handle_remove(bpy.types.Operator):
    """Remove the selected handle of the list"""

    bl_idname = "specdeform.handle_remove"
    bl_label = "Remove Handle"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        s = context.object.specdeform if _poll_mesh(context) else None
        return s is not None and not s.bound and 0 <= s.handle_index < len(s.handles)

    def execute(self, context):
        s = context.object.specdeform
        s.handles.remove(s.handle_index)
        s.handle_index = min(s.handle_index, len(s.handles) - 1)
        return {"FINISHED"}
