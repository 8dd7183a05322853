#include "editor_session.h"

#include <unistd.h>

#include <algorithm>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <numeric>
#include <thread>

#include <gtest/gtest.h>
#include <zip.h>
#include <nlohmann/json.hpp>

#include "pose.h"
#include "preview.h"
#include "protocol.h"
#include "specdeform/deform/influence.h"
#include "specdeform/deform/scene.h"
#include "specdeform/mesh/generate.h"
#include "support/corpus.h"

namespace specdeform::server {
namespace {

using Json = nlohmann::json;

struct Sent {
  bool binary;
  std::string data;
};

GroupSelection plain(Selection s) {
  const size_t g = s.handles.size();
  return {std::move(s), std::vector<Eigen::Affine3d>(g, Eigen::Affine3d::Identity()),
          std::vector<bool>(g, false), std::vector<bool>(g, false)};
}

// The editor's options with the linear energy: one solve per frame, the same result for the
// same transforms whatever came before (ARAP starts from the previous frame); the transfer
// factored before the frame (EditorSessionBackground: in the background).
DeformOptions linear_options() {
  DeformOptions o = editor_deform_options();
  o.energy = DeformEnergy::Linear;
  o.background_transfer = false;
  return o;
}

// An editor session on a small sphere with everything it sends recorded.
class EditorSessionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    session_ =
        std::make_unique<EditorSession>(EditorConfig{.modes = 30, .options = linear_options()},
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

  Json last_text(const std::string& type = "") {
    for (auto it = sent_.rbegin(); it != sent_.rend(); ++it) {
      if (it->binary) continue;
      Json j = Json::parse(it->data);
      if (type.empty() || j["type"] == type) return j;
    }
    return {};
  }

  // The text message types sent since the last clear, in order.
  std::vector<std::string> text_types() {
    std::vector<std::string> out;
    for (const Sent& s : sent_) {
      if (!s.binary) out.push_back(Json::parse(s.data)["type"]);
    }
    return out;
  }

  const std::string* last_binary(Tag tag) {
    for (auto it = sent_.rbegin(); it != sent_.rend(); ++it) {
      if (it->binary && message_tag(it->data) == tag) return &it->data;
    }
    return nullptr;
  }

  // The rest shape frames are sent against: the last mesh's parts' (a pose changes it).
  Vertices current_rest() {
    auto start = std::find_if(sent_.rbegin(), sent_.rend(),
                              [](const Sent& m) { return m.binary && starts_mesh(m.data); });
    if (start == sent_.rend()) return rest_;
    Vertices V(rest_.rows(), 3);
    for (auto it = std::prev(start.base()); it != sent_.end(); ++it) {
      if (!it->binary || message_tag(it->data) != Tag::Mesh) continue;
      const MeshPartHeader h = mesh_part_header(it->data);
      if (h.kind != 0) continue;  // triangles
      for (uint32_t i = 0; i < 3 * h.count; ++i) {
        float x = 0;
        std::memcpy(&x, it->data.data() + 24 + 4 * i, 4);
        V(h.first + i / 3, i % 3) = x;
      }
    }
    return V;
  }

  Vertices last_frame(const PreviewMesh* preview = nullptr) {
    const std::string* m = last_binary(Tag::FrameResult);
    return m ? decode_frame_positions(*m, current_rest(), preview) : Vertices();
  }

  std::string frame(const Eigen::Affine3d& t, uint32_t seq = 1) { return encode_frame({seq, {t}}); }
  void select(const GroupSelection& s) {
    session_->handle(true, encode_selection(s, Tag::Selection));
  }

  std::unique_ptr<EditorSession> session_;
  std::vector<Sent> sent_;
  Vertices rest_;
  Selection selection_;
};

TEST_F(EditorSessionTest, OpenAnnouncesTheMeshAndItsBasis) {
  ASSERT_TRUE(last_binary(Tag::Mesh));
  const Json ready = last_text("ready");
  EXPECT_EQ(ready["vertices"], rest_.rows());
  EXPECT_EQ(ready["modes"], 30);
  EXPECT_EQ(ready["settings"]["detail"], "transfer");
  EXPECT_EQ(ready["settings"]["energy"], "linear");
  EXPECT_EQ(ready["mesh_id"].get<std::string>().size(), 16u);
  EXPECT_FALSE(ready["basis"]["approximate"]);  // 162 vertices: the exact solver by default
  EXPECT_EQ(last_text()["type"], "state");
}

// An editor asked for the multilevel basis says so, and deforms with it.
TEST(EditorSessionMultilevel, AnnouncesAnApproximateBasis) {
  std::vector<Json> texts;
  EditorSession session(EditorConfig{.modes = 20, .eigensolver = EigenSolver::Multilevel},
                        [&](bool binary, std::string data) {
                          if (!binary) texts.push_back(Json::parse(data));
                        });
  LoadedMesh mesh;
  mesh.mesh = make_icosphere(5);  // 10,242 vertices: a coarse space of 500 functions
  mesh.info = identity_read_info(mesh.mesh);
  session.open(std::move(mesh), "sphere.obj");
  const auto ready = std::find_if(texts.rbegin(), texts.rend(),
                                  [](const Json& j) { return j["type"] == "ready"; });
  ASSERT_NE(ready, texts.rend());
  EXPECT_TRUE((*ready)["basis"]["approximate"]);
  EXPECT_GT((*ready)["basis"]["residual"].get<double>(), 1e-4);
}

TEST_F(EditorSessionTest, FramesMeetTheHandleTargets) {
  select(plain(selection_));
  EXPECT_EQ(last_text()["type"], "state");
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

// The editor on meshes as tools write them (support/corpus.h's messy(): zero-area faces and
// vertices, fins, pinches, misoriented triangles, many pieces), with its own default options
// (ARAP, the transfer factored before the frame): opened, a drag moves the handle to its target,
// and back at the identity the frame is the rest, exactly.
TEST(EditorSessionMessy, OpenAndDragEveryMessyMesh) {
  for (const test::MessyMesh& m : test::messy()) {
    std::vector<Sent> sent;
    DeformOptions options = editor_deform_options();
    options.background_transfer = false;
    EditorSession session(EditorConfig{.modes = 30, .options = options},
                          [&](bool binary, std::string data) {
                            sent.push_back({binary, std::move(data)});
                          });
    LoadedMesh mesh;
    mesh.mesh = m.mesh;
    mesh.info = identity_read_info(mesh.mesh);
    session.open(std::move(mesh), m.name + ".obj");
    const Vertices& rest = m.mesh.V;
    const double diagonal = bounding_box_diagonal(rest);
    Selection selection;
    selection.handles.resize(1);
    const double top = rest.col(0).maxCoeff(), low = rest.col(0).minCoeff();
    for (int i = 0; i < rest.rows(); ++i) {
      if (rest(i, 0) > top - 0.1 * (top - low)) selection.handles[0].push_back(i);
      if (rest(i, 0) < low + 0.1 * (top - low)) selection.fixed.push_back(i);
    }
    session.handle(true, encode_selection(plain(selection), Tag::Selection));
    const auto frame = [&](const Eigen::Affine3d& t, uint32_t seq) {
      session.handle(true, encode_frame({seq, {t}}));
      for (auto it = sent.rbegin(); it != sent.rend(); ++it) {
        if (it->binary && message_tag(it->data) == Tag::FrameResult) {
          return decode_frame_positions(it->data, rest, nullptr);
        }
      }
      return Vertices();
    };
    const Eigen::Affine3d drag = Eigen::Translation3d(0.0, 0.1 * diagonal, 0.05 * diagonal) *
                                 Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ());
    const Vertices bent = frame(drag, 1);
    ASSERT_EQ(bent.rows(), rest.rows()) << m.name;
    ASSERT_TRUE(bent.allFinite()) << m.name;
    for (const int i : selection.handles[0]) {
      EXPECT_LT((bent.row(i).transpose() - drag * rest.row(i).transpose()).norm(), 0.01 * diagonal)
          << m.name << " " << i;
    }
    EXPECT_TRUE(frame(Eigen::Affine3d::Identity(), 2) == rest) << m.name;
  }
}

// The transfer factored in the background (the editor's default): after a selection, frames
// come with displacements until the factorisation is ready; the session is then told (post) and
// sends the frame with the transfer's details, the same as a session that factors at once.
TEST(EditorSessionBackground, TheTransfersFrameFollowsItsFactorisation) {
  std::mutex mutex;
  std::condition_variable posted;
  std::deque<std::function<void()>> jobs;
  std::vector<Sent> sent[2];
  DeformOptions o = linear_options();
  std::unique_ptr<EditorSession> sessions[2];
  for (int k = 0; k < 2; ++k) {
    o.background_transfer = k == 1;
    sessions[k] = std::make_unique<EditorSession>(
        EditorConfig{.modes = 30, .options = o},
        [&sent, k](bool binary, std::string data) {
          sent[k].push_back({binary, std::move(data)});
        },
        [&](std::function<void()> job) {
          std::lock_guard lock(mutex);
          jobs.push_back(std::move(job));
          posted.notify_all();
        });
    LoadedMesh mesh;
    mesh.mesh = make_icosphere(5);
    mesh.info = identity_read_info(mesh.mesh);
    sessions[k]->open(std::move(mesh), "sphere.obj");
  }
  const Vertices rest = make_icosphere(5).V;
  Selection selection;
  selection.handles.resize(1);
  for (int i = 0; i < rest.rows(); ++i) {
    if (rest(i, 2) > 0.7) selection.handles[0].push_back(i);
    if (rest(i, 2) < -0.7) selection.fixed.push_back(i);
  }
  const Eigen::Affine3d turn(Eigen::Translation3d(0.1, 0.0, 0.3) *
                             Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitX()));
  for (auto& session : sessions) {
    session->handle(true, encode_selection(plain(selection), Tag::Selection));
    session->handle(true, encode_frame({1, {turn}}));
  }
  // An export does not wait for the message: it is the transfer's result at once.
  sessions[1]->handle(false, R"({"type": "export_mesh", "format": "obj"})");
  const NamedFile obj = decode_file(sent[1].back().data);
  const Vertices exported = read_mesh_from_memory(obj.data, MeshFormat::Obj, obj.name).mesh.V;
  {
    std::unique_lock lock(mutex);
    ASSERT_TRUE(posted.wait_for(lock, std::chrono::seconds(30), [&] { return !jobs.empty(); }));
  }
  while (true) {
    std::function<void()> job;
    {
      std::lock_guard lock(mutex);
      if (jobs.empty()) break;
      job = std::move(jobs.front());
      jobs.pop_front();
    }
    job();
  }
  const auto last = [&](int k, bool binary) -> const std::string& {
    for (auto it = sent[k].rbegin(); it != sent[k].rend(); ++it)
      if (it->binary == binary && (!binary || message_tag(it->data) == Tag::FrameResult))
        return it->data;
    throw std::runtime_error("nothing sent");
  };
  const Vertices expected = decode_frame_positions(last(0, true), rest);
  const Vertices shown = decode_frame_positions(last(1, true), rest);
  EXPECT_LT((shown - expected).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_LT((exported - expected).cwiseAbs().maxCoeff(), 1e-5);  // frames: 16 bits a coordinate
  EXPECT_FALSE(Json::parse(last(1, false))["detail_pending"]);
  EXPECT_FALSE(Json::parse(last(0, false))["detail_pending"]);
}

TEST_F(EditorSessionTest, BadMessagesAreAnsweredAndChangeNothing) {
  select(plain(selection_));
  const Eigen::Affine3d lift(Eigen::Translation3d(0, 0, 0.2));
  session_->handle(true, frame(lift));
  const Vertices before = last_frame();
  Eigen::Affine3d nan = lift;
  nan(0, 0) = std::nan("");
  const std::vector<std::tuple<bool, std::string, std::string>> bad = {
      {true, encode_frame({3, {lift, lift}}), "frame"},  // two groups, one selected
      {true, frame(nan, 3), "frame"},                    // not finite
      {true, encode_selection(plain({{{9999}}, {}}), Tag::Selection), "selection"},
      {true, encode_selection(plain({{{0}, {0}}, {}}), Tag::Selection), "selection"},
      {true, std::string("\x07\0\0\0", 4), "binary"},  // unknown tag
      {true, std::string("\x02\0", 2), "binary"},      // truncated
      {true, encode_file({"x.xyz", "1 2 3"}, Tag::MeshFile), "mesh_file"},
      {true, encode_file({"x.sel", "2\n2\n"}, Tag::SelectionFile), "selection_file"},
      {true,
       encode_file({"x.json", R"({"handles": [{"selection": "/etc/passwd"}]})"}, Tag::SceneFile),
       "scene_file"},
      {false, "not json", "text"},
      {false, R"({"type": "launch"})", "launch"},
      {false, R"({"type": "export_mesh", "format": "docx"})", "export_mesh"},
      {false, R"({"type": "export_mesh", "morph_targets": "twist"})", "export_mesh"},
      {false, R"({"type": "export_mesh", "joints": "stay"})", "export_mesh"},
      {false, R"({"type": "preview"})", "preview"},
      {false, R"({"type": "redo"})", "redo"},
  };
  for (const auto& [binary, message, request] : bad) {
    sent_.clear();
    session_->handle(binary, message);
    ASSERT_EQ(sent_.size(), 1u) << message;
    const Json reply = Json::parse(sent_[0].data);
    EXPECT_EQ(reply["type"], "error");
    EXPECT_EQ(reply["request"], request);
    EXPECT_EQ(reply["message"].get<std::string>().find('\n'), std::string::npos);
  }
  session_->handle(true, frame(lift, 4));
  EXPECT_LT((last_frame() - before).cwiseAbs().maxCoeff(), 1e-7);
}

// A rejected setting is answered with the error and the settings in force; the next valid
// one, and one that changes nothing, are answered with "ready" (the page never waits forever).
TEST_F(EditorSessionTest, EverySettingsRequestEndsInReady) {
  for (const std::string bad :
       {R"({"type": "settings", "kb": 0})", R"({"type": "settings", "modes": -3})",
        R"({"type": "settings", "detail": "sparkles"})",
        R"({"type": "settings", "energy": "elastic"})",
        R"({"type": "settings", "unconstrained": "drift"})"}) {
    sent_.clear();
    session_->handle(false, bad);
    EXPECT_EQ(text_types(), (std::vector<std::string>{"error", "ready"})) << bad;
    EXPECT_EQ(last_text("error")["request"], "settings");
    EXPECT_EQ(last_text("ready")["settings"]["kb"], 1.0);
    EXPECT_EQ(last_text("ready")["modes"], 30);
  }
  for (const std::string good :
       {R"({"type": "settings", "kb": 1})", R"({"type": "settings", "kb": 2})",
        R"({"type": "settings", "constraints": "hard"})",
        R"({"type": "settings", "constraints": "soft"})",
        R"({"type": "settings", "unconstrained": "keep"})"}) {
    sent_.clear();
    session_->handle(false, good);
    EXPECT_EQ(text_types(), std::vector<std::string>{"ready"}) << good;
  }
  EXPECT_EQ(last_text("ready")["settings"]["kb"], 2.0);
  EXPECT_EQ(last_text("ready")["settings"]["unconstrained"], "keep");
}

// A region of influence: the surface farther from the handle than the radius stays in place (to
// the frame's float precision); the setting is reported, and the selection itself is unchanged.
TEST_F(EditorSessionTest, TheRegionOfInfluenceHoldsTheSurfaceBeyondIt) {
  select(plain(selection_));
  session_->handle(false, R"({"type": "settings", "influence": 0.25})");
  EXPECT_EQ(last_text("ready")["settings"]["influence"], 0.25);
  session_->handle(true, frame(Eigen::Affine3d(Eigen::Translation3d(0.3, 0, 0.2))));
  const Vertices V = last_frame();
  const Eigen::VectorXd d = handle_distances({rest_, make_icosphere(2).F}, selection_);
  const double radius = 0.25 * bounding_box_diagonal(rest_);
  int held = 0;
  for (int i = 0; i < rest_.rows(); ++i) {
    if (d[i] <= radius) continue;
    EXPECT_LT((V.row(i) - rest_.row(i)).norm(), 1e-5) << i;
    ++held;
  }
  EXPECT_GT(held, 20);
  EXPECT_GT((V.row(selection_.handles[0][0]) - rest_.row(selection_.handles[0][0])).norm(), 0.2);
  EXPECT_EQ(last_text("state")["fixed"], selection_.fixed.size());
}

TEST_F(EditorSessionTest, SettingsRebuildAndKeepTheSelection) {
  select(plain(selection_));
  const Eigen::Vector3d t(0, 0, 0.25);
  session_->handle(true, frame(Eigen::Affine3d(Eigen::Translation3d(t))));
  session_->handle(false, R"({"type": "settings", "detail": "displacement", "modes": 20})");
  const Json ready = last_text("ready");
  EXPECT_EQ(ready["settings"]["detail"], "displacement");
  EXPECT_EQ(ready["modes"], 20);
  const Vertices V = last_frame();  // the frame is solved again with the new settings
  for (int i : selection_.fixed) EXPECT_LT((V.row(i) - rest_.row(i)).norm(), 1e-2);
  EXPECT_GT((V - rest_).rowwise().norm().maxCoeff(), 0.2);

  session_->handle(false, R"({"type": "settings", "view": "base"})");
  EXPECT_NE(last_frame(), V);
}

TEST_F(EditorSessionTest, ArapIsAnEnergyOfThePanel) {
  select(plain(selection_));
  const Eigen::Affine3d turn(Eigen::AngleAxisd(0.8, Eigen::Vector3d::UnitX()));
  session_->handle(true, frame(turn));
  const Vertices linear = last_frame();
  session_->handle(false, R"({"type": "settings", "energy": "arap"})");
  EXPECT_EQ(last_text("ready")["settings"]["energy"], "arap");
  EXPECT_GT(last_text("ready")["arap_clusters"], 0);
  const std::string& m = *last_binary(Tag::FrameResult);
  uint32_t iterations = 0;
  std::memcpy(&iterations, m.data() + 40, 4);
  EXPECT_GT(iterations, 0u);
  EXPECT_GT((last_frame() - linear).cwiseAbs().maxCoeff(), 1e-3);
}

// A new connection ("hello") gets the whole edit back: mesh, settings, groups with their
// transforms and flags, undo, and the deformed frame (the mesh only where it lacks it).
TEST_F(EditorSessionTest, HelloRestoresTheEdit) {
  session_->handle(false, R"({"type": "settings", "kb": 3})");
  GroupSelection s = plain(selection_);
  s.transforms[0] = Eigen::Translation3d(0, 0.1, 0);
  select(s);
  sent_.clear();
  session_->handle(false, R"({"type": "hello"})");
  EXPECT_EQ(text_types(), (std::vector<std::string>{"ready", "state"}));
  EXPECT_EQ(last_text("ready")["settings"]["kb"], 3.0);
  const GroupSelection back =
      decode_selection(*last_binary(Tag::SelectionResult), static_cast<int>(rest_.rows()));
  EXPECT_EQ(back.selection.handles, selection_.handles);
  EXPECT_EQ(back.selection.fixed, selection_.fixed);
  EXPECT_TRUE(back.transforms[0].matrix().isApprox(s.transforms[0].matrix()));
  EXPECT_TRUE(last_text("state")["undo"]);
  for (int i : selection_.handles[0]) EXPECT_NEAR(last_frame()(i, 1), rest_(i, 1) + 0.1, 1e-5);
  EXPECT_NE(last_binary(Tag::Mesh), nullptr);
  // A connection that got the mesh while it was prepared: everything but the mesh.
  sent_.clear();
  session_->handle(false, R"({"type": "hello", "has_mesh": true})");
  EXPECT_EQ(text_types(), (std::vector<std::string>{"ready", "state"}));
  EXPECT_EQ(last_binary(Tag::Mesh), nullptr);
  EXPECT_NE(last_binary(Tag::SelectionResult), nullptr);
  for (int i : selection_.handles[0]) EXPECT_NEAR(last_frame()(i, 1), rest_(i, 1) + 0.1, 1e-5);
}

TEST_F(EditorSessionTest, UndoAndRedoWalkTheEdits) {
  select(plain(selection_));
  const Eigen::Affine3d up(Eigen::Translation3d(0, 0, 0.2));
  session_->handle(true, frame(up));
  session_->handle(false, R"({"type": "commit"})");
  EXPECT_TRUE(last_text("state")["undo"]);
  EXPECT_FALSE(last_text("state")["redo"]);
  const Vertices moved = last_frame();

  session_->handle(false, R"({"type": "undo"})");  // the transform back to the identity
  EXPECT_LT((last_frame() - rest_).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_TRUE(last_text("state")["redo"]);
  session_->handle(false, R"({"type": "undo"})");  // no selection
  EXPECT_EQ(decode_selection(*last_binary(Tag::SelectionResult), 162).selection.handles.size(), 0u);
  EXPECT_FALSE(last_text("state")["undo"]);
  session_->handle(false, R"({"type": "redo"})");
  session_->handle(false, R"({"type": "redo"})");
  EXPECT_LT((last_frame() - moved).cwiseAbs().maxCoeff(), 1e-6);
}

// A pinned group stays where it was shown when it was painted, whatever the handle does next.
TEST_F(EditorSessionTest, PinsHoldTheShownPosition) {
  select(plain(selection_));
  session_->handle(true, frame(Eigen::Affine3d(Eigen::Translation3d(0.3, 0, 0))));
  const Vertices shown = last_frame();
  std::vector<int> belt;  // around the equator, moved by the drag
  for (int i = 0; i < rest_.rows(); ++i) {
    if (std::abs(rest_(i, 2)) < 0.15 && rest_(i, 0) > 0.5) belt.push_back(i);
  }
  ASSERT_GT((shown(belt[0], 0) - rest_(belt[0], 0)), 0.01);
  GroupSelection s = plain(selection_);
  s.selection.handles.push_back(belt);
  s.transforms = {Eigen::Affine3d(Eigen::Translation3d(0.3, 0, 0)), Eigen::Affine3d::Identity()};
  s.pinned = {false, true};
  s.fit = {false, true};
  select(s);
  const Json state = last_text("state");
  EXPECT_TRUE(state["groups"][1]["pinned"]);
  EXPECT_LT(state["pin_error"].get<double>(), 0.01);
  // The handle moves on; the pin neither follows the frame's transform for it nor springs back.
  session_->handle(
      true,
      encode_frame(
          {5, {Eigen::Affine3d(Eigen::Translation3d(0.3, 0.3, 0)), Eigen::Affine3d::Identity()}}));
  const Vertices V = last_frame();
  for (int i : belt) EXPECT_LT((V.row(i) - shown.row(i)).norm(), 0.02) << i;
}

// "apply_pose": the shown result becomes the rest shape; pins become fixed vertices there, and
// handles start again from the identity.
TEST_F(EditorSessionTest, ApplyPoseMakesTheResultTheRestShape) {
  select(plain(selection_));
  session_->handle(true, frame(Eigen::Affine3d(Eigen::Translation3d(0.2, 0, 0))));
  const Vertices posed = last_frame();
  sent_.clear();
  session_->handle(false, R"({"type": "apply_pose"})");
  ASSERT_TRUE(last_binary(Tag::Mesh));
  EXPECT_NEAR(current_rest()(selection_.handles[0][0], 0), posed(selection_.handles[0][0], 0),
              1e-6);
  const Json ready = last_text("ready");
  EXPECT_EQ(ready["pose"], 1);
  EXPECT_NE(ready["basis"]["source"], "cache");
  EXPECT_TRUE(last_text("state")["undo"]);
  // From the new rest shape, the identity keeps the pose.
  EXPECT_LT((last_frame() - posed).cwiseAbs().maxCoeff(), 1e-5);
  // Undo returns to the first pose and its deformed frame.
  session_->handle(false, R"({"type": "undo"})");
  EXPECT_EQ(last_text("ready")["pose"], 0);
  EXPECT_LT((last_frame() - posed).cwiseAbs().maxCoeff(), 1e-5);
}

TEST_F(EditorSessionTest, PreviewFramesCarryThePreviewVertices) {
  select(plain(selection_));
  session_->handle(false, R"({"type": "preview", "vertices": 60})");
  const std::string* preview = last_binary(Tag::Preview);
  ASSERT_TRUE(preview);
  uint32_t k = 0;
  std::memcpy(&k, preview->data() + 4, 4);
  EXPECT_GE(k, 45u);
  EXPECT_LE(k, 75u);
  std::vector<uint32_t> vertices(k);
  std::memcpy(vertices.data(), preview->data() + 12, 4 * k);
  const PreviewMesh mesh{std::vector<int>(vertices.begin(), vertices.end()), Faces(0, 3)};
  const Eigen::Affine3d up(Eigen::Translation3d(0, 0, 0.2));
  session_->handle(true, encode_frame({7, {up}, true}));
  const Vertices coarse = last_frame(&mesh);
  ASSERT_EQ(coarse.rows(), k);
  // An export after previews is of the detailed result of the same transforms.
  session_->handle(false, R"({"type": "export_mesh", "format": "obj"})");
  const NamedFile obj = decode_file(sent_.back().data);
  const Vertices exported = read_mesh_from_memory(obj.data, MeshFormat::Obj, obj.name).mesh.V;
  session_->handle(true, encode_frame({8, {up}, false}));
  const Vertices full = last_frame();
  EXPECT_LT((exported - full).cwiseAbs().maxCoeff(), 1e-5);  // frames: 16 bits a coordinate
  // The preview is the deformed smooth base with the details as displacements: near the
  // detailed result, and on the handle's target where the handle is.
  for (uint32_t i = 0; i < k; ++i) {
    EXPECT_LT((coarse.row(i) - full.row(vertices[i])).norm(), 0.02) << vertices[i];
  }
  EXPECT_GT((full - rest_).cwiseAbs().maxCoeff(), 0.1);
}

TEST_F(EditorSessionTest, ExportsTheDeformedMeshAndTheSceneAndOpensItAgain) {
  select(plain(selection_));
  const Eigen::Affine3d t(Eigen::Translation3d(0.05, 0, 0.2));
  session_->handle(true, frame(t));
  session_->handle(false, R"({"type": "export_mesh", "format": "obj"})");
  ASSERT_TRUE(sent_.back().binary);
  const NamedFile obj = decode_file(sent_.back().data);
  EXPECT_EQ(obj.name, "sphere-deformed.obj");
  const LoadedMesh exported = read_mesh_from_memory(obj.data, MeshFormat::Obj, obj.name);
  EXPECT_LT((exported.mesh.V - last_frame()).cwiseAbs().maxCoeff(), 1e-5);

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

  // "Open scene" of what "Export scene" wrote: the same selection and transform, after a clear.
  const Vertices deformed = last_frame();
  select(plain({}));
  session_->handle(true, encode_file(scene_file, Tag::SceneFile));
  const GroupSelection back =
      decode_selection(*last_binary(Tag::SelectionResult), static_cast<int>(rest_.rows()));
  EXPECT_EQ(back.selection.handles, selection_.handles);
  EXPECT_EQ(back.selection.fixed, selection_.fixed);
  EXPECT_LT((last_frame() - deformed).cwiseAbs().maxCoeff(), 1e-5);
}

TEST_F(EditorSessionTest, SelectionFilesAreAdopted) {
  std::string sel;
  for (int i = 0; i < rest_.rows(); ++i) sel += i == 3 ? "2\n" : i == 5 ? "0\n" : "1\n";
  session_->handle(true, encode_file({"pick.sel", sel}, Tag::SelectionFile));
  const GroupSelection s =
      decode_selection(*last_binary(Tag::SelectionResult), static_cast<int>(rest_.rows()));
  EXPECT_EQ(s.selection.handles, std::vector<std::vector<int>>{{3}});
  EXPECT_EQ(s.selection.fixed, std::vector<int>{5});
  EXPECT_TRUE(last_text("state")["undo"]);
}

// Cancel during a basis computation: the request is answered with a "cancelled" error and the
// session keeps its mesh and settings.
TEST(EditorSessionCancel, CancelKeepsThePreviousState) {
  std::vector<Json> texts;
  EditorSession* self = nullptr;
  bool armed = false;
  EditorSession session(EditorConfig{.modes = 20}, [&](bool binary, std::string data) {
    if (binary) return;
    texts.push_back(Json::parse(data));
    if (armed && texts.back()["type"] == "progress" && texts.back()["fraction"] < 1.0) {
      self->cancel();
    }
  });
  self = &session;
  LoadedMesh mesh;
  mesh.mesh = make_icosphere(4);
  mesh.info = identity_read_info(mesh.mesh);
  session.open(std::move(mesh), "sphere.obj");
  texts.clear();
  armed = true;
  session.handle(false, R"({"type": "settings", "modes": 60})");
  ASSERT_GE(texts.size(), 3u);
  EXPECT_EQ(texts[0]["type"], "progress");
  EXPECT_TRUE(texts[0]["cancellable"]);
  const Json& error = texts[texts.size() - 2];
  EXPECT_EQ(error["type"], "error");
  EXPECT_TRUE(error["cancelled"]);
  EXPECT_EQ(texts.back()["type"], "ready");
  EXPECT_EQ(texts.back()["modes"], 20);
}

// The mesh is sent as soon as it is read, before its basis's progress, so that the page draws
// it and handles are painted meanwhile; a stage without a fraction of its own (the solver's
// set-up) has its label, not a "100%" of the basis.
TEST(EditorSessionOpen, SendsTheMeshBeforeItsBasis) {
  std::vector<std::string> order;
  EditorSession session(EditorConfig{.modes = 20}, [&](bool binary, std::string data) {
    order.push_back(
        binary ? (starts_mesh(data) ? "mesh"
                                    : std::to_string(static_cast<uint32_t>(message_tag(data))))
               : Json::parse(data)["type"].get<std::string>() +
                     (data.find("setting up the solver") != std::string::npos ? " setup" : ""));
  });
  LoadedMesh mesh;
  mesh.mesh = make_icosphere(3);
  mesh.info = identity_read_info(mesh.mesh);
  session.open(std::move(mesh), "sphere.obj");
  const auto at = [&](const std::string& what) {
    return std::find(order.begin(), order.end(), what) - order.begin();
  };
  EXPECT_EQ(order.front(), "mesh");
  EXPECT_EQ(order[1], std::to_string(static_cast<uint32_t>(Tag::Mesh)));  // its triangles
  EXPECT_LT(at("progress"), at("progress setup"));
  EXPECT_LT(at("progress setup"), at("ready"));
  EXPECT_EQ(std::count(order.begin(), order.end(), order.front()), 1);  // sent once
}

// A new mesh cancelled while its basis computes: the page gets the open mesh back.
TEST(EditorSessionOpen, ACancelledOpenSendsTheOpenMeshBack) {
  std::vector<Sent> sent;
  EditorSession* self = nullptr;
  bool armed = false;
  EditorSession session(EditorConfig{.modes = 20}, [&](bool binary, std::string data) {
    if (armed && !binary && Json::parse(data)["type"] == "progress") self->cancel();
    sent.push_back({binary, std::move(data)});
  });
  self = &session;
  LoadedMesh first;
  first.mesh = make_icosphere(2);
  first.info = identity_read_info(first.mesh);
  session.open(std::move(first), "small.obj");
  sent.clear();
  armed = true;
  session.handle(true, encode_file({"big.obj", encode_mesh(make_icosphere(4), MeshFormat::Obj)},
                                   Tag::MeshFile));
  std::vector<uint32_t> vertices;
  for (const Sent& m : sent) {
    if (m.binary && starts_mesh(m.data)) {
      vertices.push_back(0);
      std::memcpy(&vertices.back(), m.data.data() + 4, 4);
    }
  }
  EXPECT_EQ(vertices, (std::vector<uint32_t>{2562, 162}));  // the new one, then the open one
  EXPECT_EQ(Json::parse(sent.back().data)["type"], "error");
}

// A computed basis is saved to the cache after "ready", in the background, and the page is told
// when it starts and when it is done (a page that comes later, after its "ready"); the next open
// loads it.
TEST(EditorSessionOpen, SavesTheBasisInTheBackground) {
  const std::filesystem::path cache =
      std::filesystem::temp_directory_path() / ("specdeform-save-" + std::to_string(::getpid()));
  std::filesystem::remove_all(cache);
  std::mutex mutex;
  std::condition_variable saved;
  std::vector<Json> texts;
  EditorSession session(EditorConfig{.modes = 20, .cache_dir = cache},
                        [&](bool binary, std::string data) {
                          if (binary) return;
                          std::lock_guard lock(mutex);
                          texts.push_back(Json::parse(data));
                          saved.notify_all();
                        });
  const auto open = [&] {
    LoadedMesh mesh;
    mesh.mesh = make_icosphere(3);
    mesh.info = identity_read_info(mesh.mesh);
    session.open(std::move(mesh), "sphere.obj");
  };
  open();
  {
    std::unique_lock lock(mutex);
    const auto ready = std::find_if(texts.begin(), texts.end(),
                                    [](const Json& j) { return j["type"] == "ready"; });
    const auto saving = std::find_if(texts.begin(), texts.end(),
                                     [](const Json& j) { return j["type"] == "saving"; });
    ASSERT_LT(ready, saving);
    EXPECT_FALSE((*saving)["done"]);
    ASSERT_TRUE(saved.wait_for(lock, std::chrono::seconds(30), [&] {
      return texts.back()["type"] == "saving" && texts.back()["done"];
    }));
    EXPECT_EQ(texts.back()["error"], "");
    EXPECT_GT(texts.back()["bytes"], 0);
    texts.clear();
  }
  const auto saving_after_ready = [&] {
    std::lock_guard lock(mutex);
    const auto ready = std::find_if(texts.begin(), texts.end(),
                                    [](const Json& j) { return j["type"] == "ready"; });
    const auto saving =
        std::find_if(ready, texts.end(), [](const Json& j) { return j["type"] == "saving"; });
    const bool said = ready != texts.end() && saving != texts.end() && (*saving)["done"] &&
                      (*saving)["error"] == "";
    texts.clear();
    return said;
  };
  session.handle(false, R"({"type": "hello", "has_mesh": false})");
  EXPECT_TRUE(saving_after_ready());
  open();
  session.handle(false, R"({"type": "hello", "has_mesh": true})");
  EXPECT_FALSE(saving_after_ready());  // loaded: nothing saved, the last mesh's report gone
  open();
  std::lock_guard lock(mutex);
  const auto ready =
      std::find_if(texts.begin(), texts.end(), [](const Json& j) { return j["type"] == "ready"; });
  ASSERT_NE(ready, texts.end());
  EXPECT_EQ((*ready)["basis"]["source"], "cache");
  EXPECT_TRUE(std::none_of(texts.begin(), texts.end(),
                           [](const Json& j) { return j["type"] == "saving"; }));
  std::filesystem::remove_all(cache);
}

TEST(Preview, CoarsensToAboutTheTargetAndKeepsMeshVertices) {
  const TriangleMesh mesh = make_icosphere(5);  // 10242 vertices
  const PreviewMesh p = make_preview(mesh, 1000);
  EXPECT_GE(p.vertices.size(), 750u);
  EXPECT_LE(p.vertices.size(), 1250u);
  EXPECT_GT(p.faces.rows(), static_cast<Eigen::Index>(p.vertices.size()));  // a surface, ~2k
  EXPECT_GE(p.faces.minCoeff(), 0);
  EXPECT_LT(p.faces.maxCoeff(), static_cast<int>(p.vertices.size()));
  for (int v : p.vertices) ASSERT_TRUE(v >= 0 && v < mesh.num_vertices());
  EXPECT_EQ(make_preview(mesh, 20000).vertices.size(), 10242u);
  EXPECT_THROW(make_preview(mesh, 2), InputError);
}

TEST(Pose, FitTransformRecoversAMotionAndStaysInvertibleOnFlatRegions) {
  const TriangleMesh mesh = make_icosphere(2);
  const Eigen::Affine3d motion = Eigen::Translation3d(0.1, -0.4, 2) *
                                 Eigen::AngleAxisd(1.1, Eigen::Vector3d(1, 2, 0.5).normalized());
  const Vertices moved =
      (mesh.V * motion.linear().transpose()).rowwise() + motion.translation().transpose();
  std::vector<int> all(mesh.num_vertices());
  std::iota(all.begin(), all.end(), 0);
  const FittedTransform fit = fit_transform(mesh.V, moved, all);
  EXPECT_LT(fit.max_error, 1e-9);
  EXPECT_TRUE(fit.transform.matrix().isApprox(motion.matrix(), 1e-9));
  // Three vertices span a plane only: the fit is still invertible and exact on them.
  const FittedTransform flat = fit_transform(mesh.V, moved, {0, 1, 2});
  EXPECT_LT(flat.max_error, 1e-6);
  EXPECT_GT(std::abs(flat.transform.linear().determinant()), 0.1);
  EXPECT_THROW(fit_transform(mesh.V, moved, {}), InputError);
}

TEST(Pose, AReusedBasisIsExactForARigidMotion) {
  const TriangleMesh mesh = make_icosphere(3);
  const ManifoldHarmonics basis = compute_manifold_harmonics(mesh, {.num_modes = 20});
  TriangleMesh turned = mesh;
  turned.V = mesh.V * Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const ManifoldHarmonics reused = reuse_basis(turned, basis);
  EXPECT_LT(reused.max_residual, 1e-8);
  EXPECT_LT((reused.eigenvalues - basis.eigenvalues).cwiseAbs().maxCoeff(),
            1e-6 * basis.eigenvalues.maxCoeff());
  TriangleMesh stretched = mesh;
  stretched.V.col(0) *= 3.0;
  EXPECT_GT(reuse_basis(stretched, basis).max_residual, kReuseResidual);
}

}  // namespace
}  // namespace specdeform::server

namespace specdeform::server {
namespace {

// The files of a zip archive by name (libzip).
std::map<std::string, std::string> unzip(const std::string& bytes) {
  zip_error_t error;
  zip_error_init(&error);
  zip_source_t* source = zip_source_buffer_create(bytes.data(), bytes.size(), 0, &error);
  zip_t* archive = zip_open_from_source(source, ZIP_RDONLY, &error);
  EXPECT_NE(archive, nullptr);
  std::map<std::string, std::string> out;
  for (zip_int64_t i = 0; archive && i < zip_get_num_entries(archive, 0); ++i) {
    zip_stat_t stat;
    zip_stat_index(archive, i, 0, &stat);
    std::string data(stat.size, '\0');
    zip_file_t* f = zip_fopen_index(archive, i, 0);
    zip_fread(f, data.data(), data.size());
    zip_fclose(f);
    out[stat.name] = std::move(data);
  }
  if (archive) zip_close(archive);
  return out;
}

// A textured OBJ opened with its MTL and image: exported as opened, one archive of the three
// that opens again where it is unpacked; a format that holds everything (.glb) is one file.
TEST(EditorSessionExport, ASetThatWorksWhereItIsSaved) {
  std::vector<Sent> sent;
  EditorSession session(EditorConfig{.modes = 20, .options = linear_options()},
                        [&](bool binary, std::string data) {
                          sent.push_back({binary, std::move(data)});
                        });
  const std::string obj =
      "mtllib box materials.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\n"
      "v 0 1 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl skin\nf 1/1 4/2 3/3 2/4\n"
      "f 5/1 6/2 7/3 8/4\nf 1/1 2/2 6/3 5/4\nf 2/1 3/2 7/3 6/4\nf 3/1 4/2 8/3 7/4\n"
      "f 4/1 1/2 5/3 8/4\n";
  const std::string mtl = "newmtl skin\nKd 1 1 1\nmap_Kd -s 1 1 1 box skin.png\n";
  const std::string png = "\x89PNG not really";
  session.handle(true, encode_file({"box materials.mtl", mtl}, Tag::CompanionFile));
  session.handle(true, encode_file({"box skin.png", png}, Tag::CompanionFile));
  session.handle(true, encode_file({"box.obj", obj}, Tag::MeshFile));
  bool capped = false;
  for (const Sent& m : sent)
    if (!m.binary && Json::parse(m.data)["type"] == "note" &&
        Json::parse(m.data)["message"].get<std::string>().find("m = 7") != std::string::npos)
      capped = true;
  EXPECT_TRUE(capped);  // 8 vertices: the default m lowered, said in a note
  sent.clear();
  session.handle(false, R"({"type": "export_mesh"})");
  ASSERT_TRUE(sent.back().binary);
  const NamedFile archive = decode_file(sent.back().data);
  EXPECT_EQ(archive.name, "box-deformed.zip");
  const std::map<std::string, std::string> files = unzip(archive.data);
  ASSERT_EQ(files.size(), 3u);
  EXPECT_EQ(files.at("box materials.mtl"), mtl);
  EXPECT_EQ(files.at("box skin.png"), png);
  EXPECT_EQ(read_mesh_from_memory(files.at("box-deformed.obj"), MeshFormat::Obj, "o").mesh.V,
            read_mesh_from_memory(obj, MeshFormat::Obj, "i").mesh.V);
  sent.clear();
  session.handle(false, R"({"type": "export_mesh", "format": "glb"})");
  EXPECT_EQ(decode_file(sent.back().data).name, "box-deformed.glb");
}

}  // namespace
}  // namespace specdeform::server
