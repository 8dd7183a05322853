// glTF read through tinygltf and written back byte for byte but POSITION (with its min and max),
// NORMAL and TANGENT, on files built here as exporters write them.
#include <tiny_gltf.h>

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "specdeform/exceptions.h"
#include "specdeform/mesh/io.h"
#include "specdeform/mesh/mesh_file.h"
#include "support/gltf_model.h"

namespace specdeform {
namespace {

using Json = nlohmann::json;

// A scene as exporters write one: a cube split into 24 vertices (a normal, uv and tangent per
// side), POSITION and NORMAL interleaved in one buffer view, drawn by a node under a turned and
// shifted parent; a triangle under a mirroring node; a line primitive; a mesh no node draws; an
// image in a buffer view; extras.
struct TestScene : test::GltfModel {
  TestScene() {
    model.asset.version = "2.0";
    model.buffers.emplace_back();
    // The cube: per side 4 vertices.
    std::vector<float> interleaved, uv, tangent;
    std::vector<uint16_t> indices;
    for (int axis = 0; axis < 3; ++axis) {
      for (const int sign : {-1, 1}) {
        Eigen::Vector3f n = Eigen::Vector3f::Zero();
        n[axis] = float(sign);
        const Eigen::Vector3f u = Eigen::Vector3f::Unit((axis + 1) % 3) * float(sign);
        const Eigen::Vector3f v = n.cross(u);
        const uint16_t first = uint16_t(interleaved.size() / 6);
        for (const auto& [a, b] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
          const Eigen::Vector3f p = n + float(a) * u + float(b) * v;
          interleaved.insert(interleaved.end(), {p.x(), p.y(), p.z(), n.x(), n.y(), n.z()});
          uv.insert(uv.end(), {0.5f * (a + 1), 0.5f * (1 - b)});
          tangent.insert(tangent.end(), {u.x(), u.y(), u.z(), 1.0f});
        }
        for (const int c : {0, 1, 2, 0, 2, 3}) indices.push_back(uint16_t(first + c));
      }
    }
    const int cube_pn = view(interleaved, 24);
    const int position =
        accessor(cube_pn, 0, 24, TINYGLTF_TYPE_VEC3, TINYGLTF_COMPONENT_TYPE_FLOAT);
    model.accessors[position].minValues = {-1, -1, -1};
    model.accessors[position].maxValues = {1, 1, 1};
    const int normal = accessor(cube_pn, 12, 24, TINYGLTF_TYPE_VEC3, TINYGLTF_COMPONENT_TYPE_FLOAT);
    const int texcoord =
        accessor(view(uv), 0, 24, TINYGLTF_TYPE_VEC2, TINYGLTF_COMPONENT_TYPE_FLOAT);
    const int tangents =
        accessor(view(tangent), 0, 24, TINYGLTF_TYPE_VEC4, TINYGLTF_COMPONENT_TYPE_FLOAT);
    const int index = accessor(view(indices), 0, 36, TINYGLTF_TYPE_SCALAR,
                               TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
    tinygltf::Primitive cube;
    cube.attributes = {{"POSITION", position},
                       {"NORMAL", normal},
                       {"TEXCOORD_0", texcoord},
                       {"TANGENT", tangents}};
    cube.indices = index;
    cube.mode = TINYGLTF_MODE_TRIANGLES;
    tinygltf::Primitive line;
    line.attributes = {{"POSITION", position}};
    line.mode = TINYGLTF_MODE_LINE;
    model.meshes.emplace_back();
    model.meshes[0].name = "cube";
    model.meshes[0].primitives = {cube, line};
    // A triangle, non-indexed.
    const std::vector<float> triangle = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    tinygltf::Primitive tri;
    tri.attributes = {{"POSITION", accessor(view(triangle), 0, 3, TINYGLTF_TYPE_VEC3,
                                            TINYGLTF_COMPONENT_TYPE_FLOAT)}};
    model.accessors.back().minValues = {0, 0, 0};
    model.accessors.back().maxValues = {1, 1, 0};
    tri.mode = TINYGLTF_MODE_TRIANGLES;
    model.meshes.emplace_back();
    model.meshes[1].primitives = {tri};
    model.meshes.push_back(model.meshes[1]);  // drawn by no node
    // An image in a buffer view.
    const std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', 1, 2, 3, 4};
    tinygltf::Image image;
    image.bufferView = view(png);
    image.mimeType = "image/png";
    model.images.push_back(image);
    // Nodes: 0 turned and shifted, its child 1 draws the cube; 2 mirrors the triangle.
    tinygltf::Node parent, child, mirror;
    parent.rotation = {0, 0, std::sin(0.3), std::cos(0.3)};
    parent.translation = {1, 2, 3};
    parent.children = {1};
    child.mesh = 0;
    child.scale = {2, 2, 2};
    mirror.mesh = 1;
    mirror.matrix = {-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 5, 0, 0, 1};
    model.nodes = {parent, child, mirror};
    model.scenes.emplace_back();
    model.scenes[0].nodes = {0, 2};
    model.defaultScene = 0;
    model.extras = tinygltf::Value(tinygltf::Value::Object{{"note", tinygltf::Value("kept")}});
  }
};

std::string read_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// A .glb of `json` and `bin`.
std::string glb_of(const Json& json, std::string bin) {
  std::string text = json.dump();
  text.resize((text.size() + 3) / 4 * 4, ' ');
  bin.resize((bin.size() + 3) / 4 * 4, '\0');
  const auto u32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  return "glTF" + u32(2) + u32(uint32_t(28 + text.size() + bin.size())) +
         u32(uint32_t(text.size())) + "JSON" + text + u32(uint32_t(bin.size())) +
         std::string("BIN\0", 4) + bin;
}

LoadedMesh keep(const std::string& bytes, MeshFormat format, FileResolver companions = {}) {
  return read_mesh_from_memory(bytes, format, "test",
                               {.keep_file = true, .companions = companions});
}

// The chunks of a .glb: JSON, BIN.
std::pair<Json, std::string> chunks(const std::string& glb) {
  uint32_t json_length;
  std::memcpy(&json_length, glb.data() + 12, 4);
  uint32_t bin_length;
  std::memcpy(&bin_length, glb.data() + 20 + json_length, 4);
  return {Json::parse(glb.substr(20, json_length)), glb.substr(28 + json_length, bin_length)};
}

Eigen::Matrix4d cube_world() {
  Eigen::Affine3d t = Eigen::Affine3d::Identity();
  t.translate(Eigen::Vector3d(1, 2, 3));
  t.rotate(Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitZ()));
  t.scale(2.0);
  return t.matrix();
}

TEST(Gltf, NumberingWeldingAndWorldSpace) {
  const TestScene scene;
  const LoadedMesh m = keep(scene.glb(), MeshFormat::Glb);
  // The cube's 24 POSITION vertices, then the triangle's 3; no line, no undrawn mesh.
  ASSERT_EQ(m.info.file_vertices.rows(), 27);
  EXPECT_EQ(m.mesh.num_vertices(), 8 + 3);
  EXPECT_EQ(m.mesh.num_faces(), 12 + 1);
  EXPECT_EQ(m.info.welded_vertices, 16);
  const Eigen::Matrix4d world = cube_world();
  const auto& p = scene.model.buffers[0].data;
  for (int v = 0; v < 24; ++v) {
    float local[3];
    std::memcpy(local, p.data() + 24 * v, 12);
    const Eigen::Vector4d w = world * Eigen::Vector4d(local[0], local[1], local[2], 1);
    EXPECT_LT((m.info.file_vertices.row(v).transpose() - w.head<3>()).norm(), 1e-12);
    // Copies share their mesh vertex.
    for (int u = 0; u < v; ++u) {
      if (m.info.file_vertices.row(u) == m.info.file_vertices.row(v))
        EXPECT_EQ(m.info.file_to_vertex[u], m.info.file_to_vertex[v]);
    }
  }
  // The closed cube faces outwards; the mirrored triangle is turned to face +z in world space
  // as it does in its own.
  double volume = 0;
  for (int f = 0; f < 12; ++f) {
    const Eigen::Vector3d a = m.mesh.V.row(m.mesh.F(f, 0)), b = m.mesh.V.row(m.mesh.F(f, 1)),
                          c = m.mesh.V.row(m.mesh.F(f, 2));
    volume += a.dot(b.cross(c)) / 6;
  }
  EXPECT_NEAR(volume, 64.0, 1e-9);
  const auto& V = m.mesh.V;
  const Eigen::RowVector3i t = m.mesh.F.row(12);
  const Eigen::Vector3d n = (V.row(t[1]) - V.row(t[0])).cross(V.row(t[2]) - V.row(t[0]));
  EXPECT_GT(n.z(), 0);
  EXPECT_EQ(V.row(t[0]).x() + V.row(t[1]).x() + V.row(t[2]).x(), 14.0);  // 5 - x, mirrored
  const FileSummary s = m.file->summary();
  EXPECT_EQ(s.meshes, 2);
  EXPECT_EQ(s.primitives, 2);
  EXPECT_EQ(s.images, 1);
}

TEST(Gltf, IdentityIsByteForByte) {
  const TestScene scene;
  for (const MeshFormat format : {MeshFormat::Glb, MeshFormat::Gltf}) {
    const std::string bytes = format == MeshFormat::Glb ? scene.glb() : scene.embedded();
    const LoadedMesh m = keep(bytes, format);
    const EncodedMesh out =
        encode_mesh_file(*m.file, m.file->rest, format == MeshFormat::Glb ? "o.glb" : "o.gltf");
    ASSERT_EQ(out.files.size(), 1u);
    EXPECT_EQ(out.files[0].bytes, bytes);
  }
}

// A rigid motion in world space: positions there, normals and tangents turned (w kept), min and
// max updated; the rest of the JSON and every other byte as it was.
TEST(Gltf, MovedRewritesOnlyPositionsNormalsTangents) {
  const TestScene scene;
  const std::string glb = scene.glb();
  const LoadedMesh m = keep(glb, MeshFormat::Glb);
  Eigen::Affine3d motion = Eigen::Affine3d::Identity();
  motion.translate(Eigen::Vector3d(-2, 0.5, 1));
  motion.rotate(Eigen::AngleAxisd(1.1, Eigen::Vector3d(1, 1, 0).normalized()));
  const Vertices X =
      (m.file->rest * motion.linear().transpose()).rowwise() + motion.translation().transpose();
  const std::string out = encode_mesh_file(*m.file, X, "o.glb").files[0].bytes;
  const LoadedMesh back = keep(out, MeshFormat::Glb);
  EXPECT_LT((back.file->rest - X).cwiseAbs().maxCoeff(), 1e-5);
  const Eigen::MatrixX3d turned = m.file->attributes.normals * motion.linear().transpose();
  EXPECT_LT((back.file->attributes.normals.topRows(24) - turned.topRows(24)).cwiseAbs().maxCoeff(),
            1e-6);

  auto [json_in, bin_in] = chunks(glb);
  auto [json_out, bin_out] = chunks(out);
  // Min and max: the new positions in the cube's own space.
  const Eigen::Matrix4d to_local = cube_world().inverse();
  Eigen::Array3d lo = Eigen::Array3d::Constant(1e300), hi = -lo;
  for (int v = 0; v < 24; ++v) {
    const Eigen::Vector4d local = to_local * Eigen::Vector4d(X(v, 0), X(v, 1), X(v, 2), 1);
    lo = lo.min(local.head<3>().array());
    hi = hi.max(local.head<3>().array());
  }
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(json_out["accessors"][0]["min"][k].get<double>(), lo[k], 1e-6);
    EXPECT_NEAR(json_out["accessors"][0]["max"][k].get<double>(), hi[k], 1e-6);
  }
  for (const int a : {0, 5}) {
    json_in["accessors"][a].erase("min");
    json_in["accessors"][a].erase("max");
    json_out["accessors"][a].erase("min");
    json_out["accessors"][a].erase("max");
  }
  EXPECT_EQ(json_in, json_out);
  // Bytes: the cube's interleaved view (positions and normals), its tangents' xyz, the
  // triangle's positions differ; its uv, tangents' w, indices, the undrawn mesh and the image do
  // not.
  ASSERT_EQ(bin_in.size(), bin_out.size());
  const auto& views = json_in["bufferViews"];
  const auto range = [&](int v) {
    const size_t at = views[v].value("byteOffset", 0);
    return std::pair{at, at + size_t(views[v]["byteLength"])};
  };
  std::vector<char> may_change(bin_in.size(), 0);
  for (size_t i = range(0).first; i < range(0).second; ++i) may_change[i] = 1;
  for (size_t i = range(2).first; i < range(2).second; ++i)
    may_change[i] = (i - range(2).first) % 16 < 12;
  for (size_t i = range(4).first; i < range(4).second; ++i) may_change[i] = 1;
  int changed = 0;
  for (size_t i = 0; i < bin_in.size(); ++i) {
    if (!may_change[i]) {
      ASSERT_EQ(bin_in[i], bin_out[i]) << "byte " << i;
    } else {
      changed += bin_in[i] != bin_out[i];
    }
  }
  EXPECT_GT(changed, 100);
  // Tangents turned with their faces (the cube's own space is turned by the same rotation's
  // conjugate), w kept.
  const Eigen::Matrix3d A = cube_world().topLeftCorner<3, 3>();
  const Eigen::Matrix3d local_turn = A.inverse() * motion.linear() * A;
  for (int v = 0; v < 24; ++v) {
    float before[4], after[4];
    std::memcpy(before, bin_in.data() + range(2).first + 16 * v, 16);
    std::memcpy(after, bin_out.data() + range(2).first + 16 * v, 16);
    const Eigen::Vector3d expected =
        (local_turn * Eigen::Vector3f(before).cast<double>()).normalized();
    EXPECT_LT((Eigen::Vector3f(after).cast<double>() - expected).norm(), 1e-6);
    EXPECT_EQ(after[3], before[3]);
  }
}

// A non-rigid deformation of the welded mesh: every copy of a vertex gets the same position.
TEST(Gltf, SeamsStayClosed) {
  const TestScene scene;
  const LoadedMesh m = keep(scene.glb(), MeshFormat::Glb);
  Vertices V = m.mesh.V;
  for (int i = 0; i < V.rows(); ++i)
    V.row(i) += Eigen::RowVector3d(std::sin(V(i, 1)), 0, V(i, 0) * 0.1);
  const Vertices X = to_file_order(m.info, V, m.mesh.F).V;
  const LoadedMesh back =
      keep(encode_mesh_file(*m.file, X, "o.glb").files[0].bytes, MeshFormat::Glb);
  EXPECT_EQ(back.mesh.num_vertices(), m.mesh.num_vertices());
  for (int v = 0; v < 27; ++v)
    EXPECT_LT((back.file->rest.row(v) - V.row(m.info.file_to_vertex[v])).norm(), 1e-5);
}

// A .gltf with its buffer beside it: a changed buffer is written under the output's name, so
// that two outputs in one folder stay apart and the input's own buffer is never replaced; an
// unchanged one stays the input's, copied beside an output in another folder.
TEST(Gltf, ExternalBuffer) {
  const auto dir = std::filesystem::temp_directory_path() / "specdeform_gltf_test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir / "out");
  TestScene scene;
  scene.model.buffers[0].uri = "scene data.bin";
  tinygltf::TinyGLTF writer;
  ASSERT_TRUE(writer.WriteGltfSceneToFile(&scene.model, (dir / "scene.gltf").string(), false, false,
                                          true, false));
  const std::string input_buffer = read_bytes(dir / "scene data.bin");
  const LoadedMesh m = read_mesh(dir / "scene.gltf", {.keep_file = true, .companions = {}});
  EXPECT_EQ(m.info.file_vertices.rows(), 27);
  const EncodedMesh same = encode_mesh_file(*m.file, m.file->rest, dir / "copy.gltf");
  ASSERT_EQ(same.files.size(), 1u);  // nothing moved: the buffer is the input's
  EXPECT_EQ(same.companions, std::vector<std::string>{"scene data.bin"});
  const Vertices X = m.file->rest.array() + 1.0, Y = m.file->rest.array() * 2.0;
  write_mesh_file(dir / "a.gltf", *m.file, X);
  write_mesh_file(dir / "b.gltf", *m.file, Y);
  for (const auto& [name, positions] : {std::pair{"a", &X}, std::pair{"b", &Y}}) {
    const auto path = dir / (std::string(name) + ".gltf");
    EXPECT_EQ(Json::parse(std::ifstream(path))["buffers"][0]["uri"], std::string(name) + ".bin");
    EXPECT_LT((read_mesh(path, {.keep_file = true, .companions = {}}).file->rest - *positions)
                  .cwiseAbs()
                  .maxCoeff(),
              1e-5);
  }
  EXPECT_EQ(read_bytes(dir / "scene data.bin"), input_buffer);
  // An output named after the input's buffer does not take its name.
  write_mesh_file(dir / "scene data.gltf", *m.file, X);
  EXPECT_EQ(Json::parse(std::ifstream(dir / "scene data.gltf"))["buffers"][0]["uri"],
            "scene%20data-1.bin");
  EXPECT_EQ(read_bytes(dir / "scene data.bin"), input_buffer);
  // Into another folder: the changed buffer after the output, the unchanged one copied.
  write_mesh_file(dir / "out" / "moved.gltf", *m.file, X);
  EXPECT_EQ(Json::parse(std::ifstream(dir / "out" / "moved.gltf"))["buffers"][0]["uri"],
            "moved.bin");
  write_mesh_file(dir / "out" / "copy.gltf", *m.file, m.file->rest);
  EXPECT_EQ(read_bytes(dir / "out" / "scene data.bin"), input_buffer);
  // Without it: one clear error.
  std::filesystem::remove(dir / "scene data.bin");
  try {
    read_mesh(dir / "scene.gltf");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("scene data.bin"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

void expect_refused(const std::string& glb, const std::string& fragment) {
  try {
    read_mesh_from_memory(glb, MeshFormat::Glb, "t.glb");
    ADD_FAILURE() << "no error, expected '" << fragment << "'";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
  }
}

TEST(Gltf, MalformedIsRefused) {
  {
    TestScene s;
    s.model.accessors[5].count = 1000;  // beyond its buffer
    expect_refused(s.glb(), "beyond its buffer");
  }
  {
    TestScene s;  // the node's mesh is a string: a member of the wrong type
    Json json = chunks(s.glb()).first;
    json["nodes"][1]["mesh"] = "cube";
    expect_refused(glb_of(json, chunks(s.glb()).second), "names a missing mesh");
    json["nodes"][1]["mesh"] = 0;
    json["meshes"][0]["primitives"][0]["mode"] = "triangles";
    expect_refused(glb_of(json, chunks(s.glb()).second), "malformed glTF");
    json["meshes"][0]["primitives"][0].erase("mode");
    json["nodes"][0]["children"] = {1, 1};
    expect_refused(glb_of(json, chunks(s.glb()).second), "reached twice");
  }
  for (const std::string& bad : {std::string("glTF"), std::string("glTF\x02\0\0\0\xff\xff\0\0", 12),
                                 std::string("{\"asset\": {\"version\": \"2.0\"}}")}) {
    EXPECT_THROW(read_mesh_from_memory(bad, MeshFormat::Glb, "t.glb"), InputError);
    EXPECT_THROW(read_mesh_from_memory(bad, MeshFormat::Gltf, "t.gltf"), InputError);
  }
}

// The world positions of the mesh drawings of a kept file, keyed by (mesh, node): the drawings'
// file vertices in order, whatever the file's numbering.
std::map<std::pair<std::string, int>, Vertices> drawings(const LoadedMesh& m, const Json& json) {
  std::map<std::pair<std::string, int>, Vertices> out;
  int at = 0;
  std::vector<std::pair<int, int>> order;  // mesh, node
  for (size_t n = 0; n < json["nodes"].size(); ++n)
    if (json["nodes"][n].contains("mesh")) order.emplace_back(json["nodes"][n]["mesh"], int(n));
  std::sort(order.begin(), order.end());
  for (const auto& [mesh, node] : order) {
    int count = 0;
    for (const Json& p : json["meshes"][mesh]["primitives"])
      if (p.value("mode", 4) >= 4)
        count += int(json["accessors"][int(p["attributes"]["POSITION"])]["count"]);
    out[{json["meshes"][mesh].value("name", ""), node}] = m.file->rest.middleRows(at, count);
    at += count;
  }
  return out;
}

// The cube drawn by a second node: a drawing of its own, numbered after the first; moving one
// drawing gives it its own POSITION (a new mesh for its node), the other keeps its bytes; moving
// both alike in the cube's own space keeps one accessor.
TEST(Gltf, MeshDrawnByTwoNodes) {
  TestScene scene;
  tinygltf::Node twin;
  twin.mesh = 0;
  twin.translation = {10, 0, 0};
  scene.model.nodes.push_back(twin);
  scene.model.scenes[0].nodes.push_back(3);
  const std::string glb = scene.glb();
  const LoadedMesh m = keep(glb, MeshFormat::Glb);
  ASSERT_EQ(m.info.file_vertices.rows(), 24 + 24 + 3);
  const Eigen::Matrix4d world = cube_world();
  for (int v = 0; v < 24; ++v) {
    const Eigen::Vector4d local =
        world.inverse() *
        Eigen::Vector4d(m.file->rest(v, 0), m.file->rest(v, 1), m.file->rest(v, 2), 1);
    EXPECT_LT((m.file->rest.row(24 + v).transpose() - (local.head<3>() + Eigen::Vector3d(10, 0, 0)))
                  .norm(),
              1e-12);
  }
  EXPECT_EQ(m.mesh.num_vertices(), 8 + 8 + 3);  // two pieces, welded apart
  EXPECT_EQ(encode_mesh_file(*m.file, m.file->rest, "o.glb").files[0].bytes, glb);
  EXPECT_EQ(m.file->summary().drawings, 3);

  // The twin moved.
  Vertices X = m.file->rest;
  X.middleRows(24, 24).rowwise() += Eigen::RowVector3d(0, 0, 3);
  const EncodedMesh moved = encode_mesh_file(*m.file, X, "o.glb");
  const auto [json, bin] = chunks(moved.files[0].bytes);
  ASSERT_EQ(json["meshes"].size(), 4u);
  EXPECT_EQ(json["nodes"][1]["mesh"], 0);
  EXPECT_EQ(json["nodes"][3]["mesh"], 3);
  const Json& copy = json["meshes"][3]["primitives"][0]["attributes"];
  EXPECT_NE(copy["POSITION"], 0);
  EXPECT_EQ(copy["NORMAL"], 1);  // a translation turns no normal: still shared
  EXPECT_EQ(copy["TEXCOORD_0"], 2);
  EXPECT_EQ(json["meshes"][3]["primitives"][0]["indices"], 4);
  EXPECT_EQ(bin.substr(0, chunks(glb).second.size()), chunks(glb).second);  // the input's bytes
  ASSERT_EQ(moved.notes.size(), 1u);
  EXPECT_NE(moved.notes[0].find("1 meshes copied"), std::string::npos) << moved.notes[0];
  const LoadedMesh back = keep(moved.files[0].bytes, MeshFormat::Glb);
  const auto before = drawings(m, chunks(glb).first), after = drawings(back, json);
  EXPECT_LT((after.at({"cube", 1}) - before.at({"cube", 1})).cwiseAbs().maxCoeff(), 0.0 + 1e-300);
  EXPECT_LT((after.at({"cube", 3}) - X.middleRows(24, 24)).cwiseAbs().maxCoeff(), 1e-5);
  const Json& position = json["accessors"][int(copy["POSITION"])];
  EXPECT_EQ(position["count"], 24);
  EXPECT_EQ(position["min"], Json({-1.0, -1.0, 2.0}));  // the twin's node only translates

  // Both moved alike in the cube's space: the accessor is rewritten in place, still shared.
  Vertices Y = m.file->rest;
  for (int v = 0; v < 48; ++v) {
    const Eigen::Matrix4d w =
        v < 24 ? world : Eigen::Affine3d(Eigen::Translation3d(10, 0, 0)).matrix();
    const Eigen::Vector4d local = w.inverse() * Eigen::Vector4d(Y(v, 0), Y(v, 1), Y(v, 2), 1);
    Y.row(v) =
        (w * Eigen::Vector4d(local.x() * 1.5, local.y(), local.z(), 1)).head<3>().transpose();
  }
  const auto [json_y, bin_y] = chunks(encode_mesh_file(*m.file, Y, "o.glb").files[0].bytes);
  EXPECT_EQ(json_y["meshes"].size(), 3u);
  EXPECT_EQ(json_y["accessors"].size(), chunks(glb).first["accessors"].size());
  EXPECT_EQ(json_y["accessors"][0]["max"][0], 1.5);
}

// An accessor two meshes share, drawn at two places: each drawing its own when they differ.
TEST(Gltf, AccessorSharedByTwoMeshes) {
  TestScene scene;  // mesh 2 is mesh 1 (the triangle) again, with the same accessor
  tinygltf::Node node;
  node.mesh = 2;
  node.translation = {0, 0, 5};
  scene.model.nodes.push_back(node);
  scene.model.scenes[0].nodes.push_back(3);
  const LoadedMesh m = keep(scene.glb(), MeshFormat::Glb);
  ASSERT_EQ(m.info.file_vertices.rows(), 24 + 3 + 3);
  Vertices X = m.file->rest;
  X.bottomRows(3).col(1).array() += 1.0;  // mesh 2's drawing
  const auto [json, bin] = chunks(encode_mesh_file(*m.file, X, "o.glb").files[0].bytes);
  const int original =
      chunks(scene.glb()).first["meshes"][1]["primitives"][0]["attributes"]["POSITION"];
  EXPECT_EQ(json["meshes"][1]["primitives"][0]["attributes"]["POSITION"], original);
  EXPECT_NE(json["meshes"][2]["primitives"][0]["attributes"]["POSITION"], original);
  EXPECT_EQ(json["meshes"].size(), 3u);  // mesh 2 has one node: re-pointed where it stands
  const LoadedMesh back =
      keep(encode_mesh_file(*m.file, X, "o.glb").files[0].bytes, MeshFormat::Glb);
  EXPECT_LT((back.file->rest - X).cwiseAbs().maxCoeff(), 1e-6);
}

// Positions stored as shorts (KHR_mesh_quantization) or sparse: read, and written as a float
// accessor of their own; every accessor written has the min and max of its values.
TEST(Gltf, QuantisedAndSparsePositions) {
  TestScene scene;
  const int view = scene.view(std::vector<int16_t>{0, 0, 0, 2, 0, 0, 0, 2, 0, 0});
  scene.model.meshes[1].primitives[0].attributes["POSITION"] =
      scene.accessor(view, 0, 3, TINYGLTF_TYPE_VEC3, TINYGLTF_COMPONENT_TYPE_SHORT);
  scene.model.accessors.back().minValues = {0, 0, 0};
  scene.model.accessors.back().maxValues = {2, 2, 0};
  scene.model.extensionsUsed = {"KHR_mesh_quantization"};
  scene.model.extensionsRequired = {"KHR_mesh_quantization"};
  // The cube's normals with a min and max, as exporters write them.
  scene.model.accessors[1].minValues = {-1, -1, -1};
  scene.model.accessors[1].maxValues = {1, 1, 1};
  const LoadedMesh m = keep(scene.glb(), MeshFormat::Glb);
  EXPECT_EQ(m.file->rest.row(25), Eigen::RowVector3d(5 - 2, 0, 0));  // mirrored by its node
  Eigen::Affine3d turn(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()));
  const Vertices X = m.file->rest * turn.linear().transpose();
  const auto [json, bin] = chunks(encode_mesh_file(*m.file, X, "o.glb").files[0].bytes);
  const int position = json["meshes"][1]["primitives"][0]["attributes"]["POSITION"];
  EXPECT_EQ(json["accessors"][position]["componentType"], TINYGLTF_COMPONENT_TYPE_FLOAT);
  EXPECT_FALSE(json["accessors"][position].contains("normalized"));
  EXPECT_EQ(json["extensionsRequired"], Json({"KHR_mesh_quantization"}));
  const LoadedMesh back = keep(glb_of(json, bin), MeshFormat::Glb);
  EXPECT_LT((back.file->rest - X).cwiseAbs().maxCoeff(), 1e-5);
  // The turned normals' min and max are their own.
  const Json& normal = json["accessors"][1];
  for (int k = 0; k < 3; ++k) {
    float lo = INFINITY, hi = -INFINITY;
    for (int v = 0; v < 24; ++v) {
      float n[3];
      std::memcpy(n, bin.data() + 24 * v + 12, 12);
      lo = std::min(lo, n[k]);
      hi = std::max(hi, n[k]);
    }
    EXPECT_EQ(normal["min"][k].get<float>(), lo);
    EXPECT_EQ(normal["max"][k].get<float>(), hi);
  }

  // Sparse: the triangle's positions all zero but one vertex.
  TestScene sparse;
  tinygltf::Accessor& a = sparse.model.accessors[5];
  a.bufferView = -1;
  a.sparse.isSparse = true;
  a.sparse.count = 1;
  a.sparse.indices.bufferView = sparse.view(std::vector<uint16_t>{2, 0});
  a.sparse.indices.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
  a.sparse.indices.byteOffset = 0;
  a.sparse.values.bufferView = sparse.view(std::vector<float>{0, 3, 0});
  a.sparse.values.byteOffset = 0;
  const LoadedMesh s = keep(sparse.glb(), MeshFormat::Glb);
  EXPECT_EQ(s.file->rest.row(26), Eigen::RowVector3d(5, 3, 0));
  const Vertices Z = s.file->rest.array() + 0.5;
  const LoadedMesh s_back =
      keep(encode_mesh_file(*s.file, Z, "o.glb").files[0].bytes, MeshFormat::Glb);
  EXPECT_LT((s_back.file->rest - Z).cwiseAbs().maxCoeff(), 1e-6);
}

// A node drawing the triangle by EXT_mesh_gpu_instancing: one drawing per instance; kept where
// the instances stay alike, one child node per instance where they do not.
TEST(Gltf, GpuInstancing) {
  TestScene scene;
  const int t = scene.accessor(scene.view(std::vector<float>{0, 0, 0, 0, 3, 0, 0, 6, 0}), 0, 3,
                               TINYGLTF_TYPE_VEC3, TINYGLTF_COMPONENT_TYPE_FLOAT);
  auto [json, bin] = chunks(scene.glb());
  json["nodes"][2]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]["TRANSLATION"] = t;
  json["extensionsUsed"] = {"EXT_mesh_gpu_instancing"};
  const std::string glb = glb_of(json, bin);
  const LoadedMesh m = keep(glb, MeshFormat::Glb);
  ASSERT_EQ(m.info.file_vertices.rows(), 24 + 9);
  for (int i = 0; i < 3; ++i)
    EXPECT_EQ(m.file->rest.row(24 + 3 * i), Eigen::RowVector3d(5, 3.0 * i, 0));
  EXPECT_EQ(encode_mesh_file(*m.file, m.file->rest, "o.glb").files[0].bytes, glb);
  Vertices X = m.file->rest;
  X.row(24 + 3).x() += 1;  // instance 1's first corner
  const EncodedMesh moved = encode_mesh_file(*m.file, X, "o.glb");
  const Json out = chunks(moved.files[0].bytes).first;
  EXPECT_FALSE(out.contains("extensionsUsed"));
  EXPECT_FALSE(out["nodes"][2].contains("mesh"));
  ASSERT_EQ(out["nodes"][2]["children"], Json({3, 4, 5}));
  EXPECT_EQ(out["nodes"][3]["mesh"], out["nodes"][5]["mesh"]);
  EXPECT_NE(out["nodes"][3]["mesh"], out["nodes"][4]["mesh"]);
  EXPECT_EQ(out["nodes"][4]["translation"], Json({0.0, 3.0, 0.0}));
  const LoadedMesh back = keep(moved.files[0].bytes, MeshFormat::Glb);
  EXPECT_EQ(back.info.file_vertices.rows(), 33);
}

// .glb <-> .gltf: the same document, only where the bytes live changes.
TEST(Gltf, ContainerChangeKeepsTheDocument) {
  TestScene scene;
  scene.model.nodes[1].name = "cube node";
  tinygltf::Material material;
  material.name = "glow";
  material.emissiveFactor = {1, 0.5, 0};
  material.extensions["KHR_materials_unlit"] = tinygltf::Value(tinygltf::Value::Object());
  scene.model.materials.push_back(material);
  scene.model.meshes[0].primitives[0].material = 0;
  scene.model.extensionsUsed = {"KHR_materials_unlit"};
  const std::string glb = scene.glb();
  const LoadedMesh m = keep(glb, MeshFormat::Glb);
  const Vertices X = m.file->rest.array() * 1.25;
  const EncodedMesh gltf = encode_mesh_file(*m.file, X, "dir/out.gltf");
  ASSERT_EQ(gltf.files.size(), 2u);
  EXPECT_EQ(gltf.files[1].name, "out.bin");
  Json text = Json::parse(gltf.files[0].bytes);
  EXPECT_EQ(text["buffers"][0]["uri"], "out.bin");
  Json expected = chunks(encode_mesh_file(*m.file, X, "o.glb").files[0].bytes).first;
  text["buffers"][0].erase("uri");
  EXPECT_EQ(text, expected);  // nodes, names, materials, extensions, extras: all there
  // And back into a .glb: the buffer file and the embedded image in the BIN chunk.
  const LoadedMesh g = keep(gltf.files[0].bytes, MeshFormat::Gltf, [&](const std::string& name) {
    return name == "out.bin" ? std::optional(gltf.files[1].bytes) : std::nullopt;
  });
  const EncodedMesh again = encode_mesh_file(*g.file, g.file->rest, "again.glb");
  ASSERT_EQ(again.files.size(), 1u);
  EXPECT_EQ(chunks(again.files[0].bytes).first, expected);
  EXPECT_LT((keep(again.files[0].bytes, MeshFormat::Glb).file->rest - X).cwiseAbs().maxCoeff(),
            1e-5);
}

// A material's base colour image as its texture says: the sampler's wraps and magnification,
// KHR_texture_transform (offset * rotation * scale); unlit from KHR_materials_unlit.
TEST(Gltf, MaterialLook) {
  TestScene scene;
  tinygltf::Sampler sampler;
  sampler.wrapS = 33648;     // MIRRORED_REPEAT
  sampler.wrapT = 33071;     // CLAMP_TO_EDGE
  sampler.magFilter = 9728;  // NEAREST
  scene.model.samplers.push_back(sampler);
  tinygltf::Texture texture;
  texture.source = 0;
  texture.sampler = 0;
  scene.model.textures.push_back(texture);
  tinygltf::Material material;
  material.pbrMetallicRoughness.baseColorTexture.index = 0;
  tinygltf::Value::Object transform;
  transform["offset"] =
      tinygltf::Value(tinygltf::Value::Array{tinygltf::Value(0.5), tinygltf::Value(0.25)});
  transform["rotation"] = tinygltf::Value(0.5);
  transform["scale"] =
      tinygltf::Value(tinygltf::Value::Array{tinygltf::Value(2.0), tinygltf::Value(3.0)});
  material.pbrMetallicRoughness.baseColorTexture.extensions["KHR_texture_transform"] =
      tinygltf::Value(transform);
  material.extensions["KHR_materials_unlit"] = tinygltf::Value(tinygltf::Value::Object());
  scene.model.materials.push_back(material);
  scene.model.materials.push_back(tinygltf::Material());
  const LoadedMesh m = keep(scene.glb(), MeshFormat::Glb);
  const std::vector<Material>& materials = m.file->attributes.materials;
  ASSERT_EQ(materials.size(), 2u);
  const TextureSampling& s = materials[0].sampling;
  EXPECT_EQ(s.wrap_u, TextureSampling::Wrap::Mirror);
  EXPECT_EQ(s.wrap_v, TextureSampling::Wrap::Clamp);
  EXPECT_TRUE(s.nearest);
  EXPECT_TRUE(materials[0].unlit);
  const float c = std::cos(0.5f), n = std::sin(0.5f);
  Eigen::Matrix<float, 2, 3> expected;
  expected << 2 * c, 3 * n, 0.5f, -2 * n, 3 * c, 0.25f;
  EXPECT_LT((s.transform - expected).cwiseAbs().maxCoeff(), 1e-6f);
  EXPECT_FALSE(materials[1].unlit);  // no texture: repeat, identity
  EXPECT_EQ(materials[1].sampling.wrap_u, TextureSampling::Wrap::Repeat);
  EXPECT_EQ(materials[1].sampling.transform, (Eigen::Matrix<float, 2, 3>::Identity()));
}

}  // namespace
}  // namespace specdeform
