// Vertex clusters of about equal geodesic size: the rotation clusters of the ARAP energy
// (deform_options.h) and any other per-region fit.
//
// Seeds by farthest-point sampling of the graph distance along the mesh's edges (Dijkstra,
// edge lengths of the given positions, in single precision), each new seed the vertex farthest
// from all earlier ones; every vertex joins the cluster of its nearest seed (a graph Voronoi
// partition), so a cluster is connected and never spans two connected components. Every
// component gets at least one cluster: a mesh of c components with c > count has c clusters.
// Deterministic; O(n log n) (2.77M vertices, 200 clusters: 1.5 s).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform {

struct VertexClusters {
  Eigen::VectorXi label;  // n, cluster of each vertex, 0 .. count-1
  int count = 0;          // min(n, max(requested, connected components))
};

VertexClusters vertex_clusters(const TriangleMesh& mesh, int count);

// The same within a region (`region[v]`, n flags, whole connected components): `count`
// clusters (at most one per 16 of its vertices, at least one per component) cover the region;
// the vertices outside it form one more cluster, the last (none when the region is everything).
VertexClusters vertex_clusters(const TriangleMesh& mesh, int count,
                               const std::vector<char>& region);

}  // namespace specdeform
