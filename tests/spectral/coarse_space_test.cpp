#include "spectral/coarse_space.h"

#include <gtest/gtest.h>

#include <set>

#include "specdeform/mesh/generate.h"
#include "specdeform/mesh/mesh_info.h"
#include "specdeform/operators/cotan_laplacian.h"
#include "specdeform/operators/mass_matrix.h"
#include "support/corpus.h"

namespace specdeform {
namespace {

using Sparse = Eigen::SparseMatrix<double>;

// A partition of unity of non-negative functions, each inside one connected component, every
// component seeded (beyond the samples asked for), for the corpus's meshes and both kinds of
// lengths.
TEST(CoarseSpace, PartitionOfUnityOverEveryComponent) {
  for (const test::CorpusMesh& c : test::corpus()) {
    const TriangleMesh& mesh = c.mesh;
    const Sparse K = cotan_stiffness(mesh);
    const Sparse M = mass_matrix(mesh, MassType::Lumped);
    int components = 0;
    const Eigen::VectorXi piece = vertex_components(mesh, &components);
    for (const auto& [lengths, samples] :
         {std::pair{detail::edge_lengths(K, mesh.V), mesh.num_vertices() / 20},
          std::pair{detail::estimated_edge_lengths(K, M), mesh.num_vertices() / 20},
          std::pair{detail::edge_lengths(K, mesh.V), 1}}) {  // one seed a component
      const detail::CoarseSpace space = detail::partition_of_unity(lengths, samples, 2.5);
      const Sparse& P = space.prolongation;
      ASSERT_EQ(P.rows(), mesh.num_vertices()) << c.name;
      ASSERT_EQ(P.cols(), std::max(samples, components)) << c.name;
      EXPECT_GT(space.radius, 0.0) << c.name;
      // The row-major copy is the same matrix, each row's columns strictly ascending.
      EXPECT_EQ((Sparse(space.rows) - P).norm(), 0.0) << c.name;
      for (int i = 0; i < space.rows.outerSize(); ++i) {
        const int* column = space.rows.innerIndexPtr();
        for (int e = space.rows.outerIndexPtr()[i] + 1; e < space.rows.outerIndexPtr()[i + 1]; ++e)
          ASSERT_LT(column[e - 1], column[e]) << c.name << ": row " << i;
      }
      const Eigen::VectorXd sums = P * Eigen::VectorXd::Ones(P.cols());
      EXPECT_LT((sums.array() - 1.0).abs().maxCoeff(), 1e-14) << c.name;
      std::set<int> seeded;
      for (int j = 0; j < P.outerSize(); ++j) {
        std::set<int> pieces;
        for (Sparse::InnerIterator it(P, j); it; ++it) {
          EXPECT_GE(it.value(), 0.0);
          pieces.insert(piece[it.row()]);
        }
        EXPECT_EQ(pieces.size(), 1u) << c.name << ": function " << j;
        seeded.insert(pieces.begin(), pieces.end());
      }
      EXPECT_EQ(static_cast<int>(seeded.size()), components) << c.name;
    }
  }
}

}  // namespace
}  // namespace specdeform
