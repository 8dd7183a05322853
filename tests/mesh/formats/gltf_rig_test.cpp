// A glTF's rig following the surface (src/mesh/formats/gltf/gltf_rig.h, the morph targets in
// gltf_rewriter.cpp), on a skinned strip built here: a ladder of three rows under an armature
// node (shifted and scaled), rows 0 and 1 driven by joint A, row 2 by its child B; a morph
// target; an animation keying A's translation and B's rotation.
#include <tiny_gltf.h>

#include <gtest/gtest.h>

#include <cstring>
#include <sstream>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "specdeform/mesh/io.h"
#include "specdeform/mesh/mesh_file.h"
#include "support/gltf_model.h"

namespace specdeform {
namespace {

using Json = nlohmann::json;

struct Strip : test::GltfModel {
  // `hat`: a triangle mesh without a skin that joint B carries (node 4, B's child).
  explicit Strip(const std::vector<double>& armature_scale = {2, 2, 2}, bool hat = false) {
    model.asset.version = "2.0";
    model.buffers.emplace_back();
    std::vector<float> position, target;
    std::vector<uint16_t> joints, indices;
    std::vector<float> weights;
    for (int row = 0; row < 3; ++row) {
      for (const float x : {-0.5f, 0.5f}) {
        position.insert(position.end(), {2 * x, 2.0f * row, 0.2f * row});
        target.insert(target.end(), {0.1f, 0.0f, 0.05f});
        joints.insert(joints.end(), {uint16_t(row == 2), 0, 0, 0});
        weights.insert(weights.end(), {1, 0, 0, 0});
      }
    }
    for (const int row : {0, 1})
      for (const int c : {0, 1, 3, 0, 3, 2}) indices.push_back(uint16_t(2 * row + c));
    tinygltf::Primitive p;
    p.attributes = {{"POSITION", accessor(view(position), 0, 6, TINYGLTF_TYPE_VEC3, 5126)},
                    {"JOINTS_0", accessor(view(joints), 0, 6, TINYGLTF_TYPE_VEC4, 5123)},
                    {"WEIGHTS_0", accessor(view(weights), 0, 6, TINYGLTF_TYPE_VEC4, 5126)}};
    model.accessors[0].minValues = {-1, 0, 0};
    model.accessors[0].maxValues = {1, 4, 0.4};
    p.targets = {{{"POSITION", accessor(view(target), 0, 6, TINYGLTF_TYPE_VEC3, 5126)}}};
    model.accessors.back().minValues = {0.1, 0, 0.05};
    model.accessors.back().maxValues = {0.1, 0, 0.05};
    p.indices = accessor(view(indices), 0, 12, TINYGLTF_TYPE_SCALAR, 5123);
    p.mode = TINYGLTF_MODE_TRIANGLES;
    model.meshes.emplace_back();
    model.meshes[0].primitives = {p};
    // Nodes: 0 the armature (parent of A), 1 joint A, 2 joint B (A's child), 3 the skinned mesh.
    tinygltf::Node armature, a, b, mesh;
    armature.translation = {0.5, 0, 0};
    armature.scale = armature_scale;
    armature.children = {1};
    a.children = {2};
    b.translation = {0, 1, 0};
    mesh.mesh = 0;
    mesh.skin = 0;
    model.nodes = {armature, a, b, mesh};
    if (hat) {
      const std::vector<float> corners = {-0.2f, 0, 0, 0.2f, 0, 0, 0, 0.3f, 0.1f};
      tinygltf::Primitive p;
      p.attributes = {{"POSITION", accessor(view(corners), 0, 3, TINYGLTF_TYPE_VEC3, 5126)}};
      model.accessors.back().minValues = {-0.2, 0, 0};
      model.accessors.back().maxValues = {0.2, 0.3, 0.1};
      p.mode = TINYGLTF_MODE_TRIANGLES;
      model.meshes.emplace_back();
      model.meshes.back().primitives = {p};
      tinygltf::Node carried;
      carried.mesh = 1;
      carried.translation = {0, 0.5, 0};
      model.nodes[2].children = {4};
      model.nodes.push_back(carried);
    }
    std::vector<float> ibm;
    for (const Eigen::Matrix4d& world :
         {armature_world(), Eigen::Matrix4d(armature_world() * shift(1))}) {
      const Eigen::Matrix4f inverse = world.inverse().cast<float>();
      ibm.insert(ibm.end(), inverse.data(), inverse.data() + 16);
    }
    tinygltf::Skin skin;
    skin.joints = {1, 2};
    skin.inverseBindMatrices = accessor(view(ibm), 0, 2, TINYGLTF_TYPE_MAT4, 5126);
    model.skins = {skin};
    // The animation: A steps along z, B turns about x.
    const std::vector<float> times = {0, 1}, steps = {0, 0, 0, 0, 0, 0.5f};
    const float s = std::sin(0.4f), c = std::cos(0.4f);
    const std::vector<float> turns = {0, 0, 0, 1, s, 0, 0, c};
    const int input = accessor(view(times), 0, 2, TINYGLTF_TYPE_SCALAR, 5126);
    model.accessors.back().minValues = {0};
    model.accessors.back().maxValues = {1};
    tinygltf::Animation walk;
    for (const auto& [node, path, values, type] :
         {std::tuple{1, "translation", steps, TINYGLTF_TYPE_VEC3},
          std::tuple{2, "rotation", turns, TINYGLTF_TYPE_VEC4}}) {
      tinygltf::AnimationSampler sampler;
      sampler.input = input;
      sampler.output = accessor(view(values), 0, 2, type, 5126);
      sampler.interpolation = "LINEAR";
      walk.samplers.push_back(sampler);
      tinygltf::AnimationChannel channel;
      channel.sampler = int(walk.samplers.size()) - 1;
      channel.target_node = node;
      channel.target_path = path;
      walk.channels.push_back(channel);
    }
    model.animations = {walk};
    model.scenes.emplace_back();
    model.scenes[0].nodes = {0, 3};
    model.defaultScene = 0;
  }

  Eigen::Matrix4d armature_world() const {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    for (int k = 0; k < 3; ++k) m(k, k) = model.nodes[0].scale[k];
    m(0, 3) = 0.5;
    return m;
  }
  static Eigen::Matrix4d shift(double y) {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m(1, 3) = y;
    return m;
  }
};

// A written .glb read back: its JSON and its accessors' floats.
struct Written {
  Json json;
  std::string bin;
  std::vector<std::string> notes;

  Written(const LoadedMesh& in, const Vertices& positions, const WriteOptions& options = {}) {
    const EncodedMesh out = encode_mesh_file(*in.file, positions, "out.glb", options);
    notes = out.notes;
    const std::string& glb = out.files.at(0).bytes;
    uint32_t json_length, bin_length;
    std::memcpy(&json_length, glb.data() + 12, 4);
    std::memcpy(&bin_length, glb.data() + 20 + json_length, 4);
    json = Json::parse(glb.substr(20, json_length));
    bin = glb.substr(28 + json_length, bin_length);
  }

  std::vector<float> floats(int accessor) const {
    const Json& a = json["accessors"][accessor];
    const Json& v = json["bufferViews"][a["bufferView"].get<int>()];
    const int k = a["type"] == "MAT4" ? 16 : a["type"] == "VEC4" ? 4 : 3;
    std::vector<float> out(a["count"].get<size_t>() * k);
    std::memcpy(out.data(), bin.data() + v.value("byteOffset", 0) + a.value("byteOffset", 0),
                out.size() * 4);
    return out;
  }
  Eigen::Matrix4d ibm(int joint) const {
    const std::vector<float> all = floats(json["skins"][0]["inverseBindMatrices"]);
    return Eigen::Map<const Eigen::Matrix4f>(all.data() + 16 * joint).cast<double>();
  }
  Eigen::Matrix4d local(int node) const {
    const Json& n = json["nodes"][node];
    Eigen::Affine3d m = Eigen::Affine3d::Identity();
    if (n.contains("translation")) {
      m.translate(Eigen::Vector3d(n["translation"][0], n["translation"][1], n["translation"][2]));
    }
    if (n.contains("rotation")) {
      m.rotate(Eigen::Quaterniond(n["rotation"][3], n["rotation"][0], n["rotation"][1],
                                  n["rotation"][2]));
    }
    if (n.contains("scale")) m.scale(Eigen::Vector3d(n["scale"][0], n["scale"][1], n["scale"][2]));
    return m.matrix();
  }
};

Eigen::Matrix4d motion(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = R;
  m.topRightCorner<3, 1>() = t;
  return m;
}

LoadedMesh read(const Strip& strip) {
  return read_mesh_from_memory(strip.glb(), MeshFormat::Glb, "strip", {.keep_file = true});
}

// The whole strip turned and shifted: every joint follows, the bind pose is the moved rest, the
// delta turns, and each joint's world transform moves by the same motion.
TEST(GltfRig, ARigidMotionCarriesJointsTargetsAndBindPose) {
  const Strip strip;
  const LoadedMesh in = read(strip);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).matrix();
  const Eigen::Vector3d t(0.3, -1, 2);
  const Vertices moved = (in.file->rest * R.transpose()).rowwise() + t.transpose();
  const Written out(in, moved);
  const Eigen::Matrix4d T = motion(R, t);
  const Eigen::Matrix4d bind_a = strip.armature_world(), bind_b = bind_a * Strip::shift(1);
  EXPECT_LT((out.ibm(0) - bind_a.inverse() * T.inverse()).norm(), 1e-5);
  EXPECT_LT((out.ibm(1) - bind_b.inverse() * T.inverse()).norm(), 1e-5);
  // The rest transforms: A's world moved by T, B's local as it was (it rides on A).
  EXPECT_LT((strip.armature_world() * out.local(1) - T * bind_a).norm(), 1e-6);
  EXPECT_EQ(out.json["nodes"][2], Written(in, in.file->rest).json["nodes"][2]);
  // The morph target's delta turned by R.
  const std::vector<float> delta =
      out.floats(out.json["meshes"][0]["primitives"][0]["targets"][0]["POSITION"]);
  const Eigen::Vector3d expected = R * Eigen::Vector3d(0.1, 0, 0.05);
  for (int v = 0; v < 6; ++v)
    EXPECT_LT((Eigen::Vector3f(&delta[3 * v]).cast<double>() - expected).norm(), 1e-6);
  // A's translation keys carried by K_A = P^-1 T P (P the armature); B's rotation keys as they
  // were (K_B = I).
  const Eigen::Matrix4d K = bind_a.inverse() * T * bind_a;
  const std::vector<float> steps = out.floats(out.json["animations"][0]["samplers"][0]["output"]);
  const Eigen::Vector3d key =
      K.topLeftCorner<3, 3>() * Eigen::Vector3d(0, 0, 0.5) + K.topRightCorner<3, 1>();
  EXPECT_LT((Eigen::Vector3f(&steps[3]).cast<double>() - key).norm(), 1e-5);
  EXPECT_EQ(out.floats(8), Written(in, in.file->rest).floats(8));  // B's rotation keys
  EXPECT_NE(out.notes.back().find("2 of 2 joints followed"), std::string::npos);
}

// Only the top row moves: A keeps its bytes (matrix, node, keys); B follows its row.
TEST(GltfRig, AJointWhoseVerticesStayKeepsItsBytes) {
  const Strip strip;
  const LoadedMesh in = read(strip);
  Vertices moved = in.file->rest;
  moved.bottomRows(2).rowwise() += Eigen::RowVector3d(0.4, 0, 0);
  const Written out(in, moved);
  const Written same(in, in.file->rest);
  EXPECT_EQ(out.ibm(0), same.ibm(0));
  EXPECT_EQ(out.json["nodes"][1], same.json["nodes"][1]);
  EXPECT_EQ(out.floats(7), same.floats(7));  // A's translation keys
  const Eigen::Matrix4d bind_b = strip.armature_world() * Strip::shift(1);
  EXPECT_LT(
      (out.ibm(1) -
       bind_b.inverse() * motion(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.4, 0, 0)).inverse())
          .norm(),
      1e-6);
  // The keep modes and the rest leave every byte.
  const EncodedMesh rest = encode_mesh_file(*in.file, in.file->rest, "out.glb");
  EXPECT_EQ(rest.files.at(0).bytes, strip.glb());
  const Written kept(in, moved, {.morph_targets = MorphTargets::Keep, .joints = Joints::Keep});
  EXPECT_EQ(kept.json["skins"], same.json["skins"]);
  EXPECT_EQ(kept.json["nodes"], same.json["nodes"]);
  EXPECT_EQ(kept.ibm(1), same.ibm(1));
}

// A mesh joint B carries without a skin (a hat) stays where it was deformed to: B moves with its
// row, the hat's node is set back by as much, the hat's world positions are those written.
TEST(GltfRig, AMeshAJointCarriesStaysWhereItWasDeformed) {
  const Strip strip({2, 2, 2}, true);
  const LoadedMesh in = read(strip);
  ASSERT_EQ(in.file->rest.rows(), 9);  // the strip's 6, the hat's 3
  Vertices moved = in.file->rest;
  moved.middleRows(4, 2).rowwise() += Eigen::RowVector3d(0.4, 0, 0);  // B's row
  moved.bottomRows(3).rowwise() += Eigen::RowVector3d(0.1, 0, 0);     // the hat, as deformed
  const EncodedMesh out = encode_mesh_file(*in.file, moved, "out.glb");
  const LoadedMesh back =
      read_mesh_from_memory(out.files.at(0).bytes, MeshFormat::Glb, "back", {.keep_file = true});
  EXPECT_LT((back.file->rest - moved).cwiseAbs().maxCoeff(), 1e-6);
  const Written written(in, moved), same(in, in.file->rest);
  EXPECT_NE(written.json["nodes"][2], same.json["nodes"][2]);  // B followed its row
  EXPECT_NE(written.json["nodes"][4], same.json["nodes"][4]);  // the hat set back
  EXPECT_NE(written.notes.back().find("(and of 1 mesh they carry, kept in place)"),
            std::string::npos);
}

// Nodes outside the scene whose children lists loop (a malformed file the reader takes, for the
// scene is sound) end the walks up the parents: written, not hung.
TEST(GltfRig, ChildrenListsThatLoopOutsideTheSceneAreCut) {
  Strip strip;
  tinygltf::Node a, b;
  a.children = {5};
  b.children = {4};
  strip.model.nodes.push_back(a);
  strip.model.nodes.push_back(b);
  const LoadedMesh in = read(strip);
  Vertices moved = in.file->rest;
  moved.bottomRows(2).rowwise() += Eigen::RowVector3d(0.4, 0, 0);
  const Written out(in, moved);
  EXPECT_NE(out.notes.back().find("joints followed"), std::string::npos);
}

// Under an armature with unequal scales a joint's correction is no similarity: left as it was,
// and said.
TEST(GltfRig, UnequalScalesAboveAJointAreSaid) {
  const Strip strip({1, 2, 1});
  const LoadedMesh in = read(strip);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).matrix();
  const Written out(in, in.file->rest * R.transpose());
  const Written same(in, in.file->rest);
  EXPECT_EQ(out.json["nodes"][1], same.json["nodes"][1]);
  EXPECT_NE(out.notes.back().find("joint 1 (under a transform with shear or unequal scales)"),
            std::string::npos);
}

}  // namespace
}  // namespace specdeform
