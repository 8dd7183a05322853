#include "specdeform/deform/detail_reconstruction.h"

#include <Eigen/CholmodSupport>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include "anchored_poisson.h"
#include "parallel.h"
#include "specdeform/exceptions.h"
#include "specdeform/operators/cotan_laplacian.h"

namespace specdeform {

namespace {

using Sparse = Eigen::SparseMatrix<double>;

// Orthonormal frame (tangent, bitangent, normal) as the columns of a 3 x 3 matrix; the zero
// matrix where the normal or the tangent is undefined.
Eigen::Matrix3d vertex_frame(const Eigen::Vector3d& normal, const Eigen::Vector3d& edge) {
  const Eigen::Vector3d t = edge - edge.dot(normal) * normal;
  if (normal.squaredNorm() == 0.0 || t.norm() <= 1e-12 * edge.norm()) {
    return Eigen::Matrix3d::Zero();
  }
  Eigen::Matrix3d frame;
  frame.col(0) = t.normalized();
  frame.col(2) = normal;
  frame.col(1) = normal.cross(frame.col(0));
  return frame;
}

// [c - a, b - a, n] of triangle f, n the unit normal (zero for a degenerate triangle).
Eigen::Matrix3d triangle_frame(const Vertices& V, const Faces& F, int f) {
  const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
  Eigen::Matrix3d m;
  m.col(0) = c - a;
  m.col(1) = b - a;
  const Eigen::Vector3d n = (b - a).cross(c - a);
  m.col(2) = n.norm() > 0.0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::Zero();
  return m;
}

}  // namespace

struct DetailReconstruction::Poisson {
  // Per triangle f, with B_f = [c - a, b - a, n] of the base and
  // Q_f = A_f [grad phi_a; grad phi_b; grad phi_c] [grad x, grad y, grad z] (corners by
  // coordinates): the Poisson right-hand side of the transferred gradients J_f S_f^T,
  // S_f = B'_f B_f^-1, is the scatter over the corners of Q_f S_f^T = P_f B'_f^T with
  // P_f = Q_f B_f^-T. Where the base's triangle is degenerate, S_f = I and P_f holds Q_f.
  std::vector<Eigen::Matrix3d> transfer;  // P_f (or Q_f)
  std::vector<char> identity;             // 1 where S_f = I
  Sparse K;                               // cotangent stiffness of the detailed mesh
  Sparse coupling;                        // n x n': K's columns of the anchors, anchor rows zeroed
  std::vector<int> anchors;
  std::unique_ptr<detail::AnchoredPoisson> system;
};

namespace {

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

// Adds, for triangles [begin, end), the Poisson right-hand side of the transferred gradients:
// S_f maps the base's triangle to the deformed one (positions), and the corners' share of the
// divergence of the transformed detail gradients is Q_f S_f^T (J' = J S^T).
// Compiled for AVX2 as well, chosen at run time: no -march flag is needed.
__attribute__((target_clones("avx2", "default"))) void accumulate_divergence(
    const DetailReconstruction::Poisson& p, const Faces& faces, const RowMajor& positions,
    int begin, int end, RowMajor& out) {
  for (int f = begin; f < end; ++f) {
    const int a = faces(f, 0), b = faces(f, 1), c = faces(f, 2);
    Eigen::Matrix3d C = p.transfer[f];
    if (!p.identity[f]) {
      Eigen::Matrix3d frame;
      frame.col(0) = (positions.row(c) - positions.row(a)).transpose();
      frame.col(1) = (positions.row(b) - positions.row(a)).transpose();
      const Eigen::Vector3d normal = frame.col(1).cross(frame.col(0));
      const double length = normal.norm();
      frame.col(2) = length > 0.0 ? Eigen::Vector3d(normal / length) : Eigen::Vector3d::Zero();
      C = p.transfer[f] * frame.transpose();
    }
    out.row(a) += C.row(0);
    out.row(b) += C.row(1);
    out.row(c) += C.row(2);
  }
}

}  // namespace

DetailReconstruction::DetailReconstruction(const TriangleMesh& detailed, const Vertices& base,
                                           DetailMethod method)
    : method_(method), faces_(detailed.F) {
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
      const int n = detailed.num_vertices();
      frame_neighbour_.assign(n, -1);
      for (int f = detailed.num_faces() - 1; f >= 0; --f)  // ends with the first incident face
        for (int k = 0; k < 3; ++k) frame_neighbour_[faces_(f, k)] = faces_(f, (k + 1) % 3);
      const auto normals = vertex_normals(TriangleMesh{base, faces_});
      details_.resize(n, 3);
      for (int i = 0; i < n; ++i) {
        const Eigen::Matrix3d frame =
            vertex_frame(normals.row(i), (base.row(frame_neighbour_[i]) - base.row(i)).transpose());
        // Where no frame exists the offset is kept as a plain displacement.
        details_.row(i) = frame.isZero() ? Eigen::RowVector3d(offset.row(i))
                                         : Eigen::RowVector3d(offset.row(i) * frame);
      }
      break;
    }
    case DetailMethod::Transfer: {
      poisson_ = std::make_unique<Poisson>();
      Poisson& p = *poisson_;
      const Sparse G = gradient_operator(detailed);
      const Eigen::VectorXd areas = face_areas(detailed);
      const Eigen::MatrixX3d J = G * detailed.V;  // rows 3f..3f+2: gradients of x, y, z
      const int nf = detailed.num_faces();
      p.transfer.resize(nf);
      p.identity.resize(nf);
      for (int f = 0; f < nf; ++f) {
        const Eigen::Matrix3d m = triangle_frame(base, faces_, f);
        bool invertible = false;
        Eigen::Matrix3d inv = Eigen::Matrix3d::Zero();
        m.computeInverseWithCheck(inv, invertible, 1e-300);
        Eigen::Matrix3d corners = Eigen::Matrix3d::Zero();  // rows: corners, columns: x, y, z
        for (int k = 0; k < 3; ++k)
          for (int d = 0; d < 3; ++d) corners(k, d) = G.coeff(3 * f + d, faces_(f, k));
        const Eigen::Matrix3d Q = areas[f] * corners * J.middleRows<3>(3 * f);
        p.identity[f] = !(invertible && m.col(2).squaredNorm() > 0);
        p.transfer[f] = p.identity[f] ? Q : Eigen::Matrix3d(Q * inv.transpose());
      }
      p.K = cotan_stiffness(detailed);
      p.system = std::make_unique<detail::AnchoredPoisson>(p.K);
      break;
    }
  }
}

DetailReconstruction::~DetailReconstruction() = default;
DetailReconstruction::DetailReconstruction(DetailReconstruction&&) noexcept = default;
DetailReconstruction& DetailReconstruction::operator=(DetailReconstruction&&) noexcept = default;

void DetailReconstruction::set_anchors(const std::vector<int>& vertices) {
  if (method_ != DetailMethod::Transfer) return;
  Poisson& p = *poisson_;
  p.anchors = vertices;
  std::vector<char> anchored(p.K.rows(), 0);
  for (const int v : vertices) anchored[v] = 1;
  p.system->set_anchors(vertices);
  std::vector<Eigen::Triplet<double>> coupling;
  for (size_t i = 0; i < vertices.size(); ++i) {
    for (Sparse::InnerIterator it(p.K, vertices[i]); it; ++it) {
      if (!anchored[it.row()]) coupling.emplace_back(it.row(), static_cast<int>(i), it.value());
    }
  }
  p.coupling.resize(p.K.rows(), static_cast<int>(vertices.size()));
  p.coupling.setFromTriplets(coupling.begin(), coupling.end());
}

Vertices DetailReconstruction::apply(const Vertices& s, const Eigen::MatrixX3d& anchors) const {
  switch (method_) {
    case DetailMethod::None:
      return s;
    case DetailMethod::Displacement:
      return s + details_;
    case DetailMethod::Frames: {
      const auto normals = vertex_normals(TriangleMesh{s, faces_});
      Vertices out(s.rows(), 3);
      for (Eigen::Index i = 0; i < s.rows(); ++i) {
        const Eigen::Matrix3d frame =
            vertex_frame(normals.row(i), (s.row(frame_neighbour_[i]) - s.row(i)).transpose());
        out.row(i) =
            s.row(i) + (frame.isZero() ? Eigen::RowVector3d(details_.row(i))
                                       : Eigen::RowVector3d(details_.row(i) * frame.transpose()));
      }
      return out;
    }
    case DetailMethod::Transfer:
      break;
  }
  const Poisson& p = *poisson_;
  if (anchors.rows() != static_cast<Eigen::Index>(p.anchors.size())) {
    throw InputError("deformation transfer: anchor positions do not match the anchors");
  }
  const RowMajor positions = s;  // contiguous rows for the per-triangle gathers
  // Two halves of the triangles on two threads, each into its own buffer.
  const int nf = static_cast<int>(faces_.rows());
  RowMajor halves[2] = {RowMajor::Zero(s.rows(), 3), RowMajor::Zero(s.rows(), 3)};
  detail::split_in_two(nf, [&](Eigen::Index begin, Eigen::Index end) {
    accumulate_divergence(p, faces_, positions, static_cast<int>(begin), static_cast<int>(end),
                          halves[begin == 0 ? 0 : 1]);
  });
  Eigen::MatrixX3d rhs = halves[0] + halves[1];
  rhs -= p.coupling * anchors;
  for (size_t i = 0; i < p.anchors.size(); ++i) rhs.row(p.anchors[i]) = anchors.row(i);
  return p.system->solve(rhs);
}

}  // namespace specdeform
