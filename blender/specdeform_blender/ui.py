"""The sidebar (N) panel: handles, fixed group, settings, Bind / Unbind / Apply, Bake, timings and
status."""

import bpy

from . import binding, library


class SPECDEFORM_UL_handles(bpy.types.UIList):
    """The further handles: a vertex group and its target on each row."""

    def draw_item(self, context, layout, _data, item, _icon, _active_data, _active_property):
        row = layout.row(align=True)
        row.prop_search(item, "group", context.object, "vertex_groups", text="")
        row.prop(item, "target", text="")


def _status(layout, obj, s):
    b = binding.binding(obj)
    if obj.name_full in binding.problems:
        layout.label(text=binding.problems[obj.name_full], icon="ERROR")
    elif s.bound and b is None:
        layout.label(text="Bound in the file: press Bind to resume", icon="INFO")
    if b is None:
        return
    if obj.mode == "EDIT":
        layout.label(text="Edit Mode edits the rest shape;", icon="INFO")
        layout.label(text="leaving it binds again and poses it")
    st = b.status
    layout.label(text=f"Basis: {st['basis']}")
    layout.label(text=f"Residual {st['residual']:.0e}")
    layout.label(text=f"Bind {st['bind_s']:.2f} s (basis {st['basis_s']:.2f} s)")
    if "solve_ms" in st:
        layout.label(text=f"Solve {st['solve_ms']:.1f} ms, {st['iterations']} iterations")
        layout.label(text=f"Write {st['write_ms']:.1f} ms")
    if "detail" in st:
        layout.label(text=st["detail"], icon="TIME")
    if "note" in st:
        layout.label(text=st["note"], icon="INFO")
    if "error" in st:
        layout.label(text=st["error"], icon="ERROR")


class VIEW3D_PT_specdeform(bpy.types.Panel):
    bl_label = "specdeform"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "specdeform"

    @classmethod
    def poll(cls, context):
        return context.object is not None and context.object.type == "MESH"

    def draw(self, context):
        layout = self.layout
        if library.specdeform is None:
            layout.label(text=library.problem, icon="ERROR")
            return
        obj = context.object
        s = obj.specdeform
        col = layout.column()
        col.enabled = not s.bound
        col.prop_search(s, "handle_group", obj, "vertex_groups")
        col.prop(s, "target")
        row = col.row()
        row.template_list("SPECDEFORM_UL_handles", "", s, "handles", s, "handle_index", rows=2)
        buttons = row.column(align=True)
        buttons.operator("specdeform.handle_add", icon="ADD", text="")
        buttons.operator("specdeform.handle_remove", icon="REMOVE", text="")
        col.prop_search(s, "fixed_group", obj, "vertex_groups")
        col.prop(s, "modes")
        col.prop(s, "eigensolver")
        col.prop(s, "energy")
        col.prop(s, "detail")
        col.prop(s, "unconstrained", text="Free")
        col.prop(s, "constraint_weight")
        layout.prop(s, "quick_drags")
        row = layout.row(align=True)
        row.operator("specdeform.bind")
        row.operator("specdeform.unbind")
        row.operator("specdeform.apply")
        row = layout.row(align=True)
        row.operator("specdeform.bake")
        row.operator("specdeform.bake_pose")
        _status(layout, obj, s)
