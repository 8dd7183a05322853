#include <unistd.h>

#include <cerrno>
#include <cstdio>

#include <pybind11/stl/filesystem.h>

#include "bindings.h"
#include "convert.h"
#include "specdeform/exceptions.h"
#include "specdeform/mesh/generate.h"
#include "specdeform/mesh/io.h"

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
      .def_readonly("welded_corners", &MeshReadInfo::welded_corners,
                    "STL: triangle corners merged into an existing vertex.")
      .def("__repr__", [](const MeshReadInfo& i) {
        return "MeshReadInfo(file_vertices=" + std::to_string(i.file_vertices.rows()) +
               ", file_faces=" + std::to_string(i.file_faces) +
               ", unused_vertices=" + std::to_string(i.unused_vertices) +
               ", collapsed_faces=" + std::to_string(i.collapsed_faces) +
               ", duplicate_faces=" + std::to_string(i.duplicate_faces) +
               ", welded_corners=" + std::to_string(i.welded_corners) + ")";
      });

  m.def(
      "read_mesh",
      [](const std::filesystem::path& path, bool return_info) -> py::tuple {
        check_readable(path);
        LoadedMesh loaded;
        {
          py::gil_scoped_release release;
          loaded = read_mesh(path);
        }
        py::tuple VF = mesh_arrays(std::move(loaded.mesh));
        if (!return_info) return VF;
        return py::make_tuple(VF[0], VF[1], std::move(loaded.info));
      },
      py::arg("path"), py::arg("return_info") = false,
      R"(Reads an OBJ, OFF, PLY or STL file: (V, F), V float64 (n, 3), F int32 (f, 3).

Polygons are fan-triangulated; vertices no face uses and faces that repeat a vertex are dropped.
With return_info=True, (V, F, info): info (a MeshReadInfo) maps the mesh back to the file.
Raises OSError if the file cannot be opened, InputError if it is malformed.)");

  m.def(
      "write_mesh",
      [](const std::filesystem::path& path, py::handle V, py::handle F, const MeshReadInfo* info) {
        check_writable(path);
        TriangleMesh mesh = to_mesh(V, F);
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
      R"(Writes a mesh; the format from the extension (.obj .off .ply .stl), atomically.

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
