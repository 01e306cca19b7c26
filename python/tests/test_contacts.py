"""calibrate_contacts: the same fit and figures as `activecal calibrate` on
MUKCa's contact file, the same written files, and its errors."""

import csv

import numpy as np
import pytest

import activecal
from conftest import FIXTURES, cli

PANDA = FIXTURES / "mukca" / "panda.urdf"
CSV = FIXTURES / "mukca" / "panda_2.csv"


def rows():
    with open(CSV) as f:
        r = list(csv.reader(f))
    head, body = r[0], r[1:]
    q = np.array([[float(x) for x in row[:-1]] for row in body])
    return head[:-1], q, [row[-1] for row in body]


def test_mukca_panda_equals_the_cli(tmp_path):
    names, q, touched = rows()
    blocks = sorted({t.split("/")[0] for t in touched})
    distances = {(f"{b}/0", f"{b}/1"): 0.05 for b in blocks}
    args = ["--robot", PANDA, "--tip", "ball_link", "--measurements", CSV]
    for b in blocks:
        args += ["--point-distance", f"{b}/0,{b}/1=0.05"]
    urdf, frames = tmp_path / "cli.urdf", tmp_path / "cli.yaml"
    want = cli("calibrate", *args, "--out", urdf, "--out", frames)
    r = activecal.Robot.from_urdf(PANDA, tip="ball_link")
    assert r.joint_names == names
    c = activecal.calibrate_contacts(r, q, touched, distances)
    got = c.report
    for k in ("fit", "in_sample", "downweighted", "predicted_true_error", "frames", "rows"):
        assert got[k] == want[k], k
    assert c.converged and got["exit_status"] == 0
    assert c.estimate == dict(zip(want["fit"]["names"], want["fit"]["estimate"]))
    assert set(c.points) == set(touched)
    c.write_urdf(tmp_path / "py.urdf")
    c.write_frames(tmp_path / "py.yaml")
    assert (tmp_path / "py.urdf").read_text() == urdf.read_text()
    assert (tmp_path / "py.yaml").read_text() == frames.read_text()


def test_contact_errors_name_the_argument():
    names, q, touched = rows()
    r = activecal.Robot.from_urdf(PANDA, tip="ball_link")
    with pytest.raises(activecal.InputError, match="^points: 3 names"):
        activecal.calibrate_contacts(r, q, touched[:3], {("a", "b"): 0.05})
    with pytest.raises(activecal.InputError, match="^distances"):
        activecal.calibrate_contacts(r, q, touched, [])
    with pytest.raises(activecal.InputError, match="^distances: .*no point 'nowhere/0'"):
        activecal.calibrate_contacts(r, q, touched, {("nowhere/0", "front_left/0"): 0.05})
    with pytest.raises(activecal.InputError, match="^distances: a dict"):
        activecal.calibrate_contacts(r, q, touched, 0.05)
