"""The sidebar (N) panel: groups, target, settings, Bind / Unbind / Apply, timings and status."""

import bpy

from . import library, operators


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
        col.prop_search(s, "fixed_group", obj, "vertex_groups")
        col.prop(s, "target")
        col.prop(s, "modes")
        col.prop(s, "energy")
        col.prop(s, "detail")
        col.prop(s, "unconstrained")
        col.prop(s, "constraint_weight")
        row = layout.row(align=True)
        row.operator("specdeform.bind")
        row.operator("specdeform.unbind")
        row.operator("specdeform.apply")
        b = operators.binding(obj)
        if s.bound and b is None:
            layout.label(text="Bound in the file: press Bind to resume", icon="INFO")
        elif b is not None:
            st = b.status
            layout.label(text=f"Basis: {st['basis']}")
            layout.label(text=f"Residual {st['residual']:.0e}")
            layout.label(text=f"Bind {st['bind_s']:.2f} s (basis {st['basis_s']:.2f} s)")
            if "solve_ms" in st:
                layout.label(text=f"Solve {st['solve_ms']:.1f} ms, {st['iterations']} iterations")
                layout.label(text=f"Write {st['write_ms']:.1f} ms")
            if "error" in st:
                layout.label(text=st["error"], icon="ERROR")
