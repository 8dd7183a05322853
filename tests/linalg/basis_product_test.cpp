#include "linalg/basis_product.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include <Eigen/Sparse>

#include "specdeform/exceptions.h"

namespace specdeform {
namespace {

// base + H C against Eigen's product, for both bases and both outputs: row counts that are not a
// multiple of the blocks (and one smaller than a block), and rows of floats with a padded stride.
TEST(BasisProduct, MatchesEigensProduct) {
  for (const int n : {1, 37, 256, 1000, 4097}) {
    const Eigen::MatrixXd H = Eigen::MatrixXd::Random(n, 13);
    const Eigen::MatrixXf H32 = H.cast<float>();
    const Eigen::MatrixX3d base = Eigen::MatrixX3d::Random(n, 3),
                           C = Eigen::MatrixX3d::Random(13, 3);
    const Eigen::MatrixX3d expected = base + H * C;
    const Eigen::MatrixX3d expected32 = base + H32.cast<double>() * C;
    Eigen::MatrixX3d out;
    detail::add_basis_product(base, H, C, out);
    EXPECT_LT((out - expected).cwiseAbs().maxCoeff(), 1e-12) << n;
    detail::add_basis_product(base, H32, C, out);
    EXPECT_LT((out - expected32).cwiseAbs().maxCoeff(), 1e-12) << n;
    Eigen::Matrix<float, Eigen::Dynamic, 4, Eigen::RowMajor> padded =
        Eigen::Matrix<float, Eigen::Dynamic, 4, Eigen::RowMajor>::Constant(n, 4, 7.0f);
    Eigen::Map<FloatVertices, 0, Eigen::OuterStride<>> rows(padded.data(), n, 3,
                                                            Eigen::OuterStride<>(4));
    detail::add_basis_product(base, H, C, rows);
    EXPECT_LT((rows.cast<double>() - expected).cwiseAbs().maxCoeff(), 1e-5) << n;
    detail::add_basis_product(base, H32, C, rows);
    EXPECT_LT((rows.cast<double>() - expected32).cwiseAbs().maxCoeff(), 1e-5) << n;
    EXPECT_TRUE((padded.col(3).array() == 7.0f).all()) << n;  // the padding left alone
  }
  FloatVertices wrong(3, 3);
  const Eigen::MatrixXd H = Eigen::MatrixXd::Zero(4, 2);
  EXPECT_THROW(detail::add_basis_product(Eigen::MatrixX3d::Zero(4, 3), H,
                                         Eigen::MatrixX3d::Zero(2, 3), wrong),
               InputError);
}

// A factored basis H = P Z: base + P (Z C) against the product of the dense H, into both
// outputs; P Z itself against Eigen's; sizes that do not match are refused.
TEST(BasisProduct, FactoredMatchesTheDenseBasis) {
  for (const int n : {1, 37, 1000, 4097}) {
    const int N = std::max(1, n / 10);
    std::vector<Eigen::Triplet<double>> entries;
    for (int i = 0; i < n; ++i) {
      for (int k = 0; k < 5; ++k) entries.emplace_back(i, (7 * i + 3 * k) % N, 0.1 + 0.2 * k);
    }
    FactoredBasis f;
    f.prolongation.resize(n, N);
    f.prolongation.setFromTriplets(entries.begin(), entries.end());
    f.prolongation.makeCompressed();
    f.coarse = Eigen::MatrixXd::Random(N, 13);
    const Eigen::MatrixXd H = f.prolongation * f.coarse;
    EXPECT_LT((detail::factored_product(f) - H).cwiseAbs().maxCoeff(), 1e-12) << n;
    Eigen::MatrixXd storage = Eigen::MatrixXd::Constant(n, 13, 7.0);  // H's memory, reused
    const double* memory = storage.data();
    const Eigen::MatrixXd into = detail::factored_product(f, std::move(storage));
    EXPECT_EQ(into.data(), memory) << n;
    EXPECT_LT((into - H).cwiseAbs().maxCoeff(), 1e-12) << n;
    const Eigen::MatrixXd beside = detail::factored_product(f, Eigen::MatrixXd::Zero(n + 1, 13));
    EXPECT_LT((beside - H).cwiseAbs().maxCoeff(), 1e-12) << n;  // not H's size: a new matrix
    const Eigen::MatrixX3d base = Eigen::MatrixX3d::Random(n, 3),
                           C = Eigen::MatrixX3d::Random(13, 3);
    const Eigen::MatrixX3d expected = base + H * C;
    Eigen::MatrixX3d out;
    detail::add_basis_product(base, f, C, out);
    EXPECT_LT((out - expected).cwiseAbs().maxCoeff(), 1e-12) << n;
    FloatVertices rows(n, 3);
    detail::add_basis_product(base, f, C, rows);
    EXPECT_LT((rows.cast<double>() - expected).cwiseAbs().maxCoeff(), 1e-5) << n;
    EXPECT_THROW(detail::add_basis_product(base, f, Eigen::MatrixX3d::Zero(12, 3), out),
                 InputError);
    FloatVertices wrong(n + 1, 3);
    EXPECT_THROW(detail::add_basis_product(base, f, C, wrong), InputError);
  }
}

}  // namespace
}  // namespace specdeform
