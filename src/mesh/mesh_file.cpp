#include "specdeform/mesh/mesh_file.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>

#include "file_layout.h"
#include "file_normals.h"
#include "formats/gltf/data_uri.h"
#include "mesh_writers.h"
#include "specdeform/atomic_file.h"
#include "specdeform/exceptions.h"
#include "specdeform/mesh/io.h"

namespace specdeform {

namespace {

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext;
}

bool leaves_folder(const std::filesystem::path& name) {
  return name.empty() || name.is_absolute() || name.has_root_name() ||
         std::find(name.begin(), name.end(), "..") != name.end();
}

std::optional<std::string> read_file(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return std::nullopt;
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  return std::string(std::istreambuf_iterator<char>(in), {});
}

std::string mime_type(const std::string& name) {
  const std::string ext = lower_extension(name);
  if (ext == ".png") return "image/png";
  if (ext == ".jpg" || ext == ".jpeg") return "image/jpeg";
  if (ext == ".webp") return "image/webp";
  return "application/octet-stream";
}

}  // namespace

MeshFormat mesh_format_from_path(const std::filesystem::path& path) {
  const std::string ext = lower_extension(path);
  if (ext == ".obj") return MeshFormat::Obj;
  if (ext == ".off") return MeshFormat::Off;
  if (ext == ".ply") return MeshFormat::Ply;
  if (ext == ".stl") return MeshFormat::Stl;
  if (ext == ".gltf") return MeshFormat::Gltf;
  if (ext == ".glb") return MeshFormat::Glb;
  throw InputError(path.string() + ": unknown mesh format '" + ext +
                   "' (expected .obj, .off, .ply, .stl, .gltf or .glb)");
}

std::string format_name(MeshFormat format) {
  switch (format) {
    case MeshFormat::Obj:
      return "OBJ";
    case MeshFormat::Off:
      return "OFF";
    case MeshFormat::Ply:
      return "PLY";
    case MeshFormat::Stl:
      return "STL";
    case MeshFormat::Gltf:
      return "glTF (.gltf)";
    case MeshFormat::Glb:
      return "glTF binary (.glb)";
  }
  return "?";
}

std::string_view name(NormalUpdate mode) {
  switch (mode) {
    case NormalUpdate::Follow:
      return "follow";
    case NormalUpdate::Recompute:
      return "recompute";
    case NormalUpdate::Rotate:
      return "rotate";
  }
  return "?";
}

NormalUpdate normal_update_from_name(std::string_view text) {
  for (const NormalUpdate m : {NormalUpdate::Follow, NormalUpdate::Recompute, NormalUpdate::Rotate})
    if (name(m) == text) return m;
  throw InputError("normals: '" + std::string(text) + "' is not follow, recompute or rotate");
}

std::string_view name(MorphTargets mode) {
  return mode == MorphTargets::Turn ? "turn" : "keep";
}

std::string_view name(Joints mode) {
  return mode == Joints::Follow ? "follow" : "keep";
}

MorphTargets morph_targets_from_name(std::string_view text) {
  for (const MorphTargets m : {MorphTargets::Turn, MorphTargets::Keep})
    if (name(m) == text) return m;
  throw InputError("morph targets: '" + std::string(text) + "' is not turn or keep");
}

Joints joints_from_name(std::string_view text) {
  for (const Joints m : {Joints::Follow, Joints::Keep})
    if (name(m) == text) return m;
  throw InputError("joints: '" + std::string(text) + "' is not follow or keep");
}

FileResolver folder_resolver(const std::filesystem::path& folder, Confinement confinement) {
  return [folder, confinement](const std::string& name) -> std::optional<std::string> {
    const std::filesystem::path relative(name);
    if (confinement == Confinement::Confined && leaves_folder(relative)) {
      throw InputError(name + ": refused (a name outside the mesh file's folder)");
    }
    return read_file(relative.is_absolute() ? relative : folder / relative);
  };
}

FileSummary MeshFile::summary() const {
  FileSummary s;
  const FileAttributes& a = attributes;
  s.format = format_name(format);
  for (int p = 0; p < a.num_polygons(); ++p) ++s.polygon_sizes[a.offsets[p + 1] - a.offsets[p]];
  const auto distinct = [](const std::vector<int>& rows) {
    std::vector<int> used(rows);
    std::sort(used.begin(), used.end());
    used.erase(std::unique(used.begin(), used.end()), used.end());
    return static_cast<int>(used.size()) - (!used.empty() && used.front() < 0 ? 1 : 0);
  };
  s.texture_coordinates = distinct(a.corner_uv);
  s.uv_sets = a.uv.rows() > 0 ? 1 : 0;
  s.normals = distinct(a.corner_normal);
  s.vertex_colours = a.colours.rows() > 0;
  for (const Material& m : a.materials) s.materials.push_back(m.name);
  s.round_trip = "everything; positions and normals rewritten";
  std::visit(
      [&](const auto& l) {
        using L = std::decay_t<decltype(l)>;
        if constexpr (std::is_same_v<L, detail::ObjLayout>) {
          s.groups = l.groups;
        } else if constexpr (std::is_same_v<L, detail::PlyLayout>) {
          s.format += l.encoding == detail::PlyEncoding::Ascii    ? " (ascii)"
                      : l.encoding == detail::PlyEncoding::Little ? " (binary little endian)"
                                                                  : " (binary big endian)";
          for (const detail::PlyElement& e : l.elements) {
            for (const detail::PlyProperty& p : e.properties) {
              if (e.name == "vertex" && (p.name == "x" || p.name == "y" || p.name == "z")) continue;
              s.properties.push_back(e.name + "." + p.name + " (" +
                                     (p.is_list ? std::string("list of ") : std::string()) +
                                     detail::ply_scalar_name(p.type) + ")");
            }
          }
        } else if constexpr (std::is_same_v<L, detail::StlLayout>) {
          s.format += l.ascii ? " (ascii)" : " (binary)";
          s.round_trip = "everything; positions and facet normals rewritten";
        } else if constexpr (std::is_same_v<L, detail::GltfLayout>) {
          detail::summarize_gltf(l, s);
        }
      },
      layout->format);
  return s;
}

std::optional<std::pair<std::string, std::string>> MeshFile::texture(int material) const {
  if (material < 0 || material >= int(attributes.materials.size())) return std::nullopt;
  const Material& m = attributes.materials[material];
  if (const auto* gltf = std::get_if<detail::GltfLayout>(&layout->format);
      gltf && m.gltf_image >= 0) {
    if (std::optional<std::pair<std::string, std::string>> image =
            detail::gltf_image(gltf->doc, m.gltf_image)) {
      return image;
    }
  }
  if (m.texture.empty() || detail::is_data_uri(m.texture) || !companions) return std::nullopt;
  try {
    if (std::optional<std::string> bytes = companions(m.texture)) {
      return std::pair{std::move(*bytes), mime_type(m.texture)};
    }
  } catch (const InputError&) {
  }
  return std::nullopt;
}

std::vector<int> triangle_corners(const MeshFile& file, const MeshReadInfo& info, const Faces& F) {
  const FileAttributes& a = file.attributes;
  std::vector<int> out(3 * size_t(F.rows()), -1);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const int p = info.face_to_file[f];
    for (int k = 0; k < 3; ++k) {
      for (int c = a.offsets[p]; c < a.offsets[p + 1]; ++c) {
        if (info.file_to_vertex[a.corners[c]] == F(f, k)) {
          out[3 * f + k] = c;
          break;
        }
      }
    }
  }
  return out;
}

std::vector<std::string> contents_beyond_triangles(const MeshFile& file) {
  return detail::beyond_triangles(file);
}

std::vector<std::string> companion_names(const MeshFile& file) {
  std::vector<std::string> names;
  std::set<std::string> seen;
  const auto add = [&](const std::string& name) {
    if (!name.empty() && !detail::is_data_uri(name) && seen.insert(name).second) {
      names.push_back(name);
    }
  };
  std::visit(
      [&](const auto& l) {
        using L = std::decay_t<decltype(l)>;
        if constexpr (std::is_same_v<L, detail::ObjLayout>) {
          for (const std::string& library : l.mtllib) add(library);
          for (const std::string& texture : l.textures) add(texture);
        } else if constexpr (std::is_same_v<L, detail::PlyLayout>) {
          for (const std::string& texture : l.textures) add(texture);
        } else if constexpr (std::is_same_v<L, detail::GltfLayout>) {
          for (const std::string& name : detail::gltf_companions(l.doc)) add(name);
        }
      },
      file.layout->format);
  return names;
}

namespace {

// `positions` with those within kRounding of the bounding box's diagonal from their rest put
// back at rest: a solve's rounding (a zero deformation's result differs from the input in the
// last bits) is not a move, so the file's own values, normals included, are written.
Vertices unmoved_at_rest(const Vertices& rest, const Vertices& positions) {
  constexpr double kRounding = 1e-10;
  if (rest.rows() == 0) return positions;
  const double tolerance =
      kRounding * (rest.colwise().maxCoeff() - rest.colwise().minCoeff()).norm();
  Vertices out = positions;
  for (Eigen::Index v = 0; v < out.rows(); ++v) {
    if ((out.row(v) - rest.row(v)).cwiseAbs().maxCoeff() <= tolerance) out.row(v) = rest.row(v);
  }
  return out;
}

}  // namespace

EncodedMesh encode_mesh_file(const MeshFile& file, const Vertices& moved,
                             const std::filesystem::path& out_name, const WriteOptions& options) {
  if (moved.rows() != file.rest.rows()) {
    throw InputError(out_name.string() + ": " + std::to_string(moved.rows()) +
                     " positions for a file of " + std::to_string(file.rest.rows()) + " vertices");
  }
  if (!moved.allFinite()) {
    throw InputError(out_name.string() + ": a position is NaN or infinite");
  }
  const Vertices positions = unmoved_at_rest(file.rest, moved);
  const MeshFormat format = mesh_format_from_path(out_name);
  const FileAttributes& a = file.attributes;
  const Eigen::MatrixX3d normals =
      a.normals.rows() > 0 ? detail::updated_normals(a, file.rest, positions, options.normals)
                           : Eigen::MatrixX3d();
  const auto is_gltf = [](MeshFormat f) { return f == MeshFormat::Gltf || f == MeshFormat::Glb; };
  if (format != file.format && !(is_gltf(format) && is_gltf(file.format))) {
    return detail::encode_converted(file, positions, normals, out_name);
  }
  EncodedMesh out;
  if (normals.rows() > 0) {
    const detail::SharedNormals shared = detail::shared_normals(a, file.rest, positions, normals);
    if (shared.turned_apart > 0) {
      out.notes.push_back(
          std::to_string(shared.turned_apart) +
          " normals are each shared by corners at several positions (the exporter merged equal "
          "normals) that the deformation turns apart, by up to " +
          std::to_string(static_cast<int>(std::lround(shared.largest_degrees))) +
          " degrees: each is written as their mean, so shading there is approximate (the file's "
          "normal indexing is kept; glTF, or an OBJ exported without merged normals, avoids it)");
    }
  }
  switch (format) {
    case MeshFormat::Obj:
      out.files.push_back(
          {out_name.filename().string(), detail::rewrite_obj(file, positions, normals)});
      break;
    case MeshFormat::Off:
      out.files.push_back(
          {out_name.filename().string(), detail::rewrite_off(file, positions, normals)});
      break;
    case MeshFormat::Ply:
      out.files.push_back(
          {out_name.filename().string(), detail::rewrite_ply(file, positions, normals)});
      break;
    case MeshFormat::Stl:
      out.files.push_back(
          {out_name.filename().string(), detail::rewrite_stl(file, positions, normals)});
      break;
    case MeshFormat::Gltf:
    case MeshFormat::Glb: {
      // A changed buffer never takes the name of a file of the input's in its folder.
      std::set<std::string> taken;
      std::error_code ec;
      const std::filesystem::path input(file.name);
      if (std::filesystem::equivalent(input.parent_path().empty() ? "." : input.parent_path(),
                                      out_name.parent_path().empty() ? "." : out_name.parent_path(),
                                      ec) ||
          ec) {
        taken.insert(input.filename().string());
        for (const std::string& name : companion_names(file)) taken.insert(name);
      }
      EncodedMesh gltf = detail::rewrite_gltf(file, positions, normals, out_name, taken, options);
      gltf.notes.insert(gltf.notes.begin(), out.notes.begin(), out.notes.end());
      return gltf;
    }
  }
  out.companions = companion_names(file);
  return out;
}

std::vector<std::string> write_mesh_file(const std::filesystem::path& path, const MeshFile& file,
                                         const Vertices& positions, const WriteOptions& options) {
  EncodedMesh encoded = encode_mesh_file(file, positions, path, options);
  const std::filesystem::path folder = path.parent_path();
  for (size_t f = 1; f < encoded.files.size(); ++f) {
    write_file_atomically(folder / encoded.files[f].name, encoded.files[f].bytes);
  }
  write_file_atomically(path, encoded.files.front().bytes);
  // The unchanged companions, beside an output in another folder.
  std::error_code ec;
  const std::filesystem::path input_folder = std::filesystem::path(file.name).parent_path();
  if (std::filesystem::equivalent(input_folder.empty() ? "." : input_folder,
                                  folder.empty() ? "." : folder, ec) ||
      !file.companions) {
    return std::move(encoded.notes);
  }
  for (const std::string& name : encoded.companions) {
    if (leaves_folder(name)) {
      encoded.notes.push_back(name + ", which the output names, is outside its folder: not copied");
      continue;
    }
    const std::filesystem::path target = folder / name;
    if (std::filesystem::exists(target, ec)) {
      const std::optional<std::string> there = read_file(target);
      std::optional<std::string> ours;
      try {
        ours = file.companions(name);
      } catch (const InputError&) {
      }
      if (ours && there != ours) {
        encoded.notes.push_back(target.string() + " exists and differs from the input's " + name +
                                ": left as it is");
      }
      continue;
    }
    std::optional<std::string> bytes;
    try {
      bytes = file.companions(name);
    } catch (const InputError&) {
    }
    if (!bytes) {
      encoded.notes.push_back(name + ", which the input names, was not found: not copied");
      continue;
    }
    std::filesystem::create_directories(target.parent_path(), ec);
    write_file_atomically(target, *bytes);
    encoded.notes.push_back("copied " + name + " beside the output");
  }
  return std::move(encoded.notes);
}

}  // namespace specdeform
