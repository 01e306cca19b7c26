#!/usr/bin/env python3
"""Select, move and measure, calibrate — the loop a capture script runs,
with Pinocchio standing in for the robot and the tracker.

The true robot is a UR5 (example-robot-data) whose joint origins are off
by 0.5-2 mm and 0.05-0.3 deg, measured by a tracker 2.6 m away through a
marker on the flange 2 mm from where the nominal model puts it
(verify/python/truth.py builds it). activecal chooses 30 poses, the loop
"moves the arm" to each and reads the tracker (with Gaussian noise), then
activecal calibrates, writes the calibrated URDF and frames file, and the
true error at 1000 random configurations is printed before and after,
beside the error the design predicted.

    .venv/bin/python examples/python/capture_loop.py [--out DIR] [--seed S]

Prints one JSON object (millimetres); python/tests runs it.
"""

import argparse
import json
import os
import sys
import tempfile
from pathlib import Path

import numpy as np

import activecal

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "verify" / "python"))
import truth  # noqa: E402  (the Pinocchio harness of verify/)

URDF = REPO / "fixtures" / "example-robot-data" / "ur5_robot.urdf"
TIP = "tool0"
NOISE = 50e-6  # the tracker's σ per coordinate, metres


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", help="directory for the calibrated files (default: a temporary one)")
    ap.add_argument("--seed", type=int, default=1, help="seed of the true robot and the noise")
    ap.add_argument("--n", type=int, default=30, help="poses to measure")
    a = ap.parse_args(argv)
    out = Path(a.out or tempfile.mkdtemp(prefix="capture_loop_"))
    out.mkdir(parents=True, exist_ok=True)

    # The true robot and tracker (Pinocchio), made once by truth.py.
    with open(os.devnull, "w") as quiet:
        saved, sys.stdout = sys.stdout, quiet
        try:
            truth.cmd_make(argparse.Namespace(
                urdf=str(URDF), base=None, tip=TIP, seed=a.seed, marker=None, pose=False,
                out=str(out / "truth.json")))
        finally:
            sys.stdout = saved
    world = truth.Truth(str(out / "truth.json"))
    rng = np.random.default_rng(a.seed)

    # 1. The poses to measure, for the nominal model and the nominal marker.
    robot = activecal.Robot.from_urdf(URDF, tip=TIP, marker=(TIP, truth.DEFAULT_MARKER))
    design = activecal.select(robot, a.n, noise=NOISE)
    design.write(out / "design.csv", overwrite=True)

    # 2. Move and measure: a real loop commands the arm to q and reads the
    # tracker; here Pinocchio's true robot answers.
    points = np.array([
        world.measured(q).translation + rng.normal(scale=NOISE, size=3) for q in design.q
    ])

    # 3. Calibrate and write the calibrated robot.
    cal = activecal.calibrate(robot, design.q, points)
    if not cal.converged:
        raise SystemExit("the calibration did not converge: %s" % cal.report["status"])
    cal.write_urdf(out / "calibrated.urdf", overwrite=True)
    cal.write_frames(out / "calibrated.yaml", overwrite=True)

    # 4. The true error at random configurations, before and after.
    qs = world.chain.random_configurations(1000, rng)
    before = truth.errors(world, world.nominal, world.tracker,
                          truth.iso_from_json(world.j["nominal_tool"]), qs)
    m, tool, _, base, tip, _ = truth.read_frames(str(out / "calibrated.yaml"))
    fitted = truth.Chain(str(out / "calibrated.urdf"), base or world.chain.base, tip or TIP)
    after = truth.errors(world, fitted, m, tool, qs)
    predicted = design.predicted["position_rms_mm"]
    print(json.dumps({
        "poses": len(design),
        "noise_mm": NOISE * 1e3,
        "fit_rms_mm": cal.residuals["position_rms_mm"],
        "true_rms_before_mm": before["rms_mm"],
        "true_rms_after_mm": after["rms_mm"],
        "predicted_rms_mm": predicted,
        "after_over_predicted": after["rms_mm"] / predicted,
        "out": str(out),
    }))


if __name__ == "__main__":
    main()
