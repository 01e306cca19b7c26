"""examples/python/capture_loop.py runs (so it never rots) and calibrates:
the true error after calibration within 1.3× the design's prediction."""

import json
import subprocess
import sys

import pytest

from conftest import REPO


@pytest.mark.parametrize("seed", [1, 3])
def test_capture_loop(tmp_path, seed):
    out = subprocess.run(
        [sys.executable, str(REPO / "examples" / "python" / "capture_loop.py"),
         "--out", str(tmp_path), "--seed", str(seed)],
        capture_output=True, text=True, check=True,
    )
    r = json.loads(out.stdout)
    assert r["true_rms_before_mm"] > 1.0
    assert r["true_rms_after_mm"] < 1.3 * r["predicted_rms_mm"], r
    for f in ("calibrated.urdf", "calibrated.yaml", "design.csv"):
        assert (tmp_path / f).is_file()
