// Internal: what the scene's readers (scene_files.cpp, scene_json.cpp) and its selection builders
// (scene_selection.cpp) share.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform::detail {

// The contents of a scene's file (JSON, .sel, .dmat, .def); InputError, naming the file, for one
// that cannot be read, is not a regular file, or is a Git LFS pointer.
std::string read_scene_file(const std::filesystem::path& path);

// Of the vertices `among` (ascending), those within `radius` of `center`, ascending.
std::vector<int> vertices_within(const Vertices& V, const std::vector<int>& among,
                                 const Eigen::Vector3d& center, double radius);

// The `fraction` of the vertices `among` lowest along `axis`, minus those in `excluded`,
// ascending.
std::vector<int> lowest_vertices(const Vertices& V, const std::vector<int>& among, double fraction,
                                 int axis, const std::vector<std::vector<int>>& excluded);

}  // namespace specdeform::detail
