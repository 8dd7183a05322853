// A kept file written back: the same format gives the same file but its positions and normals
// (byte for byte where nothing moved), another format carries what it can and says what it drops.
#include "specdeform/mesh/mesh_file.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <Eigen/Geometry>

#include "specdeform/exceptions.h"
#include "specdeform/mesh/generate.h"
#include "specdeform/mesh/io.h"
#include "support/corpus.h"

namespace specdeform {
namespace {

LoadedMesh keep(std::string_view text, MeshFormat format, FileResolver companions = {}) {
  return read_mesh_from_memory(text, format, "test", {.keep_file = true, .companions = companions});
}

std::string write(const LoadedMesh& m, const Vertices& positions, const std::string& name,
                  const WriteOptions& options = {}) {
  return encode_mesh_file(*m.file, positions, name, options).files.front().bytes;
}

// A rigid motion: a turn about a tilted axis and a shift.
Eigen::Affine3d motion() {
  Eigen::Affine3d t = Eigen::Affine3d::Identity();
  t.translate(Eigen::Vector3d(0.3, -1.2, 2.0));
  t.rotate(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  return t;
}

Vertices moved(const Vertices& V, const Eigen::Affine3d& t = motion()) {
  return (V * t.linear().transpose()).rowwise() + t.translation().transpose();
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

bool starts_with_any(const std::string& line, std::initializer_list<const char*> keys) {
  for (const char* k : keys)
    if (line.rfind(k, 0) == 0) return true;
  return false;
}

// Every line of `out` that does not start with one of `keys` equals the input's, in order.
void expect_other_lines_equal(const std::string& in, const std::string& out,
                              std::initializer_list<const char*> keys) {
  const std::vector<std::string> a = lines(in), b = lines(out);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    if (starts_with_any(a[i], keys)) {
      EXPECT_TRUE(starts_with_any(b[i], keys)) << i << ": " << b[i];
    } else {
      EXPECT_EQ(a[i], b[i]) << "line " << i;
    }
  }
}

// A cube as a user's OBJ holds it: comments, a material library, groups, smoothing, quads with
// v/vt/vn corners and one normal per side (hard edges), a vertex colour, a polyline and a face
// with negative indices.
constexpr const char* kCubeObj =
    "# a cube\nmtllib cube.mtl\no Cube\n"
    "v -1 -1 -1 1 0 0\nv 1 -1 -1 1 0 0\nv 1 1 -1 1 0 0\nv -1 1 -1 1 0 0\n"
    "v -1 -1 1 0 1 0\nv 1 -1 1 0 1 0\nv 1 1 1 0 1 0\nv -1 1 1 0 1 0\n"
    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
    "vn 0 0 -1\nvn 0 0 1\nvn 0 -1 0\nvn 0 1 0\nvn -1 0 0\nvn 1 0 0\n"
    "g sides\nusemtl red\ns off\n"
    "f 1/1/1 4/4/1 3/3/1 2/2/1\nf 5/1/2 6/2/2 7/3/2 8/4/2\n"
    "usemtl blue\nf 1/1/3 2/2/3 6/3/3 5/4/3\nf 4/1/4 8/2/4 7/3/4 3/4/4\n"
    "f -8/1/5 -4/2/5 -1/3/5 -5/4/5\nf 2/1/6 3/2/6 7/3/6 6/4/6\n"
    "l 1 7\n";

TEST(MeshFile, ObjIdentityIsByteForByte) {
  const LoadedMesh m = keep(kCubeObj, MeshFormat::Obj);
  ASSERT_TRUE(m.file);
  EXPECT_EQ(write(m, m.file->rest, "out.obj"), kCubeObj);
  const FileAttributes& a = m.file->attributes;
  EXPECT_EQ(a.num_polygons(), 6);
  EXPECT_EQ(a.uv.rows(), 4);
  EXPECT_EQ(a.normals.rows(), 6);
  EXPECT_EQ(a.colours.rows(), 8);
  EXPECT_EQ(a.colours.row(5), Eigen::RowVector4f(0, 1, 0, 1));
  ASSERT_EQ(a.materials.size(), 2u);
  EXPECT_EQ(a.polygon_material, (std::vector<int>{0, 0, 1, 1, 1, 1}));
  EXPECT_EQ(a.corner_normal[16], 4);  // -8/1/5: the fifth side's normal
  EXPECT_EQ(a.corners[16], 0);
}

// A zero deformation's rounding (positions off by a few ulps, as a solve gives them) is not a
// move: the same bytes, normals included; a move just above it is one.
TEST(MeshFile, RoundingIsNotAMove) {
  const LoadedMesh m = keep(kCubeObj, MeshFormat::Obj);
  Vertices X = m.file->rest;
  X(6, 0) += 1e-15;
  X(2, 1) -= 3e-16;
  EXPECT_EQ(write(m, X, "out.obj"), kCubeObj);
  X(6, 0) += 1e-8;
  EXPECT_NE(write(m, X, "out.obj"), kCubeObj);
}

// Moved rigidly: every line but v and vn as it was; v lines at the new positions (colours kept),
// each hard-edged side's normal turned with it in every mode.
TEST(MeshFile, ObjMovedKeepsEveryOtherLine) {
  const LoadedMesh m = keep(kCubeObj, MeshFormat::Obj);
  const Vertices X = moved(m.file->rest);
  for (const NormalUpdate mode :
       {NormalUpdate::Follow, NormalUpdate::Recompute, NormalUpdate::Rotate}) {
    const std::string out = write(m, X, "out.obj", {.normals = mode});
    expect_other_lines_equal(kCubeObj, out, {"v ", "vn "});
    const LoadedMesh back = keep(out, MeshFormat::Obj);
    EXPECT_LT((back.file->rest - X).cwiseAbs().maxCoeff(), 1e-6);
    EXPECT_EQ(back.file->attributes.colours, m.file->attributes.colours);
    const Eigen::MatrixX3d expected = m.file->attributes.normals * motion().linear().transpose();
    const double tolerance = mode == NormalUpdate::Rotate ? 1e-6 : 1e-6;
    EXPECT_LT((back.file->attributes.normals - expected).cwiseAbs().maxCoeff(), tolerance)
        << name(mode);
  }
}

// Numbers that did not change keep their text; new ones are as short as the file's precision
// allows: float32 for a file whose positions have 9 significant digits or fewer, double where one
// has more (a file written in double precision has round values too: 0.5, 1).
TEST(MeshFile, NumbersKeepTheirTextAndPrecision) {
  const std::string single = "v 0.100000 1.0 +2\nv 0.123457 0 0\nv 0 1 0\nf 1 2 3\n";
  const LoadedMesh a = keep(single, MeshFormat::Obj);
  EXPECT_EQ(write(a, a.file->rest, "a.obj"), single);
  Vertices X = a.file->rest;
  X(0, 0) = 1.0 / 3.0;
  X(1, 0) = 0.3;
  EXPECT_EQ(write(a, X, "a.obj"), "v 0.33333334 1.0 +2\nv 0.3 0 0\nv 0 1 0\nf 1 2 3\n");
  const std::string full = "v 0.5 1 0\nv 0.12345678901234 0 0\nv 0 1 0\nf 1 2 3\n";
  const LoadedMesh b = keep(full, MeshFormat::Obj);
  EXPECT_EQ(write(b, b.file->rest, "b.obj"), full);
  X = b.file->rest;
  X(0, 0) = 1.0 / 3.0;
  EXPECT_EQ(write(b, X, "b.obj"),
            "v 0.3333333333333333 1 0\nv 0.12345678901234 0 0\nv 0 1 0\nf 1 2 3\n");
}

// Line continuations are kept (trimesh's wallhole.obj has them in its faces): the rest written
// back is the file; a moved vertex changes its own numbers only. One that splits a v line is
// written joined.
TEST(MeshFile, ObjContinuationsKept) {
  const std::string text =
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 \\\n2 3\nv 1 1 0\nf 2 \\  \r\n4 3\nv 2 2 0\nf 2 5 4\n";
  const LoadedMesh m = keep(text, MeshFormat::Obj);
  EXPECT_EQ(write(m, m.file->rest, "a.obj"), text);
  Vertices X = m.file->rest;
  X(4, 1) = 3.0;
  EXPECT_EQ(write(m, X, "a.obj"),
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 \\\n2 3\nv 1 1 0\nf 2 \\  \r\n4 3\nv 2 3 0\nf 2 5 4\n");
  const LoadedMesh split = keep("v 0 0 \\\n0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", MeshFormat::Obj);
  EXPECT_EQ(write(split, split.file->rest, "a.obj"), "v 0 0  0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
}

// A file read in two halves keeps the same record as one read whole: vt, vn and usemtl before
// the split apply after it, negative indices reach back across it.
TEST(MeshFile, LargeObjKeptAcrossTheSplit) {
  std::string text = "mtllib m.mtl\nusemtl first\nvt 0.5 0.5\nvn 0 0 1\nv 0 0 0\nv 0 1 0\n";
  constexpr int kQuads = 120'000;
  for (int q = 1; q <= kQuads; ++q) {
    const std::string x = std::to_string(q);
    text += "v " + x + " 0 0\nv " + x + " 1 0\nvt 0.25 0.75\n";
    text += "f -4/1/1 -2/-1/1 -1/-1/1 -3/1/-1\n";
    if (q == kQuads - 10) text += "usemtl last\n";
  }
  ASSERT_GT(text.size(), size_t{8} << 20);
  const LoadedMesh m = keep(text, MeshFormat::Obj);
  const FileAttributes& a = m.file->attributes;
  EXPECT_EQ(a.uv.rows(), kQuads + 1);
  EXPECT_EQ(a.corner_uv[4 * (kQuads - 1) + 1], kQuads);
  EXPECT_EQ(a.corner_uv[4 * 70'000 + 3], 0);
  EXPECT_EQ(a.corner_normal[4 * 100'000], 0);
  ASSERT_EQ(a.materials.size(), 2u);
  EXPECT_EQ(a.polygon_material[90'000], 0);
  EXPECT_EQ(a.polygon_material.back(), 1);
  EXPECT_EQ(write(m, m.file->rest, "a.obj"), text);
  const Vertices X = moved(m.file->rest);
  const LoadedMesh back = keep(write(m, X, "a.obj"), MeshFormat::Obj);
  // Its numbers have 9 digits or fewer: written back at float32 precision.
  EXPECT_LT((back.file->rest - X).cwiseAbs().maxCoeff(), 1e-7 * X.cwiseAbs().maxCoeff());
}

// PLY as scanners write it: a header with comments and obj_info, colour and confidence per
// vertex, normals, a face colour and an element no mesh reader knows; in ASCII and binary of
// both byte orders.
std::string scan_ply(const std::string& format) {
  const TriangleMesh m = make_icosphere(1);
  const auto N = vertex_normals(m);
  std::ostringstream h;
  h << "ply\nformat " << format << " 1.0\ncomment made by a scanner\nobj_info frame 7\n"
    << "element vertex " << m.num_vertices() << "\nproperty float x\nproperty float y\n"
    << "property float z\nproperty float nx\nproperty float ny\nproperty float nz\n"
    << "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty float confidence\n"
    << "element face " << m.num_faces() << "\nproperty list uchar int vertex_indices\n"
    << "property uchar flags\nelement edge 1\nproperty int vertex1\nproperty int vertex2\n"
    << "end_header\n";
  std::string s = h.str();
  const bool ascii = format == "ascii", big = format == "binary_big_endian";
  const auto put = [&](auto v) {
    char b[sizeof v];
    std::memcpy(b, &v, sizeof v);
    if (big) std::reverse(b, b + sizeof v);
    s.append(b, sizeof v);
  };
  for (int i = 0; i < m.num_vertices(); ++i) {
    const float values[7] = {float(m.V(i, 0)),    float(m.V(i, 1)), float(m.V(i, 2)),
                             float(N(i, 0)),      float(N(i, 1)),   float(N(i, 2)),
                             0.25f * float(i % 4)};
    const uint8_t rgb[3] = {uint8_t(i), uint8_t(2 * i), 200};
    if (ascii) {
      for (int k = 0; k < 6; ++k) s += std::to_string(values[k]) + " ";
      for (int k = 0; k < 3; ++k) s += std::to_string(rgb[k]) + " ";
      s += std::to_string(values[6]) + "\n";
    } else {
      for (int k = 0; k < 6; ++k) put(values[k]);
      for (int k = 0; k < 3; ++k) put(rgb[k]);
      put(values[6]);
    }
  }
  for (int f = 0; f < m.num_faces(); ++f) {
    if (ascii) {
      s += "3 " + std::to_string(m.F(f, 0)) + " " + std::to_string(m.F(f, 1)) + " " +
           std::to_string(m.F(f, 2)) + " " + std::to_string(f % 3) + "\n";
    } else {
      put(uint8_t{3});
      for (int k = 0; k < 3; ++k) put(int32_t{m.F(f, k)});
      put(uint8_t(f % 3));
    }
  }
  if (ascii) {
    s += "0 5\n";
  } else {
    put(int32_t{0});
    put(int32_t{5});
  }
  return s;
}

TEST(MeshFile, PlyKeepsEveryPropertyAndItsFormat) {
  for (const char* format : {"ascii", "binary_little_endian", "binary_big_endian"}) {
    SCOPED_TRACE(format);
    const std::string text = scan_ply(format);
    const LoadedMesh m = keep(text, MeshFormat::Ply);
    EXPECT_EQ(write(m, m.file->rest, "a.ply"), text);
    EXPECT_EQ(m.file->attributes.colours(3, 1), 6.0f / 255.0f);
    const Vertices X = moved(m.file->rest);
    const std::string out = write(m, X, "a.ply");
    const size_t header = text.find("end_header\n") + 11;
    EXPECT_EQ(out.substr(0, header), text.substr(0, header));
    const LoadedMesh back = keep(out, MeshFormat::Ply);
    EXPECT_LT((back.file->rest - X).cwiseAbs().maxCoeff(), 1e-5);
    EXPECT_EQ(back.file->attributes.colours, m.file->attributes.colours);
    const Eigen::MatrixX3d expected = m.file->attributes.normals * motion().linear().transpose();
    EXPECT_LT((back.file->attributes.normals - expected).cwiseAbs().maxCoeff(), 1e-5);
    if (std::string(format) == "ascii") {
      // Every token but x y z nx ny nz is the input's.
      const std::vector<std::string> a = lines(text), b = lines(out);
      ASSERT_EQ(a.size(), b.size());
      for (size_t i = 0; i < a.size(); ++i) {
        std::istringstream ia(a[i]), ib(b[i]);
        std::vector<std::string> ta, tb;
        for (std::string t; ia >> t;) ta.push_back(t);
        for (std::string t; ib >> t;) tb.push_back(t);
        ASSERT_EQ(ta.size(), tb.size());
        const bool vertex = i >= lines(text.substr(0, header)).size() &&
                            i < lines(text.substr(0, header)).size() + 42;
        for (size_t k = vertex ? 6 : 0; k < ta.size(); ++k) EXPECT_EQ(ta[k], tb[k]) << i;
      }
    } else {
      // Bytes differ only in the vertices' first 24 (x y z nx ny nz).
      ASSERT_EQ(out.size(), text.size());
      for (size_t i = header; i < text.size(); ++i) {
        const size_t in_vertex = (i - header) % 31;
        if (i - header < 42 * 31 && in_vertex < 24) continue;
        ASSERT_EQ(out[i], text[i]) << "byte " << i;
      }
    }
  }
}

// OFF with normals and colours; per-face colours after the indices.
TEST(MeshFile, OffKeepsColoursAndTurnsNormals) {
  const std::string text =
      "CNOFF\n# a tetrahedron\n4 4 0\n"
      "0 0 0 -1 -1 -1 255 0 0 255\n1 0 0 1 -1 -1 0 255 0 255\n0 1 0 -1 1 -1 0 0 255 255\n"
      "0 0 1 -1 -1 1 9 9 9 255\n"
      "3 0 2 1 1 0 0\n3 0 1 3 0 1 0\n3 0 3 2 0 0 1\n3 1 2 3 1 1 1\n";
  const LoadedMesh m = keep(text, MeshFormat::Off);
  EXPECT_EQ(write(m, m.file->rest, "a.off"), text);
  EXPECT_EQ(m.file->attributes.colours(1, 1), 1.0f);
  const std::string out = write(m, moved(m.file->rest), "a.off");
  const std::vector<std::string> a = lines(text), b = lines(out);
  for (size_t i = 0; i < a.size(); ++i) {
    if (i >= 3 && i < 7) {
      EXPECT_EQ(a[i].substr(a[i].rfind(' ', a[i].size() - 5)),
                b[i].substr(b[i].rfind(' ', b[i].size() - 5)));
      EXPECT_TRUE(b[i].ends_with(a[i].substr(a[i].size() - 10))) << b[i];
    } else {
      EXPECT_EQ(a[i], b[i]);
    }
  }
}

// STL keeps its solid name or header and attribute bytes; facet normals follow the facets.
TEST(MeshFile, StlKeepsNameAndAttributes) {
  const std::string ascii =
      "solid part_7\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n"
      "   vertex 0 1 0\n  endloop\n endfacet\n facet normal 0 0 0\n  outer loop\n"
      "   vertex 1 0 0\n   vertex 1 1 0\n   vertex 0 1 0\n  endloop\n endfacet\nendsolid part_7\n";
  const LoadedMesh a = keep(ascii, MeshFormat::Stl);
  EXPECT_EQ(write(a, a.file->rest, "a.stl"), ascii);
  const std::string out = write(a, moved(a.file->rest), "a.stl");
  expect_other_lines_equal(ascii, out, {" facet normal", "   vertex"});
  const LoadedMesh back = keep(out, MeshFormat::Stl);
  const Eigen::Vector3d up = motion().linear() * Eigen::Vector3d::UnitZ();
  for (int f = 0; f < 2; ++f)  // the zero normal too: recomputed
    EXPECT_LT((back.file->attributes.normals.row(f).transpose() - up).norm(), 1e-6);

  std::string binary = encode_mesh(make_icosphere(1), MeshFormat::Stl);
  binary.replace(0, 12, std::string("COLOR=\x11\x22\x33\x44 x", 12));
  for (int f = 0; f < 80; ++f) binary[84 + 50 * f + 48] = char(f);  // attribute bytes
  const LoadedMesh b = keep(binary, MeshFormat::Stl);
  EXPECT_EQ(write(b, b.file->rest, "b.stl"), binary);
  const std::string moved_binary = write(b, moved(b.file->rest), "b.stl");
  EXPECT_EQ(moved_binary.substr(0, 84), binary.substr(0, 84));
  for (int f = 0; f < 80; ++f)
    EXPECT_EQ(moved_binary.substr(84 + 50 * f + 48, 2), binary.substr(84 + 50 * f + 48, 2));
}

// What the fuzzer found: files whose identity write must still be the file. A vertical tab
// between numbers; an STL facet whose "normal" follows its loop; bytes after a .glb's length.
TEST(MeshFile, AwkwardLayoutsComeBackWhole) {
  const std::string obj = "v 0 0 0\nv \v1 0 0\nv 0 1 0\nf 1 2 3\n";
  const LoadedMesh a = keep(obj, MeshFormat::Obj);
  EXPECT_EQ(write(a, a.file->rest, "a.obj"), obj);
  const std::string stl =
      "solid s\n outer loop\n vertex 0 0 0\n vertex 1 0 0\n vertex 0 1 0\n endloop\n"
      " facet normal 0 0 1\n endfacet\nendsolid s\n";
  const LoadedMesh b = keep(stl, MeshFormat::Stl);
  EXPECT_EQ(write(b, b.file->rest, "b.stl"), stl);
  const std::string moved = write(b, b.file->rest.array() + 1.0, "b.stl");
  EXPECT_NE(moved.find("vertex 1 1 1"), std::string::npos) << moved;
  EXPECT_NE(moved.find("facet normal 0 0 1"), std::string::npos) << moved;
  std::string glb = encode_mesh(make_icosphere(0), MeshFormat::Glb);
  glb += "trailing";
  const LoadedMesh c = keep(glb, MeshFormat::Glb);
  EXPECT_EQ(write(c, c.file->rest, "c.glb"), glb);
}

// Another format carries what it can and names the rest.
TEST(MeshFile, OtherFormatsCarryWhatTheyCan) {
  const LoadedMesh m = keep(kCubeObj, MeshFormat::Obj);
  const Vertices X = moved(m.file->rest);
  // OBJ -> glTF -> OBJ: texture coordinates (v turned) and normals per corner survive.
  const EncodedMesh glb = encode_mesh_file(*m.file, X, "cube.glb");
  const LoadedMesh g = keep(glb.files.front().bytes, MeshFormat::Glb);
  EXPECT_EQ(g.mesh.num_vertices(), 8);  // 24 glTF vertices welded at the corners
  EXPECT_EQ(g.file->attributes.num_polygons(), 12);
  ASSERT_EQ(g.file->attributes.materials.size(), 2u);
  EXPECT_EQ(g.file->attributes.materials[1].name, "blue");
  for (int c = 0; c < 36; ++c) {
    const Eigen::RowVector2d uv = g.file->attributes.uv.row(g.file->attributes.corner_uv[c]);
    EXPECT_TRUE(uv.x() == 0 || uv.x() == 1) << uv;
  }
  for (int v = 0; v < g.file->rest.rows(); ++v) {  // each glTF vertex at one of the cube's
    const Eigen::VectorXd distance = (X.rowwise() - g.file->rest.row(v)).rowwise().norm();
    EXPECT_LT(distance.minCoeff(), 1e-6);
  }
  EXPECT_FALSE(glb.notes.empty());
  const EncodedMesh obj = encode_mesh_file(*g.file, g.file->rest, "cube.obj");
  const LoadedMesh o = keep(obj.files.front().bytes, MeshFormat::Obj);
  EXPECT_EQ(o.file->attributes.corner_uv.size(), 36u);
  EXPECT_EQ(o.file->attributes.uv.rows(), g.file->attributes.uv.rows());
  EXPECT_EQ(obj.files[1].name, "cube.mtl");
  EXPECT_NE(obj.files[1].bytes.find("newmtl blue"), std::string::npos);
  // STL: triangles only, said so.
  const EncodedMesh stl = encode_mesh_file(*m.file, X, "cube.stl");
  ASSERT_EQ(stl.notes.size(), 1u);
  for (const char* lost :
       {"polygons", "texture coordinates", "normals", "vertex colours", "materials", "groups"})
    EXPECT_NE(stl.notes[0].find(lost), std::string::npos) << lost << ": " << stl.notes[0];
  // PLY: quads, colours and per-corner texture coordinates kept.
  const LoadedMesh p =
      keep(encode_mesh_file(*m.file, X, "cube.ply").files.front().bytes, MeshFormat::Ply);
  EXPECT_EQ(p.file->attributes.num_polygons(), 6);
  EXPECT_EQ(p.file->attributes.colours.leftCols<3>(), m.file->attributes.colours.leftCols<3>());
  EXPECT_EQ(p.file->attributes.corner_uv.size(), 24u);
}

TEST(MeshFile, PositionsMustMatch) {
  const LoadedMesh m = keep(kCubeObj, MeshFormat::Obj);
  EXPECT_THROW(encode_mesh_file(*m.file, Vertices::Zero(3, 3), "a.obj"), InputError);
  Vertices X = m.file->rest;
  X(2, 1) = std::nan("");
  EXPECT_THROW(encode_mesh_file(*m.file, X, "a.obj"), InputError);
  EXPECT_THROW(encode_mesh_file(*m.file, m.file->rest, "a.dae"), InputError);
}

// write_mesh_file copies the companions into another folder, never over the input's.
TEST(MeshFile, CompanionsCopiedBesideTheOutput) {
  const auto dir = std::filesystem::temp_directory_path() / "specdeform_mesh_file_test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir / "in" / "tex");
  std::filesystem::create_directories(dir / "out");
  std::ofstream(dir / "in" / "cube.obj") << kCubeObj;
  std::ofstream(dir / "in" / "cube.mtl")
      << "newmtl red\nKd 1 0 0\nmap_Kd -clamp on -s 2 3 1 -o 0.5 0.25 tex/red.png\n"
         "newmtl blue\nKd 0 0 1\n";
  std::ofstream(dir / "in" / "tex" / "red.png") << "PNG";
  const LoadedMesh m = read_mesh(dir / "in" / "cube.obj", {.keep_file = true, .companions = {}});
  ASSERT_EQ(m.file->attributes.materials[0].texture, "tex/red.png");
  EXPECT_EQ(m.file->attributes.materials[0].base_color, Eigen::Vector4f(1, 0, 0, 1));
  const TextureSampling& sampling = m.file->attributes.materials[0].sampling;
  EXPECT_EQ(sampling.wrap_u, TextureSampling::Wrap::Clamp);
  Eigen::Matrix<float, 2, 3> laid;
  laid << 2, 0, 0.5, 0, 3, 0.25;  // (2 u + 0.5, 3 v + 0.25)
  EXPECT_EQ(sampling.transform, laid);
  EXPECT_EQ(m.file->attributes.materials[1].sampling.wrap_v, TextureSampling::Wrap::Repeat);
  EXPECT_EQ(m.file->texture(0)->first, "PNG");
  EXPECT_EQ(companion_names(*m.file), (std::vector<std::string>{"cube.mtl", "tex/red.png"}));
  write_mesh_file(dir / "out" / "cube.obj", *m.file, m.file->rest);
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "tex" / "red.png"));
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "cube.mtl"));
  std::ofstream(dir / "out" / "cube.mtl") << "someone else's";
  const std::vector<std::string> notes =
      write_mesh_file(dir / "out" / "cube.obj", *m.file, m.file->rest);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("differs"), std::string::npos);
  // Confined, as the editor reads: a name leaving the folder is refused.
  const FileResolver confined = folder_resolver(dir / "in", Confinement::Confined);
  EXPECT_TRUE(confined("tex/red.png"));
  EXPECT_THROW(confined("../out/cube.mtl"), InputError);
  EXPECT_THROW(confined("/etc/passwd"), InputError);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace specdeform
