#include "specdeform/operators/laplacian.h"

#include <array>
#include <string>

#include "specdeform/exceptions.h"
#include "specdeform/operators/cotan_laplacian.h"
#include "specdeform/operators/intrinsic_delaunay.h"

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

LaplacianOperators laplacian_operators(const TriangleMesh& mesh, MassType mass,
                                       LaplacianType type) {
  if (type == LaplacianType::Cotan) return {cotan_stiffness(mesh), mass_matrix(mesh, mass)};
  const IntrinsicTriangulation tri = intrinsic_delaunay(mesh);
  return {stiffness_matrix(tri), mass_matrix(tri, mass)};
}

Eigen::SparseMatrix<double> stiffness_matrix(const TriangleMesh& mesh, LaplacianType type) {
  if (type == LaplacianType::Cotan) return cotan_stiffness(mesh);
  return stiffness_matrix(intrinsic_delaunay(mesh));
}

Eigen::SparseMatrix<double> mass_matrix(const TriangleMesh& mesh, MassType mass,
                                        LaplacianType type) {
  if (type == LaplacianType::Cotan) return mass_matrix(mesh, mass);
  return mass_matrix(intrinsic_delaunay(mesh), mass);
}

}  // namespace specdeform
