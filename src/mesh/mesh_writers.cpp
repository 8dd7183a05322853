#include "mesh_writers.h"

#include <tiny_gltf.h>

#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <sstream>

#include <Eigen/Geometry>

#include "float_cast.h"
#include "linalg/parallel.h"
#include "specdeform/exceptions.h"

namespace specdeform::detail {

namespace {

void append_number(std::string& s, double v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);  // shortest round-trip form
  s.append(buf, end);
}

void append_number(std::string& s, float v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  s.append(buf, end);
}

void append_number(std::string& s, int v) {
  char buf[16];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  s.append(buf, end);
}

template <typename T>
void append_le(std::string& s, T v) {
  static_assert(std::endian::native == std::endian::little, "writers assume a little-endian host");
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  s.append(b, sizeof(T));
}

// Lines i = 0 .. count - 1 encoded in two halves at once, one on each thread (692k vertices,
// OBJ: 0.41 -> 0.2-0.26 s with the write). `bytes`: the usual line's length, reserved (a string
// that regrows holds two copies for a moment).
template <typename Line>
std::vector<std::string> lines_in_halves(int count, size_t bytes, const Line& line) {
  std::vector<std::string> part(2);
  const auto encode = [&](int half) {
    const int begin = half * (count / 2), end = half == 0 ? count / 2 : count;
    part[half].reserve(static_cast<size_t>(end - begin) * bytes);
    for (int i = begin; i < end; ++i) line(part[half], i);
  };
  run_pair([&] { encode(0); }, [&] { encode(1); });
  return part;
}

void append_parts(std::vector<std::string>& to, std::vector<std::string>&& parts) {
  for (std::string& p : parts) to.push_back(std::move(p));
}

// One row per vertex where every corner of the vertex uses the same row (-1: none of its
// corners has one); empty where some vertex's corners use different rows.
std::vector<int> per_vertex(const FileAttributes& a, const std::vector<int>& rows, int vertices) {
  if (rows.empty()) return {};
  std::vector<int> out(vertices, -1);
  for (size_t c = 0; c < a.corners.size(); ++c) {
    int& row = out[a.corners[c]];
    if (rows[c] < 0) continue;
    if (row >= 0 && row != rows[c]) return {};
    row = rows[c];
  }
  return out;
}

// The corners of polygon p's fan triangles: (0, k, k + 1).
template <typename Visit>
void for_each_triangle(const FileAttributes& a, const Visit& visit) {
  for (int p = 0; p < a.num_polygons(); ++p) {
    const int first = a.offsets[p];
    for (int k = first + 1; k + 1 < a.offsets[p + 1]; ++k) visit(p, first, k, k + 1);
  }
}

int count_triangles(const FileAttributes& a) {
  int count = 0;
  for (int p = 0; p < a.num_polygons(); ++p)
    count += std::max(0, a.offsets[p + 1] - a.offsets[p] - 2);
  return count;
}

bool has_polygons(const FileAttributes& a) {
  for (int p = 0; p < a.num_polygons(); ++p)
    if (a.offsets[p + 1] - a.offsets[p] != 3) return true;
  return false;
}

uint8_t to_byte(float c) {
  return static_cast<uint8_t>(std::lround(std::clamp(c, 0.f, 1.f) * 255));
}

// What the target must say it dropped: the source's attributes the target does not hold.
struct Carried {
  bool polygons = true, uv = true, normals = true, colours = true, materials = true;
};

std::vector<std::string> dropped(const FileAttributes& a, const Carried& c,
                                 const FileSummary* source) {
  std::vector<std::string> out;
  if (!c.polygons && has_polygons(a)) out.push_back("polygons (triangulated)");
  if (!c.uv && !a.corner_uv.empty()) out.push_back("texture coordinates");
  if (!c.normals && !a.corner_normal.empty()) out.push_back("normals");
  if (!c.colours && a.colours.rows() > 0) out.push_back("vertex colours");
  if (!c.materials && !a.materials.empty()) out.push_back("materials");
  if (source == nullptr) return out;
  if (source->groups > 0) out.push_back("groups");
  if (!source->properties.empty())
    out.push_back("PLY properties beyond positions, normals and colours");
  if (source->skins > 0) out.push_back(std::to_string(source->skins) + " skins");
  if (source->animations > 0) out.push_back(std::to_string(source->animations) + " animations");
  if (source->morph_targets > 0)
    out.push_back(std::to_string(source->morph_targets) + " morph targets");
  if (source->uv_sets > 1) out.push_back("texture coordinate sets beyond the first");
  return out;
}

// The file's name without its folder, and its stem (for companions).
struct Target {
  std::string name, stem;
};

// A file in parts to be concatenated (a large one is written part by part), its companions and
// what it dropped.
struct Encoded {
  std::vector<std::string> parts;
  std::vector<OutputFile> companions;
  std::vector<std::string> notes;
};

Encoded encode_obj(const FileAttributes& a, const Vertices& X, const Eigen::MatrixX3d& normals,
                   const Target& target, const MeshFile* file) {
  Encoded out;
  std::vector<std::string>& parts = out.parts;
  parts.push_back("# written by specdeform\n");
  if (!a.materials.empty()) {
    // The MTL beside it: each material's Kd and base colour image (a glTF's own written out).
    std::string mtl = "# written by specdeform\n";
    for (size_t m = 0; m < a.materials.size(); ++m) {
      const Material& mat = a.materials[m];
      const std::string name = mat.name.empty() ? "material_" + std::to_string(m) : mat.name;
      mtl += "newmtl " + name + "\nKd";
      for (int k = 0; k < 3; ++k) {
        mtl += ' ';
        append_number(mtl, mat.base_color[k]);
      }
      mtl += '\n';
      std::string texture = mat.gltf_image >= 0 ? std::string() : mat.texture;
      if (mat.gltf_image >= 0 && file != nullptr) {
        if (auto image = file->texture(static_cast<int>(m))) {
          const std::string ext = image->second == "image/jpeg" ? ".jpg" : ".png";
          texture = target.stem + "-" + std::to_string(m) + ext;
          out.companions.push_back({texture, std::move(image->first)});
        }
      }
      if (!texture.empty()) mtl += "map_Kd " + texture + "\n";
    }
    out.companions.push_back({target.stem + ".mtl", std::move(mtl)});
    parts.push_back("mtllib " + target.stem + ".mtl\n");
  }
  const bool colours = a.colours.rows() > 0;
  append_parts(parts, lines_in_halves(int(X.rows()), colours ? 96 : 64, [&](std::string& s, int i) {
                 s += 'v';
                 for (int k = 0; k < 3; ++k) {
                   s += ' ';
                   append_number(s, X(i, k));
                 }
                 for (int k = 0; colours && k < 3; ++k) {
                   s += ' ';
                   append_number(s, a.colours(i, k));
                 }
                 s += '\n';
               }));
  std::string attributes;
  const bool uv = !a.corner_uv.empty(), normal = !a.corner_normal.empty() && normals.rows() > 0;
  for (Eigen::Index t = 0; uv && t < a.uv.rows(); ++t) {
    attributes += "vt ";
    append_number(attributes, a.uv(t, 0));
    attributes += ' ';
    append_number(attributes, a.uv(t, 1));
    attributes += '\n';
  }
  for (Eigen::Index n = 0; normal && n < normals.rows(); ++n) {
    attributes += "vn";
    for (int k = 0; k < 3; ++k) {
      attributes += ' ';
      append_number(attributes, to_float(normals(n, k), "a normal"));
    }
    attributes += '\n';
  }
  parts.push_back(std::move(attributes));
  // Faces, a usemtl where the material changes.
  const size_t face_bytes = 3 * (std::to_string(X.rows()).size() + 1) * (1 + uv + normal) + 4;
  const bool materials = !a.materials.empty();
  const auto face = [&](std::string& s, int p) {
    if (materials && (p == 0 || a.polygon_material[p] != a.polygon_material[p - 1])) {
      const int m = a.polygon_material[p];
      s += "usemtl ";
      s += m < 0                         ? std::string("none")
           : a.materials[m].name.empty() ? "material_" + std::to_string(m)
                                         : a.materials[m].name;
      s += '\n';
    }
    s += 'f';
    for (int c = a.offsets[p]; c < a.offsets[p + 1]; ++c) {
      s += ' ';
      append_number(s, a.corners[c] + 1);
      const int t = uv ? a.corner_uv[c] : -1, n = normal ? a.corner_normal[c] : -1;
      if (t >= 0 || n >= 0) s += '/';
      if (t >= 0) append_number(s, t + 1);
      if (n >= 0) {
        s += '/';
        append_number(s, n + 1);
      }
    }
    s += '\n';
  };
  if (materials) {  // the material's state runs from face to face: one thread
    std::string faces;
    for (int p = 0; p < a.num_polygons(); ++p) face(faces, p);
    parts.push_back(std::move(faces));
  } else {
    append_parts(parts, lines_in_halves(a.num_polygons(), face_bytes, face));
  }
  return out;
}

std::vector<std::string> off_parts(const FileAttributes& a, const Vertices& X,
                                   const Eigen::MatrixX3d& normals,
                                   const std::vector<int>& vertex_normal) {
  const bool colours = a.colours.rows() > 0, normal = !vertex_normal.empty();
  std::string header = std::string(colours ? "C" : "") + (normal ? "N" : "") + "OFF\n";
  append_number(header, int(X.rows()));
  header += ' ';
  append_number(header, a.num_polygons());
  header += " 0\n";
  std::vector<std::string> parts{std::move(header)};
  append_parts(parts, lines_in_halves(int(X.rows()), 64, [&](std::string& s, int i) {
                 for (int k = 0; k < 3; ++k) {
                   if (k > 0) s += ' ';
                   append_number(s, X(i, k));
                 }
                 for (int k = 0; normal && k < 3; ++k) {
                   s += ' ';
                   append_number(s, vertex_normal[i] < 0
                                        ? 0.f
                                        : to_float(normals(vertex_normal[i], k), "a normal"));
                 }
                 for (int k = 0; colours && k < 4; ++k) {
                   s += ' ';
                   append_number(s, int(to_byte(a.colours(i, k))));
                 }
                 s += '\n';
               }));
  const size_t face_bytes = 3 * std::to_string(X.rows()).size() + 6;
  append_parts(parts, lines_in_halves(a.num_polygons(), face_bytes, [&](std::string& s, int p) {
                 append_number(s, a.offsets[p + 1] - a.offsets[p]);
                 for (int c = a.offsets[p]; c < a.offsets[p + 1]; ++c) {
                   s += ' ';
                   append_number(s, a.corners[c]);
                 }
                 s += '\n';
               }));
  return parts;
}

std::string ply_bytes(const FileAttributes& a, const Vertices& X, const Eigen::MatrixX3d& normals,
                      const std::vector<int>& vertex_normal) {
  const bool colours = a.colours.rows() > 0, normal = !vertex_normal.empty();
  const bool uv = !a.corner_uv.empty();
  std::string s = "ply\nformat binary_little_endian 1.0\ncomment written by specdeform\n";
  s += "element vertex " + std::to_string(X.rows()) + "\n";
  s += "property double x\nproperty double y\nproperty double z\n";
  if (normal) s += "property float nx\nproperty float ny\nproperty float nz\n";
  if (colours)
    s += "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n";
  s += "element face " + std::to_string(a.num_polygons()) + "\n";
  s += "property list uchar int vertex_indices\n";
  if (uv) s += "property list uchar float texcoord\n";
  s += "end_header\n";
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    for (int k = 0; k < 3; ++k) append_le(s, X(i, k));
    for (int k = 0; normal && k < 3; ++k) {
      append_le(s, vertex_normal[i] < 0 ? 0.f : to_float(normals(vertex_normal[i], k), "a normal"));
    }
    for (int k = 0; colours && k < 4; ++k) append_le(s, to_byte(a.colours(i, k)));
  }
  for (int p = 0; p < a.num_polygons(); ++p) {
    const int k = a.offsets[p + 1] - a.offsets[p];
    if (k > 255)
      throw InputError("a polygon of " + std::to_string(k) + " corners does not fit PLY's list");
    append_le(s, static_cast<uint8_t>(k));
    for (int c = a.offsets[p]; c < a.offsets[p + 1]; ++c) append_le(s, int32_t{a.corners[c]});
    if (!uv) continue;
    append_le(s, static_cast<uint8_t>(2 * k));
    for (int c = a.offsets[p]; c < a.offsets[p + 1]; ++c) {
      const int t = a.corner_uv[c];
      append_le(s, t < 0 ? 0.f : to_float(a.uv(t, 0), "a texture coordinate"));
      append_le(s, t < 0 ? 0.f : to_float(a.uv(t, 1), "a texture coordinate"));
    }
  }
  return s;
}

std::string stl_bytes(const FileAttributes& a, const Vertices& X) {
  std::string s(80, ' ');
  s.replace(0, 22, "binary STL, specdeform");
  append_le(s, static_cast<uint32_t>(count_triangles(a)));
  for_each_triangle(a, [&](int, int i, int j, int k) {
    const Eigen::Vector3d p = X.row(a.corners[i]), q = X.row(a.corners[j]), r = X.row(a.corners[k]);
    const Eigen::Vector3d n = (q - p).cross(r - p);
    const Eigen::Vector3d unit = n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : n;
    for (int d = 0; d < 3; ++d) append_le(s, static_cast<float>(unit[d]));
    for (const Eigen::Vector3d* v : {&p, &q, &r})
      for (int d = 0; d < 3; ++d) append_le(s, to_float((*v)[d], "a position"));
    append_le(s, uint16_t{0});
  });
  return s;
}

// glTF through tinygltf's writer: one buffer, one primitive per material.
std::string gltf_bytes(const FileAttributes& a, const Vertices& X, const Eigen::MatrixX3d& normals,
                       bool binary, const MeshFile* file) {
  const bool uv = !a.corner_uv.empty(), normal = !a.corner_normal.empty() && normals.rows() > 0;
  const bool colours = a.colours.rows() > 0;
  // Vertices split by (vertex, uv row, normal row), per material.
  std::map<int, std::vector<int>> triangles;  // material -> split vertex per corner
  std::map<std::array<int, 3>, int> split;
  std::vector<std::array<int, 3>> vertices;
  const auto vertex = [&](int c) {
    const std::array<int, 3> key{a.corners[c], uv ? a.corner_uv[c] : -1,
                                 normal ? a.corner_normal[c] : -1};
    const auto [it, added] = split.emplace(key, int(vertices.size()));
    if (added) vertices.push_back(key);
    return it->second;
  };
  for_each_triangle(a, [&](int p, int i, int j, int k) {
    std::vector<int>& t = triangles[a.polygon_material.empty() ? -1 : a.polygon_material[p]];
    for (const int c : {i, j, k}) t.push_back(vertex(c));
  });
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "specdeform";
  tinygltf::Buffer buffer;
  const auto view = [&](const void* data, size_t bytes, int target) {
    while (buffer.data.size() % 4) buffer.data.push_back(0);
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = buffer.data.size();
    v.byteLength = bytes;
    v.target = target;
    const auto* b = static_cast<const unsigned char*>(data);
    buffer.data.insert(buffer.data.end(), b, b + bytes);
    model.bufferViews.push_back(v);
    return int(model.bufferViews.size()) - 1;
  };
  const auto accessor = [&](const std::vector<float>& values, int type, int components) {
    tinygltf::Accessor acc;
    acc.bufferView = view(values.data(), values.size() * 4, TINYGLTF_TARGET_ARRAY_BUFFER);
    acc.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
    acc.count = values.size() / components;
    acc.type = type;
    model.accessors.push_back(acc);
    return int(model.accessors.size()) - 1;
  };
  const int nv = static_cast<int>(vertices.size());
  std::vector<float> position(3 * nv), texcoord, normal_values, colour;
  for (int v = 0; v < nv; ++v)
    for (int k = 0; k < 3; ++k) position[3 * v + k] = to_float(X(vertices[v][0], k), "a position");
  const int position_accessor = accessor(position, TINYGLTF_TYPE_VEC3, 3);
  Eigen::Array3f lo = Eigen::Array3f::Constant(INFINITY), hi = -lo;
  for (int v = 0; v < nv; ++v) {
    const Eigen::Array3f p(position[3 * v], position[3 * v + 1], position[3 * v + 2]);
    lo = lo.min(p);
    hi = hi.max(p);
  }
  model.accessors[position_accessor].minValues = {lo[0], lo[1], lo[2]};
  model.accessors[position_accessor].maxValues = {hi[0], hi[1], hi[2]};
  std::map<std::string, int> attributes{{"POSITION", position_accessor}};
  if (uv) {
    for (const auto& [vtx, t, n] : vertices) {
      texcoord.push_back(t < 0 ? 0.f : to_float(a.uv(t, 0), "a texture coordinate"));
      texcoord.push_back(t < 0 ? 0.f : to_float(1.0 - a.uv(t, 1), "a texture coordinate"));
    }
    attributes["TEXCOORD_0"] = accessor(texcoord, TINYGLTF_TYPE_VEC2, 2);
  }
  if (normal) {
    for (const auto& [vtx, t, n] : vertices)
      for (int k = 0; k < 3; ++k) {
        normal_values.push_back(n < 0 ? 0.f : to_float(normals(n, k), "a normal"));
      }
    attributes["NORMAL"] = accessor(normal_values, TINYGLTF_TYPE_VEC3, 3);
  }
  if (colours) {
    for (const auto& [vtx, t, n] : vertices)
      for (int k = 0; k < 4; ++k) colour.push_back(a.colours(vtx, k));
    attributes["COLOR_0"] = accessor(colour, TINYGLTF_TYPE_VEC4, 4);
  }
  for (size_t m = 0; m < a.materials.size(); ++m) {
    const Material& mat = a.materials[m];
    tinygltf::Material gm;
    gm.name = mat.name;
    gm.pbrMetallicRoughness.baseColorFactor = {mat.base_color[0], mat.base_color[1],
                                               mat.base_color[2], mat.base_color[3]};
    if (file != nullptr) {
      if (auto image = file->texture(static_cast<int>(m))) {
        tinygltf::Image gi;
        gi.mimeType = image->second;
        gi.bufferView = view(image->first.data(), image->first.size(), 0);
        model.bufferViews.back().target = 0;
        model.images.push_back(gi);
        tinygltf::Texture texture;
        texture.source = int(model.images.size()) - 1;
        model.textures.push_back(texture);
        gm.pbrMetallicRoughness.baseColorTexture.index = int(model.textures.size()) - 1;
      }
    }
    model.materials.push_back(gm);
  }
  tinygltf::Mesh mesh;
  for (const auto& [material, corners] : triangles) {
    tinygltf::Primitive p;
    p.attributes = attributes;
    p.material = material;
    p.mode = TINYGLTF_MODE_TRIANGLES;
    std::vector<uint32_t> indices(corners.begin(), corners.end());
    tinygltf::Accessor acc;
    acc.bufferView = view(indices.data(), indices.size() * 4, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    acc.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    acc.count = indices.size();
    acc.type = TINYGLTF_TYPE_SCALAR;
    model.accessors.push_back(acc);
    p.indices = int(model.accessors.size()) - 1;
    mesh.primitives.push_back(p);
  }
  model.meshes.push_back(mesh);
  tinygltf::Node node;
  node.mesh = 0;
  model.nodes.push_back(node);
  tinygltf::Scene scene;
  scene.nodes = {0};
  model.scenes.push_back(scene);
  model.defaultScene = 0;
  model.buffers.push_back(std::move(buffer));
  std::ostringstream stream;
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&model, stream, false, binary)) {
    throw InputError("the glTF writer failed");
  }
  return stream.str();
}

FileAttributes triangles_of(const TriangleMesh& mesh) {
  FileAttributes a;
  a.corners.resize(3 * size_t(mesh.num_faces()));
  a.offsets.resize(mesh.num_faces() + 1);
  for (int f = 0; f < mesh.num_faces(); ++f) {
    for (int k = 0; k < 3; ++k) a.corners[3 * f + k] = mesh.F(f, k);
    a.offsets[f + 1] = 3 * (f + 1);
  }
  return a;
}

Encoded encode(const FileAttributes& a, const Vertices& X, const Eigen::MatrixX3d& normals,
               MeshFormat format, const Target& target, const MeshFile* file) {
  Encoded out;
  const FileSummary summary = file ? file->summary() : FileSummary();
  const FileSummary* source = file ? &summary : nullptr;
  const std::vector<int> vertex_normal =
      normals.rows() > 0 ? per_vertex(a, a.corner_normal, int(X.rows())) : std::vector<int>();
  Carried carried;
  std::string bytes;
  switch (format) {
    case MeshFormat::Obj:
      out = encode_obj(a, X, normals, target, file);
      break;
    case MeshFormat::Off:
      out.parts = off_parts(a, X, normals, vertex_normal);
      carried.uv = carried.materials = false;
      carried.normals = vertex_normal.size() > 0 || a.corner_normal.empty();
      break;
    case MeshFormat::Ply:
      bytes = ply_bytes(a, X, normals, vertex_normal);
      carried.materials = false;
      carried.normals = vertex_normal.size() > 0 || a.corner_normal.empty();
      break;
    case MeshFormat::Stl:
      bytes = stl_bytes(a, X);
      carried = {false, false, false, false, false};
      break;
    case MeshFormat::Gltf:
    case MeshFormat::Glb:
      bytes = gltf_bytes(a, X, normals, format == MeshFormat::Glb, file);
      carried.polygons = false;
      break;
  }
  if (out.parts.empty()) out.parts.push_back(std::move(bytes));
  if (source != nullptr) {
    const std::vector<std::string> lost = dropped(a, carried, source);
    std::string note = "written as " + format_name(format) + " from " + source->format;
    if (!lost.empty()) {
      note += "; dropped:";
      for (size_t i = 0; i < lost.size(); ++i) note += (i ? ", " : " ") + lost[i];
    }
    out.notes.push_back(note);
    if (format == MeshFormat::Gltf || format == MeshFormat::Glb) {
      out.notes.push_back(
          "vertices split where texture coordinates or normals differ: the "
          "output's vertex numbering is not the input's");
    }
  }
  return out;
}

}  // namespace

EncodedMesh encode_converted(const MeshFile& file, const Vertices& positions,
                             const Eigen::MatrixX3d& normals,
                             const std::filesystem::path& out_name) {
  Encoded e = encode(file.attributes, positions, normals, mesh_format_from_path(out_name),
                     {out_name.filename().string(), out_name.stem().string()}, &file);
  EncodedMesh out;
  out.files.push_back({out_name.filename().string(), {}});
  for (const std::string& p : e.parts) out.files.front().bytes += p;
  for (OutputFile& f : e.companions) out.files.push_back(std::move(f));
  out.notes = std::move(e.notes);
  return out;
}

std::vector<std::string> beyond_triangles(const MeshFile& file) {
  const FileSummary summary = file.summary();
  return dropped(file.attributes, {false, false, false, false, false}, &summary);
}

std::vector<std::string> encode_plain(const TriangleMesh& mesh, MeshFormat format) {
  return encode(triangles_of(mesh), mesh.V, {}, format, {"mesh", "mesh"}, nullptr).parts;
}

}  // namespace specdeform::detail
