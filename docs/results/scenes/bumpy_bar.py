#!/usr/bin/env python3
"""The scenes of docs/results.md ("Rotations") on a bar we generate.

Usage: docs/results/scenes/bumpy_bar.py SHAPE MESH [SPECDEFORM]

SHAPE is bumpy-bar (square, 4 long, 10,370 vertices) or bumpy-tube (round, 6 long, 6,962
vertices), as `specdeform generate SHAPE` makes it along x; the bar is written to MESH. Beside
this script: SHAPE-twist.json (the handle turned 150 degrees about the bar's axis) and
SHAPE-bend.json (the bar between 10% and 90% of its length bent into a 100-degree arc, the handle
moved and turned with the arc's end). The first tenth of the bar is fixed, the last tenth is the
handle. The scenes name no mesh: pass MESH on the command line.
"""
import json
import math
import subprocess
import sys
from pathlib import Path

def read_off_x(path):
    lines = Path(path).read_text().split("\n")
    n = int(lines[1].split()[0])
    return [float(line.split()[0]) for line in lines[2 : 2 + n]]


def write_scene(name, x, length, transform):
    scene = {
        "handles": [
            {"vertices": [i for i, v in enumerate(x) if v > 0.9 * length], "transform": transform}
        ],
        "fixed": [i for i, v in enumerate(x) if v < 0.1 * length],
        "settings": {"modes": 100},
    }
    (Path(__file__).parent / name).write_text(json.dumps(scene) + "\n")


def main():
    shape, mesh = sys.argv[1], sys.argv[2]
    specdeform = sys.argv[3] if len(sys.argv) > 3 else "build/bin/specdeform"
    subprocess.run([specdeform, "generate", shape, "-o", mesh], check=True)
    x = read_off_x(mesh)
    length = max(x)  # the bar starts at x = 0
    write_scene(
        f"{shape}-twist.json",
        x,
        length,
        {"rotate": {"axis": [1, 0, 0], "degrees": 150}, "center": [0, 0, 0]},
    )
    # A circular arc of angle t from a to b: its end, and the handle turned by t about z there.
    t, a, b = math.radians(100), 0.1 * length, 0.9 * length
    radius = (b - a) / t
    end = [a + radius * math.sin(t), radius * (1 - math.cos(t)), 0.0]
    write_scene(
        f"{shape}-bend.json",
        x,
        length,
        {
            "rotate": {"axis": [0, 0, 1], "degrees": 100},
            "center": [b, 0, 0],
            "translate": [round(end[0] - b, 12), round(end[1], 12), 0],
        },
    )


if __name__ == "__main__":
    main()
