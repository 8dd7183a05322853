// How well the cotangent and the intrinsic Delaunay Laplacians of a mesh with slivers give its
// surface's spectrum: the first m eigenvalues of each, against those of a finer well-shaped
// version of the same surface (CGAL's isotropic remeshing at `refine` times the mean edge length,
// the cotangent Laplacian there); beside them, a well-shaped remeshing at the mesh's own edge
// length, for what a good mesh of that size achieves. Also the mesh's defects (negative cotangent
// weights, caps, needles, folds), the intrinsic flips, and the time of each Laplacian's operators
// (median of 5) and basis.
//
//   build/bin/laplacian_agreement [--modes 50] [--refine 0.5] [--mass lumped|consistent]
//                                 [--json F] [--markdown F] [MESH...]
//
// Without meshes: every .obj and .off of ../shared/meshes/models. Relative errors
// |lambda_i - lambda_i^ref| / lambda_i^ref over the nonzero eigenvalues i < m (the zeros, one per
// connected component, left out), median and max.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <numbers>
#include <sstream>
#include <string>
#include <tuple>
#include <unordered_map>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "isotropic_remesh.h"
#include "specdeform/atomic_file.h"
#include "specdeform/exceptions.h"
#include "specdeform/mesh/io.h"
#include "specdeform/operators/cotan_laplacian.h"
#include "specdeform/operators/intrinsic_delaunay.h"
#include "specdeform/operators/laplacian.h"
#include "specdeform/spectral/manifold_harmonics.h"

namespace {

using namespace specdeform;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

struct Defects {
  int edges = 0, negative_weights = 0, caps = 0, needles = 0, degenerate = 0, folds = 0;
};

// Vertex pairs joined by an edge, and those with a negative weight (beyond rounding: a positive
// off-diagonal entry of K).
std::pair<int, int> pairs_and_negative_weights(const Eigen::SparseMatrix<double>& K) {
  int pairs = 0, negative = 0;
  for (int j = 0; j < K.outerSize(); ++j) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(K, j); it; ++it) {
      if (it.row() >= it.col()) continue;
      ++pairs;
      if (it.value() > 1e-12) ++negative;
    }
  }
  return {pairs, negative};
}

// Negative cotangent weights, triangles with an angle above 150 degrees (caps), with one below 5
// degrees and none above 150 (needles), degenerate ones, and edges whose two triangles' normals
// are more than 120 degrees apart (folds).
Defects defects(const TriangleMesh& mesh) {
  Defects d;
  std::tie(d.edges, d.negative_weights) = pairs_and_negative_weights(cotan_stiffness(mesh));
  constexpr double kDegree = std::numbers::pi / 180.0;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d p[3] = {mesh.V.row(mesh.F(f, 0)), mesh.V.row(mesh.F(f, 1)),
                                  mesh.V.row(mesh.F(f, 2))};
    if (is_degenerate_triangle(p[0], p[1], p[2])) {
      ++d.degenerate;
      continue;
    }
    double smallest = std::numbers::pi, largest = 0.0;
    for (int c = 0; c < 3; ++c) {
      const Eigen::Vector3d u = p[(c + 1) % 3] - p[c], v = p[(c + 2) % 3] - p[c];
      const double angle = std::atan2(u.cross(v).norm(), u.dot(v));
      smallest = std::min(smallest, angle), largest = std::max(largest, angle);
    }
    if (largest > 150 * kDegree) {
      ++d.caps;
    } else if (smallest < 5 * kDegree) {
      ++d.needles;
    }
  }
  const auto normals = face_normals(mesh);
  std::unordered_map<uint64_t, int> face_of;
  const auto key = [](int a, int b) { return (uint64_t(uint32_t(a)) << 32) | uint32_t(b); };
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int c = 0; c < 3; ++c) face_of[key(mesh.F(f, c), mesh.F(f, (c + 1) % 3))] = f;
  for (const auto& [k, f] : face_of) {
    const int a = int(k >> 32), b = int(k & 0xffffffffu);
    const auto twin = face_of.find(key(b, a));
    if (a < b && twin != face_of.end() && normals.row(f).dot(normals.row(twin->second)) < -0.5)
      ++d.folds;
  }
  return d;
}

struct Spectrum {
  Eigen::VectorXd eigenvalues;
  double seconds = 0.0;
  double residual = 0.0;  // eigen_residual: far below the errors measured here even where it
                          // misses the solver's tolerance
};

Spectrum spectrum(const TriangleMesh& mesh, int modes, MassType mass, LaplacianType type) {
  ManifoldHarmonicsOptions o;
  o.num_modes = modes;
  o.mass = mass;
  o.laplacian = type;
  const auto start = Clock::now();
  const ManifoldHarmonics h = compute_manifold_harmonics(mesh, o);
  return {h.eigenvalues, seconds_since(start), h.max_residual};
}

// Median of 5 runs of the operators (stiffness and lumped mass), in milliseconds.
double operators_ms(const TriangleMesh& mesh, LaplacianType type) {
  std::vector<double> times;
  for (int r = 0; r < 5; ++r) {
    const auto start = Clock::now();
    laplacian_operators(mesh, MassType::Lumped, type);
    times.push_back(1e3 * seconds_since(start));
  }
  std::sort(times.begin(), times.end());
  return times[2];
}

struct RelativeError {
  double median = 0.0, max = 0.0;
};

// The zero eigenvalues: one per connected component.
int zeros(const Eigen::VectorXd& lambda) {
  return static_cast<int>((lambda.array() < 1e-8 * lambda[lambda.size() - 1]).count());
}

RelativeError relative_error(const Eigen::VectorXd& lambda, const Eigen::VectorXd& reference) {
  std::vector<double> e;
  for (int i = zeros(reference); i < reference.size(); ++i)
    e.push_back(std::abs(lambda[i] - reference[i]) / reference[i]);
  std::sort(e.begin(), e.end());
  return {e[e.size() / 2], e.back()};
}

std::string fixed(double x, int digits) {
  char s[64];
  std::snprintf(s, sizeof s, "%.*f", digits, x);
  return s;
}

std::string percent(const RelativeError& e) {
  return fixed(100 * e.median, 2) + " / " + fixed(100 * e.max, 2);
}

}  // namespace

int main(int argc, char** argv) {
  int modes = 50;
  double refine = 0.5;
  MassType mass = MassType::Lumped;
  std::string json_path, markdown_path;
  std::vector<std::filesystem::path> meshes;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    const bool has_value = a + 1 < argc;
    if (arg == "--modes" && has_value) {
      modes = std::stoi(argv[++a]);
    } else if (arg == "--refine" && has_value) {
      refine = std::stod(argv[++a]);
    } else if (arg == "--mass" && has_value) {
      mass = std::string(argv[++a]) == "consistent" ? MassType::Consistent : MassType::Lumped;
    } else if (arg == "--json" && has_value) {
      json_path = argv[++a];
    } else if (arg == "--markdown" && has_value) {
      markdown_path = argv[++a];
    } else if (arg.starts_with("-")) {
      std::cerr << "usage: laplacian_agreement [--modes M] [--refine F] [--mass lumped|consistent] "
                   "[--json FILE] [--markdown FILE] [MESH...]\n";
      return 2;
    } else {
      meshes.emplace_back(arg);
    }
  }
  if (meshes.empty()) {
    const auto models = std::filesystem::path(SPECDEFORM_SHARED_DIR) / "meshes" / "models";
    if (!std::filesystem::exists(models)) {
      std::cerr << "laplacian_agreement: give meshes (" << models << " is absent)\n";
      return 2;
    }
    for (const auto& entry : std::filesystem::directory_iterator(models))
      if (entry.path().extension() == ".obj" || entry.path().extension() == ".off")
        meshes.push_back(entry.path());
    std::sort(meshes.begin(), meshes.end());
  }

  std::ostringstream table;
  table << "| mesh | vertices | negative cotan weights | caps > 150° | needles < 5° | folds | "
           "intrinsic flips | negative weights left (boundary) | operators cotan / intrinsic (ms) "
           "| basis cotan / intrinsic (s) | "
           "cotan error % (median / max) | intrinsic-delaunay error % | cotan vs intrinsic % | "
           "well-shaped, same size error % | reference vertices |\n"
        << "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  for (const auto& path : meshes) {
    const std::string name = path.stem().string();
    try {
      const TriangleMesh mesh = read_mesh(path).mesh;
      std::cerr << name << ": defects\n";
      const Defects d = defects(mesh);
      const IntrinsicTriangulation tri = intrinsic_delaunay(mesh);
      const int negative_left = pairs_and_negative_weights(stiffness_matrix(tri)).second;
      const double cotan_ms = operators_ms(mesh, LaplacianType::Cotan);
      const double intrinsic_ms = operators_ms(mesh, LaplacianType::IntrinsicDelaunay);
      std::cerr << name << ": spectra\n";
      const Spectrum cotan = spectrum(mesh, modes, mass, LaplacianType::Cotan);
      const Spectrum intrinsic = spectrum(mesh, modes, mass, LaplacianType::IntrinsicDelaunay);
      std::cerr << name << ": remeshing\n";
      const double edge = bench::mean_edge_length(mesh);
      const TriangleMesh fine = bench::isotropic_remesh(mesh, refine * edge);
      const TriangleMesh same = bench::isotropic_remesh(mesh, edge);
      std::cerr << name << ": reference spectra (" << fine.num_vertices() << " vertices)\n";
      const Spectrum reference = spectrum(fine, modes, mass, LaplacianType::Cotan);
      const Spectrum well_shaped = spectrum(same, modes, mass, LaplacianType::Cotan);
      // CGAL cuts non-manifold edges apart: then the spectra do not correspond.
      const bool comparable = zeros(reference.eigenvalues) == zeros(cotan.eigenvalues);
      const RelativeError cotan_error = relative_error(cotan.eigenvalues, reference.eigenvalues);
      const RelativeError intrinsic_error =
          relative_error(intrinsic.eigenvalues, reference.eigenvalues);
      const RelativeError difference = relative_error(cotan.eigenvalues, intrinsic.eigenvalues);
      const RelativeError same_error =
          relative_error(well_shaped.eigenvalues, reference.eigenvalues);
      const Defects fine_defects = defects(fine);
      const std::string apart = "remeshed into " + std::to_string(zeros(reference.eigenvalues)) +
                                " pieces, not comparable";
      table << "| " << name << " | " << mesh.num_vertices() << " | " << d.negative_weights << " of "
            << d.edges << " | " << d.caps << " | " << d.needles << " | " << d.folds << " | "
            << tri.flips << (tri.tufted ? " (tufted)" : "") << " | " << negative_left << " | "
            << fixed(cotan_ms, 1) << " / " << fixed(intrinsic_ms, 1) << " | "
            << fixed(cotan.seconds, 2) << " / " << fixed(intrinsic.seconds, 2) << " | "
            << (comparable ? percent(cotan_error) : apart) << " | "
            << (comparable ? percent(intrinsic_error) : "") << " | " << percent(difference) << " | "
            << (comparable ? percent(same_error) : "") << " | " << fine.num_vertices() << " |\n";
      const auto values = [](const Eigen::VectorXd& v) {
        return std::vector<double>(v.data(), v.data() + v.size());
      };
      rows.push_back(
          {{"mesh", name},
           {"vertices", mesh.num_vertices()},
           {"edges", d.edges},
           {"negative_cotan_weights", d.negative_weights},
           {"caps", d.caps},
           {"needles", d.needles},
           {"degenerate", d.degenerate},
           {"folds", d.folds},
           {"intrinsic_flips", tri.flips},
           {"negative_weights_after_flips", negative_left},
           {"tufted", tri.tufted},
           {"operators_ms", {{"cotan", cotan_ms}, {"intrinsic_delaunay", intrinsic_ms}}},
           {"basis_s", {{"cotan", cotan.seconds}, {"intrinsic_delaunay", intrinsic.seconds}}},
           {"comparable", comparable},
           {"error_cotan", {{"median", cotan_error.median}, {"max", cotan_error.max}}},
           {"error_intrinsic_delaunay",
            {{"median", intrinsic_error.median}, {"max", intrinsic_error.max}}},
           {"cotan_vs_intrinsic_delaunay",
            {{"median", difference.median}, {"max", difference.max}}},
           {"error_well_shaped_same_size",
            {{"median", same_error.median}, {"max", same_error.max}}},
           {"reference_vertices", fine.num_vertices()},
           {"reference_negative_cotan_weights", fine_defects.negative_weights},
           {"well_shaped_vertices", same.num_vertices()},
           {"max_residual",
            {{"cotan", cotan.residual},
             {"intrinsic_delaunay", intrinsic.residual},
             {"reference", reference.residual},
             {"well_shaped_same_size", well_shaped.residual}}},
           {"eigenvalues",
            {{"cotan", values(cotan.eigenvalues)},
             {"intrinsic_delaunay", values(intrinsic.eigenvalues)},
             {"reference", values(reference.eigenvalues)},
             {"well_shaped_same_size", values(well_shaped.eigenvalues)}}}});
    } catch (const std::exception& e) {
      std::cerr << name << ": " << e.what() << "\n";
      table << "| " << name << " | " << e.what() << " |\n";
    }
  }
  const nlohmann::ordered_json out = {{"modes", modes},
                                      {"refine", refine},
                                      {"mass", mass == MassType::Lumped ? "lumped" : "consistent"},
                                      {"meshes", rows}};
  if (!json_path.empty()) write_file_atomically(json_path, out.dump(2) + "\n");
  if (!markdown_path.empty()) write_file_atomically(markdown_path, table.str());
  std::cout << table.str();
  return 0;
}
