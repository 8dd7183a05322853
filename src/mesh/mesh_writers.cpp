#include "mesh_writers.h"

#include "formats/converted.h"
#include "formats/gltf/gltf.h"
#include "formats/obj/obj.h"
#include "formats/off/off.h"
#include "formats/ply/ply.h"
#include "formats/stl/stl.h"
#include "specdeform/exceptions.h"

namespace specdeform::detail {

namespace {

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
  out.companions = std::move(e.kept);
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
