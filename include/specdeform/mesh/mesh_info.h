// Topological and geometric summary of a triangle mesh (what `specdeform info` prints).
#pragma once

#include <Eigen/Core>

#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform {

struct MeshInfo {
  int vertices = 0;
  int faces = 0;
  int edges = 0;                 // undirected edges
  int boundary_edges = 0;        // edges with one incident face
  int non_manifold_edges = 0;    // edges with three or more incident faces
  int boundary_loops = 0;        // connected chains of boundary edges
  int components = 0;            // connected through shared vertices
  int euler_characteristic = 0;  // V - E + F
  int degenerate_faces = 0;      // see is_degenerate_triangle
  double area = 0.0;
  Eigen::Vector3d bbox_min = Eigen::Vector3d::Zero();
  Eigen::Vector3d bbox_max = Eigen::Vector3d::Zero();
  double bbox_diagonal = 0.0;
};

MeshInfo compute_mesh_info(const TriangleMesh& mesh);

// Component label (0 .. count-1) of every vertex; vertices are connected through faces.
Eigen::VectorXi vertex_components(const TriangleMesh& mesh, int* count = nullptr);

}  // namespace specdeform
