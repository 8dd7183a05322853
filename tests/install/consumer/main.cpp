// The installed library's manifold harmonics of the unit sphere: eigenvalues 0, then l (l + 1)
// = 2 three times, up to the discretisation. Exits 0 when they are, printing them.
#include <cmath>
#include <cstdio>

#include "specdeform/mesh/generate.h"
#include "specdeform/spectral/manifold_harmonics.h"

int main() {
  const specdeform::TriangleMesh sphere = specdeform::make_icosphere(4);
  specdeform::ManifoldHarmonicsOptions options;
  options.num_modes = 4;
  const specdeform::ManifoldHarmonics h = specdeform::compute_manifold_harmonics(sphere, options);
  bool ok = h.status == specdeform::SolveStatus::Converged && std::abs(h.eigenvalues[0]) < 1e-8;
  for (int k = 1; k < 4; ++k) ok = ok && std::abs(h.eigenvalues[k] - 2.0) < 0.02;
  std::printf("eigenvalues %.4f %.4f %.4f %.4f: %s\n", h.eigenvalues[0], h.eigenvalues[1],
              h.eigenvalues[2], h.eigenvalues[3], ok ? "ok" : "wrong");
  return ok ? 0 : 1;
}
