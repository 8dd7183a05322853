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

#include "file_layout.h"
#include "linalg/huge_pages.h"
#include "linalg/parallel.h"
#include "mesh_writers.h"
#include "polygon_soup.h"
#include "specdeform/atomic_file.h"
#include "specdeform/exceptions.h"
#include "text_scanner.h"

namespace specdeform {

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

PositionIndex::PositionIndex(const std::vector<double>& xyz, size_t expected) : xyz_(xyz) {
  slots_.assign(std::bit_ceil(std::max<size_t>(16, 2 * expected)), -1);
}

size_t PositionIndex::slot_of(int v) const {
  uint64_t h = 0;
  for (int k = 0; k < 3; ++k) {
    const double c = xyz_[3 * size_t(v) + k] + 0.0;  // -0.0 as +0.0
    h = (h ^ std::bit_cast<uint64_t>(c)) * 0x9e3779b97f4a7c15ULL;
    h ^= h >> 29;
  }
  return h & (slots_.size() - 1);
}

int PositionIndex::first_at(int v) {
  const double* p = xyz_.data() + 3 * size_t(v);
  for (size_t s = slot_of(v);; s = (s + 1) & (slots_.size() - 1)) {
    const int u = slots_[s];
    if (u < 0) {
      slots_[s] = v;
      if (2 * ++count_ > slots_.size()) grow();
      return v;
    }
    const double* q = xyz_.data() + 3 * size_t(u);
    if (p[0] == q[0] && p[1] == q[1] && p[2] == q[2]) return u;
  }
}

void PositionIndex::grow() {
  std::vector<int> old(2 * slots_.size(), -1);
  old.swap(slots_);
  for (const int v : old) {
    if (v < 0) continue;
    size_t s = slot_of(v);
    while (slots_[s] >= 0) s = (s + 1) & (slots_.size() - 1);
    slots_[s] = v;
  }
}

std::vector<int> weld_coincident(const std::vector<double>& xyz) {
  const int n = static_cast<int>(xyz.size() / 3);
  PositionIndex index(xyz, n);
  std::vector<int> weld(n);
  for (int v = 0; v < n; ++v) weld[v] = index.first_at(v);
  return weld;
}

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
  check_coordinate_range(
      Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(soup.xyz.data(),
                                                                                  nv, 3),
      name);
  LoadedMesh out;
  MeshReadInfo& info = out.info;
  info.file_faces = soup.num_polygons();
  info.welded_corners = soup.welded_corners;
  info.file_vertices = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(
      soup.xyz.data(), nv, 3);

  if (!soup.weld.empty()) {
    for (int& v : soup.indices) v = soup.weld[v];
  }
  std::vector<int> tris;  // 3 per triangle: k - 2 of a polygon of k corners
  const auto fans = std::ssize(soup.indices) - 2 * std::ptrdiff_t{soup.num_polygons()};
  tris.reserve(3 * std::max<std::ptrdiff_t>(fans, 0));
  detail::advise_huge_pages(tris.data(), sizeof(int) * tris.capacity());
  info.face_to_file.reserve(tris.capacity() / 3);
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
  info.file_to_vertex.resize(nv);
  for (int i = 0; i < nv; ++i) {
    const int r = soup.weld.empty() ? i : soup.weld[i];
    info.file_to_vertex[i] = new_index[r];
    if (new_index[r] < 0) {
      ++info.unused_vertices;
    } else if (r != i) {
      ++info.welded_vertices;
    }
  }
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

LoadedMesh read_mesh_from_memory(std::string_view data, MeshFormat format, std::string_view name,
                                 const ReadOptions& options) {
  const std::string n(name);
  detail::reject_git_lfs_pointer(data, n, "mesh");
  const bool gltf = format == MeshFormat::Gltf || format == MeshFormat::Glb;
  const FileResolver companions =
      gltf ? detail::uri_resolver(options.companions) : options.companions;
  detail::KeptRecord record;
  detail::KeptRecord* keep = options.keep_file ? &record : nullptr;
  detail::PolygonSoup soup;
  switch (format) {
    case MeshFormat::Obj:
      soup = detail::parse_obj(data, n, keep);
      break;
    case MeshFormat::Off:
      soup = detail::parse_off(data, n, keep);
      break;
    case MeshFormat::Ply:
      soup = detail::parse_ply(data, n, keep);
      break;
    case MeshFormat::Stl:
      soup = detail::parse_stl(data, n, keep);
      break;
    case MeshFormat::Gltf:
    case MeshFormat::Glb:
      soup = detail::parse_gltf(data, format, n, companions, keep);
      break;
  }
  if (keep) {
    record.attributes.corners = soup.indices;
    record.attributes.offsets = soup.offsets;
    if (format == MeshFormat::Obj) detail::read_obj_materials(record, options.companions);
  }
  LoadedMesh out = detail::build_mesh(std::move(soup), n);
  if (keep) {
    auto file = std::make_shared<MeshFile>();
    file->format = format;
    file->name = n;
    file->rest = out.info.file_vertices;
    file->attributes = std::move(record.attributes);
    file->companions = companions;
    file->layout = std::make_shared<const detail::FileLayout>(std::move(record.layout));
    out.file = std::move(file);
  }
  return out;
}

namespace {

// The file's bytes; a binary STL's first triangles are checked before the rest is read (a
// garbage file is refused at once).
std::string file_bytes(const std::filesystem::path& path, MeshFormat format) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InputError(path.string() + ": is a directory");
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError(path.string() + ": cannot open file");
  std::string bytes;
  const auto size = std::filesystem::file_size(path, ec);  // unknown for a pipe
  std::vector<char> chunk(1 << 20);
  bool first = true;
  while (file.read(chunk.data(), static_cast<std::streamsize>(chunk.size())) || file.gcount() > 0) {
    const std::string_view piece(chunk.data(), static_cast<size_t>(file.gcount()));
    if (first && !ec) {
      if (format == MeshFormat::Stl) detail::check_stl_start(piece, size, path.string());
      bytes.reserve(size);  // the buffer then takes the whole file (no regrowth), on huge pages
      detail::advise_huge_pages(bytes.data(), size);
    }
    first = false;
    bytes.append(piece);
  }
  if (file.bad()) throw InputError(path.string() + ": read error");
  return bytes;
}

}  // namespace

LoadedMesh read_mesh(const std::filesystem::path& path, const ReadOptions& options) {
  const MeshFormat format = mesh_format_from_path(path);
  const std::string bytes = file_bytes(path, format);
  ReadOptions o = options;
  if (!o.companions) o.companions = folder_resolver(path.parent_path());
  return read_mesh_from_memory(bytes, format, path.string(), o);
}

MeshFileReport inspect_mesh_file(const std::filesystem::path& path) {
  const MeshFormat format = mesh_format_from_path(path);
  const std::string bytes = file_bytes(path, format);
  const FileResolver companions = folder_resolver(path.parent_path());
  MeshFileReport report;
  try {
    report.loaded = read_mesh_from_memory(bytes, format, path.string(),
                                          {.keep_file = true, .companions = companions});
    report.contents = report.loaded->file->summary();
    return report;
  } catch (const InputError& e) {
    if (format != MeshFormat::Gltf && format != MeshFormat::Glb) throw;
    report.refused = e.what();
  }
  report.contents =
      detail::gltf_document_summary(bytes, format, path.string(), detail::uri_resolver(companions));
  return report;
}

MeshReadInfo identity_read_info(const TriangleMesh& mesh) {
  MeshReadInfo info;
  info.file_vertices = mesh.V;
  info.file_faces = mesh.num_faces();
  info.vertex_to_file.resize(mesh.num_vertices());
  std::iota(info.vertex_to_file.begin(), info.vertex_to_file.end(), 0);
  info.face_to_file.resize(mesh.num_faces());
  std::iota(info.face_to_file.begin(), info.face_to_file.end(), 0);
  info.file_to_vertex = info.vertex_to_file;
  return info;
}

TriangleMesh to_file_order(const MeshReadInfo& info, const Vertices& V, const Faces& F) {
  TriangleMesh out{info.file_vertices, Faces(F.rows(), 3)};
  for (int v = 0; v < out.V.rows(); ++v)
    if (info.file_to_vertex[v] >= 0) out.V.row(v) = V.row(info.file_to_vertex[v]);
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) out.F(f, k) = info.vertex_to_file[F(f, k)];
  return out;
}

std::string encode_mesh(const TriangleMesh& mesh, MeshFormat format) {
  std::string out;
  for (const std::string& part : detail::encode_plain(mesh, format)) out += part;
  return out;
}

void write_mesh(const std::filesystem::path& path, const TriangleMesh& mesh) {
  const std::vector<std::string> parts = detail::encode_plain(mesh, mesh_format_from_path(path));
  const std::vector<std::string_view> views(parts.begin(), parts.end());
  write_file_atomically(path, views);
}

}  // namespace specdeform
