// Reading and writing triangle meshes: OBJ, OFF, PLY and STL.
//
// Readers:
//  - OBJ: negative (relative) indices, the v, v/vt, v//vn and v/vt/vn corner forms and
//    backslash line continuations are accepted; groups, materials, texture coordinates and
//    normals are ignored. A face of fewer than 3 corners is an error (a file cut inside a face
//    line is reported as truncated).
//  - OFF: OFF, COFF, NOFF, CNOFF and STOFF headers, '#' comments, extra per-vertex or per-face
//    values (colours, normals) ignored.
//  - PLY: ascii, binary_little_endian and binary_big_endian; x/y/z of any scalar type; faces from
//    a list property named vertex_indices or vertex_index of any integer types, in element
//    "face" (polygons) or "tristrips" (triangle strips as the Stanford and VCG files have them:
//    -1 starts a new strip, every second triangle is turned to face the same way as the first,
//    and the triangles of a strip's turns, which repeat a vertex, are left out; each other
//    triangle counts as one file polygon); every other element and property is skipped (in
//    ASCII files, so is anything after an entry's values on its line).
//  - STL: ascii and binary; exactly coincident corners are welded into shared vertices, so file
//    triangle t has the corners F(t, 0..2) (no triangle is reordered).
// Every reader validates what it reads and throws InputError with a one-line message naming the
// file: empty file, header only, no faces, index out of range, NaN/Inf coordinates, truncated
// data, a Git LFS pointer left in place of the mesh ("run git lfs pull"). Polygons are
// fan-triangulated from their first corner whose diagonals are not edges of the mesh already (two
// polygons that share two sides would otherwise both take one diagonal: a triangle twice, back to
// back). Faces that repeat a vertex are dropped; vertices that no face uses are dropped. The maps
// in MeshReadInfo lead back to the file, so results can be written in the file's order.
//
// Writers choose the format from the extension (.obj .off .ply .stl). OBJ and OFF print the
// shortest decimal that reads back to the same double; PLY is binary little-endian with double
// coordinates; STL is binary (float32, as the format demands). Files are written atomically.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform {

enum class MeshFormat { Obj, Off, Ply, Stl };

// Format from a file name's extension, case-insensitive. Throws InputError for anything else.
MeshFormat mesh_format_from_path(const std::filesystem::path& path);

struct MeshReadInfo {
  Vertices file_vertices;           // every vertex of the file (for STL: after welding)
  int file_faces = 0;               // polygons in the file
  std::vector<int> vertex_to_file;  // mesh vertex i is file vertex vertex_to_file[i]
  std::vector<int> face_to_file;    // mesh triangle f comes from file polygon face_to_file[f]
  int unused_vertices = 0;          // file vertices no face uses (dropped)
  int collapsed_faces = 0;          // triangles that repeat a vertex (dropped)
  int duplicate_faces = 0;          // triangles on the same three vertices as an earlier one,
                                    // in any order (dropped: a doubled face would count its
                                    // area and stiffness twice)
  int welded_corners = 0;           // STL: triangle corners merged into an existing vertex
};

struct LoadedMesh {
  TriangleMesh mesh;
  MeshReadInfo info;
};

LoadedMesh read_mesh(const std::filesystem::path& path);

// Parses a file held in memory; `name` is used in error messages only.
LoadedMesh read_mesh_from_memory(std::string_view data, MeshFormat format, std::string_view name);

// What reading `mesh` from a file would record when nothing is dropped or merged (for meshes
// made in memory, e.g. by generate.h).
MeshReadInfo identity_read_info(const TriangleMesh& mesh);

// The mesh in the file's numbering: vertex positions V (one row per mesh vertex) placed at their
// file indices, dropped vertices at their file positions, and the faces renumbered accordingly.
TriangleMesh to_file_order(const MeshReadInfo& info, const Vertices& V, const Faces& F);

void write_mesh(const std::filesystem::path& path, const TriangleMesh& mesh);

// The bytes write_mesh would write.
std::string encode_mesh(const TriangleMesh& mesh, MeshFormat format);

}  // namespace specdeform
