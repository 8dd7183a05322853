"""Rigged characters as an artist's tool writes them: Debian's Blender builds a figure with an
armature, skin weights, shape keys and keyframed actions, and its glTF exporter writes it (issue
53's kinds). Run by Blender:
    blender -b --factory-startup --python export_rig.py -- OUT

Writes to OUT:
  figure.glb   a standing figure (a column 2 high along glTF's +Y, 32 around, 48 rings, capped),
               skinned to a chain of four bones: root [0, 0.5], spine [0.5, 1.2], neck [1.2, 1.8],
               head [1.8, 2] (each vertex blended over the 0.06 above each joint, so the head's
               vertices all lie at y >= 1.8); a "walk" action (25 frames: the root steps along
               +Z, spine, neck and head turn, the head nods); shape keys "smile" (a bump on the
               head's +X side) and "swell" (the spine's girth), keyed in the same action: morph
               targets with NORMAL deltas
  horse.glb    the same figure without its armature, galloping by its shape keys only (a
               morph-animated mesh, as three.js's Horse)
"""

import math
import sys

import bmesh
import bpy
from mathutils import Matrix, Vector

out = sys.argv[sys.argv.index("--") + 1]
JOINTS = [("root", 0.0, 0.5), ("spine", 0.5, 1.2), ("neck", 1.2, 1.8), ("head", 1.8, 2.0)]
BLEND = 0.06

bpy.ops.wm.read_factory_settings(use_empty=True)

# The body: Blender's Z up (the exporter writes glTF's +Y up).
bm = bmesh.new()
bmesh.ops.create_cone(bm, cap_ends=True, cap_tris=False, segments=32, radius1=0.3, radius2=0.3,
                      depth=2.0, matrix=Matrix.Translation((0, 0, 1.0)))
bmesh.ops.subdivide_edges(bm, edges=[e for e in bm.edges
                                     if abs(e.verts[0].co.z - e.verts[1].co.z) > 1.0],
                          cuts=47, use_grid_fill=True)
bmesh.ops.triangulate(bm, faces=[f for f in bm.faces if len(f.verts) > 4])
mesh = bpy.data.meshes.new("figure")
bm.to_mesh(mesh)
bm.free()
body = bpy.data.objects.new("figure", mesh)
bpy.context.scene.collection.objects.link(body)


def weights(z):
    """Each joint's weight at height z: its own span, blended over BLEND above each joint."""
    w = []
    for k, (_, lo, hi) in enumerate(JOINTS):
        a = 1.0 if k == 0 else min(max((z - lo) / BLEND, 0.0), 1.0)
        b = 1.0 if k == len(JOINTS) - 1 else 1.0 - min(max((z - hi) / BLEND, 0.0), 1.0)
        w.append(min(a, b))
    total = sum(w)
    return [x / total for x in w]


groups = [body.vertex_groups.new(name=name) for name, _, _ in JOINTS]
for v in mesh.vertices:
    for g, w in zip(groups, weights(v.co.z)):
        if w > 0:
            g.add([v.index], w, "REPLACE")

# Shape keys.
body.shape_key_add(name="Basis")
smile = body.shape_key_add(name="smile")
swell = body.shape_key_add(name="swell")
for i, v in enumerate(mesh.vertices):
    x, y, z = v.co
    if z > 1.84 and x > 0.1:
        smile.data[i].co = v.co + Vector((0.06 * x / 0.3, 0.03 * math.sin(8 * z), 0.02))
    if 0.6 < z < 1.1:
        r = 1.0 + 0.15 * math.sin(math.pi * (z - 0.6) / 0.5)
        swell.data[i].co = Vector((x * r, y * r, z))


def key_shapes(owner, frames):
    for frame, s, w in frames:
        owner.data.shape_keys.key_blocks["smile"].value = s
        owner.data.shape_keys.key_blocks["smile"].keyframe_insert("value", frame=frame)
        owner.data.shape_keys.key_blocks["swell"].value = w
        owner.data.shape_keys.key_blocks["swell"].keyframe_insert("value", frame=frame)


SHAPE_FRAMES = [(1, 0.0, 0.0), (7, 1.0, 0.5), (13, 0.2, 1.0), (19, 0.8, 0.3), (25, 0.0, 0.0)]

# The horse: the figure galloping by its shape keys alone.
key_shapes(body, SHAPE_FRAMES)
bpy.context.scene.frame_start, bpy.context.scene.frame_end = 1, 25
bpy.ops.export_scene.gltf(filepath=f"{out}/horse.glb", export_format="GLB", export_animations=True,
                          export_morph=True, export_morph_normal=True, export_skins=False,
                          export_yup=True)

# The armature: one chain along Z.
arm_data = bpy.data.armatures.new("rig")
rig = bpy.data.objects.new("rig", arm_data)
bpy.context.scene.collection.objects.link(rig)
bpy.context.view_layer.objects.active = rig
bpy.ops.object.mode_set(mode="EDIT")
parent = None
for name, lo, hi in JOINTS:
    bone = arm_data.edit_bones.new(name)
    bone.head, bone.tail = (0, 0, lo), (0, 0, hi)
    if parent is not None:
        bone.parent = parent
        bone.use_connect = True
    parent = bone
bpy.ops.object.mode_set(mode="OBJECT")
body.parent = rig
modifier = body.modifiers.new("rig", "ARMATURE")
modifier.object = rig

# The walk: keyed bone rotations (quaternions) and the root's translation.
bpy.ops.object.mode_set(mode="POSE")
poses = rig.pose.bones
for frame in range(1, 26, 4):
    phase = 2 * math.pi * (frame - 1) / 24
    poses["root"].location = (0, 0.15 * (frame - 1) / 24, 0)  # bone space: along the bone's Y
    poses["root"].keyframe_insert("location", frame=frame)
    for name, axis, degrees in (("spine", "X", 12), ("neck", "Y", 18), ("head", "X", 25)):
        poses[name].rotation_mode = "QUATERNION"
        poses[name].rotation_quaternion = Matrix.Rotation(
            math.radians(degrees) * math.sin(phase + len(name)), 4, axis).to_quaternion()
        poses[name].keyframe_insert("rotation_quaternion", frame=frame)
bpy.ops.object.mode_set(mode="OBJECT")
for p in poses:
    p.location, p.rotation_quaternion = (0, 0, 0), (1, 0, 0, 0)

bpy.ops.export_scene.gltf(filepath=f"{out}/figure.glb", export_format="GLB",
                          export_animations=True, export_skins=True, export_morph=True,
                          export_morph_normal=True, export_yup=True, export_all_influences=False)
