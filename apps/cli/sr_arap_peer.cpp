#include "sr_arap_peer.h"

#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_deformation.h>

#include <chrono>

#include "specdeform/exceptions.h"

namespace specdeform::cli {

namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;
using Deformation =
    CGAL::Surface_mesh_deformation<Mesh, CGAL::Default, CGAL::Default, CGAL::SRE_ARAP>;

}  // namespace

struct SrArapPeer::Impl {
  Mesh mesh;
  std::vector<Mesh::Vertex_index> vertex;
  std::unique_ptr<Deformation> deformation;
  std::vector<std::pair<Mesh::Vertex_index, Kernel::Point_3>> targets;
};

SrArapPeer::SrArapPeer(const TriangleMesh& mesh, const ConstrainedSet& set,
                       const Eigen::MatrixX3d& targets)
    : impl_(std::make_unique<Impl>()) {
  const auto start = std::chrono::steady_clock::now();
  Impl& p = *impl_;
  for (int i = 0; i < mesh.num_vertices(); ++i)
    p.vertex.push_back(p.mesh.add_vertex({mesh.V(i, 0), mesh.V(i, 1), mesh.V(i, 2)}));
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const auto face =
        p.mesh.add_face(p.vertex[mesh.F(f, 0)], p.vertex[mesh.F(f, 1)], p.vertex[mesh.F(f, 2)]);
    if (face == Mesh::null_face()) {
      throw InputError("SR-ARAP (CGAL): face " + std::to_string(f) +
                       " makes the mesh non-manifold, which CGAL's surface mesh cannot hold");
    }
  }
  p.deformation = std::make_unique<Deformation>(p.mesh);
  p.deformation->insert_roi_vertices(p.mesh.vertices().begin(), p.mesh.vertices().end());
  for (const int v : set.vertices) p.deformation->insert_control_vertex(p.vertex[v]);
  if (!p.deformation->preprocess()) {
    throw SolverError("SR-ARAP (CGAL): the system could not be factored");
  }
  for (size_t i = 0; i < set.vertices.size(); ++i) {
    const Eigen::RowVector3d t = targets.row(i);
    p.targets.emplace_back(p.vertex[set.vertices[i]], Kernel::Point_3(t.x(), t.y(), t.z()));
  }
  setup_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  reset();
}

SrArapPeer::~SrArapPeer() = default;

void SrArapPeer::reset() {
  Impl& p = *impl_;
  p.deformation->reset();  // the rest pose, the constrained vertices' included
  for (const auto& [v, target] : p.targets) p.deformation->set_target_position(v, target);
}

Vertices SrArapPeer::iterate(int iterations) {
  Impl& p = *impl_;
  p.deformation->deform(static_cast<unsigned>(iterations), 0.0);
  Vertices out(static_cast<Eigen::Index>(p.vertex.size()), 3);
  for (size_t i = 0; i < p.vertex.size(); ++i) {
    const Kernel::Point_3& q = p.mesh.point(p.vertex[i]);
    out.row(static_cast<Eigen::Index>(i)) << q.x(), q.y(), q.z();
  }
  return out;
}

}  // namespace specdeform::cli
