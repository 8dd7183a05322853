#include "linalg/locality_order.h"

#include <algorithm>
#include <utility>
#include <vector>

#include "linalg/huge_pages.h"
#include "linalg/parallel.h"

namespace specdeform::detail {

Permutation breadth_first_order(const Eigen::SparseMatrix<double>& A) {
  if (!A.isCompressed()) {
    Eigen::SparseMatrix<double> B = A;
    B.makeCompressed();
    return breadth_first_order(B);
  }
  return breadth_first_order(static_cast<int>(A.rows()), A.outerIndexPtr(), A.innerIndexPtr());
}

Permutation breadth_first_order(int n, const int* start, const int* neighbour) {
  Permutation P(n);
  std::vector<int> order;
  order.reserve(n);
  std::vector<char> seen(n, 0);
  for (int root = 0; root < n; ++root) {
    if (seen[root]) continue;
    seen[root] = 1;
    order.push_back(root);
    for (size_t head = order.size() - 1; head < order.size(); ++head) {  // order is the queue
      for (int e = start[order[head]]; e < start[order[head] + 1]; ++e) {
        const int j = neighbour[e];
        if (!seen[j]) {
          seen[j] = 1;
          order.push_back(j);
        }
      }
    }
  }
  for (int k = 0; k < n; ++k) P.indices()[order[k]] = k;
  return P;
}

Eigen::SparseMatrix<double> renumbered(const Eigen::SparseMatrix<double>& A, const Permutation& P) {
  const int n = static_cast<int>(A.cols());
  const int* to = P.indices().data();
  Eigen::SparseMatrix<double> B(A.rows(), n);
  B.resizeNonZeros(A.nonZeros());
  advise_huge_pages(B);
  int* start = B.outerIndexPtr();
  start[0] = 0;
  for (int j = 0; j < n; ++j) start[to[j] + 1] = A.outerIndexPtr()[j + 1] - A.outerIndexPtr()[j];
  for (int c = 0; c < n; ++c) start[c + 1] += start[c];
  std::vector<std::pair<int, double>> column;
  for (int j = 0; j < n; ++j) {
    column.clear();
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, j); it; ++it)
      column.emplace_back(to[it.index()], it.value());
    std::sort(column.begin(), column.end());
    int at = start[to[j]];
    for (const auto& [row, value] : column) {
      B.innerIndexPtr()[at] = row;
      B.valuePtr()[at++] = value;
    }
  }
  return B;
}

void permute_rows_back(const Permutation& P, Eigen::MatrixXd& X) {
  const int* to = P.indices().data();
  split_in_two(X.cols(), [&](Eigen::Index begin, Eigen::Index end) {
    Eigen::VectorXd column(X.rows());
    for (Eigen::Index j = begin; j < end; ++j) {
      column = X.col(j);
      double* x = X.col(j).data();
      for (Eigen::Index i = 0; i < X.rows(); ++i) x[i] = column[to[i]];
    }
  });
}

void permute_rows_back(const Permutation& P, Eigen::SparseMatrix<double, Eigen::RowMajor>& X) {
  const int* to = P.indices().data();
  const Eigen::Index n = X.rows();
  if (!X.isCompressed()) X.makeCompressed();
  const int* start = X.outerIndexPtr();
  Eigen::SparseMatrix<double, Eigen::RowMajor> out(n, X.cols());
  int* out_start = out.outerIndexPtr();
  out_start[0] = 0;
  for (Eigen::Index i = 0; i < n; ++i)
    out_start[i + 1] = out_start[i] + start[to[i] + 1] - start[to[i]];
  out.resizeNonZeros(out_start[n]);
  advise_huge_pages(out);
  split_in_two(n, [&](Eigen::Index begin, Eigen::Index end) {
    for (Eigen::Index i = begin; i < end; ++i) {
      const int from = start[to[i]], size = start[to[i] + 1] - from;
      std::copy_n(X.innerIndexPtr() + from, size, out.innerIndexPtr() + out_start[i]);
      std::copy_n(X.valuePtr() + from, size, out.valuePtr() + out_start[i]);
    }
  });
  X.swap(out);  // Eigen's sparse matrices have no moves
}

}  // namespace specdeform::detail
