#include "protocol.h"

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
  std::string take() { return std::move(out_); }
  void reserve(size_t n) { out_.reserve(n); }

 private:
  std::string out_;
};

}  // namespace

Tag message_tag(std::string_view message) {
  return static_cast<Tag>(Reader(message, "binary").get<uint32_t>());
}

Selection decode_selection(std::string_view message, int num_vertices) {
  Reader r(message, "selection");
  r.get<uint32_t>();
  const uint32_t groups = r.get<uint32_t>(), fixed = r.get<uint32_t>();
  if (groups > kMaxGroups) r.fail(std::to_string(groups) + " handle groups (at most 64)");
  std::vector<uint32_t> sizes(groups);
  uint64_t total = fixed;
  for (uint32_t& s : sizes) total += s = r.get<uint32_t>();
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
  Selection s;
  s.fixed = read_list(fixed);
  for (uint32_t size : sizes) s.handles.push_back(read_list(size));
  return s;
}

FrameRequest decode_frame(std::string_view message, int num_groups) {
  Reader r(message, "frame");
  r.get<uint32_t>();
  FrameRequest f;
  f.seq = r.get<uint32_t>();
  const uint32_t groups = r.get<uint32_t>();
  r.get<uint32_t>();
  if (groups != static_cast<uint32_t>(num_groups)) {
    r.fail(std::to_string(groups) + " transforms for " + std::to_string(num_groups) +
           " handle groups");
  }
  if (r.remaining() != groups * 16 * sizeof(double)) r.fail("wrong length");
  for (uint32_t g = 0; g < groups; ++g) {
    Eigen::Matrix4d m;
    for (int i = 0; i < 16; ++i) m(i / 4, i % 4) = r.get<double>();
    f.transforms.push_back(checked_transform(m, "frame message: transform " + std::to_string(g)));
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

std::string encode_selection(const Selection& selection, Tag tag) {
  Writer w;
  w.put(static_cast<uint32_t>(tag));
  w.put(static_cast<uint32_t>(selection.handles.size()));
  w.put(static_cast<uint32_t>(selection.fixed.size()));
  for (const auto& g : selection.handles) w.put(static_cast<uint32_t>(g.size()));
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
  w.put(uint32_t{0});
  for (const Eigen::Affine3d& t : frame.transforms) {
    for (int i = 0; i < 16; ++i) w.put(t.matrix()(i / 4, i % 4));
  }
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

std::string encode_mesh_message(const TriangleMesh& mesh) {
  Writer w;
  w.reserve(12 + 12 * (mesh.V.rows() + mesh.F.rows()));
  w.put(static_cast<uint32_t>(Tag::Mesh));
  w.put(static_cast<uint32_t>(mesh.V.rows()));
  w.put(static_cast<uint32_t>(mesh.F.rows()));
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i) {
    for (int k = 0; k < 3; ++k) w.put(static_cast<float>(mesh.V(i, k)));
  }
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) w.put(static_cast<uint32_t>(mesh.F(f, k)));
  }
  return w.take();
}

std::string encode_frame_result(uint32_t seq, bool base_view, const FrameStats& stats,
                                const Vertices& positions) {
  Writer w;
  w.reserve(40 + 12 * positions.rows());
  w.put(static_cast<uint32_t>(Tag::FrameResult));
  w.put(seq);
  w.put(static_cast<uint32_t>(positions.rows()));
  w.put(static_cast<uint32_t>(base_view ? 1 : 0));
  for (double ms : {stats.reduced_solve, stats.inverse_transform, stats.detail, stats.total}) {
    w.put(static_cast<float>(ms * 1e3));
  }
  w.put(static_cast<float>(stats.error_max));
  w.put(static_cast<float>(stats.error_rms));
  for (Eigen::Index i = 0; i < positions.rows(); ++i) {
    for (int k = 0; k < 3; ++k) w.put(static_cast<float>(positions(i, k)));
  }
  return w.take();
}

}  // namespace specdeform::server
