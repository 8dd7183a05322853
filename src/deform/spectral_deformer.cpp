#include "specdeform/deform/spectral_deformer.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "deform/free_pieces.h"
#include "deform/moving_basis.h"
#include "deform/reduced_forms.h"
#include "linalg/basis_product.h"
#include "linalg/parallel.h"
#include "specdeform/deform/reduced_solver.h"
#include "specdeform/deform/spatial_solver.h"
#include "specdeform/exceptions.h"
#include "specdeform/mesh/mesh_info.h"
#include "specdeform/operators/laplacian.h"
#include "specdeform/operators/mass_matrix.h"
#include "specdeform/spectral/spectral_transform.h"

namespace specdeform {

namespace {

// A front end's vertex buffer for `call` must have a row per vertex.
void check_rows(const char* call, Eigen::Index rows, int vertices) {
  if (rows != vertices) {
    throw InputError(std::string(call) + ": an output of " + std::to_string(rows) + " rows for " +
                     std::to_string(vertices) + " vertices");
  }
}

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

// The linear energy's reduced Hessian D (reduced_solver.h), from the basis itself (a basis need
// not be made of eigenvectors): its Laplacian's stiffness, and the bending in the mixed form of
// deform/reduced_forms.h (the spatial solver's lumped mass).
Eigen::MatrixXd linear_hessian(const TriangleMesh& mesh, const ManifoldHarmonics& basis,
                               const DeformOptions& options) {
  const LaplacianOperators L = laplacian_operators(mesh, MassType::Lumped, basis.laplacian);
  const Eigen::VectorXd area = L.mass.diagonal();
  const Eigen::MatrixXd S = detail::reduced_stiffness(L.stiffness, basis);
  return options.ks * S +
         (options.kb * area.sum()) *
             detail::reduced_bending(S, area, basis.basis, basis.mass == MassType::Lumped);
}

// Each column's piece: the piece of its largest entry (a basis of several pieces is computed
// piece by piece, each mode on one).
std::vector<int> piece_of_columns(const Eigen::MatrixXd& H, const Eigen::VectorXi& components) {
  std::vector<int> out(H.cols());
  for (Eigen::Index j = 0; j < H.cols(); ++j) {
    Eigen::Index i;
    H.col(j).cwiseAbs().maxCoeff(&i);
    out[j] = components[i];
  }
  return out;
}

}  // namespace

SpectralDeformer::SpectralDeformer(TriangleMesh mesh, ManifoldHarmonics basis,
                                   const DeformOptions& options)
    : SpectralDeformer(std::move(mesh), std::make_shared<const ManifoldHarmonics>(std::move(basis)),
                       options) {}

SpectralDeformer::SpectralDeformer(TriangleMesh mesh,
                                   std::shared_ptr<const ManifoldHarmonics> basis,
                                   const DeformOptions& options)
    : mesh_(std::move(mesh)),
      diagonal_(bounding_box_diagonal(mesh_.V)),
      basis_(std::move(basis)),
      options_(options) {
  options_.validate();
  const int n = mesh_.num_vertices();
  const bool has_basis = basis_ && basis_->basis.cols() > 0;
  if (has_basis && basis_->basis.rows() != n) {
    throw InputError("deformation: the basis has " + std::to_string(basis_->basis.rows()) +
                     " rows, the mesh " + std::to_string(n) + " vertices");
  }
  if (!has_basis && options_.solver == DeformSolver::Spectral) {
    throw InputError("deformation: the spectral solver needs a basis");
  }
  Clock clock;
  components_ = vertex_components(mesh_, &num_components_);
  if (has_basis) {
    piece_of_mode_ = num_components_ > 1 ? piece_of_columns(basis_->basis, components_)
                                         : std::vector<int>(basis_->basis.cols(), 0);
    const Eigen::MatrixXd& H = basis_->basis;
    base_ = harmonics_inverse(
        H, harmonics_forward(H, mass_matrix(mesh_, basis_->mass, basis_->laplacian), mesh_.V));
  } else {
    base_ = mesh_.V;
  }
  // On several pieces under soft constraints, the spectral solvers wait for the selection: they
  // work in the modes of the pieces that move (deform/moving_basis.h).
  if (!by_moving_pieces()) build_solvers(basis_);
  setup_.reduced_system = clock.lap();
  if (!options_.single_solve) {
    details_ = std::make_unique<DetailReconstruction>(
        mesh_, base_, options_.detail,
        options_.background_transfer ? TransferSolves::Background : TransferSolves::Repeated);
    setup_.detail_factorization = clock.lap();
  }
  deformed_base_ = base_;
}

bool SpectralDeformer::by_moving_pieces() const {
  return options_.solver == DeformSolver::Spectral && num_components_ > 1 &&
         options_.constraints == ConstraintMode::Soft;
}

void SpectralDeformer::build_solvers(std::shared_ptr<const ManifoldHarmonics> basis,
                                     const std::vector<char>& moving) {
  const bool spectral = options_.solver == DeformSolver::Spectral;
  solve_basis_ = std::move(basis);
  solve_piece_modes_.assign(num_components_, 0);
  for (const int c :
       solve_basis_ == basis_ ? piece_of_mode_ : piece_of_columns(solve_basis_->basis, components_))
    ++solve_piece_modes_[c];
  if (options_.energy == DeformEnergy::Arap) {
    arap_ = std::make_unique<ArapSolver>(mesh_, base_, spectral ? solve_basis_ : nullptr,
                                         options_.arap, moving);
    clusters_ = arap_->clusters();
  }
  if (spectral) {
    reduced_ = std::make_unique<ReducedSolver>(
        solve_basis_,
        arap_ ? arap_->reduced_hessian() : linear_hessian(mesh_, *solve_basis_, options_),
        piece_area_fractions(vertex_areas(mesh_), components_, num_components_), options_);
    factored_ = solve_basis_->factored.smaller_than_dense(options_.float32_basis ? 4 : 8);
    if (options_.float32_basis && !factored_) basis32_ = solve_basis_->basis.cast<float>();
  } else {
    spatial_ = std::make_unique<SpatialSolver>(mesh_, options_);
  }
}

SpectralDeformer::~SpectralDeformer() = default;
SpectralDeformer::SpectralDeformer(SpectralDeformer&&) noexcept = default;
SpectralDeformer& SpectralDeformer::operator=(SpectralDeformer&&) noexcept = default;

void SpectralDeformer::set_selection(const Selection& selection) {
  Clock total, clock;
  constrained_ = constrained_set(selection, components_, num_components_, options_.unconstrained);
  constrained_piece_modes_.clear();
  std::vector<char> driving(num_components_, 0);
  for (size_t i = 0; i < constrained_.first_free; ++i)
    driving[components_[constrained_.vertices[i]]] = 1;
  if (by_moving_pieces()) {
    std::vector<char> moving(num_components_, 0);
    for (const std::vector<int>& group : selection.handles)
      for (const int v : group) moving[components_[v]] = 1;
    if (moving != moving_) {
      clock.lap();
      moving_ = moving;
      if (std::find(moving.begin(), moving.end(), 1) == moving.end()) {
        build_solvers(basis_);  // no handle vertex: nothing moves, in any basis
      } else {
        std::vector<char> vertices(mesh_.num_vertices());
        for (int v = 0; v < mesh_.num_vertices(); ++v) vertices[v] = moving[components_[v]];
        build_solvers(detail::moving_basis(mesh_, *basis_, components_, piece_of_mode_, moving_),
                      vertices);
      }
      setup_.reduced_system = clock.lap();
    }
  }
  for (int c = 0; c < num_components_; ++c)
    if (driving[c]) constrained_piece_modes_.push_back(solve_piece_modes_[c]);
  follow_.reset();
  if (constrained_.free_pieces > 0 && options_.unconstrained == UnconstrainedPieces::Follow) {
    follow_ = std::make_unique<detail::FreePieces>(mesh_, components_, driving);
  }
  if (reduced_) {
    reduced_->set_constraints(constrained_.vertices);
    reduced_->set_groups(constrained_.group, constrained_.num_groups, base_);
  } else {
    clock.lap();
    spatial_->set_constraints(constrained_.vertices);
    setup_.reduced_system = clock.lap();  // the spatial solver's factorisation
  }
  clock.lap();
  if (details_) {
    details_->set_anchors(constrained_.vertices);
    if (options_.detail == DetailMethod::Transfer && !options_.background_transfer) {
      setup_.detail_factorization = clock.lap();
    }
  }
  setup_.selection = total.lap();
  detail_targets_.resize(0, 3);
  state_ = ArapState{};  // warm starts continue a drag, not across selections
}

Eigen::MatrixX3d SpectralDeformer::solve_coefficients(
    const std::vector<Eigen::Affine3d>& transforms) {
  if (constrained_.vertices.empty()) throw InputError("deformation: no selection set");
  if (options_.single_solve && !reduced_ && !spatial_) {
    throw InputError("deformation: a single-solve deformer solves once");
  }
  Clock clock;
  Eigen::MatrixX3d base_targets = constraint_targets(constrained_, base_, transforms);
  // ARAP starts from the handles' rotations spread over the surface, or from the last frame
  // when asked to.
  const Eigen::Index size = reduced_ ? solve_basis_->basis.cols() : mesh_.num_vertices();
  // With every transform the identity, the cold start is the rest itself, where ARAP stops at
  // once; a warm start from the last drag would stop near the rest, not on it.
  const bool at_rest = std::all_of(
      transforms.begin(), transforms.end(),
      [](const Eigen::Affine3d& t) { return t.matrix() == Eigen::Matrix4d::Identity(); });
  const bool warm = options_.arap.warm_start && state_.x.rows() == size && !at_rest;
  arap_report_ = ArapReport{};
  arap_report_.converged = true;
  if (reduced_) {
    const ReducedSolver::Targets targets = reduced_->prepare(transforms);
    if (arap_) {
      state_ = arap_->solve(
          *reduced_, targets,
          warm ? std::move(state_) : arap_->start(*reduced_, targets, constrained_, transforms),
          &arap_report_);
    } else {
      state_.x = reduced_->solve(targets, Eigen::MatrixX3d());
    }
  } else {
    Eigen::MatrixX3d displacement_targets = base_targets;
    for (size_t i = 0; i < constrained_.vertices.size(); ++i)
      displacement_targets.row(i) -= base_.row(constrained_.vertices[i]);
    const SpatialSolver::Targets targets = spatial_->prepare(displacement_targets);
    if (arap_) {
      state_ = arap_->solve(
          *spatial_, targets,
          warm ? std::move(state_) : arap_->start(*spatial_, targets, constrained_, transforms),
          &arap_report_);
    } else {
      state_.x = spatial_->solve(targets, Eigen::MatrixX3d());
    }
  }
  frame_.reduced_solve = clock.lap();
  return base_targets;
}

void SpectralDeformer::inverse_transform(const Vertices& origin, Vertices& deformed) const {
  if (!reduced_) {
    deformed = origin + state_.x;
  } else if (factored_) {
    detail::add_basis_product(origin, solve_basis_->factored, state_.x, deformed);
  } else if (options_.float32_basis) {
    detail::add_basis_product(origin, basis32_, state_.x, deformed);
  } else {
    detail::add_basis_product(origin, solve_basis_->basis, state_.x, deformed);
  }
  keep_free_pieces(origin, deformed);
}

template <typename Out>
void SpectralDeformer::keep_free_pieces(const Vertices& origin, Out& deformed) const {
  // Free pieces stay exactly where they are (the solvers hold them only as well as soft
  // constraints do), then follow the deformed surface around them.
  const std::vector<int>& constrained = constrained_.vertices;
  for (size_t i = constrained_.first_free; i < constrained.size(); ++i)
    deformed.row(constrained[i]) = origin.row(constrained[i]).template cast<typename Out::Scalar>();
}

Vertices SpectralDeformer::preview(const std::vector<Eigen::Affine3d>& transforms) {
  Clock total;
  solve_coefficients(transforms);
  Clock clock;
  Vertices out;
  if (follow_) {  // the pieces' motions are the deformed base's
    inverse_transform(base_, out);
    follow_->apply(follow_->motions(base_, out), base_, out);
    out += mesh_.V - base_;
  } else {
    inverse_transform(mesh_.V, out);  // x + H c = s' + (x - s) in one pass
  }
  frame_.inverse_transform = clock.lap();
  frame_.total = total.lap();
  return out;
}

void SpectralDeformer::preview(const std::vector<Eigen::Affine3d>& transforms,
                               Eigen::Ref<FloatVertices> out) {
  check_rows("preview", out.rows(), mesh_.num_vertices());
  if (follow_ || !reduced_) {  // through the frame in double precision
    out = preview(transforms).cast<float>();
    return;
  }
  Clock total;
  solve_coefficients(transforms);
  Clock clock;
  if (factored_) {
    detail::add_basis_product(mesh_.V, solve_basis_->factored, state_.x, out);
  } else if (options_.float32_basis) {
    detail::add_basis_product(mesh_.V, basis32_, state_.x, out);
  } else {
    detail::add_basis_product(mesh_.V, solve_basis_->basis, state_.x, out);
  }
  keep_free_pieces(mesh_.V, out);
  frame_.inverse_transform = clock.lap();
  frame_.total = total.lap();
}

Vertices SpectralDeformer::preview(const std::vector<Eigen::Affine3d>& transforms,
                                   const std::vector<int>& vertices) {
  for (const int v : vertices) {
    if (v < 0 || v >= mesh_.num_vertices()) {
      throw InputError("preview: vertex " + std::to_string(v) + " out of range");
    }
  }
  if (follow_) return preview(transforms)(vertices, Eigen::all);
  Clock total;
  solve_coefficients(transforms);
  Clock clock;
  Vertices out(vertices.size(), 3);
  for (size_t k = 0; k < vertices.size(); ++k) {
    const int v = vertices[k];
    if (reduced_) {
      out.row(k) = mesh_.V.row(v) + solve_basis_->basis.row(v) * state_.x;
    } else {
      out.row(k) = mesh_.V.row(v) + state_.x.row(v);
    }
  }
  frame_.inverse_transform = clock.lap();
  frame_.total = total.lap();
  return out;
}

Vertices SpectralDeformer::solve(const std::vector<Eigen::Affine3d>& transforms) {
  Vertices result;
  solve(transforms, result);
  return result;
}

void SpectralDeformer::solve(const std::vector<Eigen::Affine3d>& transforms,
                             Eigen::Ref<FloatVertices> out) {
  check_rows("solve", out.rows(), mesh_.num_vertices());
  solve(transforms, result_);
  detail::split_in_two(out.rows(), [&](Eigen::Index begin, Eigen::Index end) {
    out.middleRows(begin, end - begin) = result_.middleRows(begin, end - begin).cast<float>();
  });
}

void SpectralDeformer::solve(const std::vector<Eigen::Affine3d>& transforms, Vertices& result) {
  Clock total;
  const Eigen::MatrixX3d base_targets = solve_coefficients(transforms);
  Clock clock;
  inverse_transform(base_, deformed_base_);
  frame_.inverse_transform = clock.lap();
  const std::vector<int>& constrained = constrained_.vertices;
  base_miss_ = ConstraintError{};
  for (size_t i = 0; i < constrained_.first_free; ++i) {
    const double d = (deformed_base_.row(constrained[i]) - base_targets.row(i)).norm();
    base_miss_.max = std::max(base_miss_.max, d);
    base_miss_.rms += d * d;
  }
  base_miss_.max /= diagonal_;
  base_miss_.rms =
      std::sqrt(base_miss_.rms / std::max<size_t>(constrained_.first_free, 1)) / diagonal_;
  detail_targets_ = options_.detail == DetailMethod::None
                        ? base_targets
                        : constraint_targets(constrained_, mesh_.V, transforms);
  const Vertices& rest = options_.detail == DetailMethod::None ? base_ : mesh_.V;
  if (deformed_base_ == base_ && detail_targets_ == rest(constrained, Eigen::all)) {
    // Nothing moved: the result of every detail method is the rest itself, to the bit (a
    // Poisson solve or a fitted rotation would give it to rounding only).
    result = rest;
    frame_.detail = clock.lap();
    frame_.total = total.lap();
    return;
  }
  double deferred = 0.0;
  if (options_.single_solve) {  // the solvers' memory back before the details take theirs
    clock.lap();
    basis_.reset();
    solve_basis_.reset();
    basis32_ = Eigen::MatrixXf();
    reduced_.reset();
    spatial_.reset();
    arap_.reset();
    details_ =
        std::make_unique<DetailReconstruction>(mesh_, base_, options_.detail, TransferSolves::Once);
    details_->set_anchors(constrained_.vertices);
    deferred = setup_.detail_factorization = clock.lap();
  }
  details_->apply(deformed_base_, detail_targets_, result);
  if (follow_) {
    const std::vector<Eigen::Affine3d> motions = follow_->motions(rest, result);
    follow_->apply(motions, base_, deformed_base_);
    follow_->apply(motions, rest, result);
  }
  for (size_t i = constrained_.first_free; i < constrained.size(); ++i) {
    if (follow_) {
      detail_targets_.row(i) = result.row(constrained[i]);
    } else {
      result.row(constrained[i]) = detail_targets_.row(i);
    }
  }
  frame_.detail = clock.lap();
  frame_.total = total.lap() - deferred;
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

Vertices deform(const TriangleMesh& mesh, const ManifoldHarmonics& basis,
                const Selection& selection, const std::vector<Eigen::Affine3d>& transforms,
                const DeformOptions& options) {
  // The deformer lives only in this call: it may use the caller's basis without owning it.
  const std::shared_ptr<const ManifoldHarmonics> borrowed(std::shared_ptr<void>(), &basis);
  DeformOptions once = options;
  once.single_solve = true;
  once.background_transfer = false;
  SpectralDeformer deformer(mesh, borrowed, once);
  deformer.set_selection(selection);
  return deformer.solve(transforms);
}

}  // namespace specdeform
