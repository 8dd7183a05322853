// glTF 2.0 (.gltf with external or embedded buffers, .glb) through tinygltf: the triangle
// primitives (modes 4, 5 and 6) of every mesh the default scene draws, in world space through
// the node transforms (a skinned mesh in its bind pose: its node's transform is ignored, as the
// specification says), numbered mesh by mesh in the meshes array's order, primitive by primitive,
// POSITION element by element. Vertices at exactly the same world position are welded for the
// solve (glTF splits them along UV seams and hard edges); a mirroring node's triangles are turned
// to face outwards in world space. Refused, one line each: Draco or meshopt compression,
// quantised, sparse or buffer-less positions, a mesh drawn by two nodes, an accessor drawn with
// two transforms, a node reached twice.
#include <tiny_gltf.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>

#include <Eigen/Geometry>

#include "gltf.h"
#include "mesh/polygon_soup.h"
#include "specdeform/exceptions.h"

namespace specdeform::detail {

namespace {

constexpr uint32_t kGlbMagic = 0x46546C67, kJsonChunk = 0x4E4F534A, kBinChunk = 0x004E4942;

uint32_t read_u32(std::string_view data, size_t at) {
  uint32_t v;
  std::memcpy(&v, data.data() + at, 4);
  return v;
}

// A .glb's chunks: the JSON, the BIN chunk (if any) and what follows it.
struct GlbChunks {
  std::string_view json, bin, tail, after;  // after: bytes beyond the header's length
  bool has_bin = false;
};

GlbChunks split_glb(std::string_view data, const std::string& name) {
  const auto fail = [&](const std::string& what) -> GlbChunks {
    throw InputError(name + ": not a glTF binary file (" + what + ")");
  };
  if (data.size() < 20) fail("shorter than its header");
  if (read_u32(data, 0) != kGlbMagic) fail("no 'glTF' magic");
  if (read_u32(data, 4) != 2) fail("version " + std::to_string(read_u32(data, 4)) + ", not 2");
  if (read_u32(data, 8) > data.size()) fail("truncated: the header announces more bytes");
  GlbChunks out;
  out.after = data.substr(read_u32(data, 8));
  data = data.substr(0, read_u32(data, 8));
  size_t at = 12;
  for (int chunk = 0; at + 8 <= data.size(); ++chunk) {
    const uint32_t length = read_u32(data, at), type = read_u32(data, at + 4);
    if (length > data.size() - at - 8) fail("truncated chunk " + std::to_string(chunk));
    const std::string_view body = data.substr(at + 8, length);
    if (chunk == 0) {
      if (type != kJsonChunk) fail("the first chunk is not JSON");
      out.json = body;
    } else if (chunk == 1 && type == kBinChunk) {
      out.bin = body;
      out.has_bin = true;
    } else {
      out.tail = data.substr(at);
      break;
    }
    at += 8 + length;
  }
  if (out.tail.empty()) out.tail = data.substr(std::min(at, data.size()));  // under a chunk header
  if (out.json.empty()) fail("no JSON chunk");
  return out;
}

// tinygltf reads the files a .gltf names through the FileResolver, each once.
struct Companions {
  const FileResolver* resolve;
  std::map<std::string, std::optional<std::string>> read;

  const std::optional<std::string>& get(std::string name) {
    if (name.starts_with("./")) name.erase(0, 2);
    auto it = read.find(name);
    if (it == read.end()) it = read.emplace(name, *resolve ? (*resolve)(name) : std::nullopt).first;
    return it->second;
  }
};

tinygltf::FsCallbacks companion_callbacks(Companions& companions) {
  tinygltf::FsCallbacks fs{};
  fs.FileExists = [](const std::string& name, void* user) {
    return static_cast<Companions*>(user)->get(name).has_value();
  };
  fs.ExpandFilePath = [](const std::string& name, void*) { return name; };
  fs.ReadWholeFile = [](std::vector<unsigned char>* out, std::string* err, const std::string& name,
                        void* user) {
    const std::optional<std::string>& bytes = static_cast<Companions*>(user)->get(name);
    if (!bytes) {
      *err = "not found";
      return false;
    }
    out->assign(bytes->begin(), bytes->end());
    return true;
  };
  fs.WriteWholeFile = [](std::string* err, const std::string&, const std::vector<unsigned char>&,
                         void*) {
    *err = "not written";
    return false;
  };
  fs.user_data = &companions;
  return fs;
}

// Images are kept as bytes, never decoded.
bool keep_image_undecoded(tinygltf::Image*, const int, std::string*, std::string*, int, int,
                          const unsigned char*, int, void*) {
  return true;
}

std::string first_line(const std::string& s) {
  std::string line = s.substr(0, s.find('\n'));
  return line.empty() ? "unknown error" : line;
}

// An accessor's elements, checked against its buffer view and buffer.
struct Elements {
  const unsigned char* data = nullptr;
  size_t stride = 0, offset = 0;  // offset: of element 0 in its buffer
  int count = 0, components = 0, buffer = 0;
  int type = 0;  // component type
  bool normalized = false;

  double get(int i, int k) const {
    const unsigned char* p = data + size_t(i) * stride;
    const auto as = [&](auto v) {
      std::memcpy(&v, p + k * sizeof v, sizeof v);
      return v;
    };
    switch (type) {
      case TINYGLTF_COMPONENT_TYPE_FLOAT:
        return as(float{});
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        return normalized ? as(uint8_t{}) / 255.0 : as(uint8_t{});
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
        return normalized ? as(uint16_t{}) / 65535.0 : as(uint16_t{});
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
        return as(uint32_t{});
      case TINYGLTF_COMPONENT_TYPE_BYTE:
        return normalized ? std::max(as(int8_t{}) / 127.0, -1.0) : as(int8_t{});
      case TINYGLTF_COMPONENT_TYPE_SHORT:
        return normalized ? std::max(as(int16_t{}) / 32767.0, -1.0) : as(int16_t{});
    }
    return 0.0;
  }
};

class GltfReader {
 public:
  GltfReader(const tinygltf::Model& model, const std::string& name) : m_(model), name_(name) {}

  [[noreturn]] void fail(const std::string& what) const { throw InputError(name_ + ": " + what); }

  // Accessor `index` for `what`, with `components` components; nullopt when index is -1.
  std::optional<Elements> elements(int index, int components, const std::string& what) const {
    if (index < 0) return std::nullopt;
    if (index >= int(m_.accessors.size())) fail(what + " names a missing accessor");
    const tinygltf::Accessor& a = m_.accessors[index];
    const std::string which = what + " (accessor " + std::to_string(index) + ")";
    if (a.sparse.isSparse) fail(which + " is sparse: it cannot be rewritten");
    if (a.bufferView < 0 || a.bufferView >= int(m_.bufferViews.size())) {
      fail(which + " has no buffer view (compressed, or all zeros)");
    }
    const int size = tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType));
    if (size <= 0 || tinygltf::GetNumComponentsInType(uint32_t(a.type)) != components) {
      fail(which + " has the wrong type");
    }
    const tinygltf::BufferView& v = m_.bufferViews[a.bufferView];
    if (v.buffer < 0 || v.buffer >= int(m_.buffers.size())) fail(which + ": missing buffer");
    const size_t element = size_t(size) * components;
    const size_t stride = v.byteStride == 0 ? element : v.byteStride;
    const size_t buffer = m_.buffers[v.buffer].data.size();
    const size_t need = a.count == 0 ? 0 : a.byteOffset + stride * (a.count - 1) + element;
    if (stride < element || v.byteOffset > buffer || v.byteLength > buffer - v.byteOffset ||
        need > v.byteLength || a.count > size_t(INT32_MAX / 4)) {
      fail(which + " reaches beyond its buffer");
    }
    Elements e;
    e.offset = v.byteOffset + a.byteOffset;
    e.data = m_.buffers[v.buffer].data.data() + e.offset;
    e.stride = stride;
    e.count = static_cast<int>(a.count);
    e.components = components;
    e.buffer = v.buffer;
    e.type = a.componentType;
    e.normalized = a.normalized;
    return e;
  }

  // A float accessor the writer can put new values in.
  GltfSlots float_slots(const Elements& e, int accessor, const std::string& what) const {
    if (e.type != TINYGLTF_COMPONENT_TYPE_FLOAT) {
      fail(what + " (accessor " + std::to_string(accessor) +
           ") is not float (quantised): it cannot be rewritten");
    }
    return {accessor, e.buffer, e.offset, e.stride, e.count};
  }

  Eigen::Matrix4d local_matrix(const tinygltf::Node& n) const {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    if (n.matrix.size() == 16) {
      for (int k = 0; k < 16; ++k) m(k % 4, k / 4) = n.matrix[k];  // column-major
      return m;
    }
    Eigen::Affine3d t = Eigen::Affine3d::Identity();
    if (n.translation.size() == 3) t.translate(Eigen::Vector3d(n.translation.data()));
    if (n.rotation.size() == 4) {
      t.rotate(Eigen::Quaterniond(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2])
                   .normalized());
    }
    if (n.scale.size() == 3) t.scale(Eigen::Vector3d(n.scale.data()));
    return t.matrix();
  }

  // Each mesh's world matrix, from the nodes of the default scene (or, without scenes, of every
  // node no other node has as a child); meshes it does not draw are absent.
  std::map<int, Eigen::Matrix4d> drawn_meshes() const {
    std::vector<int> roots;
    const int scene = m_.defaultScene >= 0 ? m_.defaultScene : m_.scenes.empty() ? -1 : 0;
    if (scene >= int(m_.scenes.size())) fail("the default scene does not exist");
    if (scene >= 0) {
      roots = m_.scenes[scene].nodes;
    } else {
      std::vector<char> child(m_.nodes.size(), 0);
      for (const tinygltf::Node& n : m_.nodes)
        for (const int c : n.children)
          if (c >= 0 && c < int(child.size())) child[c] = 1;
      for (size_t n = 0; n < child.size(); ++n)
        if (!child[n]) roots.push_back(int(n));
    }
    std::map<int, Eigen::Matrix4d> world;
    std::map<int, int> drawn_by;
    std::vector<char> seen(m_.nodes.size(), 0);
    std::vector<std::pair<int, Eigen::Matrix4d>> stack;
    for (const int r : roots) stack.emplace_back(r, Eigen::Matrix4d::Identity());
    while (!stack.empty()) {
      const auto [index, parent] = stack.back();
      stack.pop_back();
      if (index < 0 || index >= int(m_.nodes.size())) fail("a scene names a missing node");
      if (seen[index]) fail("node " + std::to_string(index) + " is reached twice in the scene");
      seen[index] = 1;
      const tinygltf::Node& node = m_.nodes[index];
      const Eigen::Matrix4d matrix = parent * local_matrix(node);
      if (node.extensions.count("EXT_mesh_gpu_instancing")) {
        fail("node " + std::to_string(index) + " is instanced (EXT_mesh_gpu_instancing)");
      }
      if (node.mesh >= int(m_.meshes.size())) fail("a node names a missing mesh");
      if (node.mesh >= 0) {
        if (const auto [it, first] = drawn_by.emplace(node.mesh, index); !first) {
          fail("mesh " + mesh_name(node.mesh) + " is drawn by two nodes (" +
               std::to_string(it->second) + " and " + std::to_string(index) +
               "): it cannot take two deformations");
        }
        world[node.mesh] = node.skin >= 0 ? Eigen::Matrix4d::Identity() : matrix;
        if (!matrix.allFinite() || std::abs(matrix.topLeftCorner<3, 3>().determinant()) < 1e-300) {
          fail("node " + std::to_string(index) + "'s transform is not invertible");
        }
      }
      for (const int c : node.children) stack.emplace_back(c, matrix);
    }
    return world;
  }

  std::string mesh_name(int m) const {
    const std::string& n = m_.meshes[m].name;
    return std::to_string(m) + (n.empty() ? "" : " ('" + n + "')");
  }

 private:
  const tinygltf::Model& m_;
  const std::string& name_;
};

tinygltf::Model load_model(std::string_view data, MeshFormat format, const std::string& name,
                           const FileResolver& resolve) {
  tinygltf::TinyGLTF loader;
  Companions companions{&resolve, {}};
  loader.SetFsCallbacks(companion_callbacks(companions));
  loader.SetImageLoader(keep_image_undecoded, nullptr);
  tinygltf::Model model;
  std::string err, warn;
  const bool ok =
      format == MeshFormat::Glb
          ? loader.LoadBinaryFromMemory(&model, &err, &warn,
                                        reinterpret_cast<const unsigned char*>(data.data()),
                                        static_cast<unsigned int>(data.size()))
          : loader.LoadASCIIFromString(&model, &err, &warn, data.data(),
                                       static_cast<unsigned int>(data.size()), "");
  if (!ok) {
    if (err.find("File not found") != std::string::npos) {
      throw InputError(name + ": " + first_line(err) +
                       " (a .gltf's buffers must be beside it; or open the .glb)");
    }
    throw InputError(name + ": not a valid glTF file: " + first_line(err));
  }
  return model;
}

}  // namespace

PolygonSoup parse_gltf(std::string_view data, MeshFormat format, const std::string& name,
                       const FileResolver& companions, KeptRecord* keep) {
  if (data.empty()) throw InputError(name + ": empty file");
  GlbChunks glb;
  if (format == MeshFormat::Glb) glb = split_glb(data, name);
  const tinygltf::Model m = load_model(data, format, name, companions);
  const GltfReader r(m, name);
  for (const std::string& e : m.extensionsRequired) {
    if (e == "KHR_draco_mesh_compression" || e == "EXT_meshopt_compression" ||
        e == "KHR_mesh_quantization" || e == "EXT_mesh_gpu_instancing") {
      r.fail("uses " + e + ": positions stored this way cannot be rewritten");
    }
  }
  const std::map<int, Eigen::Matrix4d> world = r.drawn_meshes();

  PolygonSoup soup;
  GltfLayout layout;
  FileAttributes* a = keep ? &keep->attributes : nullptr;
  std::vector<double> uv, normal, tangent;  // per file vertex: 2, 3, 4
  std::vector<float> colour;                // 4 per file vertex
  std::vector<char> with_uv, with_normal;   // per file vertex
  bool has_uv = false, has_normal = false, has_colour = false;
  std::map<int, const Eigen::Matrix4d*> accessor_world;  // POSITION accessors drawn so far
  for (const auto& [mesh, matrix] : world) {
    const Eigen::Matrix3d linear = matrix.topLeftCorner<3, 3>();
    const bool mirrors = linear.determinant() < 0;
    const tinygltf::Mesh& gm = m.meshes[mesh];
    for (size_t p = 0; p < gm.primitives.size(); ++p) {
      const tinygltf::Primitive& prim = gm.primitives[p];
      const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
      if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
          mode != TINYGLTF_MODE_TRIANGLE_FAN) {
        continue;  // points and lines are not a surface
      }
      const std::string what = "mesh " + r.mesh_name(mesh) + " primitive " + std::to_string(p);
      if (prim.extensions.count("KHR_draco_mesh_compression")) {
        r.fail(what + " is Draco-compressed: its positions cannot be rewritten");
      }
      const auto attribute = [&](const char* key) {
        const auto it = prim.attributes.find(key);
        return it == prim.attributes.end() ? -1 : it->second;
      };
      const int position_accessor = attribute("POSITION");
      if (position_accessor < 0) r.fail(what + " has no POSITION");
      const Elements position = *r.elements(position_accessor, 3, what + " POSITION");
      if (const auto [it, first] = accessor_world.emplace(position_accessor, &matrix);
          !first && *it->second != matrix) {
        r.fail(what + " POSITION (accessor " + std::to_string(position_accessor) +
               ") is drawn with two transforms");
      }
      const int first = soup.num_vertices();
      GltfPrimitive gp;
      gp.first_vertex = first;
      gp.world = matrix;
      gp.position = r.float_slots(position, position_accessor, what + " POSITION");
      for (int i = 0; i < position.count; ++i) {
        const Eigen::Vector4d x(position.get(i, 0), position.get(i, 1), position.get(i, 2), 1.0);
        const Eigen::Vector4d w = matrix * x;
        soup.xyz.insert(soup.xyz.end(), {w.x(), w.y(), w.z()});
      }
      // Triangles.
      const std::optional<Elements> index = r.elements(prim.indices, 1, what + " indices");
      if (index && index->type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
          index->type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
          index->type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
        r.fail(what + " indices are not unsigned integers");
      }
      const int count = index ? index->count : position.count;
      const auto corner = [&](int k) {
        const double v = index ? index->get(k, 0) : k;
        if (!(v < position.count)) {
          r.fail(what + " index " + std::to_string(k) + " is beyond its " +
                 std::to_string(position.count) + " vertices");
        }
        return first + static_cast<int>(v);
      };
      const auto triangle = [&](int i, int j, int k) {
        for (const int c : {i, j, k}) soup.add_polygon_corner(c);
        if (mirrors) std::swap(soup.indices.end()[-1], soup.indices.end()[-2]);
        soup.end_polygon();
        if (keep) a->polygon_material.push_back(prim.material);
      };
      if (mode == TINYGLTF_MODE_TRIANGLES) {
        for (int k = 0; k + 2 < count; k += 3) triangle(corner(k), corner(k + 1), corner(k + 2));
      } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
        for (int k = 0; k + 2 < count; ++k) {
          if (k % 2 == 0)
            triangle(corner(k), corner(k + 1), corner(k + 2));
          else
            triangle(corner(k + 1), corner(k), corner(k + 2));
        }
      } else {
        for (int k = 1; k + 1 < count; ++k) triangle(corner(0), corner(k), corner(k + 1));
      }
      if (!keep) continue;
      // What the writer rewrites, and the attributes.
      const int vertices = position.count;
      uv.resize(2 * soup.num_vertices(), 0.0);
      normal.resize(3 * soup.num_vertices(), 0.0);
      tangent.resize(4 * soup.num_vertices(), 0.0);
      colour.resize(4 * soup.num_vertices(), 1.0f);
      with_uv.resize(soup.num_vertices(), 0);
      with_normal.resize(soup.num_vertices(), 0);
      if (const auto t = r.elements(attribute("TEXCOORD_0"), 2, what + " TEXCOORD_0")) {
        if (t->count != vertices) r.fail(what + " TEXCOORD_0 has another count than POSITION");
        for (int i = 0; i < vertices; ++i)
          for (int k = 0; k < 2; ++k) uv[2 * (first + i) + k] = t->get(i, k);
        std::fill(with_uv.begin() + first, with_uv.end(), 1);
        has_uv = true;
      }
      const int normal_accessor = attribute("NORMAL");
      if (const auto n = r.elements(normal_accessor, 3, what + " NORMAL")) {
        if (n->count != vertices) r.fail(what + " NORMAL has another count than POSITION");
        gp.normal = r.float_slots(*n, normal_accessor, what + " NORMAL");
        for (int i = 0; i < vertices; ++i) {
          // To world space: n <- A^-T n.
          const Eigen::Vector3d local(n->get(i, 0), n->get(i, 1), n->get(i, 2));
          const Eigen::Vector3d w = linear.transpose().partialPivLu().solve(local);
          const double norm = w.norm();
          for (int k = 0; k < 3; ++k) normal[3 * (first + i) + k] = norm > 0 ? w[k] / norm : 0;
        }
        std::fill(with_normal.begin() + first, with_normal.end(), 1);
        has_normal = true;
        const int tangent_accessor = attribute("TANGENT");
        if (const auto t = r.elements(tangent_accessor, 4, what + " TANGENT")) {
          if (t->count != vertices) r.fail(what + " TANGENT has another count than POSITION");
          gp.tangent = r.float_slots(*t, tangent_accessor, what + " TANGENT");
          for (int i = 0; i < vertices; ++i) {
            const Eigen::Vector3d w =
                linear * Eigen::Vector3d(t->get(i, 0), t->get(i, 1), t->get(i, 2));
            for (int k = 0; k < 3; ++k) tangent[4 * (first + i) + k] = w[k];
            tangent[4 * (first + i) + 3] = t->get(i, 3);
          }
        }
      }
      const int colour_accessor = attribute("COLOR_0");
      if (colour_accessor >= 0) {
        const bool rgb = colour_accessor < int(m.accessors.size()) &&
                         m.accessors[colour_accessor].type == TINYGLTF_TYPE_VEC3;
        const int components = rgb ? 3 : 4;
        const auto c = r.elements(colour_accessor, components, what + " COLOR_0");
        if (c->count != vertices) r.fail(what + " COLOR_0 has another count than POSITION");
        for (int i = 0; i < vertices; ++i)
          for (int k = 0; k < components; ++k) colour[4 * (first + i) + k] = float(c->get(i, k));
        has_colour = true;
      }
      layout.primitives.push_back(gp);
    }
  }
  if (soup.num_polygons() == 0) {
    r.fail(world.empty() ? "the scene draws no mesh" : "no triangle primitives in the scene");
  }
  soup.weld = weld_coincident(soup.xyz);
  if (!keep) return soup;

  // Rows of uv and normals are file vertices; corners of primitives without them use none.
  const int n = soup.num_vertices();
  const auto corner_rows = [&](const std::vector<char>& with) {
    std::vector<int> rows = soup.indices;
    for (int& c : rows)
      if (!with[c]) c = -1;
    return rows;
  };
  if (has_uv) {
    a->uv = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>>(uv.data(),
                                                                                        n, 2);
    a->corner_uv = corner_rows(with_uv);
  }
  if (has_normal) {
    a->normals = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(
        normal.data(), n, 3);
    a->corner_normal = corner_rows(with_normal);
    layout.tangents = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor>>(
        tangent.data(), n, 4);
  }
  if (has_colour) {
    a->colours = Eigen::Map<const Eigen::Matrix<float, Eigen::Dynamic, 4, Eigen::RowMajor>>(
        colour.data(), n, 4);
  }
  for (const tinygltf::Material& gm : m.materials) {
    Material mat;
    mat.name = gm.name;
    const std::vector<double>& f = gm.pbrMetallicRoughness.baseColorFactor;
    if (f.size() == 4) mat.base_color = Eigen::Vector4d(f.data()).cast<float>();
    const int texture = gm.pbrMetallicRoughness.baseColorTexture.index;
    if (texture >= 0 && texture < int(m.textures.size())) {
      const int image = m.textures[texture].source;
      if (image >= 0 && image < int(m.images.size())) {
        mat.gltf_image = image;
        mat.texture = m.images[image].uri;
      }
    }
    a->materials.push_back(std::move(mat));
  }
  if (m.materials.empty()) {
    a->polygon_material.clear();
  } else {
    for (int& mat : a->polygon_material)
      if (mat >= int(m.materials.size())) mat = -1;
  }

  layout.container = format == MeshFormat::Glb ? GltfContainer::Glb : GltfContainer::Gltf;
  layout.json = std::string(format == MeshFormat::Glb ? glb.json : data);
  for (size_t b = 0; b < m.buffers.size(); ++b) {
    GltfBuffer buffer;
    buffer.uri = m.buffers[b].uri;
    if (format == MeshFormat::Glb && b == 0 && buffer.uri.empty()) {
      buffer.source = GltfBufferSource::GlbChunk;
      buffer.bytes = std::string(glb.bin);
    } else {
      buffer.source =
          tinygltf::IsDataURI(buffer.uri) ? GltfBufferSource::DataUri : GltfBufferSource::External;
      buffer.bytes.assign(m.buffers[b].data.begin(), m.buffers[b].data.end());
    }
    layout.buffers.push_back(std::move(buffer));
  }
  layout.glb_tail = std::string(glb.tail);
  layout.glb_after = std::string(glb.after);
  layout.meshes = static_cast<int>(world.size());
  layout.skins = static_cast<int>(m.skins.size());
  layout.animations = static_cast<int>(m.animations.size());
  layout.images = static_cast<int>(m.images.size());
  for (const auto& [mesh, matrix] : world)
    for (const tinygltf::Primitive& prim : m.meshes[mesh].primitives) {
      layout.morph_targets += static_cast<int>(prim.targets.size());
      int sets = 0;
      while (prim.attributes.count("TEXCOORD_" + std::to_string(sets))) ++sets;
      layout.uv_sets = std::max(layout.uv_sets, sets);
    }
  keep->layout.format = std::move(layout);
  return soup;
}

}  // namespace specdeform::detail
