#include "specdeform/spectral/basis_cache.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "specdeform/exceptions.h"
#include "specdeform/mesh/generate.h"
#include "specdeform/spectral/basis_store.h"
#include "support/corpus.h"

namespace specdeform {
namespace {

class BasisCache : public ::testing::Test {
 protected:
  void SetUp() override {
    // One folder per test: ctest runs the tests of this fixture in parallel.
    dir_ = std::filesystem::temp_directory_path() /
           ("specdeform_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    std::filesystem::create_directories(dir_);
    mesh_ = make_torus(1.0, 0.35, 40, 12);
    ManifoldHarmonicsOptions o;
    o.num_modes = 20;
    h_ = compute_manifold_harmonics(mesh_, o);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::filesystem::path dir_;
  TriangleMesh mesh_;
  ManifoldHarmonics h_;
};

TEST_F(BasisCache, RoundTrip) {
  save_basis(dir_ / "b.sdbasis", h_, mesh_);
  const ManifoldHarmonics back = load_basis(dir_ / "b.sdbasis", mesh_);
  EXPECT_EQ(back.basis, h_.basis);
  EXPECT_EQ(back.eigenvalues, h_.eigenvalues);
  EXPECT_EQ(back.mass, MassType::Lumped);
  save_basis(dir_ / "f.sdbasis", h_, mesh_, BasisPrecision::Float32);
  const ManifoldHarmonics single = load_basis(dir_ / "f.sdbasis", mesh_);
  EXPECT_LT((single.basis - h_.basis).cwiseAbs().maxCoeff(), 1e-6 * h_.basis.cwiseAbs().maxCoeff());
  EXPECT_LT(std::filesystem::file_size(dir_ / "f.sdbasis"),
            0.6 * std::filesystem::file_size(dir_ / "b.sdbasis"));
}

// A multilevel basis is saved as its factors: exact, smaller than the float32 basis, and read
// back with them; a file whose factors do not make a matrix of its sizes is refused.
TEST_F(BasisCache, FactoredRoundTrip) {
  const TriangleMesh torus = make_torus(1.0, 0.35, 100, 40);
  ManifoldHarmonicsOptions o;
  o.num_modes = 60;  // below m of about 40, P Z is more bytes than H
  o.solver = EigenSolver::Multilevel;
  const ManifoldHarmonics h = compute_manifold_harmonics(torus, o);
  ASSERT_TRUE(h.factored.smaller_than_dense(4));
  save_basis(dir_ / "p.sdbasis", h, torus, BasisPrecision::Float32);
  const ManifoldHarmonics back = load_basis(dir_ / "p.sdbasis", torus);
  EXPECT_TRUE(back.approximate);
  EXPECT_TRUE(back.factored.prolongation.isApprox(h.factored.prolongation, 0.0));
  EXPECT_EQ(back.factored.coarse, h.factored.coarse);
  EXPECT_LT((back.basis - h.basis).cwiseAbs().maxCoeff(), 1e-14 * h.basis.cwiseAbs().maxCoeff());
  EXPECT_EQ(back.eigenvalues, h.eigenvalues);
  ManifoldHarmonics dense = h;
  dense.factored = FactoredBasis{};
  save_basis(dir_ / "d.sdbasis", dense, torus, BasisPrecision::Float32);
  EXPECT_TRUE(load_basis(dir_ / "d.sdbasis", torus).factored.empty());
  EXPECT_LT(std::filesystem::file_size(dir_ / "p.sdbasis"),
            std::filesystem::file_size(dir_ / "d.sdbasis"));

  std::string bytes;
  {
    std::ifstream file(dir_ / "p.sdbasis", std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(file), {});
  }
  const size_t m = h.basis.cols(), n = torus.num_vertices();
  const size_t columns = 32 + 56 + 8 + 16 * m + 4 + 8 + 4 * (n + 1);  // P's first column index
  // The file's bytes with `value` written at `offset`: refused with `message`.
  const auto refused = [&](size_t offset, const auto value, const std::string& message) {
    std::string broken = bytes;
    std::memcpy(broken.data() + offset, &value, sizeof value);
    std::ofstream(dir_ / "b.sdbasis", std::ios::binary | std::ios::trunc) << broken;
    try {
      load_basis(dir_ / "b.sdbasis", torus);
      ADD_FAILURE() << "accepted: " << message;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  };
  refused(columns, int32_t{h.coarse_functions}, "corrupt basis factors");  // outside P
  // A count of entries beyond the file's end: refused before allocating.
  refused(columns - 4 * (n + 1) - 8, uint64_t{1} << 30, "truncated");
  std::ofstream(dir_ / "b.sdbasis", std::ios::binary | std::ios::trunc)
      << bytes.substr(0, bytes.size() - 8);
  EXPECT_THROW(load_basis(dir_ / "b.sdbasis", torus), InputError);
}

TEST_F(BasisCache, RecordsTheLaplacian) {
  ManifoldHarmonicsOptions o;
  o.num_modes = 10;
  o.laplacian = LaplacianType::IntrinsicDelaunay;
  const ManifoldHarmonics intrinsic = compute_manifold_harmonics(mesh_, o);
  save_basis(dir_ / "i.sdbasis", intrinsic, mesh_);
  const ManifoldHarmonics back = load_basis(dir_ / "i.sdbasis", mesh_);
  EXPECT_EQ(back.laplacian, LaplacianType::IntrinsicDelaunay);
  EXPECT_EQ(back.basis, intrinsic.basis);
  EXPECT_NO_THROW(
      require_operators("i.sdbasis", back, MassType::Lumped, LaplacianType::IntrinsicDelaunay));
  try {
    require_operators("i.sdbasis", back, MassType::Lumped, LaplacianType::Cotan);
    FAIL() << "a basis of the other Laplacian was accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "i.sdbasis: the basis was computed with the intrinsic-delaunay Laplacian, not the "
                 "cotan Laplacian; recompute it or ask for the same operators");
  }
  EXPECT_THROW(
      require_operators("i.sdbasis", back, MassType::Consistent, LaplacianType::IntrinsicDelaunay),
      InputError);
}

// Rewrites a file of this version (m pairs) as an older one: that version number, without the
// layout (8 bytes after the report) that version 5 added, the residuals per pair (8 m bytes
// after the eigenvalues) that version 4 added and, before version 3, without the solver report
// (56 bytes after the 32-byte header).
void downgrade(const std::filesystem::path& path, uint32_t version, size_t m) {
  std::string bytes;
  {
    std::ifstream file(path, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(file), {});
  }
  bytes.erase(32 + 56, 8);
  bytes.erase(32 + 56 + 8 * m, 8 * m);
  if (version < 3) bytes.erase(32, 56);
  std::memcpy(bytes.data() + 8, &version, sizeof version);
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

TEST_F(BasisCache, ReadsVersionsOneToThree) {
  // Version 3 has the report without the residuals per pair (and only exact bases).
  save_basis(dir_ / "b.sdbasis", h_, mesh_);
  downgrade(dir_ / "b.sdbasis", 3, h_.basis.cols());
  const ManifoldHarmonics three = load_basis(dir_ / "b.sdbasis", mesh_);
  EXPECT_EQ(three.basis, h_.basis);
  EXPECT_EQ(three.max_residual, h_.max_residual);
  EXPECT_EQ(three.residuals, Eigen::VectorXd::Constant(h_.basis.cols(), h_.max_residual));
  EXPECT_FALSE(three.approximate);
  // Version 1 had a reserved zero where version 2 keeps the Laplacian; neither has the report.
  for (const uint32_t version : {1u, 2u}) {
    save_basis(dir_ / "b.sdbasis", h_, mesh_);
    downgrade(dir_ / "b.sdbasis", version, h_.basis.cols());
    const ManifoldHarmonics back = load_basis(dir_ / "b.sdbasis", mesh_);
    EXPECT_EQ(back.laplacian, LaplacianType::Cotan);
    EXPECT_EQ(back.basis, h_.basis);
    EXPECT_TRUE(std::isnan(back.max_residual)) << "not recorded: unknown, not 0";
  }
  {
    std::fstream file(dir_ / "b.sdbasis", std::ios::in | std::ios::out | std::ios::binary);
    const uint32_t version = 5;
    file.seekp(8);
    file.write(reinterpret_cast<const char*>(&version), sizeof version);
  }
  EXPECT_THROW(load_basis(dir_ / "b.sdbasis", mesh_), InputError);
}

// The solver's report comes back with the basis (the editor shows it for a cached basis).
TEST_F(BasisCache, KeepsTheSolverReport) {
  save_basis(dir_ / "b.sdbasis", h_, mesh_);
  const ManifoldHarmonics back = load_basis(dir_ / "b.sdbasis", mesh_);
  EXPECT_GT(h_.max_residual, 0.0);
  EXPECT_EQ(back.max_residual, h_.max_residual);
  EXPECT_EQ(back.rounding_floor, h_.rounding_floor);
  EXPECT_EQ(back.threshold, h_.threshold);
  EXPECT_EQ(back.max_orthogonality_error, h_.max_orthogonality_error);
  EXPECT_EQ(back.status, h_.status);
  EXPECT_EQ(back.cluster_truncated, h_.cluster_truncated);
  EXPECT_EQ(back.bands, h_.bands);
  EXPECT_EQ(back.restarts, h_.restarts);
  EXPECT_EQ(back.solves, h_.solves);
}

TEST_F(BasisCache, RefusesAnotherMeshOrABrokenFile) {
  save_basis(dir_ / "b.sdbasis", h_, mesh_);
  TriangleMesh moved = mesh_;
  moved.V(3, 1) += 1e-12;
  EXPECT_THROW(load_basis(dir_ / "b.sdbasis", moved), InputError);
  EXPECT_THROW(load_basis(dir_ / "b.sdbasis", make_torus(1.0, 0.35, 40, 13)), InputError);
  std::filesystem::resize_file(dir_ / "b.sdbasis", 1000);
  EXPECT_THROW(load_basis(dir_ / "b.sdbasis", mesh_), InputError);
  std::ofstream(dir_ / "junk.sdbasis") << "not a basis at all, but long enough for a header";
  EXPECT_THROW(load_basis(dir_ / "junk.sdbasis", mesh_), InputError);
  EXPECT_THROW(load_basis(dir_ / "missing.sdbasis", mesh_), InputError);
}

// A basis of several pieces records them and the m asked for (it has more columns); it serves
// that m only, and a folder's file of an older version for such a mesh is computed anew.
TEST_F(BasisCache, APieceByPieceBasisServesItsOwnM) {
  TriangleMesh shifted = make_icosphere(2);
  shifted.V.col(0).array() += 3.0;
  const TriangleMesh two = test::concatenate(make_icosphere(2), shifted);
  ManifoldHarmonicsOptions o;
  o.num_modes = 20;
  const ObtainedBasis first = obtain_basis(two, o, dir_);
  EXPECT_FALSE(first.loaded);
  EXPECT_EQ(first.harmonics->pieces, 2);
  EXPECT_EQ(first.harmonics->basis.cols(), 32);  // 10 each by area, 16 each by the floor
  const ObtainedBasis again = obtain_basis(two, o, dir_);
  EXPECT_TRUE(again.loaded);
  EXPECT_EQ(again.harmonics->basis, first.harmonics->basis);
  EXPECT_EQ(again.harmonics->requested_modes, 20);
  ManifoldHarmonicsOptions fewer = o;
  fewer.num_modes = 10;
  EXPECT_THROW(obtain_basis(two, fewer, again.file), InputError);
  downgrade(again.file, 3, 32);
  const ObtainedBasis anew = obtain_basis(two, o, dir_);
  EXPECT_FALSE(anew.loaded);
  EXPECT_EQ(anew.harmonics->basis.cols(), 32);
}

// A cache keeps an exact basis in float64 (read back bit for bit) and an approximate (multilevel)
// one in float32: half the file, its entries within float32's rounding.
TEST_F(BasisCache, KeepsAMultilevelBasisInSinglePrecision) {
  const TriangleMesh sphere = make_icosphere(4);
  ManifoldHarmonicsOptions o;
  o.num_modes = 16;
  const ObtainedBasis exact = obtain_basis(sphere, o, dir_);
  o.solver = EigenSolver::Multilevel;
  o.policy.multilevel_min_samples = 1;  // N = 160 coarse functions
  std::filesystem::remove(exact.file);
  const ObtainedBasis multilevel = obtain_basis(sphere, o, dir_);
  ASSERT_TRUE(multilevel.harmonics->approximate);
  EXPECT_EQ(cache_precision(*exact.harmonics), BasisPrecision::Float64);
  EXPECT_EQ(cache_precision(*multilevel.harmonics), BasisPrecision::Float32);
  const ObtainedBasis back = obtain_basis(sphere, o, dir_);
  ASSERT_TRUE(back.loaded);
  const Eigen::MatrixXd& H = multilevel.harmonics->basis;
  EXPECT_NE(back.harmonics->basis, H);
  EXPECT_LT((back.harmonics->basis - H).cwiseAbs().maxCoeff(), 1e-6 * H.cwiseAbs().maxCoeff());
  const double entry_bytes =
      static_cast<double>(std::filesystem::file_size(back.file)) / static_cast<double>(H.size());
  EXPECT_LT(entry_bytes, 5.0);
}

}  // namespace
}  // namespace specdeform
