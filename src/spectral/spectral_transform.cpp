#include "specdeform/spectral/spectral_transform.h"

#include <string>

#include "specdeform/exceptions.h"

namespace specdeform {

Eigen::MatrixXd harmonics_forward(const Eigen::MatrixXd& H, const Eigen::SparseMatrix<double>& M,
                                  const Eigen::MatrixXd& X) {
  if (X.rows() != H.rows() || M.rows() != H.rows()) {
    throw InputError("manifold harmonics transform: the signal has " + std::to_string(X.rows()) +
                     " rows, the basis " + std::to_string(H.rows()));
  }
  return H.transpose() * (M * X);
}

Eigen::MatrixXd harmonics_inverse(const Eigen::MatrixXd& H, const Eigen::MatrixXd& C, int k) {
  const int m = static_cast<int>(H.cols());
  if (k < 0) k = m;
  if (k > m || C.rows() < k) {
    throw InputError("inverse manifold harmonics transform: asked for " + std::to_string(k) +
                     " frequencies, have " + std::to_string(std::min<int>(m, C.rows())));
  }
  return H.leftCols(k) * C.topRows(k);
}

Eigen::MatrixXd spectral_filter(const Eigen::MatrixXd& H, const Eigen::SparseMatrix<double>& M,
                                const Eigen::MatrixXd& X, const Eigen::VectorXd& gains,
                                double residual_gain) {
  if (gains.size() != H.cols()) {
    throw InputError("spectral filter: " + std::to_string(gains.size()) + " gains for " +
                     std::to_string(H.cols()) + " frequencies");
  }
  const Eigen::MatrixXd C = harmonics_forward(H, M, X);
  Eigen::MatrixXd out = H * (gains.asDiagonal() * C);
  if (residual_gain != 0.0) out += residual_gain * (X - H * C);
  return out;
}

Eigen::VectorXd band_gains(const Eigen::VectorXd& eigenvalues,
                           const std::vector<FrequencyBand>& bands) {
  Eigen::VectorXd g = Eigen::VectorXd::Ones(eigenvalues.size());
  for (Eigen::Index i = 0; i < eigenvalues.size(); ++i) {
    for (const FrequencyBand& band : bands) {
      if (eigenvalues[i] <= band.max_eigenvalue) {
        g[i] = band.gain;
        break;
      }
    }
  }
  return g;
}

}  // namespace specdeform
