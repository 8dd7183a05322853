// Internal: mesh files written afresh, for a mesh made in memory (write_mesh) or a kept file
// written in another format than its own (encode_mesh_file). Each format carries what it can:
//  - OBJ: polygons, texture coordinates, normals, vertex colours (after v), materials (an MTL
//    beside it, named <stem>.mtl, with Kd and map_Kd; glTF's embedded images written beside it);
//  - OFF: polygons, colours (COFF), normals where each vertex has one (NOFF);
//  - PLY (binary little endian, double positions): polygons, normals where each vertex has one,
//    colours (uchar), texture coordinates as each face's texcoord list;
//  - STL (binary): triangles, facet normals of the new shape;
//  - glTF (.gltf with its buffer embedded, or .glb): one mesh of one primitive per material,
//    its vertices split where texture coordinates or normals differ; TEXCOORD_0 with v turned
//    (glTF's v runs down), NORMAL, COLOR_0, materials with their base colour and texture.
// Polygons are fan-triangulated where the format has none. EncodedMesh::notes names what the
// source held and the target cannot.
#pragma once

#include <string>
#include <vector>

#include "specdeform/mesh/io.h"
#include "specdeform/mesh/mesh_file.h"

namespace specdeform::detail {

// `normals`: the file's updated normal rows (empty when it has none).
EncodedMesh encode_converted(const MeshFile& file, const Vertices& positions,
                             const Eigen::MatrixX3d& normals,
                             const std::filesystem::path& out_name);

// What the file holds beyond positions and triangles (contents_beyond_triangles).
std::vector<std::string> beyond_triangles(const MeshFile& file);

// A mesh made in memory: its triangles only, the file in parts to be concatenated.
std::vector<std::string> encode_plain(const TriangleMesh& mesh, MeshFormat format);

}  // namespace specdeform::detail
