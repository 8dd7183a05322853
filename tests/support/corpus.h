// A categorised corpus of small meshes for invariant tests (in the manner of geometry-central's
// load_test_meshes): closed, with boundary, several components, awkward. All generated, so the
// suite needs no data files; real meshes from ../shared are added where that folder exists.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "specdeform/deform/selection.h"
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

// Meshes as tools write them (issue 52), each with vertices on an edge, touched by a zero-area
// face (T-junctions, and vertices of zero area that the zero-area face alone touches), and the
// edge's ends:
//  - t_junctions_and_dust: a bumpy plane whose cells have vertices on their diagonals, each
//    touched by one zero-area face, and a piece of zero-area faces alone (collinear points);
//  - misoriented_fin_pinch: a sphere with half its triangles wound the other way, a fin (an
//    edge of three triangles) and a second sphere touching it at one vertex;
//  - confetti: a bumpy bar among 60 specks of one triangle or four (thousands of pieces in
//    game scenes);
//  - caps_and_needles: a grid cut into caps (angles a hair below pi) with a zero-length edge
//    (two vertices at one place, both in faces of their own, as Blender's doubles).
struct MessyMesh {
  std::string name;
  TriangleMesh mesh;
  std::vector<std::array<int, 3>> t_junctions;  // (a, q, b): q on the edge a-b
};
const std::vector<MessyMesh>& messy();

// ../shared beside the checkout, or an empty path if it is absent.
std::filesystem::path shared_dir();

// Two meshes side by side as one (vertex indices of `b` shifted).
TriangleMesh concatenate(const TriangleMesh& a, const TriangleMesh& b);

// The assemblies' scene: the highest tenth (along z) of piece 0 (`label` from
// vertex_components) lifted by 0.1 and moved by 0.05 diagonals and turned by 0.4 rad about x,
// its lowest tenth fixed; the other pieces free.
struct PieceScene {
  Selection selection;
  Eigen::Affine3d transform;
};
PieceScene first_piece_scene(const TriangleMesh& mesh, const Eigen::VectorXi& label);

}  // namespace specdeform::test
