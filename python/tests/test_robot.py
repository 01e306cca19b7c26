"""Robot: loading, joints, limits, unknowns and forward kinematics against
the command line."""

import numpy as np
import pytest

import activecal
from conftest import UR5_URDF, cli


def test_version():
    assert activecal.__version__ == "0.1.0"


def test_builtin_matches_the_cli():
    r = activecal.Robot.builtin("puma560")
    robots = cli("robots")
    entry = next(x for x in robots["robots"] if x["name"] == "puma560") if isinstance(robots, dict) else None
    assert r.dof == 6
    assert r.limits.shape == (6, 2) and r.limits.dtype == np.float64
    if entry is not None:
        assert np.array_equal(r.limits, np.array(entry["limits"]))
    assert len(r.unknowns) == 27
    assert r.joint_names == ["0", "1", "2", "3", "4", "5"]


@pytest.mark.parametrize("q", [[0.1, 0.2, 0.3, 0.4, 0.5, 0.6], [-1.0, 0.5, -0.3, 2.0, -1.2, 3.0]])
def test_fk_equals_the_cli(q):
    r = activecal.Robot.builtin("puma560:pose")
    R, p = r.fk(np.array(q))
    want = cli("fk", "--robot", "puma560:pose", "--q", ",".join(map(repr, q)))
    assert R.shape == (3, 3) and p.shape == (3,)
    assert np.array_equal(p, np.array(want["position"]))
    assert np.allclose(R.T @ R, np.eye(3), atol=1e-14)


def test_urdf_with_a_marker():
    a = activecal.Robot.from_urdf(UR5_URDF, tip="tool0", marker=("tool0", (0.031, -0.024, 0.097)))
    b = activecal.Robot.from_urdf(str(UR5_URDF), tip="tool0", marker="tool0@0.031,-0.024,0.097")
    assert a.unknowns == b.unknowns
    assert a.unknowns[-3:] == ["marker1_x", "marker1_y", "marker1_z"]
    assert a.joint_names == [
        "shoulder_pan_joint",
        "shoulder_lift_joint",
        "elbow_joint",
        "wrist_1_joint",
        "wrist_2_joint",
        "wrist_3_joint",
    ]
    q = np.zeros(6)
    want = cli("fk", "--robot", UR5_URDF, "--tip", "tool0", "--q", "0,0,0,0,0,0")
    assert np.array_equal(activecal.Robot.from_urdf(UR5_URDF, tip="tool0").fk(q)[1], want["position"])


@pytest.mark.parametrize(
    "q, words",
    [
        ([0.0, 1.0, 2.0], ["q:", "shape (6,)", "(3,)"]),
        ([[0.0] * 6], ["q:", "shape (6,)", "(1, 6)"]),
        ([0.0, 0.1, float("nan"), 0, 0, 0], ["q:", "q[2]", "not a finite number"]),
        ([0.0, 0.1, 0.2, 0, 0, "x"], ["q:", "not an array of numbers"]),
        ([0.0, 90.0, 0.0, 0.0, 0.0, 0.0], ["q", "limit"]),
    ],
)
def test_fk_refuses_bad_joint_values_naming_q(q, words):
    r = activecal.Robot.builtin("puma560")
    with pytest.raises(activecal.Error) as e:
        r.fk(q)
    for w in words:
        assert w in str(e.value), str(e.value)


def test_loading_errors_name_what_is_wrong():
    with pytest.raises(activecal.Error, match="unknown robot 'nope'"):
        activecal.Robot.builtin("nope")
    with pytest.raises(activecal.Error, match="^path: .*no such file"):
        activecal.Robot.from_urdf("/nonexistent.urdf")
    with pytest.raises(activecal.Error, match="^marker: "):
        activecal.Robot.from_urdf(UR5_URDF, tip="tool0", marker="tool0@1,2")
    with pytest.raises(activecal.Error, match="nope"):
        activecal.Robot.from_urdf(UR5_URDF, tip="nope")
    with pytest.raises(activecal.Error, match="nope_joint"):
        activecal.Robot.from_urdf(UR5_URDF, tip="tool0", lock={"nope_joint": 0.1})


@pytest.mark.parametrize("name", ["puma560", "ur5:pose"])
def test_jacobian_equals_the_cli(name):
    r = activecal.Robot.builtin(name)
    q = [0.3, -0.4, 0.5, -0.6, 0.7, -0.8]
    want = cli("fk", "--robot", name, "--q", ",".join(map(repr, q)), "--jacobian")
    j = r.jacobian(q)
    assert j.shape == (6 if r.measures_orientation else 3, len(r.unknowns))
    assert want["parameter_names"] == r.unknowns
    assert np.array_equal(j, np.array(want["jacobian"]))
