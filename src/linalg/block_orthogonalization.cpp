#include "linalg/block_orthogonalization.h"

#include <algorithm>
#include <cmath>

#include "specdeform/exceptions.h"

namespace specdeform::detail {

using Mat = Eigen::MatrixXd;
using Vec = Eigen::VectorXd;

Mat random_block(int rows, int cols, std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  Mat X(rows, cols);
  for (Eigen::Index j = 0; j < X.size(); ++j) X.data()[j] = normal(rng);
  return X;
}

void project_out(Mat& W, std::initializer_list<Basis> against, const MassOperator& M) {
  if (std::all_of(against.begin(), against.end(), [](const Basis& B) { return B.cols() == 0; }))
    return;
  Vec before = M.norms(W);
  for (int pass = 0; pass < 2; ++pass) {
    for (const Basis& B : against) {  // B^T M W, with M applied to the thinner of the two
      if (B.cols() == 0) continue;
      const Mat C =
          B.cols() < W.cols() ? Mat(M.apply(B).transpose() * W) : Mat(B.transpose() * M.apply(W));
      W.noalias() -= B * C;
    }
    const Vec after = M.norms(W);
    if ((after.array() > 0.5 * before.array()).all()) break;
    before = after;
  }
}

void column_gram_schmidt(Mat& W, const MassOperator& M, double vanish, Mat& R,
                         const std::function<void(int)>& replace) {
  R.setZero();
  const auto norm = [&](int j) {
    return std::sqrt(std::max(0.0, W.col(j).dot(M.apply(W.col(j)).col(0))));
  };
  for (int j = 0; j < W.cols(); ++j) {
    const double norm0 = norm(j);
    for (int pass = 0; pass < 2 && j > 0; ++pass) {
      const Vec c = W.leftCols(j).transpose() * M.apply(W.col(j)).col(0);
      W.col(j) -= W.leftCols(j) * c;
      R.col(j).head(j) += c;
    }
    const double left = norm(j);
    if (left > vanish * norm0 && left > 0.0) {
      R(j, j) = left;
      W.col(j) /= left;
    } else {
      R.col(j).setZero();
      replace(j);
    }
  }
}

void orthonormalize(Mat& W, std::initializer_list<Basis> against, const MassOperator& M,
                    std::mt19937_64& rng) {
  for (int attempt = 0; attempt < 3; ++attempt) {
    project_out(W, against, M);
    Mat R = Mat::Identity(W.cols(), W.cols());
    if (cholesky_qr2(W, M, R)) return;
    bool replaced = false;
    column_gram_schmidt(W, M, 1e-8, R, [&](int j) {
      W.col(j) = random_block(static_cast<int>(W.rows()), 1, rng);
      replaced = true;
    });
    if (!replaced) return;
  }
  throw SolverError("cannot extend the Krylov basis (the problem is smaller than the basis)");
}

}  // namespace specdeform::detail
