"""Calibrations in the user's stack (issue #53): a xacro description that
reads a kinematics file, expanded by the `xacro` package from PyPI, against
a URDF, both in Pinocchio.

Usage (run with the project venv's python; prints one JSON object):

  stack.py xacro-fk --xacro D.urdf.xacro --arg NAME:=FILE [--arg ...]
                    --urdf U --tip LINK [--base LINK] [--n 1000] [--seed S]
                    [--out expanded.urdf]
      Expands D with the arguments (as `xacro D NAME:=FILE` does), and
      compares its chain base..tip with U's at N random configurations
      within U's joint limits: the largest distance of the tip's position
      (metres) and the largest angle between the tip's orientations
      (radians), base frame to tip frame (truth.py's Chain.relative).
"""

import argparse
import json
import os
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import truth  # noqa: E402  (the Chain of the truth gate)


def expand(path, args):
    import xacro

    mappings = {}
    for a in args:
        k, v = a.split(":=", 1)
        mappings[k] = v
    doc = xacro.process_file(path, mappings=mappings)
    return doc.toprettyxml(indent="  ")


def cmd_xacro_fk(a):
    text = expand(a.xacro, a.arg)
    out = a.out or tempfile.mkstemp(suffix=".urdf")[1]
    with open(out, "w") as f:
        f.write(text)
    ref = truth.Chain(a.urdf, a.base, a.tip)
    exp = truth.Chain(out, a.base, a.tip)
    if ref.names != exp.names:
        raise SystemExit("chains differ: %s vs %s" % (ref.names, exp.names))
    qs = ref.random_configurations(a.n, np.random.default_rng(a.seed))
    dp, dr = 0.0, 0.0
    for q in qs:
        x, y = ref.relative(q), exp.relative(q)
        dp = max(dp, float(np.linalg.norm(x.translation - y.translation)))
        dr = max(dr, float(np.linalg.norm(truth.log3(x.rotation.T @ y.rotation))))
    print(json.dumps({"n": a.n, "max_position_m": dp, "max_rotation_rad": dr,
                      "joints": ref.names}))


def main(argv=None):
    p = argparse.ArgumentParser()
    sub = p.add_subparsers(dest="cmd", required=True)
    x = sub.add_parser("xacro-fk")
    x.add_argument("--xacro", required=True)
    x.add_argument("--arg", action="append", default=[])
    x.add_argument("--urdf", required=True)
    x.add_argument("--tip", required=True)
    x.add_argument("--base")
    x.add_argument("--n", type=int, default=1000)
    x.add_argument("--seed", type=int, default=0)
    x.add_argument("--out")
    a = p.parse_args(argv)
    {"xacro-fk": cmd_xacro_fk}[a.cmd](a)


if __name__ == "__main__":
    main()
