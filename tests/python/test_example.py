"""The example script runs headless and draws its two figures."""

import subprocess
import sys

from conftest import ROOT, shared_file

SCRIPT = ROOT / "examples" / "python" / "spectral_demo.py"


def run(tmp_path, *args):
    out = subprocess.run([sys.executable, SCRIPT, *args, "-o", tmp_path], capture_output=True,
                         text=True, check=True)
    for name in ("lowpass.png", "deform.png"):
        picture = (tmp_path / name).read_bytes()
        assert picture.startswith(b"\x89PNG") and len(picture) > 20000, name
    return out.stdout


def test_example_on_the_built_in_model(tmp_path):
    out = run(tmp_path)
    assert "100 harmonics" in out and "arap: frame" in out


def test_example_on_a_mesh_file(tmp_path):
    out = run(tmp_path, shared_file("models/cow.off"), "-m", "60")
    assert out.startswith("2762 vertices: 60 harmonics")
