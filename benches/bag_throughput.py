"""Bag reading and rest detection against rosbags (issue #52's acceptance:
at least as fast as `rosbags` reading the same bag in Python). Writes the
bag of a simulated calibration run with rosbags (verify/python/bag_truth.py:
the true UR5 through a 30-pose design, /joint_states at 1 kHz, a tracker at
100 Hz, 170 MB of raw images on a camera topic: about 226 MB) in MCAP and in
SQLite 3, then times, in turn A B A B ..., `activecal extract BAG --points
/tracker --time-offset 0` (read, rests, averages; the clock offset given, as
the Python side does not estimate it) against benches/bag_rosbags_read.py
(rosbags reads and deserialises /joint_states and /tracker, NumPy finds the
rests and averages). Prints each side's median wall time, the median of the
pairs' ratios (rosbags / activecal), and activecal's median with the clock
offset estimated. Exits 1 when activecal is the slower. A benchmark, not a
test (a minute or two, 450 MB of disk).

Usage: .venv/bin/python benches/bag_throughput.py [--runs N] [--dir DIR]
Environment: ACTIVECAL_BIN (default target/debug/activecal; `cargo build`,
the dev profile is optimised).
"""

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PY = os.path.join(ROOT, ".venv", "bin", "python")
URDF = os.path.join(ROOT, "fixtures", "example-robot-data", "ur5_robot.urdf")


def run(cmd, cwd):
    subprocess.run(cmd, cwd=cwd, check=True, stdout=subprocess.DEVNULL,
                   env={**os.environ, "OPENBLAS_NUM_THREADS": "1"})


def timed(cmd, cwd):
    t = time.perf_counter()
    run(cmd, cwd)
    return time.perf_counter() - t


def setup(d, bin_):
    verify = os.path.join(ROOT, "verify", "python")
    run([PY, "-W", "ignore", os.path.join(verify, "truth.py"), "make", "--urdf", URDF, "--tip", "tool0",
         "--seed", "7", "--out", "truth.json"], d)
    run([PY, "-W", "ignore", os.path.join(verify, "truth.py"), "sensor-frames", "--truth", "truth.json",
         "--out", "nominal.yaml"], d)
    run([bin_, "select", "--robot", URDF, "--frames", "nominal.yaml", "--pool", "random", "--count", "2048",
         "--pool-seed", "7", "--n", "30", "--noise", "5e-5", "--seed", "7", "--out", "design.csv", "--force",
         "--json"], d)
    for storage in ("mcap", "sqlite3"):
        shutil.rmtree(os.path.join(d, storage), ignore_errors=True)
        run([PY, "-W", "ignore", os.path.join(verify, "bag_truth.py"), "write", "--truth", "truth.json",
             "--design", "design.csv", "--out", storage, "--storage", storage, "--joint-rate", "1000",
             "--image-mb", "170"], d)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--dir")
    a = ap.parse_args()
    bin_ = os.environ.get("ACTIVECAL_BIN", os.path.join(ROOT, "target", "debug", "activecal"))
    d = a.dir or tempfile.mkdtemp()
    os.makedirs(d, exist_ok=True)
    slower = False
    try:
        setup(d, bin_)
        for storage in ("mcap", "sqlite3"):
            size = sum(os.path.getsize(os.path.join(r, f)) for r, _, fs in os.walk(os.path.join(d, storage))
                       for f in fs) / 1e6
            extract = [bin_, "extract", storage, "--robot", URDF, "--frames", "nominal.yaml", "--points",
                       "/tracker", "--out", "m.csv", "--force", "--json"]
            ours = extract + ["--time-offset", "0"]
            theirs = [PY, os.path.join(ROOT, "benches", "bag_rosbags_read.py"), storage]
            timed(ours, d), timed(theirs, d)  # warm-up: the page cache holds the bag
            pairs = [(timed(ours, d), timed(theirs, d)) for _ in range(a.runs)]
            clock = [timed(extract, d) for _ in range(a.runs)]
            a_med = statistics.median(p[0] for p in pairs)
            b_med = statistics.median(p[1] for p in pairs)
            ratio = statistics.median(p[1] / p[0] for p in pairs)
            print(json.dumps({"storage": storage, "bag_mb": round(size, 1), "runs": a.runs,
                              "activecal_s": round(a_med, 3), "rosbags_s": round(b_med, 3),
                              "rosbags_over_activecal": round(ratio, 2),
                              "activecal_with_clock_estimate_s": round(statistics.median(clock), 3)}))
            slower |= ratio < 1.0
    finally:
        if not a.dir:
            shutil.rmtree(d, ignore_errors=True)
    return 1 if slower else 0


if __name__ == "__main__":
    sys.exit(main())
