// Adding the high-frequency details back (Rong, Cao & Guo 2008, section 4.4).
//
// The detailed mesh x (n x 3) and its smooth base s (the low-passed x) share one connectivity.
// Given the deformed base s', each method returns the deformed detailed mesh x':
//  - None:         x' = s'.
//  - Displacement: x' = s' + (x - s); details do not rotate.
//  - Frames:       x - s turned by the rotation of each vertex's local frame from s to s'
//                  (the paper's section 4.4), the frame's rotation fitted to the whole one-ring
//                  (its edge vectors and the vertex normal, by the polar decomposition): rotates
//                  details. The paper's frame, the normal and the first incident edge, twisted
//                  neighbouring details apart wherever that one edge turned differently from the
//                  ring (folds at a turned handle's border: docs/results.md).
//  - Transfer:     deformation transfer (Botsch, Sumner, Pauly & Gross 2006): per triangle the
//                  gradient S_f = [c'-a', b'-a', n'] [c-a, b-a, n]^-1 of s -> s' (unit normals),
//                  applied to the gradients of x; then the Poisson system K x' = G^T D [S grad x]
//                  on the detailed mesh, with the anchors (the constrained vertices) at their
//                  exact targets, solved for x' - x with K the mesh's mollified stiffness
//                  (operators/laplacian.h: a vertex of zero-area faces alone follows its
//                  neighbours). K is analysed once, factored (CHOLMOD LDL^T) for the first
//                  anchor set and then updated by the anchors that change (row additions and
//                  deletions); a frame is O(f) plus one back-substitution with 3 columns, both
//                  on two threads. In the background (for interactive front ends), a thread
//                  of its own, at a lower CPU priority (Linux: nice 5; frames and the page
//                  keep most of the cores, other busy programs leave it its share), builds the
//                  system and factors each new anchor set while
//                  apply() adds the details as displacements; apply() switches to the
//                  transfer once the newest anchors are factored (692k vertices on two idle
//                  cores: 6-9 s for the first, most of it METIS's ordering; then 1-3 s).
// Where the low-pass collapsed the base (a small piece keeps only its constant mode among the
// first m and its base is a point; thin tips and slivers nearly so), a base triangle's or
// one-ring's frame is rounding noise. Such a triangle (its base edges below 1e-3 of the detailed
// ones, or its base a sliver of aspect below 1e-3), and a sliver of the mesh itself (a cap or a
// needle of aspect below 1e-3, whose base is one too: its frame's inverse is rounding noise
// magnified, 4e5 times the mesh's size on a scan's cap), takes the deformation gradient of the
// nearest sound triangle of its piece, or the identity where its piece has none (the piece
// keeps its shape and follows its anchors); such a vertex keeps its offset as a displacement
// (Frames).
// Where the deformed base folds (a subspace too small for the bend a turning handle asks for),
// the details are added as displacements on the fold's zone (src/deform/fold_zone.h): the
// transfer takes the gradient of s' + (x - s) there, frames leave the offsets unturned;
// fold_zone() says how many faces that was.
// With s' = s every method returns x (to round-off).
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "specdeform/deform/deform_options.h"
#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform {

namespace detail {
class FoldZone;
}  // namespace detail

// How a Transfer's Poisson system is used: factored for each anchor set (updated where the set
// changes a little) with a two-thread solve per frame (Repeated), the same built and factored on
// a thread of its own (Background, see above; the thread starts in the constructor), or one
// anchor set solved once (Once: deform(), the command line's deform; an ordering for one
// solve, src/deform/anchored_poisson.h).
enum class TransferSolves { Repeated, Background, Once };

class DetailReconstruction {
 public:
  DetailReconstruction(const TriangleMesh& detailed, const Vertices& base, DetailMethod method,
                       TransferSolves solves = TransferSolves::Repeated);
  ~DetailReconstruction();  // waits for a background factorisation under way
  DetailReconstruction(const DetailReconstruction&) = delete;
  DetailReconstruction& operator=(const DetailReconstruction&) = delete;

  // Transfer: factors the Poisson system with these vertices anchored (in the background: hands
  // them to the thread and returns). Other methods: nothing.
  void set_anchors(const std::vector<int>& vertices);
  // Whether apply() uses the method asked for: false while a background factorisation of the
  // newest anchors runs. ready() and wait() rethrow the background thread's error (a singular
  // system).
  bool ready() const;
  void wait() const;
  // Called on the background thread, its lock held (post a message; do not call back), each
  // time the newest anchors' factorisation completes.
  void on_ready(std::function<void()> callback);

  // anchor_positions: exact positions of the anchors (n' x 3, Transfer only). Reuses buffers
  // of the previous call (not reentrant).
  Vertices apply(const Vertices& deformed_base, const Eigen::MatrixX3d& anchor_positions);
  // The same into `out` (resized to n x 3; not reallocated when it fits, not deformed_base).
  void apply(const Vertices& deformed_base, const Eigen::MatrixX3d& anchor_positions,
             Vertices& out);

  DetailMethod method() const { return method_; }
  DetailMethod applied() const { return applied_; }  // by the last apply()
  // Transfer and Frames: the faces of the last apply()'s fold zone (see above).
  int fold_zone() const { return fold_zone_; }

  struct Poisson;  // the Transfer method's precomputed system

 private:
  struct Background;
  DetailMethod method_, applied_;
  int fold_zone_ = 0;
  Faces faces_;
  Vertices details_;                    // x - s (Displacement, Frames)
  std::vector<int> ring_start_, ring_;  // Frames: each vertex's one-ring (empty: collapsed)
  Vertices base_;                       // Frames: s
  Eigen::Matrix<double, Eigen::Dynamic, 3> base_normals_;  // Frames: the vertex normals of s
  std::unique_ptr<detail::FoldZone> folds_;                // Frames
  std::unique_ptr<Poisson> poisson_;                       // Transfer
  std::unique_ptr<Background> background_;                 // after poisson_: stopped before it goes
};

}  // namespace specdeform
