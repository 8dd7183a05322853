#include "specdeform/mesh/io.h"

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <numeric>
#include <span>
#include <unordered_set>

#include "linalg/parallel.h"
#include "polygon_soup.h"
#include "specdeform/atomic_file.h"
#include "specdeform/exceptions.h"
#include "text_scanner.h"

namespace specdeform {

MeshFormat mesh_format_from_path(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  if (ext == ".obj") return MeshFormat::Obj;
  if (ext == ".off") return MeshFormat::Off;
  if (ext == ".ply") return MeshFormat::Ply;
  if (ext == ".stl") return MeshFormat::Stl;
  throw InputError(path.string() + ": unknown mesh format '" + ext +
                   "' (expected .obj, .off, .ply or .stl)");
}

namespace {

// The corner from which to fan-triangulate each polygon: the first whose diagonals are not edges
// of the mesh already (sides of polygons, or diagonals chosen before). Two polygons that share two
// consecutive sides would otherwise both take the diagonal between the far ends of those sides:
// one triangle twice, back to back, and two non-manifold edges.
std::vector<int> fan_apexes(const detail::PolygonSoup& soup) {
  const int np = soup.num_polygons();
  std::vector<int> apex(np, 0);
  const auto corners = [&](int p) { return soup.offsets[p + 1] - soup.offsets[p]; };
  bool polygons = false;
  for (int p = 0; p < np && !polygons; ++p) polygons = corners(p) > 3;
  if (!polygons) return apex;
  const auto key = [](int a, int b) {
    return uint64_t(uint32_t(std::min(a, b))) << 32 | uint32_t(std::max(a, b));
  };
  std::unordered_set<uint64_t> edges;
  for (int p = 0; p < np; ++p) {
    const int* v = soup.indices.data() + soup.offsets[p];
    for (int c = 0, k = corners(p); c < k; ++c) edges.insert(key(v[c], v[(c + 1) % k]));
  }
  for (int p = 0; p < np; ++p) {
    const int* v = soup.indices.data() + soup.offsets[p];
    const int k = corners(p);
    if (k < 4) continue;
    const auto free = [&](int s) {
      for (int j = 2; j <= k - 2; ++j)
        if (edges.count(key(v[s], v[(s + j) % k]))) return false;
      return true;
    };
    for (int s = 0; s < k; ++s) {
      if (free(s)) {
        apex[p] = s;
        break;
      }
    }
    for (int j = 2; j <= k - 2; ++j) edges.insert(key(v[apex[p]], v[(apex[p] + j) % k]));
  }
  return apex;
}

}  // namespace

namespace detail {

LoadedMesh build_mesh(PolygonSoup soup, const std::string& name) {
  const int nv = soup.num_vertices();
  if (nv == 0) throw InputError(name + ": no vertices");
  for (int i = 0; i < nv; ++i) {
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(soup.xyz[3 * i + k])) {
        throw InputError(name + ": vertex " + std::to_string(i) +
                         " has a NaN or infinite coordinate");
      }
    }
  }
  LoadedMesh out;
  MeshReadInfo& info = out.info;
  info.file_faces = soup.num_polygons();
  info.welded_corners = soup.welded_corners;
  info.file_vertices = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(
      soup.xyz.data(), nv, 3);

  std::vector<int> tris;
  const std::vector<int> apex = fan_apexes(soup);
  for (int p = 0; p < soup.num_polygons(); ++p) {
    const int* v = soup.indices.data() + soup.offsets[p];
    const int k = soup.offsets[p + 1] - soup.offsets[p];
    for (int c = 1; c + 1 < k; ++c) {  // fan triangulation
      const int a = v[apex[p]], b = v[(apex[p] + c) % k], d = v[(apex[p] + c + 1) % k];
      if (a == b || b == d || a == d) {
        ++info.collapsed_faces;
        continue;
      }
      tris.insert(tris.end(), {a, b, d});
      info.face_to_file.push_back(p);
    }
  }
  // Triangles on the same three vertices as an earlier one: bucketed by their smallest corner
  // (by counting, in file order), each bucket sorted by the other two, each run of equal ones
  // keeping its first. Sorting every face's key took 0.35 s for 1.4M faces; the buckets hold a
  // vertex's few faces.
  {
    const int count = static_cast<int>(tris.size() / 3);
    std::vector<int> start(nv + 1, 0);
    std::vector<uint64_t> rest(count);  // the two larger corners, packed
    for (int f = 0; f < count; ++f) {
      std::array<int, 3> corner{tris[3 * f], tris[3 * f + 1], tris[3 * f + 2]};
      std::sort(corner.begin(), corner.end());
      ++start[corner[0] + 1];
      rest[f] = uint64_t(uint32_t(corner[1])) << 32 | uint32_t(corner[2]);
    }
    std::partial_sum(start.begin(), start.end(), start.begin());
    std::vector<std::pair<uint64_t, int>> bucketed(count);  // (rest, face)
    for (int f = 0; f < count; ++f) {
      const int smallest = std::min({tris[3 * f], tris[3 * f + 1], tris[3 * f + 2]});
      bucketed[start[smallest]++] = {rest[f], f};
    }
    std::vector<char> keep(count, 1);
    for (int b = 0, first = 0; b < nv; first = start[b++]) {
      const auto bucket = std::span(bucketed).subspan(first, start[b] - first);
      std::sort(bucket.begin(), bucket.end());
      for (size_t i = 1; i < bucket.size(); ++i)
        if (bucket[i].first == bucket[i - 1].first) keep[bucket[i].second] = 0;
    }
    int kept = 0;
    for (int f = 0; f < count; ++f) {
      if (!keep[f]) continue;
      for (int c = 0; c < 3; ++c) tris[3 * kept + c] = tris[3 * f + c];
      info.face_to_file[kept++] = info.face_to_file[f];
    }
    info.duplicate_faces = count - kept;
    tris.resize(3 * kept);
    info.face_to_file.resize(kept);
  }
  if (tris.empty()) {
    throw InputError(name + (info.collapsed_faces > 0
                                 ? ": every face repeats a vertex"
                                 : ": no faces (a point cloud is not a surface)"));
  }
  std::vector<int> new_index(nv, -1);
  for (const int v : tris) new_index[v] = 0;
  for (int i = 0; i < nv; ++i) {
    if (new_index[i] == 0) {
      new_index[i] = static_cast<int>(info.vertex_to_file.size());
      info.vertex_to_file.push_back(i);
    }
  }
  info.unused_vertices = nv - static_cast<int>(info.vertex_to_file.size());
  const int n = static_cast<int>(info.vertex_to_file.size());
  out.mesh.V.resize(n, 3);
  for (int i = 0; i < n; ++i) out.mesh.V.row(i) = info.file_vertices.row(info.vertex_to_file[i]);
  const int nf = static_cast<int>(tris.size() / 3);
  out.mesh.F.resize(nf, 3);
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) out.mesh.F(f, k) = new_index[tris[3 * f + k]];
  return out;
}

}  // namespace detail

LoadedMesh read_mesh_from_memory(std::string_view data, MeshFormat format, std::string_view name) {
  const std::string n(name);
  detail::reject_git_lfs_pointer(data, n, "mesh");
  switch (format) {
    case MeshFormat::Obj:
      return detail::build_mesh(detail::parse_obj(data, n), n);
    case MeshFormat::Off:
      return detail::build_mesh(detail::parse_off(data, n), n);
    case MeshFormat::Ply:
      return detail::build_mesh(detail::parse_ply(data, n), n);
    case MeshFormat::Stl:
      return detail::build_mesh(detail::parse_stl(data, n), n);
  }
  throw InputError(n + ": unknown format");
}

LoadedMesh read_mesh(const std::filesystem::path& path) {
  const MeshFormat format = mesh_format_from_path(path);
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InputError(path.string() + ": is a directory");
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError(path.string() + ": cannot open file");
  std::string bytes;  // reserved when the size is known (not for a pipe): no regrowth
  if (const auto size = std::filesystem::file_size(path, ec); !ec) bytes.reserve(size);
  std::vector<char> chunk(1 << 20);
  while (file.read(chunk.data(), static_cast<std::streamsize>(chunk.size())) || file.gcount() > 0)
    bytes.append(chunk.data(), static_cast<size_t>(file.gcount()));
  if (file.bad()) throw InputError(path.string() + ": read error");
  return read_mesh_from_memory(bytes, format, path.string());
}

MeshReadInfo identity_read_info(const TriangleMesh& mesh) {
  MeshReadInfo info;
  info.file_vertices = mesh.V;
  info.file_faces = mesh.num_faces();
  info.vertex_to_file.resize(mesh.num_vertices());
  std::iota(info.vertex_to_file.begin(), info.vertex_to_file.end(), 0);
  info.face_to_file.resize(mesh.num_faces());
  std::iota(info.face_to_file.begin(), info.face_to_file.end(), 0);
  return info;
}

TriangleMesh to_file_order(const MeshReadInfo& info, const Vertices& V, const Faces& F) {
  TriangleMesh out{info.file_vertices, Faces(F.rows(), 3)};
  for (int i = 0; i < V.rows(); ++i) out.V.row(info.vertex_to_file[i]) = V.row(i);
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) out.F(f, k) = info.vertex_to_file[F(f, k)];
  return out;
}

namespace {

void append_number(std::string& s, double v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);  // shortest round-trip form
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

// A text format's vertex and face lines, each list encoded in two halves at once (the first
// halves on one thread, the second on the other): the parts of the file after its header, in
// order (692k vertices, OBJ: 0.41 -> 0.2-0.26 s with the write).
template <typename VertexLine, typename FaceLine>
std::vector<std::string> text_lines(const TriangleMesh& m, const VertexLine& vertex_line,
                                    const FaceLine& face_line) {
  std::vector<std::string> part(4);  // vertices, first and second half; then faces
  // Reserved for the usual line (three shortest round-trip doubles; three indices of n's
  // digits): a string that regrows holds two copies for a moment.
  const size_t vertex_bytes = 64, face_bytes = 3 * std::to_string(m.num_vertices()).size() + 6;
  const auto encode = [&](int half) {
    const auto lines = [&](int count, size_t bytes, std::string& s, const auto& line) {
      const int begin = half * (count / 2), end = half == 0 ? count / 2 : count;
      s.reserve(static_cast<size_t>(end - begin) * bytes);
      for (int i = begin; i < end; ++i) line(s, i);
    };
    lines(m.num_vertices(), vertex_bytes, part[half], vertex_line);
    lines(m.num_faces(), face_bytes, part[2 + half], face_line);
  };
  detail::run_pair([&] { encode(0); }, [&] { encode(1); });
  return part;
}

std::vector<std::string> encode_obj(const TriangleMesh& m) {
  std::vector<std::string> parts = text_lines(
      m,
      [&](std::string& s, int i) {
        s += 'v';
        for (int k = 0; k < 3; ++k) {
          s += ' ';
          append_number(s, m.V(i, k));
        }
        s += '\n';
      },
      [&](std::string& s, int f) {
        s += 'f';
        for (int k = 0; k < 3; ++k) {
          s += ' ';
          append_number(s, m.F(f, k) + 1);
        }
        s += '\n';
      });
  parts.insert(parts.begin(), "# written by specdeform\n");
  return parts;
}

std::vector<std::string> encode_off(const TriangleMesh& m) {
  std::vector<std::string> parts = text_lines(
      m,
      [&](std::string& s, int i) {
        for (int k = 0; k < 3; ++k) {
          append_number(s, m.V(i, k));
          s += k < 2 ? ' ' : '\n';
        }
      },
      [&](std::string& s, int f) {
        s += '3';
        for (int k = 0; k < 3; ++k) {
          s += ' ';
          append_number(s, m.F(f, k));
        }
        s += '\n';
      });
  std::string header = "OFF\n";
  append_number(header, m.num_vertices());
  header += ' ';
  append_number(header, m.num_faces());
  header += " 0\n";
  parts.insert(parts.begin(), std::move(header));
  return parts;
}

std::string encode_ply(const TriangleMesh& m) {
  std::string s = "ply\nformat binary_little_endian 1.0\ncomment written by specdeform\n";
  s += "element vertex " + std::to_string(m.num_vertices()) + "\n";
  s += "property double x\nproperty double y\nproperty double z\n";
  s += "element face " + std::to_string(m.num_faces()) + "\n";
  s += "property list uchar int vertex_indices\nend_header\n";
  for (int i = 0; i < m.num_vertices(); ++i)
    for (int k = 0; k < 3; ++k) append_le(s, m.V(i, k));
  for (int f = 0; f < m.num_faces(); ++f) {
    append_le(s, uint8_t{3});
    for (int k = 0; k < 3; ++k) append_le(s, int32_t{m.F(f, k)});
  }
  return s;
}

std::string encode_stl(const TriangleMesh& m) {
  std::string s(80, ' ');
  s.replace(0, 22, "binary STL, specdeform");
  append_le(s, static_cast<uint32_t>(m.num_faces()));
  const auto N = face_normals(m);
  for (int f = 0; f < m.num_faces(); ++f) {
    for (int k = 0; k < 3; ++k) append_le(s, static_cast<float>(N(f, k)));
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k) append_le(s, static_cast<float>(m.V(m.F(f, c), k)));
    append_le(s, uint16_t{0});
  }
  return s;
}

// The file's bytes, in parts to be concatenated.
std::vector<std::string> encode_parts(const TriangleMesh& mesh, MeshFormat format) {
  switch (format) {
    case MeshFormat::Obj:
      return encode_obj(mesh);
    case MeshFormat::Off:
      return encode_off(mesh);
    case MeshFormat::Ply:
      return {encode_ply(mesh)};
    case MeshFormat::Stl:
      return {encode_stl(mesh)};
  }
  return {};
}

}  // namespace

std::string encode_mesh(const TriangleMesh& mesh, MeshFormat format) {
  std::string out;
  for (const std::string& part : encode_parts(mesh, format)) out += part;
  return out;
}

void write_mesh(const std::filesystem::path& path, const TriangleMesh& mesh) {
  const std::vector<std::string> parts = encode_parts(mesh, mesh_format_from_path(path));
  const std::vector<std::string_view> views(parts.begin(), parts.end());
  write_file_atomically(path, views);
}

}  // namespace specdeform
