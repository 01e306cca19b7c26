"""activecal.extract: a ROS 2 bag's rests as the table `activecal extract
--out` writes (the committed bags of fixtures/bags, written by rosbags)."""

import pandas as pd
import pytest

import activecal
from conftest import FIXTURES, cli

UR5 = FIXTURES / "ur5.urdf"
TINY = FIXTURES / "bags" / "tiny.mcap"


@pytest.mark.parametrize("bag", ["tiny.mcap", "tiny_db3"])
def test_extract_is_the_table_the_command_line_writes(tmp_path, bag):
    path = FIXTURES / "bags" / bag
    out = tmp_path / "m.csv"
    cli("extract", str(path), "--robot", str(UR5), "--points", "/tracker", "--out", str(out))
    want = pd.read_csv(out)
    got = activecal.extract(path, activecal.Robot.from_urdf(str(UR5)), points="/tracker")
    assert list(got.columns) == list(want.columns)
    assert len(got) == 3
    pd.testing.assert_frame_equal(got, want, check_exact=True)
    report = got.attrs["report"]
    assert len(report["rests"]) == 3
    assert all(r["left_out"] is None for r in report["rests"])
    assert report["joints"] == "/joint_states"


def test_extract_refuses_what_the_command_line_refuses():
    robot = activecal.Robot.from_urdf(str(UR5))
    with pytest.raises(activecal.InputError, match="give the bag's measurement"):
        activecal.extract(TINY, robot)
    with pytest.raises(activecal.InputError, match="tf world: give PARENT:CHILD"):
        activecal.extract(TINY, robot, tf="world")
    with pytest.raises(activecal.InputError, match="max_offset -1: give seconds"):
        activecal.extract(TINY, robot, points="/tracker", max_offset=-1.0)
    # A topic missing from the bag: the library's message, naming it.
    with pytest.raises(activecal.Error, match="/nothing"):
        activecal.extract(TINY, robot, points="/nothing")
    # No rest: the thresholds named.
    with pytest.raises(activecal.Error, match="no rest period"):
        activecal.extract(FIXTURES / "bags" / "moving.mcap", robot, points="/tracker")


def cli_any_status(*args):
    """`activecal ARGS --json`: its exit status and JSON (a fit of the tiny
    bag's three rests may end with a non-zero verdict; the JSON is printed
    all the same)."""
    import json
    import os
    import subprocess

    from conftest import cli_path

    out = subprocess.run([str(cli_path()), *map(str, args), "--json"], capture_output=True, text=True,
                         env={**os.environ, "OPENBLAS_NUM_THREADS": "1"})
    assert "panicked" not in out.stderr, out.stderr
    return out.returncode, json.loads(out.stdout)


@pytest.mark.parametrize("bag", ["tiny.mcap", "tiny_db3"])
def test_calibrate_from_a_bag_is_the_command_lines_fit(bag):
    """calibrate(bag=...) runs the pipeline of `calibrate --bag`: the same
    fitted parameters (1e-12 relative: the same computation in the same
    order, so only the JSON's decimal round trip may differ, ~1e-16), the
    same verdict and the same extraction report."""
    path = FIXTURES / "bags" / bag
    status, want = cli_any_status("calibrate", "--robot", UR5, "--bag", path, "--points", "/tracker")
    cal = activecal.calibrate(activecal.Robot.from_urdf(str(UR5)), bag=path, points="/tracker")
    got = dict(cal.estimate)
    names = [p["name"] for p in want["parameters"]]
    assert names and sorted(names) == sorted(got)
    for p in want["parameters"]:
        x, y = p["estimate"], got[p["name"]]
        assert abs(x - y) <= 1e-12 * max(abs(x), abs(y)), (p["name"], x, y)
    assert cal.report["exit_status"] == want["exit_status"] == status
    assert cal.report["poses"] == want["poses"] == 3
    assert cal.report["bag"] == want["bag"]
    assert [r["left_out"] for r in cal.report["bag"]["extraction"]["rests"]] == [None] * 3


def test_calibrate_from_a_bag_pickles_by_its_call():
    import pickle

    cal = activecal.calibrate(activecal.Robot.from_urdf(str(UR5)), bag=TINY, points="/tracker")
    back = pickle.loads(pickle.dumps(cal))
    assert dict(back.estimate) == dict(cal.estimate)
    assert back.report["bag"] == cal.report["bag"]


def test_calibrate_from_a_bag_refuses_arrays_and_a_missing_measurement():
    import numpy as np

    robot = activecal.Robot.from_urdf(str(UR5))
    with pytest.raises(activecal.InputError, match="give the bag's measurement"):
        activecal.calibrate(robot, bag=TINY)
    with pytest.raises(activecal.InputError, match="^q: with bag"):
        activecal.calibrate(robot, np.zeros((3, 6)), bag=TINY, points="/tracker")
    with pytest.raises(activecal.InputError, match="^orientations: with bag"):
        activecal.calibrate(robot, bag=TINY, points="/tracker", orientations=np.zeros((3, 3, 3)))
    with pytest.raises(activecal.InputError, match="^points: with bag, the bag's geometry_msgs/msg/PointStamped topic"):
        activecal.calibrate(robot, bag=TINY, points=np.zeros((3, 3)))
    with pytest.raises(activecal.InputError, match="^q: give q and points"):
        activecal.calibrate(robot)
    with pytest.raises(activecal.InputError, match="^points: give q and points"):
        activecal.calibrate(robot, np.zeros((3, 6)))
    # The library's refusals, as the command line's: a missing topic named.
    with pytest.raises(activecal.Error, match="/nothing"):
        activecal.calibrate(robot, bag=TINY, points="/nothing")
