// Internal: the same-format writers of a kept file (mesh_file.h): the file's bytes with new
// positions and normals put where its reader found them, nothing else touched.
#pragma once

#include <string>

#include "file_layout.h"
#include "specdeform/mesh/mesh_file.h"

namespace specdeform::detail {

// `positions`: one row per file vertex; `normals`: the updated rows of the file's normals
// (FileAttributes::normals; file_normals.h), empty when it has none.
std::string rewrite_obj(const MeshFile& file, const Vertices& positions,
                        const Eigen::MatrixX3d& normals);
std::string rewrite_off(const MeshFile& file, const Vertices& positions,
                        const Eigen::MatrixX3d& normals);
std::string rewrite_ply(const MeshFile& file, const Vertices& positions,
                        const Eigen::MatrixX3d& normals);
std::string rewrite_stl(const MeshFile& file, const Vertices& positions,
                        const Eigen::MatrixX3d& normals);
// The .glb or .gltf, then the external buffers whose bytes changed, named as `out_name`'s
// companions (the buffer's own uri where `out_name` is in another folder than the input, else
// "<out stem>.bin", "<out stem>-1.bin", ...).
EncodedMesh rewrite_gltf(const MeshFile& file, const Vertices& positions,
                         const Eigen::MatrixX3d& normals, const std::filesystem::path& out_name,
                         bool same_folder);

}  // namespace specdeform::detail
