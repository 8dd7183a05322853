#include "specdeform/operators/laplacian.h"

#include <array>
#include <memory>
#include <string>

#include "specdeform/exceptions.h"
#include "specdeform/operators/cotan_laplacian.h"
#include "specdeform/operators/intrinsic_delaunay.h"
#include "specdeform/operators/mollification.h"

namespace specdeform {

namespace {

constexpr std::array<std::string_view, 2> kNames = {"cotan", "intrinsic-delaunay"};

}  // namespace

std::string_view name(LaplacianType type) {
  return kNames[static_cast<int>(type)];
}

LaplacianType laplacian_type_from_name(std::string_view name) {
  for (size_t i = 0; i < kNames.size(); ++i)
    if (kNames[i] == name) return static_cast<LaplacianType>(i);
  throw InputError("unknown Laplacian '" + std::string(name) + "' (cotan or intrinsic-delaunay)");
}

namespace {

// The triangulation the operators are built on where the mesh's positions cannot be used: its
// own triangles mollified (Cotan), or the intrinsic Delaunay one (always mollified). Null for a
// Cotan mesh that needs no mollification (its positions give the operators).
std::unique_ptr<IntrinsicTriangulation> triangulation(const TriangleMesh& mesh,
                                                      LaplacianType type) {
  if (type == LaplacianType::IntrinsicDelaunay) {
    return std::make_unique<IntrinsicTriangulation>(intrinsic_delaunay(mesh));
  }
  if (mollification(mesh) == 0.0) return nullptr;
  return std::make_unique<IntrinsicTriangulation>(mollified_triangulation(mesh));
}

}  // namespace

LaplacianOperators laplacian_operators(const TriangleMesh& mesh, MassType mass,
                                       LaplacianType type) {
  const auto tri = triangulation(mesh, type);
  if (!tri) return {cotan_stiffness(mesh), mass_matrix(mesh, mass)};
  return {stiffness_matrix(*tri), mass_matrix(*tri, mass)};
}

Eigen::SparseMatrix<double> stiffness_matrix(const TriangleMesh& mesh, LaplacianType type) {
  const auto tri = triangulation(mesh, type);
  return tri ? stiffness_matrix(*tri) : cotan_stiffness(mesh);
}

void check_operators(const Eigen::SparseMatrix<double>& K, const Eigen::SparseMatrix<double>& M,
                     std::string_view who) {
  const auto finite = [](const Eigen::SparseMatrix<double>& A) {
    return Eigen::Map<const Eigen::VectorXd>(A.valuePtr(), A.nonZeros()).allFinite();
  };
  if (!finite(K) || !finite(M)) {
    throw InputError(std::string(who) + ": the Laplacian has entries that are not finite");
  }
  const Eigen::VectorXd rows = M * Eigen::VectorXd::Ones(M.cols());
  const long massless = (rows.array() <= 0.0).count();
  if (massless > 0) {
    throw InputError(std::string(who) + ": " + std::to_string(massless) +
                     " vertices have zero area (their faces have no extent: all their vertices "
                     "at one point)");
  }
}

Eigen::VectorXd vertex_areas(const TriangleMesh& mesh) {
  return mass_matrix(mesh, MassType::Lumped, LaplacianType::Cotan).diagonal();
}

Eigen::SparseMatrix<double> mass_matrix(const TriangleMesh& mesh, MassType mass,
                                        LaplacianType type) {
  const auto tri = triangulation(mesh, type);
  return tri ? mass_matrix(*tri, mass) : mass_matrix(mesh, mass);
}

}  // namespace specdeform
