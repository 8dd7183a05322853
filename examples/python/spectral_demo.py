#!/usr/bin/env python3
"""specdeform from Python: a mesh's manifold harmonics, a low-pass series and a deformation.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/spectral_demo.py [MESH] [-o DIR]

Writes DIR/lowpass.png (the mesh rebuilt from its first k frequencies, the paper's Fig. 2) and
DIR/deform.png (the mesh bent by a handle at one end, the other end fixed, with the linear
energy and with ARAP). Without MESH, the built-in bumpy bar. --show opens the figures instead.
"""

import argparse
import os
import time

import matplotlib
import numpy as np

import specdeform


def rotation(axis: int, degrees: float, center: np.ndarray, shift: np.ndarray) -> np.ndarray:
    """4 x 4: a rotation about the line through `center` along `axis`, then a translation."""
    a = np.radians(degrees)
    c, s = np.cos(a), np.sin(a)
    i, j = [k for k in range(3) if k != axis]
    R = np.eye(3)
    R[i, i], R[i, j], R[j, i], R[j, j] = c, -s, s, c
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = center - R @ center + shift
    return T


def draw(ax, V: np.ndarray, F: np.ndarray, title: str, extent: np.ndarray) -> None:
    ax.plot_trisurf(V[:, 0], V[:, 1], V[:, 2], triangles=F, color="#b8c4d6", linewidth=0,
                    antialiased=False, shade=True)
    center = V.mean(axis=0)
    for set_lim, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), center):
        set_lim(c - extent / 2, c + extent / 2)
    ax.set_box_aspect((1, 1, 1))
    ax.set_axis_off()
    ax.set_title(title, fontsize=9)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("mesh", nargs="?", help="OBJ, OFF, PLY or STL (default: bumpy bar)")
    parser.add_argument("-o", "--output", default=".", help="folder for the pictures")
    parser.add_argument("-m", "--modes", type=int, default=100, help="harmonics (default 100)")
    parser.add_argument("--show", action="store_true", help="open the figures")
    args = parser.parse_args()
    if not args.show:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if args.mesh:
        V, F = specdeform.read_mesh(args.mesh)
    else:
        V, F = specdeform.bumpy_bar(cells_per_unit=12, bump_height=0.06)
    start = time.perf_counter()
    evals, evecs = specdeform.manifold_harmonics(V, F, args.modes)
    print(f"{len(V)} vertices: {args.modes} harmonics in {time.perf_counter() - start:.2f} s, "
          f"eigenvalues {evals[1]:.4g} ... {evals[-1]:.4g}")

    # The low-pass series: the shape from its first k frequencies.
    extent = np.ptp(V, axis=0).max()
    series = [k for k in (6, 20, 50) if k < args.modes] + [args.modes]
    fig = plt.figure(figsize=(3 * (len(series) + 1), 3))
    for i, k in enumerate(series):
        ax = fig.add_subplot(1, len(series) + 1, i + 1, projection="3d")
        draw(ax, specdeform.low_pass(V, F, evecs, k), F, f"k = {k}", extent)
    draw(fig.add_subplot(1, len(series) + 1, len(series) + 1, projection="3d"), V, F, "mesh",
         extent)
    os.makedirs(args.output, exist_ok=True)
    fig.savefig(os.path.join(args.output, "lowpass.png"), dpi=120, bbox_inches="tight")

    # A deformation: along the longest axis, the last 10% is the handle, turned by 60 degrees
    # and lifted; the first 10% is fixed.
    axes = np.argsort(np.ptp(V, axis=0))[::-1]
    along = V[:, axes[0]]
    low, high = np.quantile(along, [0.1, 0.9])
    handle, fixed = along >= high, along <= low
    T = rotation(axes[2], 60.0, V[handle].mean(axis=0), 0.1 * extent * np.eye(3)[axes[1]])
    fig = plt.figure(figsize=(9, 3))
    draw(fig.add_subplot(1, 3, 1, projection="3d"), V, F, "rest", 1.4 * extent)
    for i, energy in enumerate(("linear", "arap")):
        deformer = specdeform.SpectralDeformer(V, F, basis=(evals, evecs), energy=energy)
        deformer.set_selection(handles=[handle], fixed=fixed)
        X = deformer.solve([T])
        frame = deformer.timings["frame"]["total"]
        print(f"{energy}: frame {1e3 * frame:.1f} ms, {deformer.report['iterations']} iterations")
        draw(fig.add_subplot(1, 3, i + 2, projection="3d"), X, F, energy, 1.4 * extent)
    fig.savefig(os.path.join(args.output, "deform.png"), dpi=120, bbox_inches="tight")
    print(f"wrote {args.output}/lowpass.png and {args.output}/deform.png")
    if args.show:
        plt.show()


if __name__ == "__main__":
    main()
