"""The mesh's polygons as the triangles the solve uses, chosen on the rest shape: a file reopened,
which shows a pose, is triangulated as it was bound (Blender's loop triangles follow the shape
shown), so its basis is the one cached. Quads are split along their shorter diagonal; polygons
of five corners or more are filled by Blender's own polygon fill (mathutils), each triangle
turned to the polygon's winding. Runs on Bind's worker thread: polygons(), on the main thread,
read the corners in two bulk calls."""

import numpy as np
from mathutils import Vector
from mathutils.geometry import tessellate_polygon


def triangulate(sizes, corners, rest):
    """sizes: int (p,) corners of each polygon; corners: int (sum of sizes,) their vertices, polygon
    after polygon; rest: float (n, 3). Returns int32 (t, 3), each polygon's winding kept."""
    starts = np.cumsum(sizes) - sizes
    parts = [corners[starts[sizes == 3, None] + np.arange(3)]]
    quads = corners[starts[sizes == 4, None] + np.arange(4)]
    if len(quads):
        p = rest[quads]
        along_02 = (np.sum((p[:, 0] - p[:, 2]) ** 2, axis=1)
                    <= np.sum((p[:, 1] - p[:, 3]) ** 2, axis=1))[:, None]
        parts.append(np.where(along_02, quads[:, [0, 1, 2]], quads[:, [0, 1, 3]]))
        parts.append(np.where(along_02, quads[:, [0, 2, 3]], quads[:, [1, 2, 3]]))
    for start, size in zip(starts[sizes > 4], sizes[sizes > 4]):
        parts.append(_fill(corners[start:start + size], rest))
    return np.concatenate(parts).astype(np.int32, copy=False)


def _fill(ring, rest):
    """One polygon of five corners or more: Blender's fill of its rest outline, each triangle
    wound as the polygon is (its Newell normal)."""
    p = rest[ring].astype(np.float64)
    normal = np.cross(p, np.roll(p, -1, axis=0)).sum(axis=0)
    triangles = np.array(tessellate_polygon([[Vector(x) for x in p]]), np.int64).reshape(-1, 3)
    a, b, c = (p[triangles[:, i]] for i in range(3))
    flipped = np.cross(b - a, c - a) @ normal < 0
    triangles[flipped] = triangles[flipped][:, ::-1]
    return ring[triangles]
