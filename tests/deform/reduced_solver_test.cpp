#include "specdeform/deform/reduced_solver.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "specdeform/exceptions.h"
#include "specdeform/mesh/generate.h"
#include "specdeform/operators/mass_matrix.h"
#include "specdeform/spectral/manifold_harmonics.h"

namespace specdeform {
namespace {

// Each constrained vertex's target displacement T_g s_i - s_i, fixed ones 0.
Eigen::MatrixX3d displacements(const Eigen::MatrixX3d& V, const std::vector<int>& vertices,
                               const std::vector<int>& group,
                               const std::vector<Eigen::Affine3d>& transforms) {
  Eigen::MatrixX3d t = Eigen::MatrixX3d::Zero(vertices.size(), 3);
  for (size_t i = 0; i < vertices.size(); ++i) {
    if (group[i] < 0) continue;
    const Eigen::Vector3d s = V.row(vertices[i]).transpose();
    t.row(i) = (transforms[group[i]] * s - s).transpose();
  }
  return t;
}

// The right-hand side from each group's moments is the per-vertex one: two handle groups far from
// the origin (a turn about a point, a shear and a translation), a fixed group, soft and hard
// constraints; zero exactly for identities.
TEST(ReducedSolver, GroupMomentsGiveThePerVertexRightHandSide) {
  TriangleMesh torus = make_torus(1.0, 0.35, 40, 16);
  torus.V.rowwise() += Eigen::RowVector3d(40.0, -25.0, 10.0);
  ManifoldHarmonicsOptions o;
  o.num_modes = 30;
  const auto h = std::make_shared<const ManifoldHarmonics>(compute_manifold_harmonics(torus, o));
  const Eigen::MatrixXd hessian = h->eigenvalues.asDiagonal();
  const Eigen::VectorXd area = lumped_mass(torus) / lumped_mass(torus).sum();
  for (const ConstraintMode mode : {ConstraintMode::Soft, ConstraintMode::Hard}) {
    SCOPED_TRACE(mode == ConstraintMode::Soft ? "soft" : "hard");
    DeformOptions options;
    options.constraints = mode;
    ReducedSolver solver(h, hessian, area, options);
    std::vector<int> vertices, group;
    const int step = mode == ConstraintMode::Soft ? 1 : 29;  // hard: fewer vertices than modes
    for (int v = 0; v < torus.num_vertices(); v += step) {
      const double x = torus.V(v, 0) - 40.0;
      if (std::abs(x) < 0.5) continue;
      vertices.push_back(v);
      group.push_back(x > 1.0 ? 0 : x < -1.0 ? -1 : 1);
    }
    solver.set_constraints(vertices);
    solver.set_groups(group, 2, torus.V);
    const Eigen::Vector3d pivot(40.5, -25.0, 10.0);
    Eigen::Affine3d turn = Eigen::Translation3d(pivot) *
                           Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.2, 1.0, 0.3).normalized()) *
                           Eigen::Translation3d(-pivot);
    Eigen::Affine3d shear = Eigen::Affine3d::Identity();
    shear.linear()(0, 1) = 0.3;
    shear.translation() = Eigen::Vector3d(0.1, -0.2, 0.05);
    const std::vector<Eigen::Affine3d> transforms = {turn, shear};
    const ReducedSolver::Targets grouped = solver.prepare(transforms);
    const ReducedSolver::Targets direct =
        solver.prepare(displacements(torus.V, vertices, group, transforms));
    EXPECT_LT((grouped.rhs - direct.rhs).cwiseAbs().maxCoeff(),
              1e-12 * direct.rhs.cwiseAbs().maxCoeff());
    EXPECT_NEAR(grouped.constant, direct.constant, 1e-12 * direct.constant);
    const ReducedSolver::Targets rest =
        solver.prepare(std::vector<Eigen::Affine3d>(2, Eigen::Affine3d::Identity()));
    EXPECT_EQ(rest.rhs.cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ(rest.constant, 0.0);
    EXPECT_THROW(solver.prepare(std::vector<Eigen::Affine3d>(1)), InputError);
    solver.set_constraints(vertices);  // groups are per selection
    EXPECT_THROW(solver.prepare(transforms), InputError);
  }
}

}  // namespace
}  // namespace specdeform
