#include "specdeform/mesh/io.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include "specdeform/exceptions.h"
#include "specdeform/mesh/generate.h"
#include "specdeform/mesh/mesh_info.h"
#include "support/corpus.h"

namespace specdeform {
namespace {

LoadedMesh parse(std::string_view text, MeshFormat format) {
  return read_mesh_from_memory(text, format, "test");
}

// Expects an InputError whose message contains `fragment`.
void expect_error(std::string_view text, MeshFormat format, const std::string& fragment) {
  try {
    parse(text, format);
    ADD_FAILURE() << "no error, expected '" << fragment << "'";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << "one line: " << e.what();
  }
}

TriangleMesh awkward_coordinates() {
  TriangleMesh m = make_icosphere(1);
  m.V(0, 0) = 0.1;
  m.V(1, 1) = 1.0 / 3.0;
  m.V(2, 2) = -std::numeric_limits<double>::denorm_min();
  m.V(3, 0) = 1e90;
  return m;
}

TEST(MeshIo, RoundTripIsExactForDoubleFormats) {
  const TriangleMesh m = awkward_coordinates();
  for (const MeshFormat f : {MeshFormat::Obj, MeshFormat::Off, MeshFormat::Ply}) {
    const LoadedMesh back = parse(encode_mesh(m, f), f);
    EXPECT_EQ(back.mesh.V, m.V) << static_cast<int>(f);
    EXPECT_EQ(back.mesh.F, m.F) << static_cast<int>(f);
  }
}

TEST(MeshIo, StlRoundTripWeldsCornersAndKeepsTriangles) {
  const TriangleMesh m = make_icosphere(2);
  const LoadedMesh back = parse(encode_mesh(m, MeshFormat::Stl), MeshFormat::Stl);
  ASSERT_EQ(back.mesh.num_vertices(), m.num_vertices());
  ASSERT_EQ(back.mesh.num_faces(), m.num_faces());
  EXPECT_EQ(back.info.welded_corners, 3 * m.num_faces() - m.num_vertices());
  for (int f = 0; f < m.num_faces(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const Eigen::RowVector3d p = m.V.row(m.F(f, k));
      EXPECT_LT((back.mesh.V.row(back.mesh.F(f, k)) - p).norm(), 1e-6);
    }
  }
}

TEST(MeshIo, WriteIsAtomicAndReadable) {
  const auto dir = std::filesystem::temp_directory_path() / "specdeform_io_test";
  std::filesystem::create_directories(dir);
  const TriangleMesh m = make_torus(1.0, 0.3, 12, 6);
  for (const char* ext : {".obj", ".off", ".ply", ".stl", ".OBJ"}) {
    const auto path = dir / (std::string("torus") + ext);
    write_mesh(path, m);
    EXPECT_EQ(read_mesh(path).mesh.num_faces(), m.num_faces()) << ext;
  }
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    EXPECT_NE(entry.path().filename().string()[0], '.') << "temporary file left behind";
  }
  EXPECT_THROW(write_mesh(dir / "torus.xyz", m), InputError);
  EXPECT_THROW(write_mesh(dir / "missing" / "torus.obj", m), InputError);
  std::filesystem::remove_all(dir);
}

TEST(MeshIo, ObjForms) {
  const char* text =
      "# comment\nmtllib none.mtl\no thing\nv 0 0 0\nv 1 0 0 0.5 0.5 0.5\nv 1 1 0\nv 0 1 0\n"
      "vt 0 0\nvn 0 0 1\ng group\nusemtl m\ns 1\n"
      "f 1/1/1 2/1/1 3/1/1 4/1/1\n"    // a quad, with v/vt/vn
      "v 0 0 1\nf -1 1// \\\n 2//1\n"  // negative index, v//vn, line continuation
      "f 1/1/ 3/1/ 5/1/\n"             // v/vt/ with an empty normal
      "l 1 2\n";
  const LoadedMesh m = parse(text, MeshFormat::Obj);
  EXPECT_EQ(m.mesh.num_vertices(), 5);
  EXPECT_EQ(m.mesh.num_faces(), 4);
  EXPECT_EQ(m.info.file_faces, 3);
  EXPECT_EQ(m.mesh.F.row(2), Eigen::RowVector3i(4, 0, 1));
  EXPECT_EQ(m.info.face_to_file, (std::vector<int>{0, 0, 1, 2}));
}

// A file large enough to be read in two halves: a strip of quads, each with its two new
// vertices just before it and negative indices (back into the first half where the split falls),
// comments and texture lines between; the same mesh as the strip written in one piece. An error
// in the second half names the face of the whole file.
TEST(MeshIo, LargeObjInTwoHalves) {
  constexpr int kQuads = 160'000;  // about 10 MB
  std::string text = "# strip\nv 0 0 0\nv 0 1 0\n";
  for (int q = 1; q <= kQuads; ++q) {
    const std::string x = std::to_string(q);
    text += "v " + x + " 0 0\n  v\t" + x + " 1 0.5\nvt 0 0\n# quad " + x + "\nf -4 -2 -1 -3\n";
  }
  ASSERT_GT(text.size(), size_t{9} << 20);
  const LoadedMesh m = parse(text, MeshFormat::Obj);
  ASSERT_EQ(m.mesh.num_vertices(), 2 * kQuads + 2);
  ASSERT_EQ(m.info.file_faces, kQuads);
  for (int q = 0; q < kQuads; q += 997) {
    EXPECT_EQ(m.mesh.V.row(2 * q + 2), Eigen::RowVector3d(q + 1, 0, 0));
    EXPECT_EQ(m.mesh.F.row(2 * q), Eigen::RowVector3i(2 * q, 2 * q + 2, 2 * q + 3)) << q;
  }
  std::string broken = text;
  broken.replace(broken.rfind("f -4"), 4, "f -x");
  expect_error(broken, MeshFormat::Obj,
               "bad face corner '-x' in face " + std::to_string(kQuads - 1));
  broken = text;
  broken.replace(broken.rfind("f -4"), 4, "f 9999999");
  expect_error(broken, MeshFormat::Obj, "only " + std::to_string(2 * kQuads + 2) + " vertices");
}

// Two quads that share two sides (a b c d and c b a e, as the beast has them): fanned from their
// first corners both would take the diagonal a c, one triangle twice back to back; the second is
// fanned from b instead, and the mesh stays manifold and consistently oriented.
TEST(MeshIo, PolygonsSharingTwoSidesAreNotFolded) {
  const LoadedMesh m = parse(
      "v 0 0 0\nv 1 0.2 0\nv 2 0 0\nv 1 -1 0\nv 1 1 0\nf 1 2 3 4\nf 3 2 1 5\n", MeshFormat::Obj);
  Faces expected(4, 3);
  expected << 0, 1, 2, 0, 2, 3, 1, 0, 4, 1, 4, 2;
  EXPECT_EQ(m.mesh.F, expected);
  const MeshInfo info = compute_mesh_info(m.mesh);
  EXPECT_EQ(info.non_manifold_edges, 0);
  EXPECT_EQ(info.inconsistent_edges, 0);
}

TEST(MeshIo, OffVariants) {
  const char* variants[] = {
      "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n",
      "OFF 4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n",
      "# a comment\nCOFF\n4 2 5\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n1 1 0 0 0 0 1\n"
      "0 1 0 1 1 1 1\n3 0 1 2 255 0 0\n3 0 2 3\n",
      "NOFF\n# counts\n4 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n1 1 0 0 0 1\n0 1 0 0 0 1\n4 0 1 2 3\n",
      "4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n",
  };
  for (const char* text : variants) {
    const LoadedMesh m = parse(text, MeshFormat::Off);
    EXPECT_EQ(m.mesh.num_vertices(), 4) << text;
    EXPECT_EQ(m.mesh.num_faces(), 2) << text;
  }
}

// A tetrahedron as PLY with the given encoding, coordinate type and index types.
std::string tetra_ply(const std::string& format, const std::string& coord, const std::string& count,
                      const std::string& index) {
  std::string s = "ply\nformat " + format + " 1.0\ncomment test\nelement vertex 4\n";
  s += "property " + coord + " x\nproperty uchar red\nproperty " + coord + " y\nproperty " + coord +
       " z\n";
  s += "element face 4\nproperty list " + count + " " + index + " vertex_indices\n";
  s += "property float quality\nelement edge 1\nproperty int v1\nproperty int v2\nend_header\n";
  const int pts[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const int tris[4][3] = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  if (format == "ascii") {
    for (const auto& p : pts)
      s += std::to_string(p[0]) + " 7 " + std::to_string(p[1]) + " " + std::to_string(p[2]) + "\n";
    for (const auto& t : tris)
      s += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]) +
           " 0.5\n";
    return s + "0 1\n";
  }
  const bool big = format == "binary_big_endian";
  const auto put = [&](const std::string& type, double v) {
    unsigned char b[8];
    size_t size = 0;
    const auto store = [&](auto x) {
      size = sizeof(x);
      std::memcpy(b, &x, size);
    };
    if (type == "uchar" || type == "uint8") store(static_cast<uint8_t>(v));
    if (type == "char" || type == "int8") store(static_cast<int8_t>(v));
    if (type == "short" || type == "int16") store(static_cast<int16_t>(v));
    if (type == "ushort" || type == "uint16") store(static_cast<uint16_t>(v));
    if (type == "int" || type == "int32") store(static_cast<int32_t>(v));
    if (type == "uint" || type == "uint32") store(static_cast<uint32_t>(v));
    if (type == "float" || type == "float32") store(static_cast<float>(v));
    if (type == "double" || type == "float64") store(static_cast<double>(v));
    if (big) std::reverse(b, b + size);
    s.append(reinterpret_cast<const char*>(b), size);
  };
  for (const auto& p : pts) {
    put(coord, p[0]);
    put("uchar", 7);
    put(coord, p[1]);
    put(coord, p[2]);
  }
  for (const auto& t : tris) {
    put(count, 3);
    for (const int v : t) put(index, v);
    put("float", 0.5);
  }
  put("int", 0);
  put("int", 1);
  return s;
}

TEST(MeshIo, PlyEncodingsAndTypes) {
  for (const char* format : {"ascii", "binary_little_endian", "binary_big_endian"}) {
    for (const char* coord : {"float", "double", "short", "int8", "uint16"}) {
      for (const char* index : {"int", "uint", "ushort", "uchar", "int32"}) {
        const LoadedMesh m = parse(tetra_ply(format, coord, "uchar", index), MeshFormat::Ply);
        ASSERT_EQ(m.mesh.num_vertices(), 4) << format << coord << index;
        ASSERT_EQ(m.mesh.num_faces(), 4);
        EXPECT_EQ(m.mesh.V.row(3), Eigen::RowVector3d(0, 0, 1)) << format << coord << index;
        EXPECT_EQ(m.mesh.F.row(2), Eigen::RowVector3i(1, 2, 3));
      }
    }
  }
  EXPECT_EQ(parse(tetra_ply("binary_big_endian", "float", "int", "int"), MeshFormat::Ply)
                .mesh.num_faces(),
            4);
}

// Three rows of two vertices (b0 b1, t0 t1, u0 u1 at y = 0, 1, 2) and their four triangles as
// triangle strips in a list of `indices`, in the given PLY encoding (list int int).
std::string strip_ply(const std::string& format, const std::vector<int>& indices) {
  std::string s = "ply\nformat " + format + " 1.0\nelement vertex 6\nproperty float x\n";
  s += "property float y\nproperty float z\nelement tristrips 1\n";
  s += "property list int int vertex_indices\nend_header\n";
  const float pts[6][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 2, 0}, {1, 2, 0}};
  if (format == "ascii") {
    for (const auto& p : pts) s += std::to_string(p[0]) + " " + std::to_string(p[1]) + " 0\n";
    s += std::to_string(indices.size());
    for (const int i : indices) s += " " + std::to_string(i);
    return s + "\n";
  }
  const bool big = format == "binary_big_endian";
  const auto put = [&](auto x) {
    char b[sizeof(x)];
    std::memcpy(b, &x, sizeof(x));
    if (big) std::reverse(b, b + sizeof(x));
    s.append(b, sizeof(x));
  };
  for (const auto& p : pts)
    for (const float c : p) put(c);
  put(static_cast<int32_t>(indices.size()));
  for (const int i : indices) put(static_cast<int32_t>(i));
  return s;
}

TEST(MeshIo, PlyTriangleStrips) {
  // b0 t0 b1 t1 | t0 u0 t1 u1: once joined by the repeated vertices of a turn (t1 t1 t0 t0, four
  // triangles dropped, the parity kept), once restarted by -1.
  const std::vector<int> joined = {0, 2, 1, 3, 3, 2, 2, 4, 3, 5};
  const std::vector<int> restarted = {0, 2, 1, 3, -1, 2, 4, 3, 5};
  Faces expected(4, 3);
  expected << 0, 2, 1, 1, 2, 3, 2, 4, 3, 3, 4, 5;  // (a b c), (c b d): all facing -z
  for (const char* format : {"ascii", "binary_little_endian", "binary_big_endian"}) {
    for (const auto& strip : {joined, restarted}) {
      const LoadedMesh m = parse(strip_ply(format, strip), MeshFormat::Ply);
      EXPECT_EQ(m.mesh.F, expected) << format;
      EXPECT_EQ(m.info.collapsed_faces, 0) << format;
      EXPECT_EQ(m.info.file_faces, 4) << format;
      const Eigen::MatrixX3d N = face_normals(m.mesh);
      for (int f = 0; f < 4; ++f) EXPECT_EQ(N.row(f), Eigen::RowVector3d(0, 0, -1)) << format;
    }
  }
  // Faces and strips in one file; a strip's index out of range.
  std::string both = strip_ply("ascii", restarted);
  both.replace(both.find("end_header"), 10,
               "element face 1\nproperty list uchar int vertex_indices\nend_header");
  both += "3 0 1 4\n";
  EXPECT_EQ(parse(both, MeshFormat::Ply).mesh.num_faces(), 5);
  expect_error(strip_ply("ascii", {0, 2, 9}), MeshFormat::Ply,
               "triangle strip 0 references vertex 9");
}

TEST(MeshIo, StlAsciiAndBinary) {
  const char* ascii =
      "solid thing\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
      "endloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 1 0 0\nvertex 1 1 0\n"
      "vertex 0 1 0\nendloop\nendfacet\nendsolid thing\nsolid second\nfacet normal 0 0 1\n"
      "outer loop\nvertex 5 0 0\nvertex 6 0 0\nvertex 5 1 0\nendloop\nendfacet\nendsolid\n";
  const LoadedMesh m = parse(ascii, MeshFormat::Stl);
  EXPECT_EQ(m.mesh.num_faces(), 3);
  EXPECT_EQ(m.mesh.num_vertices(), 7);
  EXPECT_EQ(m.info.welded_corners, 2);
  // A binary file whose header starts with "solid" is still binary.
  std::string binary = encode_mesh(make_icosphere(0), MeshFormat::Stl);
  binary.replace(0, 5, "solid");
  EXPECT_EQ(parse(binary, MeshFormat::Stl).mesh.num_vertices(), 12);
}

TEST(MeshIo, UnusedVerticesAreDroppedAndRestored) {
  const char* text = "OFF\n5 2 0\n9 9 9\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 1 2 3\n3 1 3 4\n";
  const LoadedMesh m = parse(text, MeshFormat::Off);
  EXPECT_EQ(m.mesh.num_vertices(), 4);
  EXPECT_EQ(m.info.unused_vertices, 1);
  EXPECT_EQ(m.info.vertex_to_file, (std::vector<int>{1, 2, 3, 4}));
  Vertices moved = m.mesh.V;
  moved.col(2).array() += 1.0;
  const TriangleMesh back = to_file_order(m.info, moved, m.mesh.F);
  EXPECT_EQ(back.V.row(0), Eigen::RowVector3d(9, 9, 9));
  EXPECT_EQ(back.V.row(4), Eigen::RowVector3d(0, 1, 1));
  EXPECT_EQ(back.F.row(1), Eigen::RowVector3i(1, 3, 4));
}

TEST(MeshIo, FacesRepeatingAVertexAreDropped) {
  const LoadedMesh m =
      parse("OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 1\n", MeshFormat::Off);
  EXPECT_EQ(m.mesh.num_faces(), 1);
  EXPECT_EQ(m.info.collapsed_faces, 1);
}

// A face on the same three vertices as an earlier one, in any order (a doubled face, or the
// other side of a two-sided sheet), is dropped: it would count its area and stiffness twice.
TEST(MeshIo, DuplicateFacesAreDropped) {
  const LoadedMesh m =
      parse("OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n3 1 3 2\n3 2 1 0\n3 0 2 1\n",
            MeshFormat::Off);
  EXPECT_EQ(m.mesh.num_faces(), 2);
  EXPECT_EQ(m.info.duplicate_faces, 2);
  EXPECT_EQ(m.info.face_to_file, (std::vector<int>{0, 1}));
  EXPECT_EQ(m.mesh.F.row(1), Eigen::RowVector3i(1, 3, 2));

  // A fan of 40 faces around vertex 0, then every third of them again, turned: the repeats are
  // found among the many faces of one corner and the first of each pair is kept.
  std::string obj;
  for (int k = 0; k <= 40; ++k)
    obj += "v " + std::to_string(k) + " " + std::to_string(k % 3) + " 1\n";
  for (int k = 1; k <= 40; ++k)
    obj += "f 1 " + std::to_string(k + 1) + " " + std::to_string(k % 40 + 2) + "\n";
  for (int k = 39; k >= 1; k -= 3)
    obj += "f " + std::to_string(k % 40 + 2) + " 1 " + std::to_string(k + 1) + "\n";
  const LoadedMesh fan = parse(obj, MeshFormat::Obj);
  EXPECT_EQ(fan.mesh.num_faces(), 40);
  EXPECT_EQ(fan.info.duplicate_faces, 13);
  EXPECT_EQ(fan.info.face_to_file.back(), 39);
}

TEST(MeshIo, ClearErrors) {
  expect_error("", MeshFormat::Off, "empty file");
  expect_error("OFF\n", MeshFormat::Off, "unexpected end of file");
  expect_error("OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n", MeshFormat::Off, "no faces");
  expect_error("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n", MeshFormat::Off, "vertex 7");
  expect_error("OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n", MeshFormat::Off, "NaN");
  expect_error("OFF\n3 1 0\n0 0 0\ninf 0 0\n0 1 0\n3 0 1 2\n", MeshFormat::Off, "NaN or infinite");
  expect_error("OFF\n3 1 0\n0 0 0\n1 0 0\n", MeshFormat::Off, "unexpected end of file");
  expect_error("4OFF\n", MeshFormat::Off, "unsupported OFF variant");
  expect_error("OFF\n100000000000 1 0\n", MeshFormat::Off, "more vertices");
  expect_error("", MeshFormat::Obj, "empty file");
  expect_error("v 0 0 0\nv 1 0 0\nv 0 1 0\n", MeshFormat::Obj, "no faces");
  expect_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", MeshFormat::Obj, "references vertex 4");
  expect_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", MeshFormat::Obj, "bad face corner");
  expect_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 1 2\n", MeshFormat::Obj, "references vertex -4");
  // Cut inside the last face line; a face of two corners elsewhere.
  expect_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4", MeshFormat::Obj,
               "truncated: the file ends inside face 1");
  expect_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2/1", MeshFormat::Obj, "truncated");
  expect_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\nf 1 2 3\n", MeshFormat::Obj,
               "face 0 has 2 corners");
  EXPECT_EQ(parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3", MeshFormat::Obj).mesh.num_faces(), 1);
  // A Git LFS pointer in place of the mesh, whatever the format.
  for (const MeshFormat f : {MeshFormat::Obj, MeshFormat::Off, MeshFormat::Ply, MeshFormat::Stl}) {
    expect_error(
        "version https://git-lfs.github.com/spec/v1\noid sha256:4d7a214614ab2935c943f9e0ff69d22ea"
        "dbb8f32b1258daaa5e2ca24d17e2393\nsize 12345\n",
        f, "is a Git LFS pointer, not the mesh: run git lfs pull");
  }
  expect_error("ply\nformat ascii 1.0\nend_header\n", MeshFormat::Ply, "no vertices");
  expect_error(
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n",
      MeshFormat::Ply, "no faces");
  std::string truncated = tetra_ply("binary_little_endian", "float", "uchar", "int");
  truncated.resize(truncated.size() - 20);
  expect_error(truncated, MeshFormat::Ply, "truncated");
  // Cut 2 bytes after the last face's count: truncated, not "bad list length".
  std::string cut = encode_mesh(make_icosphere(0), MeshFormat::Ply);
  cut.resize(cut.size() - 13 + 2);
  expect_error(cut, MeshFormat::Ply, "truncated data (element 'face' entry 19's list of 3");
  expect_error("ply\nformat ascii 1.0\n", MeshFormat::Ply, "end_header");
  expect_error(
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n3 0 1 1e300\n",
      MeshFormat::Ply, "face 0 references vertex 1e+300 but there are 3 vertices");
  std::string stl = encode_mesh(make_icosphere(0), MeshFormat::Stl);
  stl.resize(stl.size() - 10);
  expect_error(stl, MeshFormat::Stl, "truncated binary STL");
  expect_error("solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n", MeshFormat::Stl,
               "truncated");
  EXPECT_THROW(read_mesh("/nonexistent/file.obj"), InputError);
  EXPECT_THROW(read_mesh("mesh.dae"), InputError);
}

// Every file of ../shared/meshes/awkward gives a mesh or one clear error line.
// Coordinates beyond what squared lengths hold, or extents below it: one error naming the range,
// not a blame of degenerate faces later.
TEST(MeshIo, CoordinatesOutOfRangeAreNamed) {
  for (const auto& [scale, fragment] :
       {std::pair{1e160, "coordinates reach 1e+160"}, std::pair{1e-300, "spans only"}}) {
    TriangleMesh m = make_icosphere(1);
    m.V *= scale;
    expect_error(encode_mesh(m, MeshFormat::Obj), MeshFormat::Obj, fragment);
  }
  TriangleMesh far = make_icosphere(1);
  far.V.array() += 1e6;  // far from the origin, of an ordinary size: fine
  EXPECT_NO_THROW(parse(encode_mesh(far, MeshFormat::Obj), MeshFormat::Obj));
}

// A garbage binary STL stops at its first bad value (before welding the rest), and a file read
// from disk is refused after its first megabyte, not after reading all of it.
TEST(MeshIo, GarbageStlStopsAtItsFirstBadValue) {
  std::string stl = encode_mesh(make_icosphere(5), MeshFormat::Stl);  // 20,480 triangles, 1 MB
  const float nan = std::nanf("");
  std::memcpy(stl.data() + 84 + 50 * 21 + 12 + 4, &nan, 4);
  expect_error(stl, MeshFormat::Stl, "triangle 21 has a NaN");
  const auto path = std::filesystem::temp_directory_path() / "specdeform_garbage.stl";
  std::string big = stl.substr(0, 84);
  const uint32_t count = 400'000;  // 20 MB
  std::memcpy(big.data() + 80, &count, 4);
  big += stl.substr(84);
  big.resize(84 + 50 * size_t{count}, '\x7f');  // 0x7f7f7f7f: a finite float, if read
  std::ofstream(path, std::ios::binary) << big;
  try {
    read_mesh(path);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("triangle 21 has a NaN"), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
}

TEST(MeshIo, AwkwardCorpus) {
  const auto shared = test::shared_dir();
  if (shared.empty()) GTEST_SKIP() << "../shared is absent: awkward corpus not available";
  int loaded = 0, rejected = 0;
  for (const auto& entry : std::filesystem::directory_iterator(shared / "meshes" / "awkward")) {
    try {
      const LoadedMesh m = read_mesh(entry.path());
      EXPECT_GT(m.mesh.num_faces(), 0);
      EXPECT_TRUE(m.mesh.V.allFinite());
      EXPECT_GE(m.mesh.F.minCoeff(), 0);
      EXPECT_LT(m.mesh.F.maxCoeff(), m.mesh.num_vertices());
      ++loaded;
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
      EXPECT_NE(std::string(e.what()).find(entry.path().filename().string()), std::string::npos);
      ++rejected;
    }
  }
  EXPECT_EQ(loaded, 16);  // all but the five empty or face-less files
  EXPECT_EQ(rejected, 5);
}

}  // namespace
}  // namespace specdeform
