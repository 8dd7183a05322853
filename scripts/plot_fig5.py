"""The paper's Fig. 5 from `specdeform bench -m ... --json`: time against m.

Usage: python3 scripts/plot_fig5.py FIG5.json OUT.svg   (matplotlib, Debian's python3-matplotlib)
Left: one frame and its stages, with the prefactored spatial solver of the same run for
reference. Right: the pre-computation (basis, reduced system).
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

rows = sorted(json.load(open(sys.argv[1])), key=lambda r: r["modes"])
m = [r["modes"] for r in rows]
ms = lambda key: [1e3 * r[key] for r in rows]  # noqa: E731

fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
left.plot(m, ms("frame"), "o-", label="frame (total)")
left.plot(m, ms("RT1_reduced_solve"), "s-", label="RT1 reduced solve")
left.plot(m, ms("inverse_transform"), "^-", label="inverse transform")
left.plot(m, ms("RT2_detail"), "v-", label="RT2 detail transfer")
left.plot(m, ms("spatial_prefactored_frame"), "k--", label="spatial, prefactored (baseline)")
left.set_xlabel("m (manifold harmonics)")
left.set_ylabel("ms per frame (median)")
left.set_title(f"{rows[0]['mesh']}, {rows[0]['vertices']:,} vertices: run time")
left.set_ylim(bottom=0)
left.legend(fontsize=8)
left.grid(alpha=0.3)

right.plot(m, [r["PT1_basis"] for r in rows], "o-", label="PT1 basis")
right.plot(m, [r["PT2_reduced_system"] for r in rows], "s-", label="PT2 reduced system")
right.plot(m, [r["spatial_from_scratch"] for r in rows], "k--", label="spatial solve from scratch")
right.set_xlabel("m (manifold harmonics)")
right.set_ylabel("seconds")
right.set_title("pre-computation")
right.set_ylim(bottom=0)
right.legend(fontsize=8)
right.grid(alpha=0.3)

fig.tight_layout()
fig.savefig(sys.argv[2])
