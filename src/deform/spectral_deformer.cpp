#include "specdeform/deform/spectral_deformer.h"

#include <chrono>

#include "linalg/basis_product.h"
#include "specdeform/deform/reduced_solver.h"
#include "specdeform/deform/spatial_solver.h"
#include "specdeform/exceptions.h"
#include "specdeform/mesh/mesh_info.h"
#include "specdeform/operators/mass_matrix.h"
#include "specdeform/spectral/spectral_transform.h"

namespace specdeform {

namespace {

class Clock {
 public:
  double lap() {
    const auto now = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(now - start_).count();
    start_ = now;
    return s;
  }

 private:
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace

SpectralDeformer::SpectralDeformer(TriangleMesh mesh, ManifoldHarmonics basis,
                                   const DeformOptions& options)
    : mesh_(std::move(mesh)), basis_(std::move(basis)), options_(options) {
  const int n = mesh_.num_vertices();
  const bool has_basis = basis_.basis.cols() > 0;
  if (has_basis && basis_.basis.rows() != n) {
    throw InputError("deformation: the basis has " + std::to_string(basis_.basis.rows()) +
                     " rows, the mesh " + std::to_string(n) + " vertices");
  }
  if (!has_basis && options_.solver == DeformSolver::Spectral) {
    throw InputError("deformation: the spectral solver needs a basis");
  }
  if (!(options_.ks >= 0 && options_.kb >= 0 && options_.ks + options_.kb > 0)) {
    throw InputError("deformation: ks and kb must be >= 0 and not both 0");
  }
  if (!(options_.constraint_weight > 0) || !std::isfinite(options_.constraint_weight)) {
    throw InputError("deformation: the constraint weight must be positive");
  }
  Clock clock;
  components_ = vertex_components(mesh_, &num_components_);
  const Eigen::VectorXd area = lumped_mass(mesh_);
  if (has_basis) {
    base_ = harmonics_inverse(
        basis_.basis, harmonics_forward(basis_.basis, mass_matrix(mesh_, basis_.mass), mesh_.V));
  } else {
    base_ = mesh_.V;
  }
  if (options_.solver == DeformSolver::Spectral) {
    reduced_ = std::make_unique<ReducedSolver>(basis_.basis, basis_.eigenvalues, area, area.sum(),
                                               options_);
    if (options_.float32_basis) basis32_ = basis_.basis.cast<float>();
  } else {
    spatial_ = std::make_unique<SpatialSolver>(mesh_, options_);
  }
  setup_.reduced_system = clock.lap();
  details_ = std::make_unique<DetailReconstruction>(mesh_, base_, options_.detail);
  setup_.detail_factorization = clock.lap();
  deformed_base_ = base_;
}

SpectralDeformer::~SpectralDeformer() = default;
SpectralDeformer::SpectralDeformer(SpectralDeformer&&) noexcept = default;
SpectralDeformer& SpectralDeformer::operator=(SpectralDeformer&&) noexcept = default;

void SpectralDeformer::set_selection(const Selection& selection) {
  Clock total, clock;
  constrained_ = constrained_set(selection, components_, num_components_);
  if (reduced_) {
    reduced_->set_constraints(constrained_.vertices);
  } else {
    clock.lap();
    spatial_->set_constraints(constrained_.vertices);
    setup_.reduced_system = clock.lap();  // the spatial solver's factorisation
  }
  clock.lap();
  details_->set_anchors(constrained_.vertices);
  if (options_.detail == DetailMethod::Transfer) setup_.detail_factorization = clock.lap();
  setup_.selection = total.lap();
  detail_targets_.resize(0, 3);
}

Vertices SpectralDeformer::solve(const std::vector<Eigen::Affine3d>& transforms) {
  if (constrained_.vertices.empty()) throw InputError("deformation: no selection set");
  Clock clock, total;
  const Eigen::MatrixX3d base_targets = constraint_targets(constrained_, base_, transforms);
  Eigen::MatrixX3d displacement_targets = base_targets;
  for (size_t i = 0; i < constrained_.vertices.size(); ++i)
    displacement_targets.row(i) -= base_.row(constrained_.vertices[i]);
  if (reduced_) {
    const Eigen::MatrixX3d c = reduced_->solve(displacement_targets);
    frame_.reduced_solve = clock.lap();
    if (options_.float32_basis) {
      detail::add_basis_product(base_, basis32_, c, deformed_base_);
    } else {
      detail::add_basis_product(base_, basis_.basis, c, deformed_base_);
    }
    frame_.inverse_transform = clock.lap();
  } else {
    const Eigen::MatrixX3d d = spatial_->solve(displacement_targets);
    frame_.reduced_solve = clock.lap();
    deformed_base_ = base_ + d;
    frame_.inverse_transform = clock.lap();
  }
  detail_targets_ = options_.detail == DetailMethod::None
                        ? base_targets
                        : constraint_targets(constrained_, mesh_.V, transforms);
  Vertices result = details_->apply(deformed_base_, detail_targets_);
  frame_.detail = clock.lap();
  frame_.total = total.lap();
  return result;
}

ConstraintError SpectralDeformer::constraint_error(const Vertices& result) const {
  ConstraintError e;
  if (detail_targets_.rows() == 0) return e;
  const double diagonal = bounding_box_diagonal(mesh_.V);
  double sum = 0.0;
  for (size_t i = 0; i < constrained_.vertices.size(); ++i) {
    const double d = (result.row(constrained_.vertices[i]) - detail_targets_.row(i)).norm();
    e.max = std::max(e.max, d);
    sum += d * d;
  }
  e.max /= diagonal;
  e.rms = std::sqrt(sum / constrained_.vertices.size()) / diagonal;
  return e;
}

}  // namespace specdeform
