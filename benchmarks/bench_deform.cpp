// One deformation frame and one selection change, spectral (m = 100, deformation transfer)
// against the prefactored spatial solver of the same energy (one back-substitution per frame,
// the honest competitor), measured in the same run; the paper's linear energy, and the ARAP
// frame beside it (spectral_arap: cold, from the rest pose, as every frame here).
//
// Scene: ../shared/meshes/models/armadillo.obj (43,243 vertices), handle = the vertices within
// 5% of the bounding-box diagonal of the right hand (vertex 42163), fixed = the lowest 10% (the
// feet), the hand moved by (0, 0.15, 0.1); and the same on the armadillo Loop-subdivided twice
// (~692k vertices). Without ../shared a generated bumpy bar of the same size stands in.
//   build/bin/bench_deform --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <memory>

#include "specdeform/deform/scene.h"
#include "specdeform/deform/spectral_deformer.h"
#include "specdeform/mesh/generate.h"
#include "specdeform/mesh/io.h"
#include "specdeform/mesh/subdivide.h"

namespace {

using namespace specdeform;

struct Setup {
  TriangleMesh mesh;
  ManifoldHarmonics basis;
  Selection selection;
  Selection other;  // a second selection, for the selection change
  std::vector<Eigen::Affine3d> move{Eigen::Affine3d(Eigen::Translation3d(0.0, 0.15, 0.1))};
};

const Setup& setup(int subdivisions) {
  static std::map<int, std::unique_ptr<Setup>> cache;
  auto& s = cache[subdivisions];
  if (s) return *s;
  s = std::make_unique<Setup>();
  const std::filesystem::path file =
      std::filesystem::path(SPECDEFORM_SHARED_DIR) / "meshes/models/armadillo.obj";
  int hand = 42163;
  if (std::filesystem::exists(file)) {
    s->mesh = read_mesh(file).mesh;
  } else {
    BumpyBarOptions o;
    o.cells_per_unit = 49;
    s->mesh = make_bumpy_bar(o);
    hand = 0;  // a corner of the bar's end
  }
  s->mesh = subdivide(s->mesh, subdivisions);  // keeps the first vertices' numbering
  ManifoldHarmonicsOptions o;
  o.num_modes = 100;
  s->basis = compute_manifold_harmonics(s->mesh, o);
  s->selection = radius_selection(s->mesh, hand, 0.05, 0.10, 1);
  s->other = radius_selection(s->mesh, hand, 0.06, 0.10, 1);
  return *s;
}

SpectralDeformer make(const Setup& s, DeformSolver solver,
                      DeformEnergy energy = DeformEnergy::Linear, bool float32 = false) {
  DeformOptions o;
  o.energy = energy;
  o.solver = solver;
  o.float32_basis = float32;
  if (solver == DeformSolver::Spatial) {
    o.detail = DetailMethod::None;  // it deforms the detailed mesh itself
    o.constraints = ConstraintMode::Hard;
    return SpectralDeformer(s.mesh, ManifoldHarmonics{}, o);
  }
  return SpectralDeformer(s.mesh, s.basis, o);
}

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// The stages' medians over the iterations, in milliseconds.
void BM_Frame(benchmark::State& state, DeformSolver solver, DeformEnergy energy, bool float32) {
  const Setup& s = setup(static_cast<int>(state.range(0)));
  SpectralDeformer d = make(s, solver, energy, float32);
  d.set_selection(s.selection);
  std::vector<double> reduced, inverse, detail;
  for (auto _ : state) {
    benchmark::DoNotOptimize(d.solve(s.move).data());
    reduced.push_back(d.frame_timings().reduced_solve);
    inverse.push_back(d.frame_timings().inverse_transform);
    detail.push_back(d.frame_timings().detail);
  }
  state.counters["n"] = s.mesh.num_vertices();
  state.counters["constrained"] =
      static_cast<double>(s.selection.handles[0].size() + s.selection.fixed.size());
  state.counters["reduced_ms"] = median(reduced) * 1e3;
  state.counters["inverse_ms"] = median(inverse) * 1e3;
  state.counters["detail_ms"] = median(detail) * 1e3;
}

void BM_SelectionChange(benchmark::State& state, DeformSolver solver) {
  const Setup& s = setup(static_cast<int>(state.range(0)));
  SpectralDeformer d = make(s, solver);
  bool flip = false;
  for (auto _ : state) {
    d.set_selection(flip ? s.other : s.selection);
    flip = !flip;
  }
  state.counters["n"] = s.mesh.num_vertices();
}

BENCHMARK_CAPTURE(BM_Frame, spectral, DeformSolver::Spectral, DeformEnergy::Linear, false)
    ->ArgName("subdiv")
    ->Arg(0)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Frame, spectral_arap, DeformSolver::Spectral, DeformEnergy::Arap, false)
    ->ArgName("subdiv")
    ->Arg(0)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Frame, spectral_float32, DeformSolver::Spectral, DeformEnergy::Linear, true)
    ->ArgName("subdiv")
    ->Arg(0)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Frame, spatial_prefactored, DeformSolver::Spatial, DeformEnergy::Linear, false)
    ->ArgName("subdiv")
    ->Arg(0)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_SelectionChange, spectral, DeformSolver::Spectral)
    ->ArgName("subdiv")
    ->Arg(0)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_SelectionChange, spatial_prefactored, DeformSolver::Spatial)
    ->ArgName("subdiv")
    ->Arg(0)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
