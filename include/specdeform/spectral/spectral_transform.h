// The manifold harmonics transform and spectral filters (Vallet & Levy 2008; Rong, Cao & Guo
// 2008, eqs. 7-8).
//
// For a basis H (n x m, H^T M H = I) and a signal X (n x d, e.g. the vertex positions, d = 3):
//   forward:  C = H^T M X                      (m x d, paper eq. 7 with M lumped)
//   inverse:  X_k = H_k C_k                    (first k <= m coefficients, eq. 8)
//   filter:   X' = H diag(g) C + r (X - H C)   (gains g per frequency, r for the frequencies
//                                               above lambda_m that H does not represent)
// The low-pass reconstruction from all m frequencies is filter(g = 1, r = 0).
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Sparse>

namespace specdeform {

Eigen::MatrixXd harmonics_forward(const Eigen::MatrixXd& H, const Eigen::SparseMatrix<double>& M,
                                  const Eigen::MatrixXd& X);

// k = -1 uses all m coefficients. Throws InputError for k outside [0, m].
Eigen::MatrixXd harmonics_inverse(const Eigen::MatrixXd& H, const Eigen::MatrixXd& C, int k = -1);

Eigen::MatrixXd spectral_filter(const Eigen::MatrixXd& H, const Eigen::SparseMatrix<double>& M,
                                const Eigen::MatrixXd& X, const Eigen::VectorXd& gains,
                                double residual_gain = 0.0);

// A piecewise-constant response: frequency i gets the gain of the first band whose upper edge
// `max_eigenvalue` is >= lambda_i (1 beyond the last band).
struct FrequencyBand {
  double max_eigenvalue;
  double gain;
};
Eigen::VectorXd band_gains(const Eigen::VectorXd& eigenvalues,
                           const std::vector<FrequencyBand>& bands);

}  // namespace specdeform
