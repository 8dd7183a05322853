"""specdeform for Blender: spectral mesh deformation (Rong, Cao & Guo 2008) driven by an object.

A thin adapter over the compiled `specdeform` module: Bind computes (or loads from the cache the
CLI and the editor share) the mesh's manifold harmonics and a deformer; while bound, moving the
target deforms the mesh through a depsgraph handler; Unbind restores the input; Apply keeps the
result. See docs/blender.md.
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

import bpy

from . import operators, properties, ui

classes = (
    properties.SpecdeformSettings,
    operators.SPECDEFORM_OT_bind,
    operators.SPECDEFORM_OT_unbind,
    operators.SPECDEFORM_OT_apply,
    ui.VIEW3D_PT_specdeform,
)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.Object.specdeform = bpy.props.PointerProperty(type=properties.SpecdeformSettings)
    bpy.app.handlers.depsgraph_update_post.append(operators.follow_targets)
    bpy.app.handlers.load_post.append(operators.forget_bindings)


def unregister():
    bpy.app.handlers.load_post.remove(operators.forget_bindings)
    bpy.app.handlers.depsgraph_update_post.remove(operators.follow_targets)
    operators.forget_bindings()
    del bpy.types.Object.specdeform
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
