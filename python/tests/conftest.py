"""Shared helpers: the repository, the command-line binary the package is
compared with, and running it with --json."""

import json
import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
FIXTURES = REPO / "fixtures"
UR5_URDF = FIXTURES / "example-robot-data" / "ur5_robot.urdf"


def cli_path():
    p = Path(os.environ.get("ACTIVECAL_BIN", REPO / "target" / "debug" / "activecal"))
    if not p.is_file():
        pytest.fail(f"{p}: the activecal binary is not built (cargo build, or set ACTIVECAL_BIN)")
    return p


def cli(*args, cwd=None):
    """Runs `activecal ARGS --json` and returns the parsed JSON."""
    out = subprocess.run(
        [str(cli_path()), *map(str, args), "--json"],
        capture_output=True,
        text=True,
        cwd=cwd,
        env={**os.environ, "OPENBLAS_NUM_THREADS": "1"},
    )
    if out.returncode != 0:
        raise AssertionError(f"activecal {' '.join(map(str, args))}: exit {out.returncode}\n{out.stderr}")
    return json.loads(out.stdout)
