"""docs/results/pictures/blender_step1.png ... blender_step5.png: an artist's first deformation in
Blender, one screenshot a step (docs/blender.md's "first deformation in five steps"):

1. a subdivided Suzanne in Edit Mode, the top of its head selected and assigned to the vertex
   group "handle" (the Properties editor's Vertex Groups list; "fixed" holds the chin);
2. an Empty added at the handle's centre;
3. the sidebar's specdeform tab with Handle, Target and Fixed filled in;
4. Bind pressed and finished: the panel's status (basis, Bind time);
5. the Empty moved up and turned: the head follows, with its full details.

Needs a display (Xvfb: scripts/apt_install.sh xvfb), event simulation and the built add-on:

    SPECDEFORM_BLENDER_DIR=build/blender XDG_CACHE_HOME=$(mktemp -d) \\
      xvfb-run -a -s "-screen 0 1600x900x24" blender --factory-startup --enable-event-simulate \\
      --python scripts/blender_first_steps.py -- docs/results/pictures
"""

import math
import os
import sys
import tempfile

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, "..", "tests", "blender"))
import support  # noqa: E402

import bmesh  # noqa: E402
import bpy  # noqa: E402
import numpy as np  # noqa: E402
from mathutils import Euler, Vector  # noqa: E402

out = os.path.abspath(sys.argv[sys.argv.index("--") + 1])
os.makedirs(out, exist_ok=True)


def window():
    """The window, its 3D viewport's area, main region and sidebar, and the Properties editor."""
    win = bpy.context.window_manager.windows[0]
    area = next(a for a in win.screen.areas if a.type == "VIEW_3D")
    region = next(r for r in area.regions if r.type == "WINDOW")
    sidebar = next(r for r in area.regions if r.type == "UI")
    props = next(a for a in win.screen.areas if a.type == "PROPERTIES")
    return win, area, region, sidebar, props


def in_viewport():
    win, area, region, _, _ = window()
    return bpy.context.temp_override(window=win, area=area, region=region, screen=win.screen)


def click(x, y):
    win = window()[0]
    win.event_simulate(type="MOUSEMOVE", value="NOTHING", x=x, y=y)
    win.event_simulate(type="LEFTMOUSE", value="PRESS", x=x, y=y)
    win.event_simulate(type="LEFTMOUSE", value="RELEASE", x=x, y=y)


def shoot(n, x0, x1):
    """blender_step<n>.png: the window's columns x0 <= x < x1, from the timeline's top to the
    viewport's header (inclusive), saved as an 8-bit RGB PNG."""
    path = os.path.join(out, f"blender_step{n}.png")
    with in_viewport():
        bpy.ops.screen.screenshot(filepath=path)
    _, area, _, _, _ = window()
    y0, y1 = area.y, area.y + area.height
    shot = bpy.data.images.load(path)
    w, h = shot.size
    pixels = np.empty(w * h * 4, np.float32)
    shot.pixels.foreach_get(pixels)
    part = np.ascontiguousarray(pixels.reshape(h, w, 4)[y0:y1, x0:x1])
    image = bpy.data.images.new(f"step{n}", part.shape[1], part.shape[0], alpha=False)
    image.pixels.foreach_set(part.ravel())
    settings = bpy.context.scene.render.image_settings
    settings.file_format, settings.color_mode, settings.compression = "PNG", "RGB", 100
    image.save_render(path)
    bpy.data.images.remove(shot)
    print(f"wrote {path} ({os.path.getsize(path) // 1024} KB)")


def script():
    with in_viewport():  # an empty scene, saved and opened (which closes the splash screen)
        for o in list(bpy.data.objects):
            bpy.data.objects.remove(o)
        sys.modules["specdeform_blender"].register()
        bpy.ops.wm.save_as_mainfile(filepath=os.path.join(tempfile.mkdtemp(), "suzanne.blend"))
        bpy.ops.wm.open_mainfile(filepath=bpy.data.filepath)
    yield 1.0

    # Step 1: Suzanne subdivided, the top of the head "handle", the chin "fixed", in Edit Mode.
    prefs = bpy.context.preferences  # a flat background: the vignette is dithered (+40% PNG)
    prefs.use_preferences_save = False
    prefs.themes[0].view_3d.space.gradients.background_type = "SINGLE_COLOR"
    with in_viewport():
        bpy.ops.mesh.primitive_monkey_add()
        obj = bpy.context.object
        obj.modifiers.new("Subdivision", "SUBSURF").levels = 2
        bpy.ops.object.modifier_apply(modifier="Subdivision")
        bpy.ops.object.shade_smooth()
        z = np.array([v.co.z for v in obj.data.vertices])
        handle, fixed = np.flatnonzero(z > 0.55), np.flatnonzero(z < -0.4)
        obj.vertex_groups.new(name="fixed").add(fixed.tolist(), 1.0, "REPLACE")
        obj.vertex_groups.new(name="handle").add(handle.tolist(), 1.0, "REPLACE")
        obj.vertex_groups.active_index = obj.vertex_groups["handle"].index
        view = window()[1].spaces[0].region_3d  # from the front, a little right and above
        view.view_rotation = Euler((math.radians(72), 0, math.radians(28))).to_quaternion()
        bpy.ops.view3d.view_selected()
        view.view_location.z += 0.3  # room above the head for the Empty and the pose
        view.view_distance *= 1.05
        bpy.ops.object.mode_set(mode="EDIT")
        bpy.context.tool_settings.mesh_select_mode = (False, False, True)  # faces: no dots
        bm = bmesh.from_edit_mesh(obj.data)
        for f in bm.faces:
            f.select_set(False)
        for f in bm.faces:
            if all(v.co.z > 0.55 for v in f.verts):
                f.select_set(True)
        bmesh.update_edit_mesh(obj.data)
    yield 1.0  # the Properties editor has the mesh's tabs once it has redrawn
    window()[4].spaces[0].context = "DATA"
    yield 2.0
    _, area, _, _, props = window()
    shoot(1, area.x, props.x + props.width)

    # Step 2: Object Mode, an Empty at the handle's centre (drawn in front of the mesh).
    with in_viewport():
        bpy.ops.object.mode_set(mode="OBJECT")
        centre = sum((obj.data.vertices[i].co for i in handle), Vector()) / len(handle)
        bpy.ops.object.empty_add(type="ARROWS", location=obj.matrix_world @ centre)
        empty = bpy.context.object
        empty.name, empty.empty_display_size, empty.show_in_front = "Empty", 0.5, True
    yield 2.0
    _, area, _, _, _ = window()
    shoot(2, area.x, area.x + area.width)

    # Step 3: the mesh selected and active, the sidebar's specdeform tab filled in.
    empty.select_set(False)
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj
    s = obj.specdeform
    s.handle_group, s.target, s.fixed_group = "handle", empty, "fixed"
    window()[1].spaces[0].show_region_ui = True
    yield 1.0
    _, _, _, sidebar, _ = window()  # the tabs: the sidebar's right edge, Item, Tool, View, ...
    click(sidebar.x + sidebar.width - 12, sidebar.y + sidebar.height - 178)
    yield 2.0
    _, area, _, _, _ = window()
    shoot(3, area.x, area.x + area.width)

    # Step 4: Bind, run as a task in the window; its status once finished.
    with in_viewport():
        bpy.ops.specdeform.bind("INVOKE_DEFAULT")
    running = sys.modules["specdeform_blender.tasks"].all_running
    while not (bpy.data.objects[obj.name].specdeform.bound and running() == []):
        yield 1.0
    yield 2.0
    _, area, _, _, _ = window()
    shoot(4, area.x, area.x + area.width)

    # Step 5: the Empty moved up and turned; the full details after it rests.
    empty.location.z += 0.4
    empty.rotation_euler.x = math.radians(30)
    bpy.context.view_layer.update()
    yield 2.0
    while any("displacements" in line for line in support.panel_lines(obj)):
        yield 1.0
    yield 1.0
    _, area, _, _, _ = window()
    shoot(5, area.x, area.x + area.width)
    bpy.ops.wm.quit_blender()


support.run_in_window(script)
