"""Bind, Unbind, Apply, and the handle list's Add and Remove."""

import bpy

from . import binding, library, mesh_helpers


def _poll_mesh(context):
    obj = context.object
    return library.specdeform is not None and obj is not None and obj.type == "MESH"


class SPECDEFORM_OT_bind(bpy.types.Operator):
    """Compute (or load from the cache) the mesh's harmonics and follow the target"""

    bl_idname = "specdeform.bind"
    bl_label = "Bind"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        ready = _poll_mesh(context) and context.mode == "OBJECT"
        return ready and binding.binding(context.object) is None  # greyed out while bound

    def execute(self, context):
        return self._done(binding.bind_now(context.object))

    def invoke(self, context, _event):
        """From the panel: the basis on a worker thread, progress in the status bar, Esc to
        cancel."""
        self.obj = context.object
        started = binding.start(self.obj)
        if isinstance(started, str):
            return self._done(started)
        self.r, self.job = started
        wm = context.window_manager
        wm.progress_begin(0, 100)
        self.timer = wm.event_timer_add(0.1, window=context.window)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        if event.type == "ESC":
            self.job.cancel()
        if event.type != "TIMER":
            return {"RUNNING_MODAL"}
        wm = context.window_manager
        wm.progress_update(int(100 * self.job.fraction))
        context.workspace.status_text_set(f"specdeform: {self.job.progress_text()} (Esc cancels)")
        if not self.job.done:
            return {"RUNNING_MODAL"}
        wm.event_timer_remove(self.timer)
        wm.progress_end()
        context.workspace.status_text_set(None)
        return self._done(binding.bind(self.obj, self.r, self.job))

    def _done(self, error):
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
