// Internal: M-orthonormalisation of blocks of vectors (n x b, M the mass operator), the kernels of
// the block Krylov eigensolver. Every result W satisfies W^T M W = I to round-off, and spans the
// same space as the input where the input's columns are independent.
//  - cholesky_qr2: Cholesky QR, twice (Fukaya et al. 2014). BLAS-3; fails (returns false) on an
//    ill-conditioned block, which then goes to column Gram-Schmidt. With a lag E it orthonormalises
//    W - V E (V an M-orthonormal basis that W has not yet been made orthogonal to) without a pass
//    over V (the Gram matrices by Pythagoras, as in DCGS2: Swirydowicz et al. 2020).
//  - project_out: block classical Gram-Schmidt against M-orthonormal bases, repeated where it
//    cancelled most of a column ("twice is enough", Kahan-Parlett).
//  - column_gram_schmidt: column by column, twice each; a column that (nearly) vanishes, i.e.
//    depends on the ones before it, is handed to a callback that replaces it.
//  - orthonormalize: all of it, with vanished columns replaced by random ones.
#pragma once

#include <functional>
#include <initializer_list>
#include <random>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "linalg/mass_operator.h"

namespace specdeform::detail {

using Basis = Eigen::Ref<const Eigen::MatrixXd>;

// rows x cols, independent standard normal entries.
Eigen::MatrixXd random_block(int rows, int cols, std::mt19937_64& rng);

// Per pass W := W U^-1 with U^T U = W^T M W, and R := U R, so that W R stays the same. `gram`
// is W^T M W where the caller already has it. False (W R still the same) when the block is too
// ill-conditioned: a pivot of U below 1e-6 of the largest.
// With `lag` (k x b): W stands for W - V E, V an n x k M-orthonormal basis and W - V E
// M-orthogonal to it; the Gram matrices are then W^T M W - E^T E, and each pass turns E into
// E U^-1 too, so that (W - V E) R stays the same (and W - V E becomes M-orthonormal).
template <typename Derived>
bool cholesky_qr2(const Eigen::MatrixBase<Derived>& block, const MassOperator& M,
                  Eigen::MatrixXd& R, Eigen::MatrixXd gram = Eigen::MatrixXd(),
                  Eigen::MatrixXd* lag = nullptr) {
  auto& W = const_cast<Eigen::MatrixBase<Derived>&>(block);  // Eigen's idiom for writable blocks
  for (int pass = 0; pass < 2; ++pass) {
    if (pass > 0 || gram.size() == 0) gram = M.gram(W);
    if (lag != nullptr) gram -= lag->transpose() * *lag;
    const Eigen::LLT<Eigen::MatrixXd> llt(0.5 * (gram + gram.transpose()));
    if (llt.info() != Eigen::Success) return false;
    const Eigen::VectorXd r = llt.matrixLLT().diagonal();
    if (!(r.minCoeff() > 1e-6 * r.maxCoeff())) return false;
    llt.matrixU().solveInPlace<Eigen::OnTheRight>(W);
    if (lag != nullptr) llt.matrixU().solveInPlace<Eigen::OnTheRight>(*lag);
    R = Eigen::MatrixXd(llt.matrixU()) * R;
  }
  return true;
}

// W's columns made M-orthogonal to the columns of each basis in `against` (each M-orthonormal).
void project_out(Eigen::MatrixXd& W, std::initializer_list<Basis> against, const MassOperator& M);

// W (before) = W (after) R, R upper triangular (overwritten). A column left with less than
// `vanish` of its M-norm gets a zero column of R and is handed to replace(j), which must put an
// M-unit vector M-orthogonal to the columns before it there.
void column_gram_schmidt(Eigen::MatrixXd& W, const MassOperator& M, double vanish,
                         Eigen::MatrixXd& R, const std::function<void(int)>& replace);

// W made M-orthonormal and M-orthogonal to the bases in `against`. Throws SolverError when no
// such block exists (n smaller than the columns wanted).
void orthonormalize(Eigen::MatrixXd& W, std::initializer_list<Basis> against, const MassOperator& M,
                    std::mt19937_64& rng);

}  // namespace specdeform::detail
