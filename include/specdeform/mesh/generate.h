// Procedural meshes: the built-in demo models and the analytic test surfaces.
//
// All are closed or open 2-manifolds with consistently counter-clockwise (outward) faces.
#pragma once

#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform {

// A bar of square cross-section along x, x in [0, length], y and z in [-thickness/2, thickness/2],
// its four long sides covered with smooth bumps (sin^2 x sin^2 profile, zero on the bar's edges)
// pushed outwards. Closed. About 4 (length * thickness + thickness^2 / 2) cells_per_unit^2 * 2
// vertices.
struct BumpyBarOptions {
  double length = 4.0;
  double thickness = 1.0;
  int cells_per_unit = 24;    // grid cells per unit length
  int bumps_per_unit = 3;     // bumps per unit length, along and across each side
  double bump_height = 0.04;  // absolute height of a bump
};
TriangleMesh make_bumpy_bar(const BumpyBarOptions& options = {});

// A round bar (a tube with closed ends) along x, x in [0, length], radius `radius`, its side
// covered with smooth bumps (sin^2 along x and around) pushed outwards, the ends closed by fans
// around a centre vertex. Closed; segments x (length * cells_per_unit + 1) + 2 vertices.
struct BumpyTubeOptions {
  double length = 6.0;
  double radius = 0.5;
  int segments = 48;          // vertices around each ring
  int cells_per_unit = 24;    // rings per unit length
  int bumps_per_unit = 3;     // bumps per unit length
  int bumps_around = 6;       // bumps around the tube
  double bump_height = 0.03;  // absolute height of a bump
};
TriangleMesh make_bumpy_tube(const BumpyTubeOptions& options = {});

// The unit square [0, size] x [0, size] in the plane z = 0, resolution x resolution cells,
// with bumps z = bump_height sin^2(pi k x / size) sin^2(pi k y / size), k = bumps per side.
// bump_height = 0 gives the flat square (free boundary) of the analytic spectrum tests.
struct BumpyPlaneOptions {
  double size = 1.0;
  int resolution = 64;
  int bumps = 8;
  double bump_height = 0.02;
};
TriangleMesh make_bumpy_plane(const BumpyPlaneOptions& options = {});

// Icosahedron refined `subdivisions` times (1-to-4 splits), projected to the sphere:
// 10 * 4^s + 2 vertices.
TriangleMesh make_icosphere(int subdivisions, double radius = 1.0);

// Torus around the z axis: major radius R, minor radius r, a major x b minor segments.
TriangleMesh make_torus(double major_radius = 1.0, double minor_radius = 0.35,
                        int major_segments = 96, int minor_segments = 32);

}  // namespace specdeform
