// Meshes with slivers whose surface is known exactly, for the Laplacian tests: flat grids cut
// into leaning triangles, and books of such pages around a shared spine (non-manifold).
#pragma once

#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform::test {

// The rectangle [0, a] x [0, b] in the plane z = 0 on an (nx + 1) x (ny + 1) grid of vertices,
// the interior ones moved by up to `jitter` cells in x and y (seeded). Each row of cells is cut
// into 2 nx triangles leaning `skew` cells sideways: 0 gives two triangles per cell (Delaunay
// without jitter), larger values slivers with angles up to about pi - 1 / skew. The triangles are
// counter-clockwise seen from +z as long as the jitter is small against 1 / skew.
TriangleMesh skewed_grid(int nx, int ny, double a, double b, int skew, double jitter = 0.0);

// `pages` copies of skewed_grid(n, n, 1, 1, skew) turned about the y axis (the spine, x = 0) by
// 2 pi / pages from one to the next, sharing the spine's vertices: each spine edge has `pages`
// triangles.
TriangleMesh book(int pages, int n, int skew);

}  // namespace specdeform::test
