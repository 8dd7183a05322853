"""The sidebar (N) panel: handles, fixed group, settings, Bind / Unbind / Apply, Bake, timings and
status."""

import blf
import bpy

from . import binding, library, tasks

HANDLES_LABEL = "More handles: a vertex group and its target per row"
WEIGHT_LABEL = ("Constraint weight: how firmly the handles reach their targets and the fixed "
                "vertices stay (higher: closer)")
# The room a label loses in the sidebar, in pixels at UI scale 1: the panel's margins and the
# sidebar's column of tabs (measured: a 229-pixel sidebar leaves 173 to its labels); an icon.
MARGIN_PX = 56
ICON_PX = 22


def interface_scale(context):
    """Blender's interface scale (U.dpi_fac): the system's pixel size times its DPI over 72 (the
    DPI includes the UI scale and the display's own)."""
    system = context.preferences.system
    return system.pixel_size * system.dpi / 72


def text_px(context, text):
    """The width of `text` in the panel's font (Blender's widget style, blf), in pixels."""
    blf.size(0, context.preferences.ui_styles[0].widget.points * interface_scale(context))
    return blf.dimensions(0, text)[0]


def wrap(context, text, room):
    """`text` in lines no wider than `room` pixels, measured in the panel's font (a word wider
    than that is a line of its own)."""
    lines = []
    for word in text.split():
        if lines and text_px(context, f"{lines[-1]} {word}") <= room:
            lines[-1] += f" {word}"
        else:
            lines.append(word)
    return lines or [""]


def _say(context, layout, text, icon="NONE"):
    """`text` wrapped at the sidebar's width (the first line with the icon, the others indented
    by as much): no line is cut off with "..." however narrow the sidebar."""
    width = context.region.width if context.region else 300
    room = width - interface_scale(context) * (MARGIN_PX + (ICON_PX if icon != "NONE" else 0))
    column = layout.column(align=True)
    for i, line in enumerate(wrap(context, text, room)):
        column.label(text=line, icon=icon if i == 0 else "BLANK1" if icon != "NONE" else "NONE")


class SPECDEFORM_UL_handles(bpy.types.UIList):
    """The further handles: a vertex group and its target on each row."""

    def draw_item(self, context, layout, _data, item, _icon, _active_data, _active_property):
        row = layout.row(align=True)
        row.prop_search(item, "group", context.object, "vertex_groups", text="")
        row.prop(item, "target", text="")


def _status(context, layout, obj, s):
    b = binding.binding(obj)
    task = tasks.running(obj)
    if task is not None:
        _say(context, layout, f"{task.text()}; meanwhile {task.showing} (Esc cancels)", "TIME")
        return
    if obj.name_full in binding.problems:
        _say(context, layout, binding.problems[obj.name_full], "ERROR")
    elif s.bound and b is None:
        _say(context, layout, "Bound in the file: press Bind to resume", "INFO")
    elif obj.name_full in binding.notices and not s.bound:
        _say(context, layout, binding.notices[obj.name_full], "INFO")
    if b is None:
        return
    if obj.mode == "EDIT":
        _say(context, layout, "Edit Mode edits the rest shape; leaving it binds again and "
             "poses it", "INFO")
    st = b.status
    _say(context, layout, st["basis"])
    _say(context, layout, f"Bind {st['bind_s']:.2f} s (basis {st['basis_s']:.2f} s)")
    if "solve_ms" in st:
        _say(context, layout, f"Solve {st['solve_ms']:.1f} ms, {st['iterations']} iterations; "
             f"write {st['write_ms']:.1f} ms")
    for key, icon in (("detail", "TIME"), ("note", "INFO"), ("error", "ERROR")):
        if key in st:
            _say(context, layout, st[key], icon)


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
            _say(context, layout, library.problem, "ERROR")
            return
        obj = context.object
        s = obj.specdeform
        col = layout.column()
        col.enabled = not s.bound
        col.prop_search(s, "handle_group", obj, "vertex_groups")
        col.prop(s, "target")
        _say(context, col, HANDLES_LABEL)
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
        col.prop(s, "unconstrained", text="Loose")
        col.prop(s, "constraint_weight", text="Weight")
        _say(context, col, WEIGHT_LABEL)
        layout.prop(s, "quick_drags")
        layout.prop(s, "enabled")
        layout.prop(s, "strength", slider=True)
        row = layout.row(align=True)
        row.operator("specdeform.bind")
        row.operator("specdeform.unbind")
        row.operator("specdeform.apply")
        row = layout.row(align=True)
        row.operator("specdeform.bake")
        row.operator("specdeform.bake_pose")
        _status(context, layout, obj, s)
