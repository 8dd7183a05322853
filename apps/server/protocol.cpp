#include "protocol.h"

#include <algorithm>
#include <bit>
#include <cstring>

#include "specdeform/deform/scene.h"
#include "specdeform/exceptions.h"

static_assert(std::endian::native == std::endian::little, "the protocol is little-endian");

namespace specdeform::server {

namespace {

// Reads fixed-size fields from a message, with the message's name in every error.
class Reader {
 public:
  Reader(std::string_view data, const char* what) : data_(data), what_(what) {}

  template <typename T>
  T get() {
    need(sizeof(T));
    T v;
    std::memcpy(&v, data_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  std::string_view bytes(size_t count) {
    need(count);
    const std::string_view out = data_.substr(pos_, count);
    pos_ += count;
    return out;
  }
  size_t remaining() const { return data_.size() - pos_; }
  void align4() { bytes((4 - pos_ % 4) % 4); }
  void align8() { bytes((8 - pos_ % 8) % 8); }
  void expect_end() const {
    if (remaining() != 0) fail(std::to_string(remaining()) + " bytes too many");
  }
  [[noreturn]] void fail(const std::string& why) const {
    throw InputError(std::string(what_) + " message: " + why);
  }

 private:
  void need(size_t count) const {
    if (count > remaining()) fail("truncated");
  }
  std::string_view data_;
  const char* what_;
  size_t pos_ = 0;
};

class Writer {
 public:
  template <typename T>
  void put(T v) {
    out_.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  void bytes(std::string_view b) { out_.append(b); }
  void align4() { out_.append((4 - out_.size() % 4) % 4, '\0'); }
  void align8() { out_.append((8 - out_.size() % 8) % 8, '\0'); }
  std::string take() { return std::move(out_); }
  void reserve(size_t n) { out_.reserve(n); }

 private:
  std::string out_;
};

Eigen::Affine3d read_transform(Reader& r, const std::string& where) {
  Eigen::Matrix4d m;
  for (int i = 0; i < 16; ++i) m(i / 4, i % 4) = r.get<double>();
  return checked_transform(m, where);
}

void write_transform(Writer& w, const Eigen::Affine3d& t) {
  for (int i = 0; i < 16; ++i) w.put(t.matrix()(i / 4, i % 4));
}

}  // namespace

Tag message_tag(std::string_view message) {
  return static_cast<Tag>(Reader(message, "binary").get<uint32_t>());
}

GroupSelection decode_selection(std::string_view message, int num_vertices) {
  Reader r(message, "selection");
  r.get<uint32_t>();
  const uint32_t groups = r.get<uint32_t>(), fixed = r.get<uint32_t>();
  const uint32_t flags = r.get<uint32_t>();
  if (flags > 1) r.fail("unknown flags");
  if (groups > kMaxGroups) r.fail(std::to_string(groups) + " handle groups (at most 64)");
  std::vector<uint32_t> sizes(groups);
  uint64_t total = fixed;
  for (uint32_t& s : sizes) total += s = r.get<uint32_t>();
  GroupSelection out;
  out.echo = flags == 1;
  for (uint32_t g = 0; g < groups; ++g) {
    const uint32_t group_flags = r.get<uint32_t>();
    if (group_flags > 3) r.fail("group " + std::to_string(g) + " has unknown flags");
    out.pinned.push_back((group_flags & 1) != 0);
    out.fit.push_back((group_flags & 2) != 0);
  }
  r.align8();
  for (uint32_t g = 0; g < groups; ++g) {
    out.transforms.push_back(
        read_transform(r, "selection message: transform " + std::to_string(g)));
  }
  if (total * 4 != r.remaining()) r.fail("the sizes do not match the message's length");
  const auto read_list = [&](uint32_t count) {
    std::vector<int> list(count);
    for (int& v : list) {
      const uint32_t i = r.get<uint32_t>();
      if (i >= static_cast<uint32_t>(num_vertices)) {
        r.fail("vertex " + std::to_string(i) + " is out of range (the mesh has " +
               std::to_string(num_vertices) + " vertices)");
      }
      v = static_cast<int>(i);
    }
    return list;
  };
  out.selection.fixed = read_list(fixed);
  for (uint32_t size : sizes) out.selection.handles.push_back(read_list(size));
  return out;
}

FrameRequest decode_frame(std::string_view message, int num_groups) {
  Reader r(message, "frame");
  r.get<uint32_t>();
  FrameRequest f;
  f.seq = r.get<uint32_t>();
  const uint32_t groups = r.get<uint32_t>();
  const uint32_t flags = r.get<uint32_t>();
  if (flags > 1) r.fail("unknown flags");
  f.preview = flags == 1;
  if (groups != static_cast<uint32_t>(num_groups)) {
    r.fail(std::to_string(groups) + " transforms for " + std::to_string(num_groups) +
           " handle groups");
  }
  if (r.remaining() != groups * 16 * sizeof(double)) r.fail("wrong length");
  for (uint32_t g = 0; g < groups; ++g) {
    f.transforms.push_back(read_transform(r, "frame message: transform " + std::to_string(g)));
  }
  return f;
}

NamedFile decode_file(std::string_view message) {
  Reader r(message, "file");
  r.get<uint32_t>();
  const uint32_t length = r.get<uint32_t>();
  if (length == 0 || length > kMaxNameLength) r.fail("bad file name length");
  NamedFile f;
  f.name = r.bytes(length);
  for (unsigned char c : f.name) {
    if (c < 0x20 || c == 0x7f) r.fail("the file name has control characters");
  }
  r.align4();
  f.data = r.bytes(r.remaining());
  return f;
}

std::string encode_selection(const GroupSelection& s, Tag tag) {
  const Selection& selection = s.selection;
  Writer w;
  w.put(static_cast<uint32_t>(tag));
  w.put(static_cast<uint32_t>(selection.handles.size()));
  w.put(static_cast<uint32_t>(selection.fixed.size()));
  w.put(uint32_t{s.echo ? 1u : 0u});
  const size_t groups = selection.handles.size();
  for (const auto& g : selection.handles) w.put(static_cast<uint32_t>(g.size()));
  for (size_t g = 0; g < groups; ++g) {
    const bool pinned = g < s.pinned.size() && s.pinned[g], fit = g < s.fit.size() && s.fit[g];
    w.put(static_cast<uint32_t>((pinned ? 1 : 0) | (fit ? 2 : 0)));
  }
  w.align8();
  for (size_t g = 0; g < groups; ++g) {
    write_transform(w, g < s.transforms.size() ? s.transforms[g] : Eigen::Affine3d::Identity());
  }
  for (int v : selection.fixed) w.put(static_cast<uint32_t>(v));
  for (const auto& g : selection.handles) {
    for (int v : g) w.put(static_cast<uint32_t>(v));
  }
  return w.take();
}

std::string encode_frame(const FrameRequest& frame) {
  Writer w;
  w.put(static_cast<uint32_t>(Tag::Frame));
  w.put(frame.seq);
  w.put(static_cast<uint32_t>(frame.transforms.size()));
  w.put(uint32_t{frame.preview ? 1u : 0u});
  for (const Eigen::Affine3d& t : frame.transforms) write_transform(w, t);
  return w.take();
}

std::string encode_file(const NamedFile& file, Tag tag) {
  Writer w;
  w.put(static_cast<uint32_t>(tag));
  w.put(static_cast<uint32_t>(file.name.size()));
  w.bytes(file.name);
  w.align4();
  w.bytes(file.data);
  return w.take();
}

std::vector<std::string> encode_mesh_parts(const TriangleMesh& mesh, uint32_t part_items) {
  const auto n = static_cast<uint32_t>(mesh.V.rows());
  const auto triangles = static_cast<uint32_t>(mesh.F.rows());
  std::vector<std::string> parts;
  const auto add = [&](uint32_t kind, uint32_t size, const auto& rows) {
    for (uint32_t first = 0; first == 0 || first < size; first += part_items) {
      const uint32_t count = std::min(part_items, size - first);
      Writer w;
      w.reserve(24 + 12 * count);
      for (uint32_t field : {static_cast<uint32_t>(Tag::Mesh), n, triangles, kind, first, count}) {
        w.put(field);
      }
      for (uint32_t i = first; i < first + count; ++i) {
        for (int k = 0; k < 3; ++k) w.put(rows(i, k));
      }
      parts.push_back(w.take());
    }
  };
  add(0, n, [&](uint32_t i, int k) { return static_cast<float>(mesh.V(i, k)); });
  add(1, triangles, [&](uint32_t f, int k) { return static_cast<uint32_t>(mesh.F(f, k)); });
  return parts;
}

MeshPartHeader mesh_part_header(std::string_view message) {
  Reader r(message, "mesh part");
  r.bytes(4);
  MeshPartHeader h{};
  for (uint32_t* field : {&h.n, &h.triangles, &h.kind, &h.first, &h.count}) {
    *field = r.get<uint32_t>();
  }
  return h;
}

bool starts_mesh(std::string_view message) {
  if (message.size() < 24 || message_tag(message) != Tag::Mesh) return false;
  const MeshPartHeader h = mesh_part_header(message);
  return h.kind == 0 && h.first == 0;
}

std::string encode_preview(const PreviewMesh& preview) {
  Writer w;
  w.reserve(12 + 4 * preview.vertices.size() + 12 * preview.faces.rows());
  w.put(static_cast<uint32_t>(Tag::Preview));
  w.put(static_cast<uint32_t>(preview.vertices.size()));
  w.put(static_cast<uint32_t>(preview.faces.rows()));
  for (int v : preview.vertices) w.put(static_cast<uint32_t>(v));
  for (Eigen::Index f = 0; f < preview.faces.rows(); ++f) {
    for (int k = 0; k < 3; ++k) w.put(static_cast<uint32_t>(preview.faces(f, k)));
  }
  return w.take();
}

std::string encode_appearance(const Appearance& a) {
  const uint32_t R = static_cast<uint32_t>(a.vertex.size());
  const uint32_t T = static_cast<uint32_t>(a.corners.size() / 3);
  const uint32_t M = static_cast<uint32_t>(a.textured.size());
  Writer w;
  w.reserve(20 + 4 * (2 * R + 3 * T + M + 2 + 12 * M) + 4 * a.uv.size() + a.rgba.size() + 4);
  w.put(static_cast<uint32_t>(Tag::Appearance));
  w.put(R);
  w.put(T);
  w.put(M);
  w.put(static_cast<uint32_t>((a.uv.empty() ? 0 : 1) | (a.rgba.empty() ? 0 : 2)));
  for (const uint32_t v : a.vertex) w.put(v);
  for (const uint32_t g : a.normal_group) w.put(g);
  for (const uint32_t c : a.corners) w.put(c);
  for (const uint32_t s : a.material_start) w.put(s);
  for (const float c : a.base_color) w.put(c);
  for (const char t : a.textured) w.put(static_cast<uint32_t>(t));
  for (size_t m = 0; m < M; ++m) {  // unlit, nearest, wrap u and v (2 bits each); transform
    const TextureSampling& t = a.sampling[m];
    w.put(static_cast<uint32_t>(a.unlit[m] | t.nearest << 1 | int(t.wrap_u) << 2 |
                                int(t.wrap_v) << 4));
    for (int r = 0; r < 2; ++r) {
      for (int c = 0; c < 3; ++c) w.put(t.transform(r, c));
    }
  }
  for (const float u : a.uv) w.put(u);
  for (const uint8_t c : a.rgba) w.put(c);
  w.align4();
  return w.take();
}

std::string encode_texture(uint32_t material, std::string_view mime, std::string_view image) {
  Writer w;
  w.reserve(16 + mime.size() + image.size());
  w.put(static_cast<uint32_t>(Tag::Texture));
  w.put(material);
  w.put(static_cast<uint32_t>(mime.size()));
  w.bytes(mime);
  w.align4();
  w.bytes(image);
  return w.take();
}

// Below this fraction of the largest coordinate a displacement is rounding (float32 resolves
// about 6e-8 of it; double solves leave 1e-14).
constexpr double kRoundingNoise = 1e-9;

std::string encode_frame_result(uint32_t seq, FrameView view, const FrameStats& stats,
                                const Vertices& positions, const Vertices& rest,
                                const PreviewMesh* preview) {
  const bool subset = view.preview && preview != nullptr;
  const size_t n = subset ? preview->vertices.size() : static_cast<size_t>(positions.rows());
  if (static_cast<size_t>(positions.rows()) != n) {
    throw InputError("frame result: " + std::to_string(positions.rows()) + " positions for " +
                     std::to_string(n) + " vertices");
  }
  const auto vertex = [&](size_t i) {
    return subset ? preview->vertices[i] : static_cast<Eigen::Index>(i);
  };
  double largest = 0.0, extent = 0.0;
  for (size_t i = 0; i < n; ++i) {
    largest = std::max(largest, (positions.row(i) - rest.row(vertex(i))).cwiseAbs().maxCoeff());
    extent = std::max(extent, rest.row(vertex(i)).cwiseAbs().maxCoeff());
  }
  // Differences within rounding of the coordinates (a solve at the rest pose) are no motion:
  // scaled up to the int16 range they would read as one.
  if (largest <= kRoundingNoise * extent) largest = 0.0;
  const float scale = largest > 0.0 ? static_cast<float>(largest / 32767.0) : 1.0f;
  const bool at_rest = largest == 0.0;  // no displacements follow
  Writer w;
  w.reserve(52 + (at_rest ? 0 : 6 * n + 2));
  w.put(static_cast<uint32_t>(Tag::FrameResult));
  w.put(seq);
  w.put(static_cast<uint32_t>(n));
  w.put(static_cast<uint32_t>((view.base ? 1 : 0) | (subset ? 2 : 0) |
                              (stats.fold_zone > 0 ? 4 : 0) | (at_rest ? 8 : 0)));
  for (double ms : {stats.reduced_solve, stats.inverse_transform, stats.detail, stats.total}) {
    w.put(static_cast<float>(ms * 1e3));
  }
  w.put(static_cast<float>(stats.error_max));
  w.put(static_cast<float>(stats.error_rms));
  w.put(static_cast<uint32_t>(stats.arap_iterations));
  w.put(uint32_t{stats.arap_converged ? 1u : 0u});
  w.put(scale);
  for (size_t i = 0; i < (at_rest ? 0 : n); ++i) {
    for (int k = 0; k < 3; ++k) {
      const double d = (positions(i, k) - rest(vertex(i), k)) / scale;
      w.put(static_cast<int16_t>(std::clamp(std::lround(d), -32767L, 32767L)));
    }
  }
  w.align4();
  return w.take();
}

Vertices decode_frame_positions(std::string_view message, const Vertices& rest,
                                const PreviewMesh* preview) {
  Reader r(message, "frame result");
  r.bytes(8);
  const uint32_t n = r.get<uint32_t>(), view = r.get<uint32_t>();
  const bool subset = (view & 2) != 0;
  if (subset && (preview == nullptr || preview->vertices.size() != n)) r.fail("not this preview's");
  if (!subset && n != rest.rows()) r.fail("not this mesh's");
  r.bytes(32);
  const float scale = r.get<float>();
  const bool at_rest = (view & 8) != 0;
  Vertices out(n, 3);
  for (uint32_t i = 0; i < n; ++i) {
    const Eigen::Index v = subset ? preview->vertices[i] : i;
    for (int k = 0; k < 3; ++k)
      out(i, k) = rest(v, k) + (at_rest ? 0.0f : scale * r.get<int16_t>());
  }
  r.align4();
  r.expect_end();
  return out;
}

}  // namespace specdeform::server
