#!/usr/bin/python3
"""The manifold harmonics against scipy's eigsh (ARPACK shift-invert Lanczos on SuperLU), timed in
the same run on the same K and M, alternating, medians reported; both results checked with the
library's residual measure and against each other.

Usage (Debian's python3, after scripts/setup.sh):
  PYTHONPATH=build/python benchmarks/basis_vs_scipy.py [MESH] [-k 100] [--repeat 3] [--json F]
Default mesh: ../shared/meshes/models/armadillo.obj. eigsh gets the shift the library starts
from (-0.1 on the unit-area scale) and its default tolerance (machine precision).
"""
import argparse
import json
import statistics
import sys
import time

import numpy as np
import scipy.sparse.linalg

import specdeform


def residuals(K, M, H, lam):
    """Per pair: A ||K h - l M h||_{D^-1} / max(A l, 1), A the area, D M's row sums."""
    d = np.asarray(M.sum(axis=1)).ravel()
    area = d.sum()
    R = K @ H - (M @ H) * lam
    return area * np.sqrt((R * R / d[:, None]).sum(axis=0)) / np.maximum(area * lam, 1.0)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("mesh", nargs="?", default="../shared/meshes/models/armadillo.obj")
    parser.add_argument("-k", type=int, default=100, help="eigenpairs (default 100)")
    parser.add_argument("--repeat", type=int, default=3, help="runs of each (default 3)")
    parser.add_argument("--tolerance", type=float, default=None, help="the library's tolerance")
    parser.add_argument("--json", help="write the result here")
    args = parser.parse_args()

    V, F = specdeform.read_mesh(args.mesh)
    K = specdeform.cotan_stiffness(V, F).tocsc()
    M = specdeform.mass_matrix(V, F).tocsc()
    area = M.sum()
    sigma = -0.1 / area
    options = {} if args.tolerance is None else {"tolerance": args.tolerance}

    times = {"specdeform": [], "scipy": []}
    for _ in range(args.repeat):
        start = time.perf_counter()
        ours = specdeform.manifold_harmonics(V, F, args.k, **options)
        times["specdeform"].append(time.perf_counter() - start)
        start = time.perf_counter()
        theirs = scipy.sparse.linalg.eigsh(K, args.k, M, sigma=sigma, which="LM")
        times["scipy"].append(time.perf_counter() - start)

    ours_l, ours_h = np.asarray(ours[0]), np.asarray(ours[1])
    order = np.argsort(theirs[0])
    theirs_l, theirs_h = theirs[0][order], theirs[1][:, order]
    scale = np.maximum(np.abs(theirs_l), 1.0 / area)
    median = {name: statistics.median(t) for name, t in times.items()}
    result = {
        "mesh": args.mesh,
        "vertices": int(V.shape[0]),
        "k": args.k,
        "runs": args.repeat,
        "seconds": times,
        "median_seconds": median,
        "ratio": median["specdeform"] / median["scipy"],
        "max_residual": {
            "specdeform": float(residuals(K, M, ours_h, ours_l).max()),
            "scipy": float(residuals(K, M, theirs_h, theirs_l).max()),
        },
        "eigenvalue_agreement": float((np.abs(ours_l - theirs_l) / scale).max()),
    }
    print(
        f"{args.mesh}: n = {result['vertices']}, k = {args.k}: specdeform {median['specdeform']:.2f} s,"
        f" scipy eigsh {median['scipy']:.2f} s (median of {args.repeat}), ratio {result['ratio']:.2f};"
        f" residuals {result['max_residual']['specdeform']:.1e} / {result['max_residual']['scipy']:.1e};"
        f" eigenvalues agree to {result['eigenvalue_agreement']:.1e}"
    )
    if args.json:
        with open(args.json, "w") as f:
            json.dump(result, f, indent=1)


if __name__ == "__main__":
    sys.exit(main())
