# SPDX-License-Identifier: GPL-3.0-or-later
"""specdeform for Blender: spectral mesh deformation (Rong, Cao & Guo 2008) driven by an object.

A thin adapter over the compiled `specdeform` module: Bind computes (or loads from the cache the
CLI and the editor share) the mesh's manifold harmonics and a deformer; while bound, moving the
targets deforms the mesh through depsgraph and frame handlers, a loaded file is bound again by a
load handler, Edit Mode edits the rest shape; Unbind restores the input; Apply keeps the result;
Bake writes shape keys or a point cache. See docs/blender.md.
"""

bl_info = {
    "name": "specdeform",
    "author": "specdeform developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "View3D > Sidebar (N) > specdeform",
    "description": "Spectral mesh deformation: faster and rounder than Laplacian Deform",
    "category": "Mesh",
}

import atexit

import bpy

from . import bake, binding, handlers, operators, properties, tasks, ui

classes = (
    properties.SpecdeformHandle,
    properties.SpecdeformSettings,
    operators.SPECDEFORM_OT_bind,
    operators.SPECDEFORM_OT_unbind,
    operators.SPECDEFORM_OT_apply,
    operators.SPECDEFORM_OT_handle_add,
    operators.SPECDEFORM_OT_handle_remove,
    tasks.SPECDEFORM_OT_watch,
    bake.SPECDEFORM_OT_bake,
    bake.SPECDEFORM_OT_bake_pose,
    ui.SPECDEFORM_UL_handles,
    ui.VIEW3D_PT_specdeform,
)
_handlers = (
    (bpy.app.handlers.depsgraph_update_post, handlers.follow_targets),
    (bpy.app.handlers.frame_change_post, handlers.follow_targets),
    (bpy.app.handlers.load_post, handlers.bind_loaded),
    (bpy.app.handlers.undo_post, handlers.undone),
    (bpy.app.handlers.redo_post, handlers.undone),
    (bpy.app.handlers.save_pre, handlers.note_before_saving),
    (bpy.app.handlers.render_init, tasks.finish_all),
)


# Installed from the extension's zip as a legacy add-on (Blender 3.4's Preferences > Install, or
# 4.2's "Install legacy Add-on"), the folder is named for the extension's id: a module "specdeform"
# that hides the compiled one of the same name. An extension is always bl_ext.<repository>.<id>.
WRONG_ZIP = (
    "specdeform: this is the zip for Blender 4.2 and later (Get Extensions > Install from Disk); "
    "for Blender 3.4-4.1, remove this add-on and install "
    f"specdeform_blender-{'.'.join(map(str, bl_info['version']))}-blender-3.4-to-4.1.zip"
)


def register():
    if __name__ == "specdeform":
        raise RuntimeError(WRONG_ZIP)
    atexit.register(binding.shutdown)
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.Object.specdeform = bpy.props.PointerProperty(type=properties.SpecdeformSettings)
    for handler_list, handler in _handlers:
        handler_list.append(handler)


def unregister():
    atexit.unregister(binding.shutdown)
    for handler_list, handler in _handlers:
        handler_list.remove(handler)
    tasks.shutdown()
    binding.shutdown()
    del bpy.types.Object.specdeform
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
