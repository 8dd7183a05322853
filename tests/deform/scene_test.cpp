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

// Expects f() to throw an InputError of one line that contains `fragment`.
template <typename F>
void expect(F&& f, const std::string& fragment) {
  try {
    f();
    ADD_FAILURE() << "no error, expected " << fragment;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
  }
}

TEST_F(SceneFiles, BadScenesGiveOneLine) {
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
  // Invertible, but beyond what lengths can be computed in: said so.
  expect(
      [&] {
        read_scene(write("e.json",
                         "{\"handles\": [{\"vertices\": [0], \"transform\": {\"scale\": 1e300}}]}"),
                   V);
      },
      "out of range");
}

TEST_F(SceneFiles, DefWithoutCommentLineAndSelComments) {
  const auto def = read_def(write("n.def", "1 0 0 1\n0 1 0 2\n0 0 1 3\n0 0 0 1\n"));
  ASSERT_EQ(def.size(), 1u);
  EXPECT_EQ(def[0].translation(), Eigen::Vector3d(1, 2, 3));
  const auto text = read_def(write("t.def", "handle transform\n2 0 0 0 0 2 0 0 0 0 2 0 0 0 0 1\n"));
  EXPECT_EQ(text[0].linear(), 2 * Eigen::Matrix3d::Identity());
  EXPECT_EQ(read_sel(write("c.sel", "0 # fixed\n2\n# free next\n1\n"), 3).handles[0],
            std::vector<int>{1});
  expect([&] { read_sel(write("x.sel", "0\n2\nfree\n"), 3); }, "x.sel: bad integer 'free'");
  expect([&] { read_dmat(write("x.dmat", "1 3\n0\n-1\n"), 3); }, "2 vertex entries");
}

// Every field is read through one checked accessor: a value of the wrong type or range, an
// unknown key or a missing one is an error naming the field, never a crash.
TEST_F(SceneFiles, FieldsOfTheWrongTypeNameThemselves) {
  const Vertices V = Eigen::MatrixX3d::Random(4, 3);
  const std::pair<std::string, std::string> cases[] = {
      {R"({"handles": [{"vertices": [0], "transform": {"rotate": {"axis": 5, "degrees": 9}}}]})",
       "handle 0 transform rotate axis: expected an array of 3 numbers, got a number"},
      {R"({"handles": [{"vertices": [0], "transform": {"rotate": 5}}]})",
       "handle 0 transform rotate: expected an object, got a number"},
      {R"({"handles": [{"vertices": [0], "transform": {"rotate": {"axis": [0, 0, 1]}}}]})",
       "handle 0 transform rotate: 'degrees' is missing"},
      {R"({"handles": [{"vertices": "all"}]})",
       "handle 0 vertices: expected an array, got a string"},
      {R"({"handles": [{"vertices": [0.5]}]})",
       "handle 0 vertices 0: expected an integer, got 0.5"},
      {R"({"handles": [{"vertices": [0], "transform": {"translate": [0, "1", 0]}}]})",
       "transform translate: expected an array of 3 numbers, got an array"},
      {R"({"handles": [{"vertices": [0], "transform": {"center": "middle"}}]})",
       R"(transform center: expected an array of 3 numbers or "centroid", got "middle")"},
      {R"({"handles": [{"vertices": [0], "transform": {"center": null}}]})",
       R"(transform center: expected an array of 3 numbers or "centroid", got null)"},
      {R"({"handles": [{"vertices": [0], "transform": {"translte": [0, 0, 1]}}]})",
       "handle 0 transform: unknown key 'translte' (known: translate, rotate, scale, center)"},
      {R"({"handles": [{"vertices": [0], "transform": [[1, 0, 0, 0], [0, 1, 0]]}]})",
       "a matrix has 4 rows of 4 numbers"},
      {R"({"handles": [{"vertices": [0], "transform": "up"}]})",
       "handle 0 transform: expected an object, got a string"},
      {R"({"handles": [{"around": {"vertex": "3", "radius": 0.1}}]})",
       "handle 0 around vertex: expected an integer, got a string"},
      {R"({"handles": [{"vertices": [0], "around": {"vertex": 0, "radius": 0.1}}]})",
       "give one of 'vertices', 'around' or 'selection'"},
      {R"({"handles": [{"vertices": [0], "group": 1}]})", "'group' goes with a 'selection'"},
      {R"({"handles": [{"selection": "x.txt"}]})", "a selection is a .sel or a .dmat file"},
      {R"({"handles": 5})", "handles: expected an array, got a number"},
      {R"({"handles": [7]})", "handle 0: expected an object, got a number"},
      {R"({"handles": [{"vertices": [0]}], "fixed": {"lowest": "10%"}})",
       "fixed lowest: expected a number, got a string"},
      {R"({"handles": [{"vertices": [0]}], "fixed": {"lowest": 0.2, "axis": 1}})",
       "fixed axis: expected a string, got a number"},
      {R"({"handles": [{"vertices": [0]}], "fixed": true})",
       "fixed: expected an array of vertices or an object, got a boolean"},
      {R"({"handles": [{"vertices": [0]}], "settings": {"modes": "many"}})",
       "settings modes: expected an integer, got a string"},
      {R"({"handles": [{"vertices": [0]}], "settings": {"energy": "elastic"}})",
       "settings energy: unknown energy 'elastic' (linear or arap)"},
      {R"({"handles": [{"vertices": [0]}], "settings": {"iterations": 0}})",
       "settings iterations: 0 is out of range [1, 1000000]"},
      {R"({"handles": [{"vertices": [0]}], "settings": {"ks": 0, "kb": 0}})",
       "settings: deformation options: ks and kb"},
      {R"({"handles": [{"vertices": [0]}], "settings": {"unconstrained": "drop"}})",
       "settings unconstrained: unknown unconstrained-pieces policy 'drop' (follow, keep or "
       "error)"},
      {R"({"handles": [{"vertices": [0]}], "settings": {"kb": -1}})", "ks and kb"},
      {R"({"handles": [{"vertices": [0]}], "influence": 0})", "influence: the radius must be > 0"},
      {R"({"handles": [{"vertices": [0]}], "influence": "far"})",
       "influence: expected a number, got a string"},
      {R"({"handles": [{"vertices": [0]}], "setings": {}})", "unknown key 'setings'"},
      {R"({"mesh": 3, "handles": [{"vertices": [0]}]})", "mesh: expected a string, got a number"},
      {R"({"mesh": "a\nb.off", "handles": [{"vertices": [0]}]})",
       "mesh: the string has control characters"},
      {R"({"handles": [{"vertices": [0]}], "a\nb": 1})", ": a key with control characters"},
      {R"([1, 2])", "expected an object, got an array"},
      {R"({"handles": [{"vertices": [0], "transform": {"scale": 1e400}}]})", "not valid JSON"},
      {"{\n  \"handles\": [\n    {\"vertices\": [0],}\n  ]\n}", "not valid JSON (line 3, column"},
  };
  for (const auto& [text, fragment] : cases) {
    const auto path = write("f.json", text);
    expect([&] { read_scene(path, V); }, path.string() + (fragment.starts_with("not") ? ": " : ""));
    expect([&] { read_scene(path, V); }, fragment);
  }
}

TEST_F(SceneFiles, AllSettingsReadAndWritten) {
  const Vertices V = Eigen::MatrixX3d::Random(4, 3);
  const Scene s = read_scene(write("s.json", R"({"handles": [{"vertices": [1]}], "influence": 0.3,
      "settings": {
      "modes": 30, "energy": "linear", "ks": 0.5, "kb": 2, "constraint_weight": 1e3,
      "constraints": "hard", "detail": "frames", "solver": "spatial", "unconstrained": "error",
      "iterations": 7, "clusters": 12, "arap_bending": 0.25, "arap_tolerance": 1e-6,
      "history": 0}})"),
                             V);
  const DeformOptions& o = s.options;
  EXPECT_EQ(s.modes, 30);
  EXPECT_EQ(o.energy, DeformEnergy::Linear);
  EXPECT_EQ(o.ks, 0.5);
  EXPECT_EQ(o.kb, 2.0);
  EXPECT_EQ(o.constraint_weight, 1e3);
  EXPECT_EQ(o.constraints, ConstraintMode::Hard);
  EXPECT_EQ(o.detail, DetailMethod::Frames);
  EXPECT_EQ(o.solver, DeformSolver::Spatial);
  EXPECT_EQ(o.unconstrained, UnconstrainedPieces::Error);
  EXPECT_EQ(o.arap.max_iterations, 7);
  EXPECT_EQ(o.arap.clusters, 12);
  EXPECT_EQ(o.arap.bending, 0.25);
  EXPECT_EQ(o.arap.tolerance, 1e-6);
  EXPECT_EQ(o.arap.history, 0);
  // Written and read back over other defaults: the same settings.
  DeformOptions other;
  other.arap.clusters = 999;
  other.unconstrained = UnconstrainedPieces::Keep;
  const Scene back = read_scene(write("b.json", encode_scene(s)), V, other);
  EXPECT_EQ(back.modes, 30);
  EXPECT_EQ(back.influence, 0.3);
  EXPECT_EQ(back.options.energy, DeformEnergy::Linear);
  EXPECT_EQ(back.options.unconstrained, UnconstrainedPieces::Error);
  EXPECT_EQ(back.options.arap.max_iterations, 7);
  EXPECT_EQ(back.options.arap.clusters, 12);
  EXPECT_EQ(back.options.arap.bending, 0.25);
  EXPECT_EQ(back.options.arap.tolerance, 1e-6);
  EXPECT_EQ(back.options.arap.history, 0);
  EXPECT_EQ(back.options.constraint_weight, 1e3);
  // Settings the scene leaves out keep the defaults given.
  EXPECT_EQ(read_scene(write("d.json", R"({"handles": [{"vertices": [1]}]})"), V, other)
                .options.arap.clusters,
            999);
}

// File vertices 0 and 3 are used by no face: the reader dropped them. A handle group or fixed set
// left without vertices is an error naming it; one that lost some, a note.
TEST_F(SceneFiles, VerticesTheReaderDropped) {
  MeshReadInfo info;
  info.file_vertices.resize(6, 3);
  info.file_vertices << 100, -10, 0, 0, 0, 0, 1, 1, 0, 50, 2, 0, 0, 3, 0, 1, 4, 0;
  info.vertex_to_file = {1, 2, 4, 5};
  info.file_to_vertex = {-1, 0, 1, -1, 2, 3};
  std::vector<std::string> notes;
  expect(
      [&] {
        to_mesh_numbering({{{1}, {0, 3}}, {}}, info, &notes, "s.json");
      },
      "s.json: handle group 1: all 2 of its vertices (file vertex 0 first) are used by no "
      "face, so the mesh reader dropped them");
  expect([&] { to_mesh_numbering({{{1}}, {3}}, info, &notes, "s.json"); }, "the fixed set: all 1");
  expect(
      [&] {
        to_mesh_numbering({{{1, 6}}, {}}, info, &notes, "s.json");
      },
      "vertex 6 is out of range (the file has 6 vertices)");
  const Selection s = to_mesh_numbering({{{0, 1, 2}, {5}}, {3, 4}}, info, &notes, "s.json");
  EXPECT_EQ(s.handles, (std::vector<std::vector<int>>{{0, 1}, {3}}));
  EXPECT_EQ(s.fixed, std::vector<int>{2});
  EXPECT_EQ(notes,
            (std::vector<std::string>{
                "handle group 0: 1 of its 3 vertices are used by no face and were left out",
                "the fixed set: 1 of its 2 vertices are used by no face and were left out"}));
  // Regions count the mesh's vertices only: the lowest half of the four kept ones, within 0.3 and
  // 0.4 diagonals of the kept vertices' box (x 0..1, y 0..4) around vertex 5; the centroid of the
  // kept vertices of a group.
  const Scene r = read_scene(write("r.json", R"({
    "handles": [{"around": {"vertex": 5, "radius": 0.3}},
                {"around": {"vertex": 5, "radius": 0.4}},
                {"vertices": [0, 4, 5], "transform": {"scale": 2}}],
    "fixed": {"lowest": 0.5}})"),
                             info);
  EXPECT_EQ(r.selection.handles[0], std::vector<int>{5});
  EXPECT_EQ(r.selection.handles[1], (std::vector<int>{4, 5}));
  EXPECT_EQ(r.selection.fixed, (std::vector<int>{1, 2}));
  EXPECT_LT((r.transforms[2] * Eigen::Vector3d(0.5, 3.5, 0) - Eigen::Vector3d(0.5, 3.5, 0)).norm(),
            1e-12);
}

// A vertex the file has several copies of (a glTF seam, a PLY split) counts once in a group's
// centroid: file vertices 1, 2 and 3 are one mesh vertex at (0, 0, 0), 4 is (3, 0, 0), so a
// group of all four turns about (1.5, 0, 0), as the welded file's group would, not about
// (0.75, 0, 0); a file vertex listed twice counts once too.
TEST_F(SceneFiles, CentroidCountsWeldedCopiesOnce) {
  MeshReadInfo info;
  info.file_vertices.resize(5, 3);
  info.file_vertices << 9, 9, 9, 0, 0, 0, 0, 0, 0, 0, 0, 0, 3, 0, 0;
  info.vertex_to_file = {0, 1, 4};
  info.file_to_vertex = {0, 1, 1, 1, 2};
  const Scene s = read_scene(write("c.json", R"({
    "handles": [{"vertices": [1, 2, 3, 4], "transform": {"scale": 2}},
                {"vertices": [4, 1, 1], "transform": {"scale": 2}}]})"),
                             info);
  for (const Eigen::Affine3d& T : s.transforms)
    EXPECT_LT((T * Eigen::Vector3d(1.5, 0, 0) - Eigen::Vector3d(1.5, 0, 0)).norm(), 1e-12);
}

TEST_F(SceneFiles, ParsedFromMemoryWithItsFiles) {
  const Vertices V = Eigen::MatrixX3d::Random(3, 3);
  MeshReadInfo info;
  info.file_vertices = V;
  info.vertex_to_file = {0, 1, 2};
  info.file_to_vertex = {0, 1, 2};
  std::vector<std::filesystem::path> asked;
  const SceneFileReader reader = [&](const std::filesystem::path& p) -> std::string {
    asked.push_back(p);
    if (p.filename() == "h.dmat") return "1 3\n-1\n0\n1\n";
    throw InputError(p.string() + ": cannot open file");
  };
  const Scene s = parse_scene(R"({"handles": [{"selection": "h.dmat", "group": 1}]})", "dir/s.json",
                              info, {}, reader);
  EXPECT_EQ(s.selection.handles[0], std::vector<int>{2});
  EXPECT_EQ(asked, std::vector<std::filesystem::path>{"dir/h.dmat"});
  expect(
      [&] {
        parse_scene(R"({"handles": [{"selection": "h.dmat", "group": 2}]})", "s.json", info, {},
                    reader);
      },
      "s.json handle 0 group: h.dmat has no group 2");
  expect(
      [&] { parse_scene(R"({"handles": [{"selection": "x.sel"}]})", "s.json", info, {}, reader); },
      "x.sel: cannot open file");
}

TEST_F(SceneFiles, TheMeshAScenesNames) {
  // Read without the mesh: the vertex indices are not checked yet.
  EXPECT_EQ(scene_mesh(write("m.json", R"({"mesh": "m.off", "handles": [{"vertices": [9]}]})")),
            dir_ / "m.off");
  EXPECT_EQ(scene_mesh(write("n.json", R"({"handles": [{"vertices": [9]}]})")),
            std::filesystem::path());
  expect([&] { scene_mesh(write("o.json", R"({"mesh": ["m.off"]})")); },
         "mesh: expected a string, got an array");
  expect([&] { scene_mesh(write("l.json", "version https://git-lfs.github.com/spec/v1\n")); },
         "is a Git LFS pointer");
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
