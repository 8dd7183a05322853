// Reading and writing meshes: OBJ, OFF, PLY, STL and glTF 2.0 (.gltf, .glb).
//
// Readers:
//  - OBJ: negative (relative) indices, the v, v/vt, v//vn and v/vt/vn corner forms and
//    backslash line continuations are accepted. A face of fewer than 3 corners is an error (a file
//    cut inside a face line is reported as truncated). Kept (ReadOptions::keep_file): vt, vn, the
//    corners' indices, colours after v, usemtl materials with their MTL's Kd and map_Kd.
//  - OFF: OFF, COFF, NOFF, CNOFF and STOFF headers, '#' comments; kept: NOFF normals, COFF colours.
//  - PLY: ascii, binary_little_endian and binary_big_endian; x/y/z of any scalar type; faces from
//    a list property named vertex_indices or vertex_index of any integer types, in element
//    "face" (polygons) or "tristrips" (triangle strips as the Stanford and VCG files have them:
//    -1 starts a new strip, every second triangle is turned to face the same way as the first,
//    and the triangles of a strip's turns, which repeat a vertex, are left out; each other
//    triangle counts as one file polygon); in ASCII files anything after an entry's values on its
//    line is skipped. Kept: nx ny nz, red green blue [alpha], s t / u v / texture_u texture_v, a
//    face's texcoord list; every other element and property passes through untouched. Vertices
//    with texture coordinates or normals, which exporters split where those differ, are welded
//    where their positions coincide exactly (the file's numbering stays the file's).
//  - STL: ascii and binary; exactly coincident corners are welded into shared vertices, so file
//    triangle t has the corners F(t, 0..2) (no triangle is reordered).
//  - glTF 2.0 (src/mesh/formats/gltf): the triangle primitives of the meshes the default scene
//  draws, in
//    world space; the vertices glTF splits along seams welded by position.
// Every reader validates what it reads and throws InputError with a one-line message naming the
// file: empty file, header only, no faces, index out of range, NaN/Inf coordinates, truncated
// data, a Git LFS pointer left in place of the mesh ("run git lfs pull"). Polygons are
// fan-triangulated from their first corner whose diagonals are not edges of the mesh already (two
// polygons that share two sides would otherwise both take one diagonal: a triangle twice, back to
// back). Faces that repeat a vertex are dropped; vertices that no face uses are dropped. The maps
// in MeshReadInfo lead back to the file, so results can be written in the file's order.
//
// write_mesh() writes a mesh made in memory, the format from the extension: OBJ and OFF print the
// shortest decimal that reads back to the same double; PLY is binary little-endian with double
// coordinates; STL is binary (float32, as the format demands); glTF one mesh of one primitive.
// A file read with keep_file is written back whole by write_mesh_file() (mesh_file.h). Files are
// written atomically.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "specdeform/mesh/mesh_file.h"
#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform {

struct MeshReadInfo {
  Vertices file_vertices;           // every vertex of the file (STL: after welding; glTF: its
                                    // triangle primitives' POSITION vertices, world space)
  int file_faces = 0;               // polygons in the file
  std::vector<int> vertex_to_file;  // mesh vertex i is file vertex vertex_to_file[i] (the first
                                    // of those welded into it)
  std::vector<int> file_to_vertex;  // file vertex v became mesh vertex file_to_vertex[v] (-1:
                                    // dropped)
  std::vector<int> face_to_file;    // mesh triangle f comes from file polygon face_to_file[f]
  int unused_vertices = 0;          // file vertices no face uses (dropped)
  int collapsed_faces = 0;          // triangles that repeat a vertex (dropped)
  int duplicate_faces = 0;          // triangles on the same three vertices as an earlier one,
                                    // in any order (dropped: a doubled face would count its
                                    // area and stiffness twice)
  int welded_corners = 0;           // STL: triangle corners merged into an existing vertex
  int welded_vertices = 0;          // glTF, PLY with uv or normals: vertices split along seams
                                    // merged into another at the same position
};

struct LoadedMesh {
  TriangleMesh mesh;
  MeshReadInfo info;
  std::shared_ptr<const MeshFile> file;  // with ReadOptions::keep_file; null otherwise
};

struct ReadOptions {
  bool keep_file = false;   // keep the file whole (LoadedMesh::file) to write it back
  FileResolver companions;  // the files it names (MTL, glTF buffers): read_mesh's default reads
                            // them beside the file; read_mesh_from_memory's has none
};

LoadedMesh read_mesh(const std::filesystem::path& path, const ReadOptions& options = {});

// Parses a file held in memory; `name` is used in error messages only.
LoadedMesh read_mesh_from_memory(std::string_view data, MeshFormat format, std::string_view name,
                                 const ReadOptions& options = {});

// What a file holds and what `deform` would do with it (`info`): the mesh read whole, or, for a
// glTF that parses but draws nothing that can be deformed (no triangles, a node reached twice,
// a bad index...), the document's contents and the one-line reason. Throws InputError where the
// file cannot be parsed at all, or where another format yields no mesh.
struct MeshFileReport {
  FileSummary contents;
  std::optional<LoadedMesh> loaded;  // read with keep_file
  std::string refused;               // why not, when `loaded` is empty
};
MeshFileReport inspect_mesh_file(const std::filesystem::path& path);

// What reading `mesh` from a file would record when nothing is dropped or merged (for meshes
// made in memory, e.g. by generate.h).
MeshReadInfo identity_read_info(const TriangleMesh& mesh);

// The mesh in the file's numbering: vertex positions V (one row per mesh vertex) placed at their
// file indices (every file vertex welded into one), dropped vertices at their file positions, and
// the faces renumbered accordingly.
TriangleMesh to_file_order(const MeshReadInfo& info, const Vertices& V, const Faces& F);

void write_mesh(const std::filesystem::path& path, const TriangleMesh& mesh);

// The bytes write_mesh would write.
std::string encode_mesh(const TriangleMesh& mesh, MeshFormat format);

}  // namespace specdeform
