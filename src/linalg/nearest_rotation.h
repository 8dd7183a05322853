// Internal: the rotation nearest to a 3 x 3 matrix A in the Frobenius norm, reflections
// excluded (the polar factor of A, made proper): R = U diag(1, 1, det(U V^T)) V^T for
// A = U S V^T, the R that maximises tr(R^T A). Used by ARAP's local step, its handles' rotations,
// the frames detail and the free pieces.
//
// V and S^2 come from the closed-form eigen-decomposition of A^T A, u_i = A v_i / s_i for the two
// largest s_i, u_3 = u_1 x u_2 and v_3 = v_1 x v_2 (no division by the smallest singular value,
// and the right orientation by construction): 2-3 times faster than a Jacobi SVD. A^T A squares
// A's condition number, so the closed form is checked: where A has rank below 2, or R^T A (the
// symmetric factor) is not symmetric to 1e-10 of |A| (an ill-conditioned A, such as a cluster's
// covariance on a mesh of slivers: eigenvalues 3e3 and 3e9, the closed form's R up to 70 degrees
// from the identity), the Jacobi SVD decides.
#pragma once

#include <Eigen/Core>

namespace specdeform::detail {

Eigen::Matrix3d nearest_rotation(const Eigen::Matrix3d& A);

}  // namespace specdeform::detail
