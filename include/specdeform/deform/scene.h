// Deformation scenes: which vertices are handles or fixed, and how the handles move.
//
// Formats read:
//  - Botsch & Sorkine benchmark: .sel, one status per file vertex (0 fixed, 1 free, 2 handle),
//    '#' comment lines; .def, a comment line, then 4 x 4 row-major transforms (one per handle
//    group; a single one for a .sel).
//  - libigl selection .dmat: header "cols rows", then one integer per vertex, column-major:
//    -1 free, k >= 0 handle group k. Groups without a transform in the .def stay put.
//  - JSON (docs/scene.md):
//      { "mesh": "bar.off",                        (relative to the scene file; optional)
//        "handles": [ { "vertices": [1, 2, 3] | "selection": "x.sel" | "selection": "x.dmat" |
//                         "around": { "vertex": v, "radius": r },  (r: of the bbox diagonal)
//                       "group": 0,                 (for a .dmat; 2 = handle for a .sel)
//                       "transform": [[4 x 4 rows]] |
//                         { "translate": [x, y, z],
//                           "rotate": { "axis": [x, y, z], "degrees": a },
//                           "scale": s,
//                           "center": [x, y, z] | "centroid" } } ],   (default: centroid)
//        "fixed": [4, 5] | { "selection": "x.sel" }   (status 0 of a .sel)
//                 | { "lowest": f, "axis": "y" },     (fraction f lowest, handles excepted)
//        "influence": r,   (optional: the vertices farther than r bounding-box diagonals from the
//                           handles, along the surface, are fixed too; influence.h)
//        "settings": { "modes": 100, "energy": "arap", "ks": 0, "kb": 1,
//                      "constraint_weight": 1e5, "constraints": "soft", "detail": "transfer",
//                      "solver": "spectral", "unconstrained": "keep", "iterations": 100,
//                      "clusters": 200, "arap_bending": 1e-3, "arap_tolerance": 1e-4,
//                      "history": 5 } }
//    The transform of a handle maps p to center + R (scale (p - center)) + translate. Every
//    field is checked: an unknown key, a value of the wrong type or out of range is an InputError
//    naming the field ("s.json handle 0 transform rotate axis: expected an array of 3 numbers,
//    got a number").
// Vertex indices are the file's. The regions ("around", "lowest") and centroids take only the
// vertices of the loaded mesh (its reader drops vertices no face uses); to_mesh_numbering() maps
// a selection to the loaded mesh. Every reader throws InputError with a one-line message.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

#include "specdeform/deform/deform_options.h"
#include "specdeform/deform/selection.h"
#include "specdeform/mesh/io.h"

namespace specdeform {

struct Scene {
  std::filesystem::path mesh;  // empty when the scene does not name one
  Selection selection;         // in the file's vertex numbering
  std::vector<Eigen::Affine3d> transforms;
  std::optional<int> modes;  // settings the scene asks for
  DeformOptions options;
  std::optional<double> influence;  // of the bounding-box diagonal (scene_selection)
};

// .sel: one handle group (status 2) and the fixed set (status 0).
Selection read_sel(const std::filesystem::path& path, int file_vertices);
// .dmat: handle group k = the vertices with value k.
Selection read_dmat(const std::filesystem::path& path, int file_vertices);
// .def: the transforms, in order.
std::vector<Eigen::Affine3d> read_def(const std::filesystem::path& path);
// The same from a file's contents; `name` prefixes error messages.
Selection parse_sel(std::string_view text, int file_vertices, std::string_view name);
Selection parse_dmat(std::string_view text, int file_vertices, std::string_view name);
std::vector<Eigen::Affine3d> parse_def(std::string_view text, std::string_view name);

// JSON scene of the mesh read as `mesh` (for its file vertices, and which of them the mesh kept).
// `options` are the defaults the scene's settings override.
Scene read_scene(const std::filesystem::path& path, const MeshReadInfo& mesh,
                 const DeformOptions& options = {});
// The same for a mesh that kept every vertex of its file.
Scene read_scene(const std::filesystem::path& path, const Vertices& file_vertices,
                 const DeformOptions& options = {});
// The same from the scene's text: `path` names it in messages and resolves the relative names of
// the files it refers to, which `read_file` reads (it throws InputError for one it cannot read).
using SceneFileReader = std::function<std::string(const std::filesystem::path&)>;
Scene parse_scene(std::string_view text, const std::filesystem::path& path,
                  const MeshReadInfo& mesh, const DeformOptions& options,
                  const SceneFileReader& read_file);

// The mesh a JSON scene names (relative to the scene's directory), or an empty path.
std::filesystem::path scene_mesh(const std::filesystem::path& path);

// The scene as JSON in the format above (vertex lists, 4 x 4 transforms, the fixed list and all
// the settings); read_scene() reads it back to the same selection, transforms and settings.
std::string encode_scene(const Scene& scene);

// `m` as an affine transform; throws InputError, `where` first, for one that is not finite, not
// affine (last row 0 0 0 1) or not invertible.
Eigen::Affine3d checked_transform(const Eigen::Matrix4d& m, const std::string& where);

// Pads `transforms` with identities up to the number of handle groups; throws InputError if
// there are more transforms than groups or the selection has no handle vertex.
std::vector<Eigen::Affine3d> match_transforms(const Selection& selection,
                                              std::vector<Eigen::Affine3d> transforms);

// A reproducible scene for benchmarks and experiments: one handle group, the vertices within
// `radius` (a fraction of the bounding-box diagonal) of vertex `center`; fixed, the
// `fixed_fraction` of all vertices lowest along axis `up` (0 = x, 1 = y, 2 = z), minus handles.
Selection radius_selection(const TriangleMesh& mesh, int center, double radius,
                           double fixed_fraction, int up);

// The benchmarks' scene for any mesh: along the bounding box's longest axis, the handle is the
// radius_selection() of 5% of the diagonal around the topmost vertex, the lowest 10% of the
// vertices are fixed, and the handle moves by 10% of the diagonal along the second-longest axis.
Scene benchmark_scene(const TriangleMesh& mesh);

// From file vertex indices to the loaded mesh's, leaving out the vertices the reader dropped
// (used by no face); copies of one welded vertex (a glTF file's seams) count once. A handle group
// or fixed set that loses all its vertices is an InputError naming it, `name` (the scene's) first;
// one that loses some adds a line to `notes`, if given
// ("handle group 0: 3 of its 40 vertices are used by no face and were left out").
Selection to_mesh_numbering(const Selection& selection, const MeshReadInfo& info,
                            std::vector<std::string>* notes = nullptr,
                            std::string_view name = "selection");

// The scene's selection on the loaded mesh: to_mesh_numbering(), then, when the scene has an
// influence radius, limit_influence() with that fraction of the mesh's bounding-box diagonal.
Selection scene_selection(const Scene& scene, const LoadedMesh& mesh,
                          std::vector<std::string>* notes = nullptr,
                          std::string_view name = "selection");

}  // namespace specdeform
