"""docs/results/pictures/blender_panel.png: the twisted bar bound in Blender, with the panel.
Needs a display (Xvfb: scripts/apt_install.sh xvfb) and event simulation:

    SPECDEFORM_BLENDER_DIR=build/blender SPECDEFORM_SHARED_DIR=../shared \\
      xvfb-run -s "-screen 0 1600x900x24" blender --factory-startup --enable-event-simulate \\
      --python scripts/blender_screenshot.py -- docs/results/pictures/blender_panel.png
"""

import math
import os
import sys
import tempfile

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, "..", "tests", "blender"))
import support  # noqa: E402

import bpy  # noqa: E402
import numpy as np  # noqa: E402
import specdeform  # noqa: E402

out = os.path.abspath(sys.argv[sys.argv.index("--") + 1])
base = os.path.join(support.shared_dir(), "meshes", "scenes", "bar-twist")
scene = specdeform.read_scene(base + ".sel", base + ".off", base + ".def")
steps = iter(range(10))


def crop(path, x0, y0, x1, y1):
    """Keeps the window's pixels x0 <= x < x1, y0 <= y < y1 (from the bottom left) of `path`."""
    shot = bpy.data.images.load(path)
    w, h = shot.size
    pixels = np.empty(w * h * 4, np.float32)
    shot.pixels.foreach_get(pixels)
    part = pixels.reshape(h, w, 4)[y0:y1, x0:x1]
    image = bpy.data.images.new("crop", part.shape[1], part.shape[0], alpha=False)
    image.pixels.foreach_set(np.ascontiguousarray(part).ravel())
    image.filepath_raw, image.file_format = path, "PNG"
    image.save()


def tick():
    win = bpy.context.window_manager.windows[0]
    area = next(a for a in win.screen.areas if a.type == "VIEW_3D")
    region = next(r for r in area.regions if r.type == "WINDOW")
    tabs = next(r for r in area.regions if r.type == "UI")
    step = next(steps)
    with bpy.context.temp_override(window=win, area=area, region=region, screen=win.screen):
        if step == 0:  # the scene built, saved and opened (which closes the splash screen)
            for o in list(bpy.data.objects):
                bpy.data.objects.remove(o)
            sys.modules["specdeform_blender"].register()
            obj, empty = support.add_object("bar", scene.V, scene.F, scene.handles[0], scene.fixed)
            empty.empty_display_type, empty.empty_display_size = "ARROWS", 0.8
            empty.location.x = scene.V[:, 0].max() + 0.3
            obj.select_set(True)
            area.spaces[0].show_region_ui = True
            bpy.ops.wm.save_as_mainfile(filepath=os.path.join(tempfile.mkdtemp(), "bar.blend"))
            bpy.ops.wm.open_mainfile(filepath=bpy.data.filepath)
        elif step == 1:
            bpy.ops.specdeform.bind("INVOKE_DEFAULT")
        elif step == 2:  # the target turned by 135 degrees, as the scene's transform
            bpy.data.objects["bar-target"].rotation_euler.x = math.radians(135)
            bpy.context.view_layer.update()
            bpy.ops.view3d.view_all()
        elif step == 3:  # the specdeform tab (the sidebar's tabs: its right edge, below Item)
            x, y = tabs.x + tabs.width - 12, tabs.y + tabs.height - 178
            win.event_simulate(type="MOUSEMOVE", value="NOTHING", x=x, y=y)
        elif step == 4:
            x, y = tabs.x + tabs.width - 12, tabs.y + tabs.height - 178
            win.event_simulate(type="LEFTMOUSE", value="PRESS", x=x, y=y)
            win.event_simulate(type="LEFTMOUSE", value="RELEASE", x=x, y=y)
        else:
            bpy.ops.screen.screenshot(filepath=out)
            top = area.y + area.height
            crop(out, area.x + 300, top - 600, area.x + area.width, top - 50)
            bpy.ops.wm.quit_blender()
            return None
    return 1.0


bpy.app.timers.register(tick, first_interval=1.0, persistent=True)
