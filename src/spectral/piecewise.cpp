#include "spectral/piecewise.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "linalg/basis_product.h"

namespace specdeform::detail {

using Sparse = Eigen::SparseMatrix<double>;

namespace {

// The rows and columns `index` of A (index[k] = the vertex of the piece's k-th unknown; `local`
// maps the vertices of the piece back, -1 elsewhere).
Sparse restricted(const Sparse& A, const std::vector<int>& index, const std::vector<int>& local) {
  std::vector<Eigen::Triplet<double>> entries;
  for (size_t k = 0; k < index.size(); ++k) {
    for (Sparse::InnerIterator it(A, index[k]); it; ++it) {
      const int row = local[it.row()];
      if (row >= 0) entries.emplace_back(row, static_cast<int>(k), it.value());
    }
  }
  Sparse out(static_cast<Eigen::Index>(index.size()), static_cast<Eigen::Index>(index.size()));
  out.setFromTriplets(entries.begin(), entries.end());
  return out;
}

}  // namespace

std::vector<int> piece_modes(const std::vector<double>& area, const std::vector<int>& vertices,
                             int m, const ManifoldHarmonicsPolicy& policy) {
  const size_t count = area.size();
  const double total = std::accumulate(area.begin(), area.end(), 0.0);
  std::vector<int> modes(count);
  long long sum = 0;
  for (size_t i = 0; i < count; ++i) {
    const int share = static_cast<int>(std::lround(m * area[i] / total));
    modes[i] =
        std::min(vertices[i], std::max(share, std::min(policy.piece_min_modes, vertices[i])));
    sum += modes[i];
  }
  const double rows = std::accumulate(vertices.begin(), vertices.end(), 0.0);
  const long long limit = std::max<long long>(
      m, std::min(static_cast<long long>(policy.piece_modes_limit) * m,
                  static_cast<long long>(policy.piece_basis_bytes / (8.0 * std::max(rows, 1.0)))));
  std::vector<size_t> by_area(count);
  std::iota(by_area.begin(), by_area.end(), size_t{0});
  std::stable_sort(by_area.begin(), by_area.end(),
                   [&](size_t a, size_t b) { return area[a] < area[b]; });
  for (size_t k = 0; k < count && sum > limit; ++k) {
    sum -= modes[by_area[k]] - 1;
    modes[by_area[k]] = 1;
  }
  for (size_t k = 0; k < count && sum > limit; ++k) {
    --sum;
    modes[by_area[k]] = 0;
  }
  return modes;
}

Spectrum solve_by_piece(const Sparse& K, const Sparse& M, const Sparse* lengths,
                        const std::vector<int>& label, int count, const ManifoldHarmonicsOptions& o,
                        const ConnectedSolver& solve) {
  const int n = static_cast<int>(K.rows());
  std::vector<std::vector<int>> index(count);
  for (int v = 0; v < n; ++v) index[label[v]].push_back(v);
  const Eigen::VectorXd row_sums = M * Eigen::VectorXd::Ones(n);
  std::vector<double> area(count, 0.0);
  std::vector<int> vertices(count);
  for (int c = 0; c < count; ++c) {
    for (const int v : index[c]) area[c] += row_sums[v];
    vertices[c] = static_cast<int>(index[c].size());
  }
  const std::vector<int> modes = piece_modes(area, vertices, o.num_modes, o.policy);
  struct Pair {
    double lambda;
    int piece, column;
  };
  std::vector<Pair> pairs;
  std::vector<Spectrum> spectra(count);
  std::vector<int> local(n, -1);
  Spectrum out;
  int done = 0;
  for (int c = 0; c < count; ++c) {
    for (int k = 0; k < vertices[c]; ++k) local[index[c][k]] = k;
    if (modes[c] == 0) {
      done += vertices[c];
      continue;
    }
    ManifoldHarmonicsOptions piece = o;
    piece.num_modes = modes[c];
    if (o.progress) {
      piece.progress = [&, c](double fraction, std::string_view stage) {
        o.progress((done + fraction * vertices[c]) / n, stage);
      };
    }
    const Sparse piece_lengths = lengths ? restricted(*lengths, index[c], local) : Sparse();
    Spectrum s = solve(restricted(K, index[c], local), restricted(M, index[c], local) / area[c],
                       lengths ? &piece_lengths : nullptr, piece);
    for (const int v : index[c]) local[v] = -1;
    done += vertices[c];
    if (!s.factored.empty()) {  // pieces are gathered into one H
      s.H = factored_product(s.factored, std::move(s.H));
    }
    // From the piece's unit-area scale to M's: K h = (lambda / a) M h, h^T M h = a.
    s.lambda /= area[c];
    s.H /= std::sqrt(area[c]);
    for (int j = 0; j < s.lambda.size(); ++j) pairs.push_back({s.lambda[j], c, j});
    if (s.status != SolveStatus::Converged) out.status = SolveStatus::NotConverged;
    out.bands += s.bands;
    out.restarts += s.restarts;
    out.solves += s.solves;
    out.cluster_truncated = out.cluster_truncated || s.cluster_truncated;
    out.coarse_functions += s.coarse_functions;
    spectra[c] = std::move(s);
  }
  std::stable_sort(pairs.begin(), pairs.end(),
                   [](const Pair& a, const Pair& b) { return a.lambda < b.lambda; });
  out.lambda.resize(static_cast<Eigen::Index>(pairs.size()));
  out.H = Eigen::MatrixXd::Zero(n, static_cast<Eigen::Index>(pairs.size()));
  for (size_t j = 0; j < pairs.size(); ++j) {
    const Pair& p = pairs[j];
    out.lambda[j] = p.lambda;
    const Eigen::MatrixXd& H = spectra[p.piece].H;
    for (size_t k = 0; k < index[p.piece].size(); ++k)
      out.H(index[p.piece][k], j) = H(static_cast<Eigen::Index>(k), p.column);
  }
  return out;
}

}  // namespace specdeform::detail
