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
  int duplicate_faces = 0;       // the same three vertices as a lower-numbered face, any order
  // Defects that later steps refuse (a vertex without area has no mass) or that matter (the
  // deformation's normals and frames assume one orientation per component):
  int zero_area_vertices = 0;      // touched only by degenerate faces (or by none)
  int pinch_vertices = 0;          // non-manifold: their faces form more than one fan
  int inconsistent_edges = 0;      // their two faces run along them in the same direction
  int misoriented_components = 0;  // components with an inconsistent edge
  int coincident_vertices = 0;  // at exactly the position of a lower-numbered vertex: the surface
                                // is cut (a seam) or touches itself there
  // The lowest-numbered offender of each kind, -1 if none.
  int first_zero_area_vertex = -1;
  int first_pinch_vertex = -1;
  Eigen::Vector2i first_inconsistent_edge{-1, -1};
  Eigen::Vector2i first_coincident_vertices{-1, -1};  // the lowest such pair
  double area = 0.0;
  Eigen::Vector3d bbox_min = Eigen::Vector3d::Zero();
  Eigen::Vector3d bbox_max = Eigen::Vector3d::Zero();
  double bbox_diagonal = 0.0;
};

MeshInfo compute_mesh_info(const TriangleMesh& mesh);

// Component label (0 .. count-1) of every vertex; vertices are connected through faces.
Eigen::VectorXi vertex_components(const TriangleMesh& mesh, int* count = nullptr);

}  // namespace specdeform
