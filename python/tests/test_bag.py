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
    with pytest.raises(activecal.InputError, match="max_offset: seconds"):
        activecal.extract(TINY, robot, points="/tracker", max_offset=-1.0)
    # A topic missing from the bag: the library's message, naming it.
    with pytest.raises(activecal.Error, match="/nothing"):
        activecal.extract(TINY, robot, points="/nothing")
    # No rest: the thresholds named.
    with pytest.raises(activecal.Error, match="no rest period"):
        activecal.extract(FIXTURES / "bags" / "moving.mcap", robot, points="/tracker")
