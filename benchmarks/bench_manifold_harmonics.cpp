// Manifold-harmonics basis: the block Krylov-Schur solver against the plain shift-invert Lanczos
// baseline (Spectra on the same CHOLMOD operator), measured in the same run, and the cache load.
//
// Meshes: ../shared/meshes/models/armadillo.obj (43,243 vertices) and that mesh Loop-subdivided
// twice (~692k); where ../shared is absent, a generated bumpy bar of similar size stands in.
// Peak memory is the process's maximum resident set size (counter "peak_rss_MB"): run one
// benchmark per process (--benchmark_filter) to read it for that benchmark alone.
//   build/bin/bench_manifold_harmonics --benchmark_filter='m:100/' --benchmark_repetitions=5
//   SPECDEFORM_BENCH_SLOW=1 build/bin/bench_manifold_harmonics   (adds the slow baselines)
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>

#include "specdeform/mesh/generate.h"
#include "specdeform/mesh/io.h"
#include "specdeform/mesh/subdivide.h"
#include "specdeform/spectral/basis_cache.h"
#include "specdeform/spectral/manifold_harmonics.h"

namespace {

using namespace specdeform;

const TriangleMesh& mesh(int subdivisions) {
  static std::map<int, TriangleMesh> cache;
  auto it = cache.find(subdivisions);
  if (it == cache.end()) {
    const std::filesystem::path file =
        std::filesystem::path(SPECDEFORM_SHARED_DIR) / "meshes/models/armadillo.obj";
    TriangleMesh base;
    if (std::filesystem::exists(file)) {
      base = read_mesh(file).mesh;
    } else {
      BumpyBarOptions o;
      o.cells_per_unit = 49;  // ~43k vertices
      base = make_bumpy_bar(o);
    }
    it = cache.emplace(subdivisions, subdivide(base, subdivisions)).first;
  }
  return it->second;
}

double peak_rss_mb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;
}

void BM_Basis(benchmark::State& state, EigenSolver solver) {
  const TriangleMesh& m = mesh(static_cast<int>(state.range(1)));
  ManifoldHarmonicsOptions o;
  o.num_modes = static_cast<int>(state.range(0));
  o.solver = solver;
  ManifoldHarmonics h;
  for (auto _ : state) {
    h = compute_manifold_harmonics(m, o);
    benchmark::DoNotOptimize(h.basis.data());
  }
  if (h.status != SolveStatus::Converged) state.SkipWithError("did not converge");
  state.counters["n"] = m.num_vertices();
  state.counters["residual"] = h.max_residual;
  state.counters["solves"] = static_cast<double>(h.solves);
  state.counters["peak_rss_MB"] = peak_rss_mb();
}

void BM_LoadBasis(benchmark::State& state) {
  const TriangleMesh& m = mesh(0);
  const auto path = std::filesystem::temp_directory_path() /
                    ("bench_basis_" + std::to_string(state.range(0)) + ".sdbasis");
  ManifoldHarmonicsOptions o;
  o.num_modes = static_cast<int>(state.range(0));
  save_basis(path, compute_manifold_harmonics(m, o), m);
  for (auto _ : state) benchmark::DoNotOptimize(load_basis(path, m).basis.data());
  std::filesystem::remove(path);
}

// Arguments: {m, subdivision levels}.
BENCHMARK_CAPTURE(BM_Basis, krylov, EigenSolver::BlockKrylov)
    ->ArgNames({"m", "subdiv"})
    ->Args({100, 0})
    ->Args({1000, 0})
    ->Args({100, 2})
    ->Unit(benchmark::kSecond)
    ->Iterations(1);
BENCHMARK_CAPTURE(BM_Basis, lanczos, EigenSolver::Lanczos)
    ->ArgNames({"m", "subdiv"})
    ->Args({100, 0})
    ->Unit(benchmark::kSecond)
    ->Iterations(1);
BENCHMARK(BM_LoadBasis)->ArgName("m")->Arg(100)->Arg(1000)->Unit(benchmark::kMillisecond);

// The plain baseline at m = 1000 takes minutes and over a gigabyte, and at 692k vertices
// minutes too: only on request.
const bool kSlow = [] {
  if (std::getenv("SPECDEFORM_BENCH_SLOW") != nullptr) {
    benchmark::RegisterBenchmark("BM_Basis/lanczos/m:1000/subdiv:0",
                                 [](benchmark::State& s) { BM_Basis(s, EigenSolver::Lanczos); })
        ->Args({1000, 0})
        ->Unit(benchmark::kSecond)
        ->Iterations(1);
    benchmark::RegisterBenchmark("BM_Basis/lanczos/m:100/subdiv:2",
                                 [](benchmark::State& s) { BM_Basis(s, EigenSolver::Lanczos); })
        ->Args({100, 2})
        ->Unit(benchmark::kSecond)
        ->Iterations(1);
  }
  return true;
}();

}  // namespace

BENCHMARK_MAIN();
