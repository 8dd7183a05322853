// Spectral mesh deformation (Rong, Cao & Guo, "Spectral mesh deformation", The Visual Computer
// 2008): low-pass the mesh to its first m manifold harmonics, deform that smooth base by
// minimising an energy of deform_options.h (the paper's linear shell, or ARAP) in the
// m-dimensional spectral space under the handle constraints, and add the details back.
//
// Built once per mesh and basis; set_selection() once per selection (handles, fixed set);
// solve() once per frame with one transform per handle group. With DeformSolver::Spatial the
// base's displacement is computed over all n vertices instead (the reference of eq. 14); the
// basis then only defines the smooth base, and may be null or empty, in which case the base is
// the mesh. The basis is shared, never copied: the caller may keep using it.
//
// Targets: the smooth base's handle vertices follow their group's transform (T s_i) and its
// fixed vertices stay; the detailed result's handle vertices should reach T x_i and its fixed
// vertices x_i. Transfer anchors them there exactly; the other methods meet them only as far as
// the base does (constraint_error() measures it). A connected component without a handle or
// fixed vertex (a free piece) moves rigidly with the deformed surface around it
// (UnconstrainedPieces::Follow, deform/free_pieces.h), stays where it is (Keep) or is an
// InputError.
//
// With every transform the identity, solve() returns the mesh bit for bit (every solver, energy
// and detail method; a warm start is not taken there).
//
// With DeformOptions::single_solve the deformer solves once, releasing the basis before it
// builds the details (basis() is then null): deform() below.
//
//   SpectralDeformer deformer(mesh, compute_manifold_harmonics(mesh, {.num_modes = 100}));
//   deformer.set_selection({.handles = {hand}, .fixed = feet});
//   Vertices frame = deformer.solve({Eigen::Affine3d(Eigen::Translation3d(0, 0.1, 0))});
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include <Eigen/Geometry>

#include "specdeform/deform/arap_solver.h"
#include "specdeform/deform/deform_options.h"
#include "specdeform/deform/detail_reconstruction.h"
#include "specdeform/deform/selection.h"
#include "specdeform/mesh/triangle_mesh.h"
#include "specdeform/spectral/manifold_harmonics.h"

namespace specdeform {

class ReducedSolver;
class SpatialSolver;
namespace detail {
class FreePieces;
}

// Seconds spent in each stage.
struct SetupTimings {
  double reduced_system = 0.0;        // spectral: Hessian, base and ARAP's cluster operator
                                      // (once per mesh); spatial: its factorisation for the
                                      // last selection
  double detail_factorization = 0.0;  // Transfer: Poisson analysis (once per mesh), then the
                                      // factorisation or its update for the last selection
                                      // (background_transfer: none, that runs aside;
                                      // single_solve: all of it, done in solve())
  double selection = 0.0;             // the whole of the last set_selection()
};

struct FrameTimings {
  double reduced_solve = 0.0;      // spectral coefficients, all ARAP iterations included
                                   // (spatial: the back-substitutions)
  double inverse_transform = 0.0;  // d = H c and s' = s + d
  double detail = 0.0;             // adding the details back
  double total = 0.0;
};

// Distances of the constrained vertices to their targets, over the bounding-box diagonal.
struct ConstraintError {
  double max = 0.0;
  double rms = 0.0;
};

class SpectralDeformer {
 public:
  // Throws InputError for options out of range (DeformOptions::validate) or a basis that does
  // not fit the mesh.
  SpectralDeformer(TriangleMesh mesh, std::shared_ptr<const ManifoldHarmonics> basis,
                   const DeformOptions& options = {});
  SpectralDeformer(TriangleMesh mesh, ManifoldHarmonics basis, const DeformOptions& options = {});
  ~SpectralDeformer();
  SpectralDeformer(SpectralDeformer&&) noexcept;
  SpectralDeformer& operator=(SpectralDeformer&&) noexcept;

  // Throws InputError for a bad selection (see constrained_set).
  void set_selection(const Selection& selection);

  // The deformed detailed mesh (n x 3) for one transform per handle group.
  Vertices solve(const std::vector<Eigen::Affine3d>& transforms);
  // The same written into `out` (n rows, InputError otherwise), a front end's own vertex buffer,
  // through a frame kept between calls: nothing the size of the mesh is allocated per frame
  // (in Blender, whose allocator returns a freed frame to the system, 10-20 ms of page faults).
  void solve(const std::vector<Eigen::Affine3d>& transforms, Eigen::Ref<FloatVertices> out);

  // A quick look at a frame for drags (the editor's coarse preview): the detailed mesh at
  // `vertices` only (k x 3, in their order), the smooth base solved as solve() solves it (warm
  // starts continue from it) and the details added as displacements (x - s). Costs the reduced
  // solve and k rows of the inverse transform (all n rows where free pieces follow the surface,
  // which their motions need). deformed_base(), base_miss() and frame_timings().detail stay
  // those of the last solve(); InputError for a vertex out of range.
  Vertices preview(const std::vector<Eigen::Affine3d>& transforms,
                   const std::vector<int>& vertices);
  // The same at every vertex (n x 3): solve()'s frame without the cost of its details (a
  // Transfer's right-hand side and back-substitution), for a front end that shows drags at full
  // resolution and solves once the handles rest. float32_basis applies.
  Vertices preview(const std::vector<Eigen::Affine3d>& transforms);
  // The same written into `out` (n rows, InputError otherwise), a front end's own vertex buffer:
  // nothing the size of the mesh is allocated, frame after frame.
  void preview(const std::vector<Eigen::Affine3d>& transforms, Eigen::Ref<FloatVertices> out);

  // Error of `result` (a solve() output) against the targets of the last solve(): 0 where the
  // details meet them exactly (transfer, frames, displacement anchor the constrained vertices).
  ConstraintError constraint_error(const Vertices& result) const;

  // How far the last solve() itself was from the handles and fixed vertices: the distances of
  // the deformed smooth base's constrained vertices to their targets (free pieces left out),
  // over the bounding-box diagonal. Soft constraints pull as hard as their weight; this is what
  // they missed by.
  const ConstraintError& base_miss() const { return base_miss_; }

  const TriangleMesh& mesh() const { return mesh_; }
  const std::shared_ptr<const ManifoldHarmonics>& basis() const { return basis_; }
  const Vertices& base() const { return base_; }                    // s
  const Vertices& deformed_base() const { return deformed_base_; }  // s' of the last solve
  const DeformOptions& options() const { return options_; }
  const SetupTimings& setup_timings() const { return setup_; }
  const FrameTimings& frame_timings() const { return frame_; }
  // ARAP: the iterations of the last solve (the linear energy: none, converged).
  const ArapReport& arap_report() const { return arap_report_; }
  // ARAP: the number of rotation clusters (0 for the linear energy).
  int rotation_clusters() const { return clusters_; }
  // Connected components without a constrained vertex in the last selection (they follow the
  // surface or are held in place, as options().unconstrained says).
  int free_pieces() const { return constrained_.free_pieces; }
  // The modes the solve deforms each piece that has a constrained vertex in the last selection
  // with, in the order of the pieces' first vertices (one entry, all the modes, for a mesh of one
  // piece; on several pieces under soft constraints, 0 for a piece held by fixed vertices alone,
  // and m split among the pieces with a handle: deform/moving_basis.h).
  const std::vector<int>& constrained_piece_modes() const { return constrained_piece_modes_; }

  // options().background_transfer (DetailReconstruction's background): whether the transfer's
  // factorisation for the last selection still runs (solve() adds displacements meanwhile),
  // waiting for it, and a callback on the background thread when it completes.
  bool detail_pending() const { return details_ && !details_->ready(); }
  void wait_for_detail() const {
    if (details_) details_->wait();
  }
  void on_detail_ready(std::function<void()> callback) {
    if (details_) details_->on_ready(std::move(callback));
  }
  // By the last solve() (options().detail before the first with single_solve).
  DetailMethod applied_detail() const { return details_ ? details_->applied() : options_.detail; }
  // Faces where the last solve() added the details as displacements because the deformed base
  // folded there (detail_reconstruction.h; 0 for the other methods).
  int detail_fold_zone() const { return details_ ? details_->fold_zone() : 0; }

 private:
  bool by_moving_pieces() const;
  // The reduced (or spatial) solve of a frame: state_, arap_report_ and frame_.reduced_solve.
  // Returns the smooth base's targets of the constrained vertices.
  Eigen::MatrixX3d solve_coefficients(const std::vector<Eigen::Affine3d>& transforms);
  // solve() into `result` (resized to n x 3; not reallocated when it fits).
  void solve(const std::vector<Eigen::Affine3d>& transforms, Vertices& result);
  // deformed = origin + H c (or + d), free pieces' rows those of origin (base_: the deformed
  // base; mesh_.V: the details added as displacements).
  void inverse_transform(const Vertices& origin, Vertices& deformed) const;
  // The free pieces' rows of `deformed` set to those of origin (unconstrained Keep, or before
  // they follow).
  template <typename Out>
  void keep_free_pieces(const Vertices& origin, Out& deformed) const;
  // The solvers in `basis`; ARAP's clusters on the `moving` vertices (n flags; empty: all).
  void build_solvers(std::shared_ptr<const ManifoldHarmonics> basis,
                     const std::vector<char>& moving = {});

  TriangleMesh mesh_;
  double diagonal_;  // of mesh_'s bounding box
  std::shared_ptr<const ManifoldHarmonics> basis_;
  // The basis the spectral solvers work in: basis_, or on several pieces under soft
  // constraints the modes of the pieces with a handle (deform/moving_basis.h), for moving_.
  std::shared_ptr<const ManifoldHarmonics> solve_basis_;
  std::vector<char> moving_;
  DeformOptions options_;
  Eigen::MatrixXf basis32_;  // float32_basis: the basis in single precision
  bool factored_ = false;    // frames read the solve basis as P Z (fewer bytes than H)
  Vertices base_, deformed_base_;
  Vertices result_;  // the frame of solve() into a front end's buffer
  std::unique_ptr<ReducedSolver> reduced_;
  std::unique_ptr<SpatialSolver> spatial_;
  std::unique_ptr<ArapSolver> arap_;
  std::unique_ptr<DetailReconstruction> details_;  // single_solve: built in solve()
  std::unique_ptr<detail::FreePieces> follow_;     // Follow: the free pieces of the selection
  Eigen::VectorXi components_;                     // connected component of each vertex
  int num_components_ = 0;
  int clusters_ = 0;                    // ARAP's rotation clusters
  std::vector<int> piece_of_mode_;      // the component of each of the basis's columns
  std::vector<int> solve_piece_modes_;  // solve_basis_'s modes on each component
  std::vector<int> constrained_piece_modes_;
  ConstrainedSet constrained_;
  ArapState state_;                  // c (spectral) or d (spatial) of the last solve, and
                                     // ARAP's rotations
  Eigen::MatrixX3d detail_targets_;  // targets of the last solve, for constraint_error
  ConstraintError base_miss_;
  ArapReport arap_report_;
  SetupTimings setup_;
  FrameTimings frame_;
};

// One deformation, start to finish: the detailed result of `selection` moved by `transforms`
// (SpectralDeformer's set_selection and solve once, with single_solve). The basis is used, not
// copied.
Vertices deform(const TriangleMesh& mesh, const ManifoldHarmonics& basis,
                const Selection& selection, const std::vector<Eigen::Affine3d>& transforms,
                const DeformOptions& options = {});

}  // namespace specdeform
