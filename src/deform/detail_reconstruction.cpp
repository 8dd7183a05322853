#include "specdeform/deform/detail_reconstruction.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <thread>

#if defined(__linux__)
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

#include <Eigen/CholmodSupport>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include "anchored_poisson.h"
#include "fold_zone.h"
#include "linalg/nearest_rotation.h"
#include "linalg/parallel.h"
#include "mesh/vertex_rings.h"
#include "specdeform/exceptions.h"
#include "specdeform/operators/cotan_laplacian.h"
#include "specdeform/operators/laplacian.h"
#include "specdeform/operators/mass_matrix.h"
#include "specdeform/operators/mollification.h"

namespace specdeform {

namespace {

using Sparse = Eigen::SparseMatrix<double>;

// The rotation nearest to the map of the one-ring of vertex i (edge vectors to its neighbours and
// its normal) from `rest` to `deformed`: R = argmin sum_j |e'_ij - R e_ij|^2 + l^2 |n'_i - R
// n_i|^2, l the mean rest edge length (the normal weighs like an edge), by the polar decomposition.
Eigen::Matrix3d ring_rotation(const Vertices& rest, const Vertices& deformed,
                              const Eigen::Matrix<double, Eigen::Dynamic, 3>& rest_normals,
                              const Eigen::Matrix<double, Eigen::Dynamic, 3>& normals,
                              const int* ring, int size, int i) {
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  double length = 0.0;
  for (int k = 0; k < size; ++k) {
    const Eigen::Vector3d e = rest.row(ring[k]) - rest.row(i);
    A += (deformed.row(ring[k]) - deformed.row(i)).transpose() * e.transpose();
    length += e.norm();
  }
  length /= std::max(size, 1);
  A += length * length * normals.row(i).transpose() * rest_normals.row(i);
  return detail::nearest_rotation(A);
}

// The corners of triangle f (rows).
Eigen::Matrix3d corners(const Vertices& V, const Faces& F, int f) {
  Eigen::Matrix3d out;
  for (int k = 0; k < 3; ++k) out.row(k) = V.row(F(f, k));
  return out;
}

// Whether a base triangle carries a deformation gradient worth transferring: it is not
// collapsed (its larger singular value at least kMinRelativeSize of the detailed triangle's)
// and not a sliver (its smaller singular value at least kMinAspect of its larger). Below that,
// B'_f B_f^-1 amplifies rounding a thousandfold or more: a low-passed piece that collapsed to a
// point (only its constant mode among the first m) gives pure noise.
constexpr double kMinRelativeSize = 1e-3;
constexpr double kMinAspect = 1e-3;

// The background transfer's nice value: below the frames' (0), which keep three quarters of a
// core it shares with them, yet a quarter of one beside other busy programs (at 19 it got 1.4%:
// 692k vertices' ordering took minutes beside two busy processes).
constexpr int kBackgroundNice = 5;

// Singular values (larger, smaller) of the edge matrix [c - a, b - a] of face f.
std::pair<double, double> edge_singular_values(const Vertices& V, const Faces& F, int f) {
  Eigen::Matrix<double, 3, 2> E;
  E.col(0) = V.row(F(f, 2)) - V.row(F(f, 0));
  E.col(1) = V.row(F(f, 1)) - V.row(F(f, 0));
  const Eigen::Matrix2d gram = E.transpose() * E;
  const double half_trace = 0.5 * gram.trace();
  const double root = std::sqrt(std::max(0.0, half_trace * half_trace - gram.determinant()));
  return {std::sqrt(half_trace + root), std::sqrt(std::max(0.0, half_trace - root))};
}

// Per face, the face whose base deformation gradient it takes: itself where its base triangle is
// sound and its own is no sliver, else the nearest sound face through shared edges (breadth first
// from all sound faces in order, each face's edges in the order of their sorted ends and the faces
// on an edge by index), or -1 where its connected piece has none (its gradient is then the
// identity: the piece keeps its shape). Only the sound faces beside an unsound one can give
// anything, so the walk starts from those alone, and it finds the faces on an edge through the
// vertices' face lists.
std::vector<int> transfer_donors(const TriangleMesh& detailed, const Vertices& base) {
  const int nf = detailed.num_faces();
  std::vector<int> donor(nf, -1);
  std::atomic<bool> all_sound = true;
  detail::split_in_two(nf, [&](Eigen::Index begin, Eigen::Index end) {
    for (Eigen::Index f = begin; f < end; ++f) {
      const auto [size, thin] = edge_singular_values(detailed.V, detailed.F, f);
      const auto [large, small] = edge_singular_values(base, detailed.F, f);
      if (thin > kMinAspect * size && large > kMinRelativeSize * size &&
          small > kMinAspect * large) {
        donor[f] = static_cast<int>(f);
      } else {
        all_sound = false;
      }
    }
  });
  if (all_sound) return donor;
  const detail::VertexFaces incident = detail::vertex_faces(detailed.F, detailed.num_vertices());
  // Calls visit(g) for each face g sharing an edge with f (f too), in the order above.
  const auto for_each_neighbour = [&](int f, auto&& visit) {
    std::array<std::pair<int, int>, 3> edges;
    for (int k = 0; k < 3; ++k) {
      const int a = detailed.F(f, k), b = detailed.F(f, (k + 1) % 3);
      edges[k] = {std::min(a, b), std::max(a, b)};
    }
    std::sort(edges.begin(), edges.end());
    for (const auto& [a, b] : edges) {
      const int* p = incident.face.data() + incident.start[a];
      const int* p_end = incident.face.data() + incident.start[a + 1];
      const int* q = incident.face.data() + incident.start[b];
      const int* q_end = incident.face.data() + incident.start[b + 1];
      while (p != p_end && q != q_end) {  // the faces on both ends, ascending
        if (*p < *q) {
          ++p;
        } else if (*q < *p) {
          ++q;
        } else {
          visit(*p);
          ++p;
          ++q;
        }
      }
    }
  };
  std::vector<char> source(nf, 0);
  for (int f = 0; f < nf; ++f) {
    if (donor[f] >= 0) continue;
    for_each_neighbour(f, [&](int g) {
      if (donor[g] >= 0) source[g] = 1;
    });
  }
  std::vector<int> queue;
  for (int f = 0; f < nf; ++f)
    if (source[f]) queue.push_back(f);
  for (size_t head = 0; head < queue.size(); ++head) {
    const int f = queue[head];
    for_each_neighbour(f, [&](int g) {
      if (donor[g] < 0) {
        donor[g] = donor[f];
        queue.push_back(g);
      }
    });
  }
  return donor;
}

// A compressed row-major matrix from each row's (column, value) entries, rows i at
// [start[i], start[i + 1]) of `entries`: each row sorted by column, the values of equal columns
// summed in their order (as setFromTriplets sums them). Rows on two threads: each merged in its
// own range first, then copied to its place.
Eigen::SparseMatrix<double, Eigen::RowMajor> compressed_rows(
    int rows, int cols, const std::vector<int>& start,
    std::vector<std::pair<int, double>>& entries) {
  std::vector<int> size(rows);
  detail::split_in_two(rows, [&](Eigen::Index first, Eigen::Index last) {
    for (Eigen::Index i = first; i < last; ++i) {
      const auto begin = entries.begin() + start[i], end = entries.begin() + start[i + 1];
      std::stable_sort(begin, end, [](const auto& x, const auto& y) { return x.first < y.first; });
      auto at = begin;
      for (auto e = begin; e != end; ++e) {
        if (at != begin && (at - 1)->first == e->first) {
          (at - 1)->second += e->second;
        } else {
          *at++ = *e;
        }
      }
      size[i] = static_cast<int>(at - begin);
    }
  });
  Eigen::SparseMatrix<double, Eigen::RowMajor> A(rows, cols);
  int* outer = A.outerIndexPtr();
  outer[0] = 0;
  for (int i = 0; i < rows; ++i) outer[i + 1] = outer[i] + size[i];
  A.resizeNonZeros(outer[rows]);
  detail::split_in_two(rows, [&](Eigen::Index first, Eigen::Index last) {
    for (Eigen::Index i = first; i < last; ++i) {
      for (int k = 0; k < size[i]; ++k) {
        A.innerIndexPtr()[outer[i] + k] = entries[start[i] + k].first;
        A.valuePtr()[outer[i] + k] = entries[start[i] + k].second;
      }
    }
  });
  return A;
}

}  // namespace

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

struct DetailReconstruction::Poisson {
  // Per triangle f, with B_f = [c - a, b - a, n] of the base and
  // Q_f = A_f [grad phi_a; grad phi_b; grad phi_c] [grad x, grad y, grad z] (corners by
  // coordinates): the Poisson right-hand side of the transferred gradients J_f S_f^T,
  // S_f = B'_f B_f^-1, is the scatter over the corners of Q_f S_f^T = P_f B'_f^T with
  // P_f = Q_f B_f^-T. Where the base's triangle is degenerate, S_f = I and the corners get Q_f.
  // Gathered per vertex i, the right-hand side is linear in the deformed base s' but for the
  // unit normals n'_f:
  //     b_i = constant_i + sum_j edges_ij s'_j + sum_f normal weight_if n'_f,
  // minus (G^T D G x)_i, the rest's own (in `constant`): the system is solved for the
  // displacement x' - x, with the mollified stiffness (operators/laplacian.h) as its matrix, so
  // that S_f = I gives back x on any mesh, and a vertex that only zero-area faces touch (a zero
  // row of G^T D G) moves with the surface around it.
  // Everything here is numbered as the Poisson factor (`order`): a nested-dissection ordering
  // keeps neighbours close in memory, and the right-hand side is assembled where the solve
  // wants it.
  Eigen::SparseMatrix<double, Eigen::RowMajor> edges;    // n x n, compressed
  Eigen::SparseMatrix<double, Eigen::RowMajor> normals;  // n x faces, compressed
  RowMajor constant;                                     // n x 3
  Sparse coupling;           // n x n': K's columns of the anchors, anchor rows zeroed (rows
                             // numbered as the factor)
  std::vector<int> anchors;  // the anchors' rows
  std::unique_ptr<detail::AnchoredPoisson> system;
  // Where the deformed base folds (fold_zone.h): the detailed mesh and whether each face's
  // right-hand side is its own base triangle's gradient (not a donor's or the identity).
  std::unique_ptr<detail::FoldZone> folds;
  RowMajor detailed;
  std::vector<char> own;
  std::vector<int> order;  // row k is vertex order[k] of the mesh
  std::vector<int> rank;   // and vertex i of the mesh is row rank[i]
  Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor> faces;  // sorted by their first row
  // Per-frame buffers, kept: a fresh allocation of this size costs its page faults each frame.
  RowMajor positions, face_normals, x;

  void build(const TriangleMesh& detailed, const Vertices& base,
             detail::AnchoredPoisson::Solves solves);  // all but the anchors
  void anchor(const std::vector<int>& vertices);       // factors
  // Adds to the right-hand side the difference the fold zone makes: on its faces the gradient
  // of s' + (x - s) instead of the base's; returns the zone's size.
  int correct_folds(const RowMajor& deformed, const RowMajor& normals, RowMajor& rhs) const;
};

// The background thread of a Transfer: builds the Poisson system, then factors the newest anchor
// set whenever one is pending (sets that arrive while it works replace each other: only the
// newest is factored).
struct DetailReconstruction::Background {
  void run(Poisson& poisson, TriangleMesh mesh, Vertices base) {
#if defined(__linux__)
    setpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)), kBackgroundNice);
#endif
    bool built = true;  // else `error` says why, for good
    try {
      poisson.build(mesh, base, detail::AnchoredPoisson::Solves::Many);
    } catch (...) {
      std::lock_guard lock(mutex);
      error = std::current_exception();
      built = false;
    }
    mesh = {};
    base.resize(0, 3);
    std::unique_lock lock(mutex);
    while (true) {
      wake.wait(lock, [&] { return stop || (built && pending); });
      if (stop) return;
      const std::vector<int> anchors = std::move(*pending);
      pending.reset();
      const long version = requested;
      lock.unlock();
      std::exception_ptr failed;
      try {
        poisson.anchor(anchors);
      } catch (...) {
        failed = std::current_exception();
      }
      lock.lock();
      error = failed;  // the last anchor set's (a singular system), cleared by the next
      if (version == requested) {
        done = version;
        if (on_ready && !error) on_ready();
      }
      wake.notify_all();
    }
  }

  std::mutex mutex;
  std::condition_variable wake;  // a new anchor set or stop (to the thread); done (to wait())
  std::optional<std::vector<int>> pending;  // the newest anchors, not yet taken
  long requested = 0, done = 0;             // anchor sets asked for, and the one factored
  bool stop = false;
  std::exception_ptr error;
  std::function<void()> on_ready;
  std::thread thread;

  ~Background() {  // waits for a factorisation under way
    {
      std::lock_guard lock(mutex);
      stop = true;
    }
    wake.notify_all();
    thread.join();
  }
};

namespace {

// out_i += sum_j A_ij x_j for the rows [begin, end) of A (CSR); x and out row-major, 3 columns.
using RowSparse = Eigen::SparseMatrix<double, Eigen::RowMajor>;
__attribute__((target_clones("avx2", "default"))) void add_product(const RowSparse& A,
                                                                   const double* x, int begin,
                                                                   int end, double* out) {
  const int* start = A.outerIndexPtr();
  const int* column = A.innerIndexPtr();
  const double* value = A.valuePtr();
  for (int i = begin; i < end; ++i) {
    double sum[3] = {out[3 * i], out[3 * i + 1], out[3 * i + 2]};
    for (int e = start[i]; e < start[i + 1]; ++e) {
      const double* xj = x + 3 * column[e];
      for (int d = 0; d < 3; ++d) sum[d] += value[e] * xj[d];
    }
    for (int d = 0; d < 3; ++d) out[3 * i + d] = sum[d];
  }
}

}  // namespace

DetailReconstruction::DetailReconstruction(const TriangleMesh& detailed, const Vertices& base,
                                           DetailMethod method, TransferSolves solves)
    : method_(method), applied_(method), faces_(detailed.F) {
  if (base.rows() != detailed.V.rows()) {
    throw InputError("details: the base has " + std::to_string(base.rows()) +
                     " vertices, the mesh " + std::to_string(detailed.V.rows()));
  }
  const Vertices offset = detailed.V - base;
  switch (method) {
    case DetailMethod::None:
      break;
    case DetailMethod::Displacement:
      details_ = offset;
      break;
    case DetailMethod::Frames: {
      // Each vertex's one-ring, except where the base's one-ring collapsed (as for the
      // transfer's triangles) or the mesh's own has no area (a vertex of zero-area faces alone:
      // its ring is a line, which fits no rotation): there the offset stays a displacement.
      const int n = detailed.num_vertices();
      const detail::VertexRings rings = detail::vertex_rings(detailed);
      const Eigen::VectorXd area = lumped_mass(detailed);
      const Eigen::VectorXd base_area = lumped_mass(TriangleMesh{base, faces_});
      ring_start_.assign(n + 1, 0);
      for (int i = 0; i < n; ++i) {
        if (area[i] > 0.0 && base_area[i] > kMinRelativeSize * kMinRelativeSize * area[i]) {
          ring_.insert(ring_.end(), rings.neighbour.begin() + rings.start[i],
                       rings.neighbour.begin() + rings.start[i + 1]);
        }
        ring_start_[i + 1] = static_cast<int>(ring_.size());
      }
      base_ = base;
      base_normals_ = vertex_normals(TriangleMesh{base, faces_});
      details_ = offset;
      folds_ = std::make_unique<detail::FoldZone>(faces_, base);
      break;
    }
    case DetailMethod::Transfer:
      poisson_ = std::make_unique<Poisson>();
      if (solves != TransferSolves::Background) {
        poisson_->build(detailed, base,
                        solves == TransferSolves::Once ? detail::AnchoredPoisson::Solves::One
                                                       : detail::AnchoredPoisson::Solves::Many);
        break;
      }
      details_ = offset;
      background_ = std::make_unique<Background>();
      background_->thread =
          std::thread([b = background_.get(), p = poisson_.get(), mesh = detailed, base]() mutable {
            b->run(*p, std::move(mesh), std::move(base));
          });
      break;
  }
}

void DetailReconstruction::Poisson::build(const TriangleMesh& detailed, const Vertices& base,
                                          detail::AnchoredPoisson::Solves solves) {
  Poisson& p = *this;
  const int nf = detailed.num_faces();
  const int n = detailed.num_vertices();
  const Sparse K = stiffness_matrix(detailed, LaplacianType::Cotan);
  // The factor's analysis (its ordering: 3.7 s at 2.77M vertices, one thread) beside what needs
  // no numbering: the rest's right-hand side G^T D G x (the mesh's own stiffness: degenerate
  // faces carry no gradient; equal to the system's where the mesh needs no mollification), the
  // donors and, per face of the mesh, P_f = Q_f B_d^-T of its donor d (f itself where its base
  // triangle is sound), or Q_f where S_f = I.
  Vertices rest_rhs;
  std::vector<int> donors;
  std::vector<Eigen::Matrix3d> P(nf);
  detail::run_pair(
      [&] { p.system = std::make_unique<detail::AnchoredPoisson>(K, solves); },
      [&] {
        rest_rhs = (mollification(detailed) == 0.0 ? K : cotan_stiffness(detailed)) * detailed.V;
        donors = transfer_donors(detailed, base);
        for (int f = 0; f < nf; ++f) {
          P[f] = detail::corner_gradients(corners(detailed.V, detailed.F, f));
          if (donors[f] >= 0) {
            P[f] *=
                detail::triangle_frame(corners(base, detailed.F, donors[f])).inverse().transpose();
          }
        }
      });
  p.order = p.system->order();
  p.rank.resize(n);
  for (int k = 0; k < n; ++k) p.rank[p.order[k]] = k;
  std::vector<int> face_order(nf), first(nf);
  for (int f = 0; f < nf; ++f) {
    face_order[f] = f;
    first[f] =
        std::min({p.rank[detailed.F(f, 0)], p.rank[detailed.F(f, 1)], p.rank[detailed.F(f, 2)]});
  }
  std::stable_sort(face_order.begin(), face_order.end(),
                   [&](int a, int b) { return first[a] < first[b]; });
  std::vector<int> slot(nf);  // face f of the mesh is face slot[f] here
  for (int g = 0; g < nf; ++g) slot[face_order[g]] = g;
  // The rows of `edges` and `normals` by counting: three entries and one per corner.
  p.faces.resize(nf, 3);
  p.constant = RowMajor::Zero(n, 3);
  std::vector<int> edge_start(n + 1, 0), normal_start(n + 1, 0);
  for (int g = 0; g < nf; ++g) {  // face g here is face f of the mesh
    const int f = face_order[g];
    for (int k = 0; k < 3; ++k) p.faces(g, k) = p.rank[detailed.F(f, k)];
    for (int r = 0; r < 3; ++r) {
      if (donors[f] < 0) {  // S_f = I
        p.constant.row(p.faces(g, r)) += P[f].row(r);
      } else {
        edge_start[p.faces(g, r) + 1] += 3;
        normal_start[p.faces(g, r) + 1] += 1;
      }
    }
  }
  for (int i = 0; i < n; ++i) {
    edge_start[i + 1] += edge_start[i];
    normal_start[i + 1] += normal_start[i];
  }
  std::vector<std::pair<int, double>> edges(edge_start[n]), normals(normal_start[n]);
  std::vector<int> edge_at(edge_start.begin(), edge_start.end() - 1);
  std::vector<int> normal_at(normal_start.begin(), normal_start.end() - 1);
  for (int g = 0; g < nf; ++g) {
    const int f = face_order[g];
    const int donor = donors[f];
    if (donor < 0) continue;
    const int a = p.rank[detailed.F(donor, 0)], b = p.rank[detailed.F(donor, 1)],
              c = p.rank[detailed.F(donor, 2)];
    for (int r = 0; r < 3; ++r) {  // P(r, :) [c' - a', b' - a', n']^T
      const int v = p.faces(g, r);
      edges[edge_at[v]++] = {c, P[f](r, 0)};
      edges[edge_at[v]++] = {b, P[f](r, 1)};
      edges[edge_at[v]++] = {a, -P[f](r, 0) - P[f](r, 1)};
      normals[normal_at[v]++] = {slot[donor], P[f](r, 2)};
    }
  }
  P = {};
  p.edges = compressed_rows(n, n, edge_start, edges);
  p.normals = compressed_rows(n, nf, normal_start, normals);
  RowMajor s(n, 3);
  p.detailed.resize(n, 3);
  for (int k = 0; k < n; ++k) {
    p.detailed.row(k) = detailed.V.row(p.order[k]);
    s.row(k) = base.row(p.order[k]);
    p.constant.row(k) -= rest_rhs.row(p.order[k]);
  }
  p.own.resize(nf);
  for (int g = 0; g < nf; ++g) p.own[g] = donors[face_order[g]] == face_order[g];
  p.folds = std::make_unique<detail::FoldZone>(p.faces, std::move(s));
}

int DetailReconstruction::Poisson::correct_folds(const RowMajor& deformed, const RowMajor& normals,
                                                 RowMajor& rhs) const {
  const std::vector<int> zone = folds->find(deformed, normals);
  for (const int f : zone) {
    if (!own[f]) continue;
    Eigen::Matrix3d x, s, s_deformed;
    for (int k = 0; k < 3; ++k) {
      x.row(k) = detailed.row(faces(f, k));
      s.row(k) = folds->base().row(faces(f, k));
      s_deformed.row(k) = deformed.row(faces(f, k));
    }
    const Eigen::Matrix3d rest_frame = detail::triangle_frame(x);
    if (rest_frame.determinant() == 0.0) continue;
    Eigen::Matrix3d base_frame = detail::triangle_frame(s_deformed);
    base_frame.col(2) = normals.row(f).transpose();  // as the right-hand side has it
    const Eigen::Matrix3d change =
        detail::corner_gradients(x) *
        (rest_frame.inverse().transpose() * detail::triangle_frame(s_deformed + x - s).transpose() -
         detail::triangle_frame(s).inverse().transpose() * base_frame.transpose());
    for (int k = 0; k < 3; ++k) rhs.row(faces(f, k)) += change.row(k);
  }
  return static_cast<int>(zone.size());
}

DetailReconstruction::~DetailReconstruction() = default;

void DetailReconstruction::Poisson::anchor(const std::vector<int>& vertices) {
  Poisson& p = *this;
  p.anchors.resize(vertices.size());
  for (size_t i = 0; i < vertices.size(); ++i) p.anchors[i] = p.rank[vertices[i]];
  const int n = static_cast<int>(p.order.size());
  std::vector<char> anchored(n, 0);
  for (const int v : vertices) anchored[v] = 1;
  p.system->set_anchors(vertices);
  const Sparse& K = p.system->stiffness();  // in the mesh's numbering
  std::vector<Eigen::Triplet<double>> coupling;
  for (size_t i = 0; i < vertices.size(); ++i) {
    for (Sparse::InnerIterator it(K, vertices[i]); it; ++it) {
      if (!anchored[it.row()]) {
        coupling.emplace_back(p.rank[it.row()], static_cast<int>(i), it.value());
      }
    }
  }
  p.coupling.resize(n, static_cast<int>(vertices.size()));
  p.coupling.setFromTriplets(coupling.begin(), coupling.end());
}

void DetailReconstruction::set_anchors(const std::vector<int>& vertices) {
  if (method_ != DetailMethod::Transfer) return;
  if (!background_) return poisson_->anchor(vertices);
  {
    std::lock_guard lock(background_->mutex);
    background_->pending = vertices;
    ++background_->requested;
  }
  background_->wake.notify_all();
}

bool DetailReconstruction::ready() const {
  if (!background_) return true;
  std::lock_guard lock(background_->mutex);
  if (background_->error) std::rethrow_exception(background_->error);
  return background_->done == background_->requested;
}

void DetailReconstruction::wait() const {
  if (!background_) return;
  std::unique_lock lock(background_->mutex);
  background_->wake.wait(
      lock, [&] { return background_->error || background_->done == background_->requested; });
  if (background_->error) std::rethrow_exception(background_->error);
}

void DetailReconstruction::on_ready(std::function<void()> callback) {
  if (!background_) return;
  std::lock_guard lock(background_->mutex);
  background_->on_ready = std::move(callback);
}

Vertices DetailReconstruction::apply(const Vertices& s, const Eigen::MatrixX3d& anchors) {
  Vertices out;
  apply(s, anchors, out);
  return out;
}

void DetailReconstruction::apply(const Vertices& s, const Eigen::MatrixX3d& anchors,
                                 Vertices& out) {
  applied_ = method_;
  fold_zone_ = 0;
  switch (method_) {
    case DetailMethod::None:
      out = s;
      return;
    case DetailMethod::Displacement:
      out = s + details_;
      return;
    case DetailMethod::Frames: {
      const auto normals = vertex_normals(TriangleMesh{s, faces_});
      const detail::RowVertices deformed = s;
      detail::RowVertices face_normals;
      detail::unit_face_normals(folds_->faces(), deformed, face_normals);
      const std::vector<int> zone = folds_->find(deformed, face_normals);
      fold_zone_ = static_cast<int>(zone.size());
      std::vector<char> unturned(s.rows(), 0);
      for (const int f : zone)
        for (int k = 0; k < 3; ++k) unturned[faces_(f, k)] = 1;
      out.resize(s.rows(), 3);
      detail::split_in_two(s.rows(), [&](Eigen::Index begin, Eigen::Index end) {
        for (Eigen::Index i = begin; i < end; ++i) {
          const int size = ring_start_[i + 1] - ring_start_[i];
          out.row(i) = s.row(i);
          if (size == 0 || unturned[i]) {
            out.row(i) += details_.row(i);
          } else {
            out.row(i) += (ring_rotation(base_, s, base_normals_, normals,
                                         ring_.data() + ring_start_[i], size, static_cast<int>(i)) *
                           details_.row(i).transpose())
                              .transpose();
          }
        }
      });
      return;
    }
    case DetailMethod::Transfer:
      if (!ready()) {
        applied_ = DetailMethod::Displacement;
        out = s + details_;
        return;
      }
      break;
  }
  Poisson& p = *poisson_;
  if (anchors.rows() != static_cast<Eigen::Index>(p.anchors.size())) {
    throw InputError("deformation transfer: anchor positions do not match the anchors");
  }
  const int n = static_cast<int>(s.rows());
  RowMajor& positions = p.positions;
  RowMajor& normals = p.face_normals;
  RowMajor& x = p.x;  // the right-hand side, then the solution
  positions.resize(n, 3);
  x.resize(p.system->workspace_rows(), 3);
  detail::split_in_two(n, [&](Eigen::Index begin, Eigen::Index end) {
    for (Eigen::Index k = begin; k < end; ++k) positions.row(k) = s.row(p.order[k]);
  });
  detail::unit_face_normals(p.faces, positions, normals);
  detail::split_in_two(n, [&](Eigen::Index begin, Eigen::Index end) {
    x.middleRows(begin, end - begin) = p.constant.middleRows(begin, end - begin);
    add_product(p.edges, positions.data(), begin, end, x.data());
    add_product(p.normals, normals.data(), begin, end, x.data());
  });
  fold_zone_ = p.correct_folds(positions, normals, x);
  for (int i = 0; i < p.coupling.outerSize(); ++i) {
    const Eigen::RowVector3d moved = anchors.row(i) - p.detailed.row(p.anchors[i]);
    for (Sparse::InnerIterator it(p.coupling, i); it; ++it) x.row(it.row()) -= it.value() * moved;
  }
  for (size_t i = 0; i < p.anchors.size(); ++i)
    x.row(p.anchors[i]) = anchors.row(i) - p.detailed.row(p.anchors[i]);
  p.system->solve_in_place(x.data());
  out.resize(n, 3);
  detail::split_in_two(n, [&](Eigen::Index begin, Eigen::Index end) {
    for (Eigen::Index k = begin; k < end; ++k) out.row(p.order[k]) = p.detailed.row(k) + x.row(k);
  });
}

}  // namespace specdeform
