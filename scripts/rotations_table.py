#!/usr/bin/env python3
"""The summary table of docs/results.md ("Rotations") from `specdeform compare` runs.

Usage: scripts/rotations_table.py OUT.md SCENE=ROWS.json...

One row per scene; in each cell linear spectral / spectral ARAP / SR-ARAP at equal time /
SR-ARAP converged, those that apply: the smallest ring radius over the original (closed bars),
the RMS distance to the converged SR-ARAP and the smooth base's handle miss (% of the diagonal;
SR-ARAP's constraints are hard), inverted faces, the frame and SR-ARAP's time to converge.
"""
import json
import sys

LINEAR, ARAP = "linear, spectral", "ARAP, spectral"
EQUAL, CONVERGED = "SR-ARAP (CGAL), equal time", "SR-ARAP (CGAL), converged"


def ring(r):
    return "-" if r["smallest_cross_section"] is None else f"{r['smallest_cross_section']:.2f}"


def percent(fraction):
    return f"{100 * fraction:.2f}"


def frame(r):
    t = r["frame_ms"]
    text = f"{t:.3g}" if t < 100 else f"{t:.0f}"
    return text + (f" ({r['iterations']} it.)" if r["method"] == EQUAL else "")


def converged(r):
    cap = "" if r["converged"] else ", not converged"
    return f"{r['frame_ms'] / 1e3:.1f} ({r['iterations']} it.{cap})"


COLUMNS = [
    ("smallest ring radius / original", [LINEAR, ARAP, EQUAL, CONVERGED], ring),
    ("RMS to converged SR-ARAP (%)", [LINEAR, ARAP, EQUAL], lambda r: percent(r["rms_to_sr_arap"])),
    ("base handle miss (%)", [LINEAR, ARAP], lambda r: percent(r["base_handle_miss"])),
    ("inverted faces", [LINEAR, ARAP, EQUAL, CONVERGED], lambda r: str(r["inverted_faces"])),
    ("frame (ms)", [LINEAR, ARAP, EQUAL], frame),
    ("SR-ARAP converged (s)", [CONVERGED], converged),
]


def main():
    out, runs = sys.argv[1], sys.argv[2:]
    text = "| scene | " + " | ".join(name for name, _, _ in COLUMNS) + " |\n"
    text += "|---" + "|---:" * len(COLUMNS) + "|\n"
    for run in runs:
        scene, path = run.split("=", 1)
        rows = {r["method"]: r for r in json.load(open(path))}
        cells = [" / ".join(f(rows[m]) for m in methods) for _, methods, f in COLUMNS]
        text += f"| {scene} | " + " | ".join(cells) + " |\n"
    open(out, "w").write(text)


if __name__ == "__main__":
    main()
