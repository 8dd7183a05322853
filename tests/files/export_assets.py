"""Real files made by a real tool: Debian's Blender exports the shared models as users' files
have them. Run by Blender:  blender -b --factory-startup --python export_assets.py -- OUT SHARED

Writes to OUT:
  spot.glb           UV-mapped, a base colour image, smooth normals, split along UV seams
  spot.obj/.mtl      the same as OBJ + MTL (+ spot_texture.png)
  spot_colors.ply    binary PLY with normals, texture coordinates and a colour per vertex
  spot_colors.glb    the same colours as glTF's COLOR_0
  beast.glb          the polygon (quad) model, triangulated by the exporter, with its UVs
  beast.obj          quads and n-gons with their texture coordinates and normals
  cad_part.obj/.glb  a machined part: a cylinder whose 48-gon caps meet its smooth side at
                     hard edges (auto smooth 30 degrees)
  fleet.glb          a scene: the spot cow drawn by three objects that share its mesh (linked
                     duplicates: one glTF mesh drawn by three nodes) under a turned parent, a
                     clear-coated and emissive textured material, named nodes
  fleet.gltf         the same as a .gltf with its buffer (fleet.bin) and texture beside it
"""

import math
import os
import sys

import bmesh
import bpy

out, shared = sys.argv[sys.argv.index("--") + 1:]
models = os.path.join(shared, "meshes", "models")


def only(obj):
    bpy.ops.object.select_all(action="DESELECT")
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj


def imported(path):
    bpy.ops.wm.obj_import(filepath=path)
    obj = bpy.context.selected_objects[0]
    only(obj)
    return obj


def textured_material(name, image_path):
    image = bpy.data.images.new(name + "_texture", 64, 64)
    image.generated_type = "UV_GRID"
    image.filepath_raw = image_path
    image.file_format = "PNG"
    image.save()
    material = bpy.data.materials.new(name)
    material.use_nodes = True
    nodes = material.node_tree.nodes
    texture = nodes.new("ShaderNodeTexImage")
    texture.image = image
    material.node_tree.links.new(texture.outputs["Color"], nodes["Principled BSDF"].inputs["Base Color"])
    return material


def export(obj, stem, gltf=True, obj_file=True):
    only(obj)
    if gltf:
        bpy.ops.export_scene.gltf(filepath=os.path.join(out, stem + ".glb"), export_format="GLB",
                                  use_selection=True)
    if obj_file:
        bpy.ops.wm.obj_export(filepath=os.path.join(out, stem + ".obj"), export_selected_objects=True,
                              export_materials=True, export_normals=True, export_uv=True,
                              path_mode="RELATIVE")


bpy.ops.wm.read_factory_settings(use_empty=True)

spot = imported(os.path.join(models, "spot.obj"))
spot.data.materials.clear()
spot.data.materials.append(textured_material("Spot", os.path.join(out, "spot_texture.png")))
bpy.ops.object.shade_smooth()
export(spot, "spot")
# Blender 3.4's PLY writer takes the (legacy) face-corner colour layer.
colors = spot.data.vertex_colors.new(name="Col")
for loop, c in zip(spot.data.loops, colors.data):
    i = loop.vertex_index
    c.color = (0.5 + 0.5 * math.sin(i), 0.5 + 0.5 * math.cos(i), 0.25, 1.0)
bpy.ops.export_mesh.ply(filepath=os.path.join(out, "spot_colors.ply"), use_selection=True,
                        use_normals=True, use_uv_coords=True, use_colors=True)
bpy.ops.export_scene.gltf(filepath=os.path.join(out, "spot_colors.glb"), export_format="GLB",
                          use_selection=True, export_colors=True)

beast = imported(os.path.join(models, "beast.obj"))
bpy.ops.object.shade_smooth()
export(beast, "beast")

mesh = bpy.data.meshes.new("cad_part")
bm = bmesh.new()
bmesh.ops.create_cone(bm, cap_ends=True, cap_tris=False, segments=48, radius1=0.5, radius2=0.5,
                      depth=4.0)
side = [e for e in bm.edges if abs(e.verts[0].co.z - e.verts[1].co.z) > 1.0]
bmesh.ops.subdivide_edges(bm, edges=side, cuts=39, use_grid_fill=False)
bm.to_mesh(mesh)
bm.free()
part = bpy.data.objects.new("cad_part", mesh)
bpy.context.scene.collection.objects.link(part)
only(part)
bpy.ops.object.shade_smooth()
mesh.use_auto_smooth = True
mesh.auto_smooth_angle = math.radians(30)
export(part, "cad_part")
# A scene: one mesh drawn by three objects under a turned parent.
bpy.ops.object.select_all(action="DESELECT")
fleet = bpy.data.objects.new("fleet", None)
bpy.context.scene.collection.objects.link(fleet)
fleet.rotation_euler = (0.3, 0.0, 0.7)
glossy = textured_material("Glossy", os.path.join(out, "fleet_texture.png"))
principled = glossy.node_tree.nodes["Principled BSDF"]
principled.inputs["Clearcoat"].default_value = 0.6
principled.inputs["Emission"].default_value = (0.2, 0.1, 0.0, 1.0)
cows = []
for i in range(3):
    cow = spot.copy()  # shares spot's mesh
    cow.name = f"cow {i}"
    cow.parent = fleet
    cow.location = (1.5 * i, 0.4 * i, 0.0)
    cow.rotation_euler = (0.0, 0.0, 0.5 * i)
    bpy.context.scene.collection.objects.link(cow)
    cows.append(cow)
spot.data.materials.clear()
spot.data.materials.append(glossy)
spot.hide_set(True)
bpy.ops.object.select_all(action="DESELECT")
fleet.select_set(True)
for cow in cows:
    cow.select_set(True)
bpy.ops.export_scene.gltf(filepath=os.path.join(out, "fleet.glb"), export_format="GLB",
                          use_selection=True)
bpy.ops.export_scene.gltf(filepath=os.path.join(out, "fleet.gltf"), export_format="GLTF_SEPARATE",
                          use_selection=True)
print("exported to", out)
