#!/usr/bin/env python3
"""The binding's overhead against the command line (issue #42's check):
`select` on the PUMA 560's 5-level lattice (15,625 poses, 30 chosen) and
`calibrate` on FIGAROH's UR10 full poses, each timed 10 times from Python
and through the CLI in alternation (paired); prints the medians and the
median of the paired ratios Python / CLI as JSON, of wall-clock time and
of CPU time (this process's threads, or the CLI's process).

    .venv/bin/python examples/python/overhead.py [--reps 10]

The CLI's time is the whole process (start, reading the inputs, printing
JSON); Python's is the call from loading the robot to the result's dict.
"""

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

import activecal

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "python" / "tests"))
from test_calibrate import figaroh_ur10  # noqa: E402

CLI = os.environ.get("ACTIVECAL_BIN", str(REPO / "target" / "debug" / "activecal"))
UR10 = REPO / "fixtures" / "figaroh" / "ur10_robot.urdf"
TIP = "ur10e_tooltip_link"


def timed(f):
    """Wall-clock seconds of f() and the CPU seconds it used: this
    process's (all threads) plus its children's (the CLI's process)."""
    def cpu():
        me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
        return me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime

    t0, c0 = time.perf_counter(), cpu()
    f()
    return time.perf_counter() - t0, cpu() - c0


def run_cli(*args):
    subprocess.run([CLI, *map(str, args), "--json"], check=True, stdout=subprocess.DEVNULL)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--reps", type=int, default=10)
    a = ap.parse_args()
    path, _, q, points, rot = figaroh_ur10()
    cases = {
        "select_puma_lattice": (
            lambda: activecal.select(activecal.Robot.builtin("puma560"), 30, pool="lattice").report,
            lambda: run_cli("select", "--robot", "puma560", "--n", 30, "--order", "none"),
        ),
        "calibrate_figaroh_ur10": (
            lambda: activecal.calibrate(
                activecal.Robot.from_urdf(UR10, tip=TIP, pose=True), q, points, orientations=rot
            ).report,
            lambda: run_cli("calibrate", "--robot", f"{UR10}:pose", "--tip", TIP,
                            "--measurements", path),
        ),
    }
    out = {}
    for name, (py, cli) in cases.items():
        py(), cli()  # warm the caches
        pairs = []
        for k in range(a.reps):
            # Alternate which goes first, so drift hits both.
            if k % 2:
                c, p = timed(cli), timed(py)
            else:
                p, c = timed(py), timed(cli)
            pairs.append((p, c))
        med = statistics.median
        out[name] = {
            "python_median_s": med(p[0] for p, _ in pairs),
            "cli_median_s": med(c[0] for _, c in pairs),
            "median_ratio_python_over_cli": med(p[0] / c[0] for p, c in pairs),
            # CPU time is what a loaded machine disturbs least.
            "python_median_cpu_s": med(p[1] for p, _ in pairs),
            "cli_median_cpu_s": med(c[1] for _, c in pairs),
            "median_cpu_ratio_python_over_cli": med(p[1] / c[1] for p, c in pairs),
            "reps": a.reps,
        }
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
