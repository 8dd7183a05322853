#include "editor_session.h"

#include <cstring>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "protocol.h"
#include "specdeform/deform/scene.h"
#include "specdeform/mesh/generate.h"

namespace specdeform::server {
namespace {

using Json = nlohmann::json;

struct Sent {
  bool binary;
  std::string data;
};

// An editor session on a small sphere with everything it sends recorded.
class EditorSessionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    session_ = std::make_unique<EditorSession>(EditorConfig{.modes = 30},
                                               [this](bool binary, std::string data) {
                                                 sent_.push_back({binary, std::move(data)});
                                               });
    LoadedMesh mesh;
    mesh.mesh = make_icosphere(2);
    mesh.info = identity_read_info(mesh.mesh);
    rest_ = mesh.mesh.V;
    session_->open(std::move(mesh), "sphere.obj");
    for (int i = 0; i < rest_.rows(); ++i) {
      if (rest_(i, 2) > 0.8) selection_.handles.resize(1), selection_.handles[0].push_back(i);
      if (rest_(i, 2) < -0.8) selection_.fixed.push_back(i);
    }
  }

  std::vector<Sent> take() { return std::exchange(sent_, {}); }

  Json last_text() {
    for (auto it = sent_.rbegin(); it != sent_.rend(); ++it) {
      if (!it->binary) return Json::parse(it->data);
    }
    return {};
  }

  // Positions of the last frame result.
  Vertices last_frame() {
    for (auto it = sent_.rbegin(); it != sent_.rend(); ++it) {
      if (!it->binary || message_tag(it->data) != Tag::FrameResult) continue;
      uint32_t n = 0;
      std::memcpy(&n, it->data.data() + 8, 4);
      Vertices V(n, 3);
      for (uint32_t i = 0; i < 3 * n; ++i) {
        float x = 0;
        std::memcpy(&x, it->data.data() + 40 + 4 * i, 4);
        V(i / 3, i % 3) = x;
      }
      return V;
    }
    return {};
  }

  std::string frame(const Eigen::Affine3d& t, uint32_t seq = 1) { return encode_frame({seq, {t}}); }

  std::unique_ptr<EditorSession> session_;
  std::vector<Sent> sent_;
  Vertices rest_;
  Selection selection_;
};

TEST_F(EditorSessionTest, OpenAnnouncesTheMeshAndItsBasis) {
  ASSERT_EQ(sent_.size() >= 2, true);
  EXPECT_EQ(message_tag(sent_[sent_.size() - 2].data), Tag::Mesh);
  const Json ready = last_text();
  EXPECT_EQ(ready["type"], "ready");
  EXPECT_EQ(ready["vertices"], rest_.rows());
  EXPECT_EQ(ready["modes"], 30);
  EXPECT_EQ(ready["settings"]["detail"], "transfer");
}

TEST_F(EditorSessionTest, FramesMeetTheHandleTargets) {
  session_->handle(true, encode_selection(selection_, Tag::Selection));
  EXPECT_EQ(last_text()["type"], "selection");
  const Eigen::Vector3d t(0.1, -0.2, 0.3);
  session_->handle(true, frame(Eigen::Affine3d(Eigen::Translation3d(t))));
  const Vertices V = last_frame();
  ASSERT_EQ(V.rows(), rest_.rows());
  for (int i : selection_.handles[0]) {
    EXPECT_LT((V.row(i) - rest_.row(i) - t.transpose()).norm(), 1e-5);
  }
  for (int i : selection_.fixed) EXPECT_LT((V.row(i) - rest_.row(i)).norm(), 1e-5);

  // The identity gives the rest shape back (to float precision).
  session_->handle(true, frame(Eigen::Affine3d::Identity(), 2));
  EXPECT_LT((last_frame() - rest_).cwiseAbs().maxCoeff(), 1e-6);
}

TEST_F(EditorSessionTest, BadMessagesAreAnsweredAndChangeNothing) {
  session_->handle(true, encode_selection(selection_, Tag::Selection));
  const Eigen::Affine3d lift(Eigen::Translation3d(0, 0, 0.2));
  session_->handle(true, frame(lift));
  const Vertices before = last_frame();
  Eigen::Affine3d nan = lift;
  nan(0, 0) = std::nan("");
  const std::vector<std::pair<bool, std::string>> bad = {
      {true, encode_frame({3, {lift, lift}})},                       // two groups, one selected
      {true, frame(nan, 3)},                                         // not finite
      {true, encode_selection({{{9999}}, {}}, Tag::Selection)},      // out of range
      {true, encode_selection({{{0}, {0}}, {}}, Tag::Selection)},    // one vertex in two groups
      {true, std::string("\x07\0\0\0", 4)},                          // unknown tag
      {true, std::string("\x02\0", 2)},                              // truncated
      {true, encode_file({"x.xyz", "1 2 3"}, Tag::MeshFile)},        // unknown format
      {true, encode_file({"x.sel", "2\n2\n"}, Tag::SelectionFile)},  // wrong vertex count
      {false, "not json"},
      {false, R"({"type": "launch"})"},
      {false, R"({"type": "settings", "modes": -3})"},
      {false, R"({"type": "settings", "detail": "sparkles"})"},
      {false, R"({"type": "settings", "ks": 0, "kb": 0})"},
      {false, R"({"type": "export_mesh", "format": "docx"})"},
  };
  for (const auto& [binary, message] : bad) {
    sent_.clear();
    session_->handle(binary, message);
    ASSERT_EQ(sent_.size(), 1u);
    const Json reply = Json::parse(sent_[0].data);
    EXPECT_EQ(reply["type"], "error");
    EXPECT_EQ(reply["message"].get<std::string>().find('\n'), std::string::npos);
  }
  session_->handle(true, frame(lift, 4));
  EXPECT_LT((last_frame() - before).cwiseAbs().maxCoeff(), 1e-7);
}

TEST_F(EditorSessionTest, SettingsRebuildAndKeepTheSelection) {
  session_->handle(true, encode_selection(selection_, Tag::Selection));
  const Eigen::Vector3d t(0, 0, 0.25);
  session_->handle(true, frame(Eigen::Affine3d(Eigen::Translation3d(t))));
  session_->handle(false, R"({"type": "settings", "detail": "displacement", "modes": 20})");
  const Json ready = last_text();
  EXPECT_EQ(ready["settings"]["detail"], "displacement");
  EXPECT_EQ(ready["modes"], 20);
  const Vertices V = last_frame();  // the frame is solved again with the new settings
  for (int i : selection_.fixed) EXPECT_LT((V.row(i) - rest_.row(i)).norm(), 1e-2);
  EXPECT_GT((V - rest_).rowwise().norm().maxCoeff(), 0.2);

  session_->handle(false, R"({"type": "settings", "view": "base"})");
  EXPECT_NE(last_frame(), V);
}

TEST_F(EditorSessionTest, ExportsTheDeformedMeshAndTheScene) {
  session_->handle(true, encode_selection(selection_, Tag::Selection));
  const Eigen::Affine3d t(Eigen::Translation3d(0.05, 0, 0.2));
  session_->handle(true, frame(t));
  session_->handle(false, R"({"type": "export_mesh", "format": "obj"})");
  ASSERT_TRUE(sent_.back().binary);
  const NamedFile obj = decode_file(sent_.back().data);
  EXPECT_EQ(obj.name, "sphere-deformed.obj");
  const LoadedMesh exported = read_mesh_from_memory(obj.data, MeshFormat::Obj, obj.name);
  EXPECT_LT((exported.mesh.V - last_frame()).cwiseAbs().maxCoeff(), 1e-6);

  session_->handle(false, R"({"type": "export_scene"})");
  const NamedFile scene_file = decode_file(sent_.back().data);
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / "specdeform-session-scene.json";
  std::ofstream(path) << scene_file.data;
  const Scene scene = read_scene(path, rest_);
  std::filesystem::remove(path);
  EXPECT_EQ(scene.mesh.filename(), "sphere.obj");
  EXPECT_EQ(scene.selection.handles, selection_.handles);
  EXPECT_EQ(scene.selection.fixed, selection_.fixed);
  ASSERT_EQ(scene.transforms.size(), 1u);
  EXPECT_TRUE(scene.transforms[0].matrix().isApprox(t.matrix(), 1e-12));
  EXPECT_EQ(scene.modes, 30);
}

TEST_F(EditorSessionTest, SelectionFilesComeBackInMeshNumbering) {
  std::string sel;
  for (int i = 0; i < rest_.rows(); ++i) sel += i == 3 ? "2\n" : i == 5 ? "0\n" : "1\n";
  session_->handle(true, encode_file({"pick.sel", sel}, Tag::SelectionFile));
  ASSERT_TRUE(sent_.back().binary);
  const Selection s = decode_selection(sent_.back().data, static_cast<int>(rest_.rows()));
  EXPECT_EQ(s.handles, std::vector<std::vector<int>>{{3}});
  EXPECT_EQ(s.fixed, std::vector<int>{5});
}

}  // namespace
}  // namespace specdeform::server
