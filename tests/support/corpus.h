// A categorised corpus of small meshes for invariant tests (in the manner of geometry-central's
// load_test_meshes): closed, with boundary, several components, awkward. All generated, so the
// suite needs no data files; real meshes from ../shared are added where that folder exists.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform::test {

enum class Category { Closed, Boundary, Components, Awkward };

struct CorpusMesh {
  std::string name;
  Category category;
  TriangleMesh mesh;
  int components = 1;  // connected components
};

// The generated corpus (each mesh has at most a few thousand vertices).
const std::vector<CorpusMesh>& corpus();

// ../shared beside the checkout, or an empty path if it is absent.
std::filesystem::path shared_dir();

// Two meshes side by side as one (vertex indices of `b` shifted).
TriangleMesh concatenate(const TriangleMesh& a, const TriangleMesh& b);

}  // namespace specdeform::test
