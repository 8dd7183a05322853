"""Messy geometry as real tools write it: Debian's Blender builds it and its own exporters write
the files (issue 52's kinds). Run by Blender:
    blender -b --factory-startup --python export_messy.py -- OUT

Writes to OUT:
  scan.ply         a scan: a noisy sheet with holes, zero-area T-junction slivers (a vertex on an
                   edge, touched only by a flat face) and a zero-length edge; binary PLY with
                   normals and texture coordinates (split at its UV seams)
  scan.obj         the same as OBJ
  cad.stl          a CAD assembly: six parts of very different sizes (a plate, a bolt, a washer,
                   a pin, a tiny screw, a sliver of a shim), binary STL (an unwelded soup)
  shells.obj       a figure of two shells, one wound inside out and one with half its faces
                   flipped, a fin (an edge of three faces) and a pinch (two cubes at one vertex)
  room.glb         a room: a floor and walls with hundreds of small props as separate objects
                   (many meshes, many pieces), props with collapsed faces
"""

import math
import os
import random
import sys

import bmesh
import bpy
from mathutils import Vector

out = sys.argv[sys.argv.index("--") + 1]
random.seed(52)


def select_only(objects):
    bpy.ops.object.select_all(action="DESELECT")
    for o in objects:
        o.select_set(True)
    bpy.context.view_layer.objects.active = objects[0]


def from_bmesh(name, bm):
    mesh = bpy.data.meshes.new(name)
    bm.to_mesh(mesh)
    bm.free()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def t_junctions(bm, every):
    """A vertex q on the edge a-b of every `every`-th triangle (a, b, c) with the zero-area face
    (a, b, q): in turn the triangle split at q (a T-junction) or kept (q is then touched by the
    zero-area face alone: a vertex of zero area, as scanned and game scenes have them)."""
    for k, f in enumerate(list(bm.faces)[::every]):
        a, b, c = f.verts
        q = bm.verts.new((a.co + b.co) / 2)
        if k % 2 == 0:
            bm.faces.remove(f)
            bm.faces.new([a, q, c])
            bm.faces.new([q, b, c])
        bm.faces.new([a, b, q])


def scan():
    bm = bmesh.new()
    bmesh.ops.create_grid(bm, x_segments=40, y_segments=40, size=1.0, calc_uvs=True)
    for v in bm.verts:
        v.co.z = 0.05 * math.sin(4 * v.co.x) * math.cos(3 * v.co.y) + random.gauss(0, 0.004)
    holes = [f for f in bm.faces
             if min((f.calc_center_median().xy - Vector(c)).length for c in [(0.3, -0.2), (-0.5, 0.4)])
             < 0.12]
    bmesh.ops.delete(bm, geom=holes, context="FACES")
    bmesh.ops.triangulate(bm, faces=bm.faces[:])
    t_junctions(bm, 17)
    bm.verts.ensure_lookup_table()
    corner = bm.verts[0]
    twin = bm.verts.new(corner.co)  # a zero-length edge: two vertices at one place, both used
    other = [e.other_vert(corner) for e in corner.link_edges][0]
    bm.faces.new([corner, other, twin])
    return from_bmesh("scan", bm)


def cad():
    parts = []
    for size, maker in [(1.0, "plate"), (0.2, "bolt"), (0.12, "washer"), (0.05, "pin"),
                        (0.01, "screw"), (0.3, "shim")]:
        if maker == "plate":
            bpy.ops.mesh.primitive_cube_add(size=size)
            bpy.context.object.scale = (1, 0.6, 0.05)
        elif maker == "bolt":
            bpy.ops.mesh.primitive_cylinder_add(vertices=48, radius=size / 4, depth=size)
        elif maker == "washer":
            bpy.ops.mesh.primitive_torus_add(major_radius=size, minor_radius=size / 5)
        elif maker == "pin":
            bpy.ops.mesh.primitive_cone_add(vertices=32, radius1=size / 3, depth=size)
        elif maker == "screw":
            bpy.ops.mesh.primitive_cylinder_add(vertices=12, radius=size / 3, depth=size)
        else:
            bpy.ops.mesh.primitive_cube_add(size=size)
            bpy.context.object.scale = (1, 1, 0.002)
        bpy.context.object.location = (random.uniform(-0.4, 0.4), random.uniform(-0.3, 0.3),
                                       random.uniform(0.03, 0.3))
        parts.append(bpy.context.object)
    select_only(parts)
    bpy.ops.object.join()
    return bpy.context.object


def shells():
    bpy.ops.mesh.primitive_uv_sphere_add(segments=24, ring_count=12, radius=0.5, location=(0, 0, 1))
    inside_out = bpy.context.object
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=3, radius=0.4, location=(0, 0, 0.1))
    half = bpy.context.object
    bpy.ops.mesh.primitive_cube_add(size=0.3, location=(0.8, 0, 0.15))
    cube_a = bpy.context.object
    bpy.ops.mesh.primitive_cube_add(size=0.3, location=(1.1, 0.3, 0.45))
    cube_b = bpy.context.object
    select_only([inside_out, half, cube_a, cube_b])
    bpy.ops.object.transform_apply(location=True)
    bpy.ops.object.join()
    obj = bpy.context.object
    bm = bmesh.new()
    bm.from_mesh(obj.data)
    bmesh.ops.remove_doubles(bm, verts=bm.verts[:], dist=1e-6)  # the cubes' corners: a pinch
    bm.faces.ensure_lookup_table()
    for f in bm.faces:
        c = f.calc_center_median()
        if c.z > 0.8 or (c.z < 0.5 and c.x < 0.5 and c.x > 0.0):
            f.normal_flip()
    bm.edges.ensure_lookup_table()
    edge = max(bm.edges, key=lambda e: (e.verts[0].co + e.verts[1].co).z)
    tip = bm.verts.new((edge.verts[0].co + edge.verts[1].co) / 2)
    tip.co.z += 0.4
    bm.faces.new([edge.verts[0], edge.verts[1], tip])  # a fin: the edge's third face
    bmesh.ops.triangulate(bm, faces=bm.faces[:])
    bm.to_mesh(obj.data)
    bm.free()
    return obj


def room():
    objects = []
    bpy.ops.mesh.primitive_plane_add(size=4)
    objects.append(bpy.context.object)
    for k, (x, y, r) in enumerate([(0, 2, 0), (2, 0, 90), (0, -2, 180), (-2, 0, 270)]):
        bpy.ops.mesh.primitive_plane_add(size=4, location=(x, y, 1),
                                         rotation=(math.radians(90), 0, math.radians(r)))
        objects.append(bpy.context.object)
    for k in range(240):
        kind = k % 3
        at = (random.uniform(-1.8, 1.8), random.uniform(-1.8, 1.8), random.uniform(0.02, 0.8))
        if kind == 0:
            bpy.ops.mesh.primitive_cube_add(size=random.uniform(0.02, 0.15), location=at)
        elif kind == 1:
            bpy.ops.mesh.primitive_cylinder_add(vertices=8, radius=0.03, depth=0.1, location=at)
        else:
            bpy.ops.mesh.primitive_plane_add(size=0.05, location=at)
        prop = bpy.context.object
        if k % 10 == 0:  # a collapsed prop: every face flat (zero area)
            prop.scale = (1, 0, 1) if kind == 2 else (1, 0, 0)
            bpy.ops.object.transform_apply(scale=True)
        objects.append(prop)
    return objects


bpy.ops.wm.read_factory_settings(use_empty=True)
s = scan()
select_only([s])
bpy.ops.export_mesh.ply(filepath=os.path.join(out, "scan.ply"), use_selection=True,
                        use_normals=True, use_uv_coords=True, use_colors=False)
bpy.ops.wm.obj_export(filepath=os.path.join(out, "scan.obj"), export_selected_objects=True,
                      export_materials=False)
bpy.ops.wm.read_factory_settings(use_empty=True)
c = cad()
select_only([c])
bpy.ops.export_mesh.stl(filepath=os.path.join(out, "cad.stl"), use_selection=True, ascii=False)
bpy.ops.wm.read_factory_settings(use_empty=True)
sh = shells()
select_only([sh])
bpy.ops.wm.obj_export(filepath=os.path.join(out, "shells.obj"), export_selected_objects=True,
                      export_materials=False)
bpy.ops.wm.read_factory_settings(use_empty=True)
select_only(room())
bpy.ops.export_scene.gltf(filepath=os.path.join(out, "room.glb"), export_format="GLB",
                          use_selection=True)
