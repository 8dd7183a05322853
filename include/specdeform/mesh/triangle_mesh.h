// The triangle mesh type shared by every algorithm of the library.
//
// A mesh is a plain pair of matrices, in the style of libigl: V (n x 3, double, one vertex per
// row) and F (f x 3, int, counter-clockwise vertex indices into V, 0-based). Algorithms take
// const references and never modify their input.
#pragma once

#include <string_view>

#include <Eigen/Core>

namespace specdeform {

using Vertices = Eigen::Matrix<double, Eigen::Dynamic, 3>;
using Faces = Eigen::Matrix<int, Eigen::Dynamic, 3>;
// Positions as renderers and modelling tools keep them: rows of three floats.
using FloatVertices = Eigen::Matrix<float, Eigen::Dynamic, 3, Eigen::RowMajor>;

struct TriangleMesh {
  Vertices V;
  Faces F;

  int num_vertices() const { return static_cast<int>(V.rows()); }
  int num_faces() const { return static_cast<int>(F.rows()); }
};

// A triangle is degenerate when its area is negligible against its longest edge:
// 2 * area <= kDegenerateTolerance * (longest edge)^2. Such triangles carry no area and no
// cotangent weight in the operators (see operators/), so they cannot produce NaN or Inf.
inline constexpr double kDegenerateTolerance = 1e-12;
bool is_degenerate_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                            const Eigen::Vector3d& c);

// The coordinates this library computes in: squared lengths, areas and volumes of coordinates
// beyond 1e100 overflow and of extents below 1e-100 vanish. Throws InputError "<name>:
// coordinates reach 1e+160 ..." (or "... span only 1e-300 ...") outside them; the readers and the
// bindings check what comes in.
inline constexpr double kLargestCoordinate = 1e100, kSmallestExtent = 1e-100;
void check_coordinate_range(const Eigen::Ref<const Eigen::MatrixXd>& V, std::string_view name);

// Length of the diagonal of the axis-aligned bounding box (0 for an empty mesh).
double bounding_box_diagonal(const Vertices& V);

// Sum of the triangle areas.
double surface_area(const TriangleMesh& mesh);

// Area of each triangle (f x 1).
Eigen::VectorXd face_areas(const TriangleMesh& mesh);

// Unit normal of each triangle (f x 3); zero for a degenerate triangle.
Eigen::Matrix<double, Eigen::Dynamic, 3> face_normals(const TriangleMesh& mesh);

// Area-weighted unit vertex normals (n x 3); zero where all incident faces are degenerate.
Eigen::Matrix<double, Eigen::Dynamic, 3> vertex_normals(const TriangleMesh& mesh);

}  // namespace specdeform
