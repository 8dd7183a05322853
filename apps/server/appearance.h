// What the browser draws of a file's look (mesh_file.h): the mesh's triangles over render
// vertices, one per (mesh vertex, texture coordinate row, normal row) that the file's corners
// use, with
//  - the texture coordinates, v up (OBJ's and three.js's convention; glTF's are turned),
//  - each render vertex's normal group: the file's normal row it shares with others (so that a
//    hard edge stays hard; the browser sums the faces' normals per group), or, without one, its
//    mesh vertex's group (smooth),
//  - the file's vertex colours, and each material's base colour, how its image is laid (in the
//    same v-up convention) and whether it is unlit; triangles sorted by material.
// A file with none of these (most scans, every OFF and STL without colours) has no appearance:
// the browser draws the plain mesh.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "specdeform/mesh/io.h"

namespace specdeform::server {

struct Appearance {
  std::vector<uint32_t> vertex;           // mesh vertex of each render vertex
  std::vector<uint32_t> normal_group;     // of each render vertex
  std::vector<uint32_t> corners;          // 3 per triangle, render numbering, sorted by material
  std::vector<uint32_t> material_start;   // material m's triangles: [start[m], start[m + 1]);
                                          // the last material is "none" (no material)
  std::vector<float> base_color;          // RGBA of each material but "none"
  std::vector<float> uv;                  // 2 per render vertex; empty: none
  std::vector<uint8_t> rgba;              // 4 per render vertex; empty: none
  std::vector<char> textured;             // per material but "none": has a base colour image
  std::vector<TextureSampling> sampling;  // per material but "none"
  std::vector<char> unlit;                // per material but "none"
};

std::optional<Appearance> file_appearance(const LoadedMesh& mesh);

}  // namespace specdeform::server
