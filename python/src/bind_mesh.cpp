#include <unistd.h>

#include <cerrno>
#include <cstdio>

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "bindings.h"
#include "convert.h"
#include "specdeform/exceptions.h"
#include "specdeform/mesh/generate.h"
#include "specdeform/mesh/io.h"
#include "specdeform/mesh/mesh_file.h"

namespace specdeform::python {

void check_readable(const std::filesystem::path& path) {
  std::error_code ec;
  std::FILE* file = nullptr;
  if (std::filesystem::is_directory(path, ec)) {
    errno = EISDIR;
  } else {
    file = std::fopen(path.c_str(), "rb");
  }
  if (file == nullptr) {
    PyErr_SetFromErrnoWithFilename(PyExc_OSError, path.c_str());
    throw py::error_already_set();
  }
  std::fclose(file);
}

void check_writable(const std::filesystem::path& path) {
  const std::filesystem::path folder = path.has_parent_path() ? path.parent_path() : ".";
  std::error_code ec;
  if (std::filesystem::exists(folder, ec) && !std::filesystem::is_directory(folder, ec)) {
    errno = ENOTDIR;
  } else if (access(folder.c_str(), W_OK) == 0) {
    return;
  }
  PyErr_SetFromErrnoWithFilename(PyExc_OSError, path.c_str());
  throw py::error_already_set();
}

namespace {

py::tuple mesh_arrays(TriangleMesh mesh) {
  return py::make_tuple(to_array(std::move(mesh.V)), to_array(std::move(mesh.F)));
}

py::array index_view(const std::vector<int>& indices, py::handle owner) {
  return view(Eigen::Map<const Eigen::VectorXi>(indices.data(), Eigen::Index(indices.size())),
              owner);
}

// A file kept whole by read_mesh(..., keep=True), with the map from its mesh to the file.
struct KeptFile {
  std::shared_ptr<const MeshFile> file;
  MeshReadInfo info;
};

py::dict summary_dict(const FileSummary& s) {
  py::dict d;
  d["format"] = s.format;
  py::dict sizes;
  for (const auto& [corners, count] : s.polygon_sizes) sizes[py::int_(corners)] = count;
  d["polygons_by_corners"] = sizes;
  d["texture_coordinates"] = s.texture_coordinates;
  d["uv_sets"] = s.uv_sets;
  d["normals"] = s.normals;
  d["vertex_colours"] = s.vertex_colours;
  d["materials"] = s.materials;
  d["groups"] = s.groups;
  d["nodes"] = s.nodes;
  d["meshes"] = s.meshes;
  d["drawings"] = s.drawings;
  d["primitives"] = s.primitives;
  d["skins"] = s.skins;
  d["animations"] = s.animations;
  d["morph_targets"] = s.morph_targets;
  d["images"] = s.images;
  d["extensions"] = s.extensions;
  d["properties"] = s.properties;
  d["round_trip_keeps"] = s.round_trip;
  d["writing_changes"] = s.changes;
  return d;
}

}  // namespace

void bind_mesh(py::module_& m) {
  py::class_<MeshReadInfo>(m, "MeshReadInfo",
                           "What read_mesh dropped or merged, and the map back to the file.")
      .def_property_readonly(
          "file_vertices",
          [](py::object self) {
            return view(self.cast<const MeshReadInfo&>().file_vertices, self);
          },
          "Every vertex of the file (N, 3); for STL after welding.")
      .def_property_readonly(
          "vertex_to_file",
          [](py::object self) {
            return index_view(self.cast<const MeshReadInfo&>().vertex_to_file, self);
          },
          "Mesh vertex i is file vertex vertex_to_file[i].")
      .def_property_readonly(
          "face_to_file",
          [](py::object self) {
            return index_view(self.cast<const MeshReadInfo&>().face_to_file, self);
          },
          "Mesh triangle t comes from file polygon face_to_file[t].")
      .def_readonly("file_faces", &MeshReadInfo::file_faces, "Polygons in the file.")
      .def_readonly("unused_vertices", &MeshReadInfo::unused_vertices,
                    "File vertices no face uses (dropped).")
      .def_readonly("collapsed_faces", &MeshReadInfo::collapsed_faces,
                    "Triangles that repeat a vertex (dropped).")
      .def_readonly("duplicate_faces", &MeshReadInfo::duplicate_faces,
                    "Triangles on the same three vertices as an earlier one (dropped).")
      .def_property_readonly(
          "file_to_vertex",
          [](py::object self) {
            return index_view(self.cast<const MeshReadInfo&>().file_to_vertex, self);
          },
          "File vertex v became mesh vertex file_to_vertex[v] (-1: dropped).")
      .def_readonly("welded_corners", &MeshReadInfo::welded_corners,
                    "STL: triangle corners merged into an existing vertex.")
      .def_readonly("welded_vertices", &MeshReadInfo::welded_vertices,
                    "glTF: vertices split along seams merged into another.")
      .def("__repr__", [](const MeshReadInfo& i) {
        return "MeshReadInfo(file_vertices=" + std::to_string(i.file_vertices.rows()) +
               ", file_faces=" + std::to_string(i.file_faces) +
               ", unused_vertices=" + std::to_string(i.unused_vertices) +
               ", collapsed_faces=" + std::to_string(i.collapsed_faces) +
               ", duplicate_faces=" + std::to_string(i.duplicate_faces) +
               ", welded_corners=" + std::to_string(i.welded_corners) + ")";
      });

  py::class_<KeptFile>(m, "MeshFile",
                       "A mesh file kept whole (read_mesh(..., keep=True)), to be written again "
                       "with new positions.")
      .def(
          "write",
          [](const KeptFile& self, const std::filesystem::path& path, py::handle V,
             const std::string& normals, const std::string& morph_targets,
             const std::string& joints) {
            check_writable(path);
            const Vertices X = to_vertices(V);
            if (X.rows() != static_cast<Eigen::Index>(self.info.vertex_to_file.size())) {
              throw InputError("write: V has " + std::to_string(X.rows()) +
                               " rows, the mesh read from the file " +
                               std::to_string(self.info.vertex_to_file.size()) + " vertices");
            }
            const WriteOptions options{normal_update_from_name(normals),
                                       morph_targets_from_name(morph_targets),
                                       joints_from_name(joints)};
            py::gil_scoped_release release;
            const Vertices positions = to_file_order(self.info, X, Faces()).V;
            return write_mesh_file(path, *self.file, positions, options);
          },
          py::arg("path"), py::arg("V"), py::arg("normals") = "follow",
          py::arg("morph_targets") = "turn", py::arg("joints") = "follow",
          R"(Writes the file again with the mesh's vertices at V (n, 3), in the format of path's
extension, atomically: in the file's own format everything but positions and normals (glTF:
POSITION with its min and max, NORMAL, TANGENT) as it was; in another, what that format can hold.
normals: "follow" (carried by each face's deformation), "recompute" or "rotate". glTF rigs:
morph_targets "turn" (each delta turned by its vertex's local rotation) or "keep"; joints "follow"
(joints move with the vertices they drive; inverse bind matrices, rest transforms and animation
keys with them) or "keep". Returns notes on what was dropped, changed or copied beside the
output.)")
      .def_property_readonly(
          "info", [](const KeptFile& self) { return self.info; },
          "The MeshReadInfo: the map from the mesh to the file.")
      .def_property_readonly("format",
                             [](const KeptFile& self) { return format_name(self.file->format); })
      .def(
          "summary", [](const KeptFile& self) { return summary_dict(self.file->summary()); },
          "What the file holds besides positions, and what a round trip keeps.")
      .def_property_readonly(
          "uv",
          [](py::object self) {
            return view(self.cast<const KeptFile&>().file->attributes.uv, self);
          },
          "Texture coordinates (k, 2) as the file has them (empty: none).")
      .def_property_readonly(
          "corner_uv",
          [](py::object self) {
            return index_view(self.cast<const KeptFile&>().file->attributes.corner_uv, self);
          },
          "Per polygon corner, its row of uv (-1: none).")
      .def_property_readonly(
          "corners",
          [](py::object self) {
            return index_view(self.cast<const KeptFile&>().file->attributes.corners, self);
          },
          "The file's polygons' corners (file vertices), concatenated; see offsets.")
      .def_property_readonly(
          "offsets",
          [](py::object self) {
            return index_view(self.cast<const KeptFile&>().file->attributes.offsets, self);
          },
          "Polygon p has the corners corners[offsets[p]:offsets[p + 1]].")
      .def_property_readonly(
          "corner_normal",
          [](py::object self) {
            return index_view(self.cast<const KeptFile&>().file->attributes.corner_normal, self);
          },
          "Per polygon corner, its row of normals (-1: none).")
      .def_property_readonly(
          "normals",
          [](py::object self) {
            return view(self.cast<const KeptFile&>().file->attributes.normals, self);
          },
          "The file's normals (k, 3), glTF's in world space (empty: none).")
      .def_property_readonly(
          "colours",
          [](py::object self) {
            return view(self.cast<const KeptFile&>().file->attributes.colours, self);
          },
          "Vertex colours (file vertices, 4), RGBA in [0, 1] (empty: none).")
      .def("__repr__", [](const KeptFile& self) {
        return "MeshFile('" + self.file->name + "', " + format_name(self.file->format) + ")";
      });

  m.def(
      "read_mesh",
      [](const std::filesystem::path& path, bool return_info, bool keep) -> py::tuple {
        check_readable(path);
        LoadedMesh loaded;
        {
          py::gil_scoped_release release;
          loaded = read_mesh(path, {.keep_file = keep, .companions = {}});
        }
        py::tuple VF = mesh_arrays(std::move(loaded.mesh));
        if (keep) {
          return py::make_tuple(VF[0], VF[1],
                                KeptFile{std::move(loaded.file), std::move(loaded.info)});
        }
        if (!return_info) return VF;
        return py::make_tuple(VF[0], VF[1], std::move(loaded.info));
      },
      py::arg("path"), py::arg("return_info") = false, py::arg("keep") = false,
      R"(Reads an OBJ, OFF, PLY, STL or glTF (.gltf, .glb) file: (V, F), V float64 (n, 3), F int32
(f, 3).

Polygons are fan-triangulated; vertices no face uses and faces that repeat a vertex are dropped;
glTF's vertices split along seams are welded. With return_info=True, (V, F, info): info (a
MeshReadInfo) maps the mesh back to the file. With keep=True, (V, F, file): file (a MeshFile) holds
the whole file, and file.write(path, X) writes it again with the vertices at X (file.info is the
map). Raises OSError if the file cannot be opened, InputError if it is malformed.)");

  m.def(
      "write_mesh",
      [](const std::filesystem::path& path, py::handle V, py::handle F, const MeshReadInfo* info) {
        check_writable(path);
        // Any coordinates can be written (to_mesh would refuse those beyond what is computed in).
        TriangleMesh mesh;
        mesh.V = to_vertices(V);
        mesh.F = to_faces(F, mesh.V.rows());
        if (info != nullptr) {
          if (mesh.num_vertices() != static_cast<int>(info->vertex_to_file.size())) {
            throw InputError("write_mesh: V has " + std::to_string(mesh.num_vertices()) +
                             " rows, the mesh that info describes " +
                             std::to_string(info->vertex_to_file.size()) + " vertices");
          }
          mesh = to_file_order(*info, mesh.V, mesh.F);
        }
        py::gil_scoped_release release;
        write_mesh(path, mesh);
      },
      py::arg("path"), py::arg("V"), py::arg("F"), py::arg("info") = py::none(),
      R"(Writes a mesh; the format from the extension (.obj .off .ply .stl .gltf .glb), atomically.

With info (from read_mesh(..., return_info=True)), in the file's numbering: the vertices the
reader dropped are written back where they were.)");

  const BumpyBarOptions bar;
  m.def(
      "bumpy_bar",
      [](double length, double thickness, int cells_per_unit, int bumps_per_unit,
         double bump_height) {
        return mesh_arrays(
            make_bumpy_bar({length, thickness, cells_per_unit, bumps_per_unit, bump_height}));
      },
      py::arg("length") = bar.length, py::arg("thickness") = bar.thickness,
      py::arg("cells_per_unit") = bar.cells_per_unit,
      py::arg("bumps_per_unit") = bar.bumps_per_unit, py::arg("bump_height") = bar.bump_height,
      "The demo model: a closed bar along x with bumps on its four long sides. (V, F).");
  const BumpyPlaneOptions plane;
  m.def(
      "bumpy_plane",
      [](double size, int resolution, int bumps, double bump_height) {
        return mesh_arrays(make_bumpy_plane({size, resolution, bumps, bump_height}));
      },
      py::arg("size") = plane.size, py::arg("resolution") = plane.resolution,
      py::arg("bumps") = plane.bumps, py::arg("bump_height") = plane.bump_height,
      "The square [0, size]^2 at z = 0 with bumps (0: flat, free boundary). (V, F).");
  m.def(
      "icosphere",
      [](int subdivisions, double radius) {
        return mesh_arrays(make_icosphere(subdivisions, radius));
      },
      py::arg("subdivisions") = 3, py::arg("radius") = 1.0,
      "Icosahedron refined `subdivisions` times, on the sphere: 10 * 4^s + 2 vertices. (V, F).");
  m.def(
      "torus",
      [](double major_radius, double minor_radius, int major_segments, int minor_segments) {
        return mesh_arrays(make_torus(major_radius, minor_radius, major_segments, minor_segments));
      },
      py::arg("major_radius") = 1.0, py::arg("minor_radius") = 0.35, py::arg("major_segments") = 96,
      py::arg("minor_segments") = 32, "Torus around the z axis. (V, F).");
}

}  // namespace specdeform::python
