"""The add-on's zip installed the way users do (Preferences > Install, then enable) into a fresh
user scripts folder (BLENDER_USER_SCRIPTS), its bundled module loaded from there, and a mesh bound
and moved. Given the extension's zip (Blender 4.2+), Blender 3.4's Install puts it in one folder
and enabling it is refused with one line naming the zip for this Blender.

    BLENDER_USER_SCRIPTS=DIR blender -b --factory-startup --python-exit-code 1 \\
        --python zip_test.py -- ZIP
"""

import os
import sys

import addon_utils
import bpy
import numpy as np

zip_path = sys.argv[sys.argv.index("--") + 1]
user_addons = bpy.utils.user_resource("SCRIPTS", path="addons")
assert user_addons.startswith(os.environ["BLENDER_USER_SCRIPTS"]), user_addons
before = set(os.listdir(user_addons)) if os.path.isdir(user_addons) else set()
assert bpy.ops.preferences.addon_install(filepath=zip_path, overwrite=True) == {"FINISHED"}
if "4.2-and-later" in os.path.basename(zip_path):
    assert set(os.listdir(user_addons)) - before <= {"specdeform"}, os.listdir(user_addons)
    errors = []
    assert addon_utils.enable("specdeform", handle_error=errors.append) is None
    assert "specdeform" not in bpy.context.preferences.addons
    print(f"refused: {errors[0]}")
    assert "for Blender 3.4-4.1" in str(errors[0]) and "-blender-3.4-to-4.1.zip" in str(errors[0])
    sys.exit(0)
addon_utils.enable("specdeform_blender", default_set=True, handle_error=None)
library = sys.modules["specdeform_blender.library"]
assert library.specdeform is not None, library.problem
assert library.specdeform.__file__.startswith(user_addons), library.specdeform.__file__

bpy.ops.mesh.primitive_uv_sphere_add(segments=32, ring_count=16)
obj = bpy.context.object
co = np.empty(3 * len(obj.data.vertices), np.float32)
obj.data.vertices.foreach_get("co", co)
z = co[2::3]
obj.vertex_groups.new(name="top").add([int(i) for i in np.flatnonzero(z > 0.8)], 1.0, "REPLACE")
obj.vertex_groups.new(name="bottom").add([int(i) for i in np.flatnonzero(z < -0.8)], 1.0, "REPLACE")
empty = bpy.data.objects.new("target", None)
bpy.context.scene.collection.objects.link(empty)
s = obj.specdeform
s.handle_group, s.fixed_group, s.target, s.modes = "top", "bottom", empty, 30
assert bpy.ops.specdeform.bind() == {"FINISHED"}
empty.location.z = 0.5
bpy.context.view_layer.update()
moved = np.empty_like(co)
obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).data.vertices.foreach_get("co", moved)
top = np.flatnonzero(z > 0.8)
assert np.abs(moved[3 * top + 2] - co[3 * top + 2] - 0.5).max() < 0.01
print("passed:", library.specdeform.__file__)
