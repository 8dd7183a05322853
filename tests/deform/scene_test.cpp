#include "specdeform/deform/scene.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "specdeform/exceptions.h"
#include "support/corpus.h"

namespace specdeform {
namespace {

class SceneFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("specdeform_scene_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return dir_ / name;
  }
  std::filesystem::path dir_;
};

TEST_F(SceneFiles, SelDefDmat) {
  const Selection sel = read_sel(write("a.sel", "# status\n0\n1\n2\n# c\n2\n0\n"), 5);
  EXPECT_EQ(sel.fixed, (std::vector<int>{0, 4}));
  EXPECT_EQ(sel.handles[0], (std::vector<int>{2, 3}));
  const auto def = read_def(write("a.def", "# transform\n1 0 0 1\n0 1 0 2\n0 0 1 3\n0 0 0 1\n"));
  ASSERT_EQ(def.size(), 1u);
  EXPECT_EQ(def[0].translation(), Eigen::Vector3d(1, 2, 3));
  const Selection dmat = read_dmat(write("a.dmat", "1 5\n-1\n0\n1\n1\n-1\n"), 5);
  ASSERT_EQ(dmat.handles.size(), 2u);
  EXPECT_EQ(dmat.handles[1], (std::vector<int>{2, 3}));
  EXPECT_EQ(match_transforms(dmat, def).size(), 2u);
}

TEST_F(SceneFiles, BadScenesGiveOneLine) {
  const auto expect = [](auto&& f, const std::string& fragment) {
    try {
      f();
      ADD_FAILURE() << "no error, expected " << fragment;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  expect([&] { read_sel(write("b.sel", "0\n1\n"), 5); }, "2 vertex entries, the mesh has 5");
  expect([&] { read_sel(write("c.sel", "0\n7\n"), 2); }, "status 7");
  expect([&] { read_def(write("b.def", "# x\n1 0 0\n")); }, "16 numbers");
  expect([&] { read_def(write("c.def", "# x\n1 0 0 0\n0 1 0 0\n0 0 nan 0\n0 0 0 1\n")); },
         "not a finite number");
  expect([&] { read_def(write("d.def", "# x\n1 0 0 0\n0 1 0 0\n0 0 0 0\n0 0 0 1\n")); },
         "not invertible");
  expect([&] { match_transforms({{{}}, {0}}, {}); }, "no handle");
  const Vertices V = Eigen::MatrixX3d::Random(4, 3);
  expect([&] { read_scene(write("a.json", "{\"handles\": [{\"vertices\": [9]}]}"), V); },
         "out of range");
  expect([&] { read_scene(write("b.json", "{\"fixed\": [1]}"), V); }, "no handles");
  expect([&] { read_scene(write("c.json", "{not json"), V); }, "not valid JSON");
  expect(
      [&] {
        read_scene(
            write("d.json", "{\"handles\": [{\"vertices\": [0], \"transform\": {\"scale\": 0}}]}"),
            V);
      },
      "not invertible");
}

TEST_F(SceneFiles, JsonScene) {
  Vertices V(4, 3);
  V << 0, 0, 0, 2, 0, 0, 0, 2, 0, 2, 2, 0;
  write("h.sel", "1\n2\n0\n1\n");
  const Scene s = read_scene(write("s.json", R"({
    "mesh": "m.off",
    "handles": [
      {"vertices": [1, 3], "transform": {"rotate": {"axis": [0, 0, 1], "degrees": 90}}},
      {"selection": "h.sel", "transform": [[1,0,0,5],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}
    ],
    "fixed": {"selection": "h.sel"},
    "settings": {"modes": 50, "kb": 2, "detail": "frames", "constraints": "hard"}
  })"),
                             V);
  EXPECT_EQ(s.mesh, dir_ / "m.off");
  ASSERT_EQ(s.selection.handles.size(), 2u);
  EXPECT_EQ(s.selection.handles[1], (std::vector<int>{1}));
  EXPECT_EQ(s.selection.fixed, (std::vector<int>{2}));
  // Rotation about the handle's centroid (2, 1, 0): vertex 1 (2, 0, 0) goes to (3, 1, 0).
  EXPECT_LT((s.transforms[0] * Eigen::Vector3d(2, 0, 0) - Eigen::Vector3d(3, 1, 0)).norm(), 1e-12);
  EXPECT_EQ(s.transforms[1].translation(), Eigen::Vector3d(5, 0, 0));
  EXPECT_EQ(*s.modes, 50);
  EXPECT_EQ(s.options.kb, 2.0);
  EXPECT_EQ(s.options.detail, DetailMethod::Frames);
  EXPECT_EQ(s.options.constraints, ConstraintMode::Hard);
}

TEST_F(SceneFiles, RegionsByRadiusAndHeight) {
  Vertices V(5, 3);  // bounding-box diagonal 5
  V << 0, 0, 0, 0, 1, 0, 0, 2, 0, 0, 3, 0, 0, 4, 3;
  const Scene s = read_scene(write("r.json", R"({
    "handles": [{"around": {"vertex": 4, "radius": 0.3}}],
    "fixed": {"lowest": 0.6, "axis": "y"}
  })"),
                             V);
  EXPECT_EQ(s.selection.handles[0], (std::vector<int>{4}));  // within 1.5 of vertex 4
  EXPECT_EQ(s.selection.fixed, (std::vector<int>{0, 1, 2}));
  const Scene t = read_scene(write("t.json", R"({
    "handles": [{"around": {"vertex": 0, "radius": 0.25}}], "fixed": {"lowest": 0.6}})"),
                             V);
  EXPECT_EQ(t.selection.handles[0], (std::vector<int>{0, 1}));
  EXPECT_EQ(t.selection.fixed, (std::vector<int>{2}));  // handles excepted
}

TEST_F(SceneFiles, EncodedScenesReadBack) {
  Vertices V = Eigen::MatrixX3d::Random(6, 3);
  Scene s;
  s.mesh = "m.obj";
  s.selection = {{{1, 2}, {5}}, {0, 3}};
  s.transforms = {Eigen::Affine3d(Eigen::Translation3d(0.5, 0, 0)) *
                  Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized())};
  s.modes = 77;
  s.options.detail = DetailMethod::Displacement;
  s.options.ks = 0.25;
  const Scene back = read_scene(write("e.json", encode_scene(s)), V);
  EXPECT_EQ(back.mesh, dir_ / "m.obj");
  EXPECT_EQ(back.selection.handles, s.selection.handles);
  EXPECT_EQ(back.selection.fixed, s.selection.fixed);
  ASSERT_EQ(back.transforms.size(), 2u);  // the second group got the identity
  EXPECT_TRUE(back.transforms[0].matrix().isApprox(s.transforms[0].matrix(), 1e-15));
  EXPECT_TRUE(back.transforms[1].matrix().isIdentity());
  EXPECT_EQ(back.modes, 77);
  EXPECT_EQ(back.options.detail, DetailMethod::Displacement);
  EXPECT_EQ(back.options.ks, 0.25);
}

TEST(Scene, SharedBenchmarkScenes) {
  const auto shared = test::shared_dir();
  if (shared.empty()) GTEST_SKIP() << "../shared is absent";
  for (const char* name : {"bar-bend", "bar-twist", "bumpy-plane", "cactus"}) {
    const auto dir = shared / "meshes" / "scenes";
    const LoadedMesh m = read_mesh(dir / (std::string(name) + ".off"));
    const Selection s = read_sel(dir / (std::string(name) + ".sel"), m.mesh.num_vertices());
    EXPECT_FALSE(s.handles[0].empty()) << name;
    EXPECT_EQ(match_transforms(s, read_def(dir / (std::string(name) + ".def"))).size(), 1u);
  }
  const auto models = shared / "meshes" / "models";
  const LoadedMesh knight = read_mesh(models / "decimated-knight.off");
  EXPECT_GE(read_dmat(models / "decimated-knight-selection.dmat", knight.mesh.num_vertices())
                .handles.size(),
            2u);
}

}  // namespace
}  // namespace specdeform
