#include "isotropic_remesh.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/detect_features.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Surface_mesh.h>

#include <array>
#include <vector>

#include "specdeform/exceptions.h"

namespace specdeform::bench {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
namespace PMP = CGAL::Polygon_mesh_processing;

}  // namespace

double mean_edge_length(const TriangleMesh& mesh) {
  double sum = 0.0;
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int c = 0; c < 3; ++c)
      sum += (mesh.V.row(mesh.F(f, c)) - mesh.V.row(mesh.F(f, (c + 1) % 3))).norm();
  return sum / (3.0 * mesh.num_faces());
}

TriangleMesh isotropic_remesh(const TriangleMesh& mesh, double target_edge_length, int iterations) {
  std::vector<Point> points;
  for (int v = 0; v < mesh.num_vertices(); ++v)
    points.emplace_back(mesh.V(v, 0), mesh.V(v, 1), mesh.V(v, 2));
  std::vector<std::array<std::size_t, 3>> polygons;
  for (int f = 0; f < mesh.num_faces(); ++f)
    polygons.push_back(
        {std::size_t(mesh.F(f, 0)), std::size_t(mesh.F(f, 1)), std::size_t(mesh.F(f, 2))});
  // Degenerate faces go, non-manifold vertices are split, the orientation made consistent.
  PMP::repair_polygon_soup(points, polygons);
  PMP::orient_polygon_soup(points, polygons);
  Mesh surface;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, surface);
  if (surface.number_of_faces() == 0) throw InputError("isotropic remeshing: no surface left");
  auto features = surface.add_property_map<Mesh::Edge_index, bool>("e:feature", false).first;
  PMP::detect_sharp_edges(surface, 60.0, features);
  PMP::isotropic_remeshing(faces(surface), target_edge_length, surface,
                           CGAL::parameters::number_of_iterations(iterations)
                               .edge_is_constrained_map(features)
                               .relax_constraints(true));
  surface.collect_garbage();
  TriangleMesh out;
  out.V.resize(surface.number_of_vertices(), 3);
  for (const Mesh::Vertex_index v : surface.vertices()) {
    const Point& p = surface.point(v);
    out.V.row(v.idx()) << p.x(), p.y(), p.z();
  }
  out.F.resize(surface.number_of_faces(), 3);
  for (const Mesh::Face_index f : surface.faces()) {
    int c = 0;
    for (const Mesh::Vertex_index v : vertices_around_face(surface.halfedge(f), surface))
      out.F(f.idx(), c++) = static_cast<int>(v.idx());
  }
  return out;
}

}  // namespace specdeform::bench
