#include "specdeform/mesh/mesh_file.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>

#include <nlohmann/json.hpp>

#include "file_layout.h"
#include "file_normals.h"
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
          s.meshes = l.meshes;
          s.primitives = static_cast<int>(l.primitives.size());
          s.skins = l.skins;
          s.animations = l.animations;
          s.morph_targets = l.morph_targets;
          s.images = l.images;
          s.uv_sets = l.uv_sets;
          s.round_trip =
              "everything; POSITION (with its min and max), NORMAL and TANGENT rewritten";
        }
      },
      layout->format);
  return s;
}

std::optional<std::pair<std::string, std::string>> MeshFile::texture(int material) const {
  if (material < 0 || material >= int(attributes.materials.size())) return std::nullopt;
  const Material& m = attributes.materials[material];
  const auto* gltf = std::get_if<detail::GltfLayout>(&layout->format);
  if (gltf && m.gltf_image >= 0) {
    try {
      const nlohmann::json json = nlohmann::json::parse(gltf->json);
      const nlohmann::json& image = json.at("images").at(m.gltf_image);
      if (image.contains("bufferView")) {
        const nlohmann::json& view = json.at("bufferViews").at(image.at("bufferView").get<int>());
        const size_t buffer = view.value("buffer", 0), offset = view.value("byteOffset", 0),
                     length = view.value("byteLength", 0);
        if (buffer >= gltf->buffers.size()) return std::nullopt;
        const std::string& bytes = gltf->buffers[buffer].bytes;
        if (offset > bytes.size() || length > bytes.size() - offset) return std::nullopt;
        return std::pair{bytes.substr(offset, length), image.value("mimeType", "")};
      }
    } catch (const nlohmann::json::exception&) {
      return std::nullopt;
    }
    if (tinygltf::IsDataURI(m.texture)) {
      std::vector<unsigned char> data;
      std::string type;
      if (!tinygltf::DecodeDataURI(&data, type, m.texture, 0, false)) return std::nullopt;
      return std::pair{std::string(data.begin(), data.end()), type};
    }
  }
  if (m.texture.empty() || !companions) return std::nullopt;
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
    if (!name.empty() && !tinygltf::IsDataURI(name) && seen.insert(name).second) {
      names.push_back(name);
    }
  };
  if (const auto* obj = std::get_if<detail::ObjLayout>(&file.layout->format)) {
    for (const std::string& library : obj->mtllib) add(library);
  }
  if (const auto* gltf = std::get_if<detail::GltfLayout>(&file.layout->format)) {
    for (const detail::GltfBuffer& b : gltf->buffers)
      if (b.source == detail::GltfBufferSource::External) add(b.uri);
  }
  for (const Material& m : file.attributes.materials) add(m.texture);
  return names;
}

EncodedMesh encode_mesh_file(const MeshFile& file, const Vertices& positions,
                             const std::filesystem::path& out_name, const WriteOptions& options) {
  if (positions.rows() != file.rest.rows()) {
    throw InputError(out_name.string() + ": " + std::to_string(positions.rows()) +
                     " positions for a file of " + std::to_string(file.rest.rows()) + " vertices");
  }
  if (!positions.allFinite()) {
    throw InputError(out_name.string() + ": a position is NaN or infinite");
  }
  const MeshFormat format = mesh_format_from_path(out_name);
  const FileAttributes& a = file.attributes;
  const Eigen::MatrixX3d normals =
      a.normals.rows() > 0 ? detail::updated_normals(a, file.rest, positions, options.normals)
                           : Eigen::MatrixX3d();
  if (format != file.format) return detail::encode_converted(file, positions, normals, out_name);
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
      std::error_code ec;
      const std::filesystem::path input(file.name);
      const bool same_folder = std::filesystem::equivalent(
          input.parent_path().empty() ? "." : input.parent_path(),
          out_name.parent_path().empty() ? "." : out_name.parent_path(), ec);
      EncodedMesh gltf =
          detail::rewrite_gltf(file, positions, normals, out_name, same_folder || ec);
      gltf.notes.insert(gltf.notes.begin(), out.notes.begin(), out.notes.end());
      return gltf;
    }
  }
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
  std::set<std::string> written;
  for (const OutputFile& f : encoded.files) written.insert(f.name);
  for (const std::string& name : companion_names(file)) {
    if (written.count(name) || leaves_folder(name)) continue;
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
