"""Design.how_many, select's visiting order, calibrate's compliance and
DataFrame inputs: each against the CLI's JSON on the same inputs (floats
to 1e-12, integers and strings exactly)."""

import json
import math

import numpy as np
import pytest

import activecal
from conftest import FIXTURES, UR5_URDF, cli
from test_calibrate import assert_same_fit, figaroh_ur10

# What differs between two runs of the same work: the clock.
CLOCK = {"seconds", "elapsed_seconds"}


def assert_close(py, want, path="", tol=1e-12):
    """Equal JSON values: floats within tol (absolute, relative above 1),
    everything else exactly; clock keys skipped."""
    if isinstance(want, dict):
        assert isinstance(py, dict) and set(py) == set(want), (path, set(py) ^ set(want))
        for k in want:
            if k not in CLOCK:
                assert_close(py[k], want[k], f"{path}.{k}", tol)
    elif isinstance(want, list):
        assert isinstance(py, list) and len(py) == len(want), path
        for i, (a, b) in enumerate(zip(py, want)):
            assert_close(a, b, f"{path}[{i}]", tol)
    elif isinstance(want, float) and not isinstance(py, bool):
        assert isinstance(py, (int, float)), path
        assert abs(py - want) <= tol * max(1.0, abs(want)), (path, py, want)
    else:
        assert type(py) is type(want) and py == want, (path, py, want)


def test_how_many_equals_the_clis_report(tmp_path):
    r = activecal.Robot.builtin("puma560")
    d = activecal.select(r, 12, pool="sobol", count=256, noise=1e-4, order="none")
    rep = tmp_path / "rep"
    cli("select", "--robot", "puma560", "--pool", "sobol", "--count", 256, "--n", 12,
        "--noise", 1e-4, "--order", "none", "--report", rep)
    want = json.loads((rep / "report.json").read_text())["how_many_poses"]
    got = d.how_many()
    assert_close(got, want)
    # p = 27 unknowns, 3 rows a pose: from 9 poses, the 12 asked among them.
    assert got["n_min"] == 9 and 12 in [p["n"] for p in got["points"]]
    # A target changes only the recommendation's rule.
    t = d.how_many(target_error=1e3)
    assert t["recommended"]["rule"] == "target" and t["points"] == got["points"]


@pytest.mark.parametrize(
    "kwargs, words",
    [
        (dict(noise=0.0), ["noise:", "> 0"]),
        (dict(noise=float("inf")), ["noise:"]),
        (dict(target_error=-1.0), ["target_error:", "mm"]),
    ],
)
def test_how_many_errors(kwargs, words):
    d = activecal.select(activecal.Robot.builtin("puma560"), 10, pool="sobol", count=128)
    with pytest.raises(activecal.InputError) as e:
        d.how_many(**kwargs)
    for w in words:
        assert w in str(e.value), str(e.value)


def test_visiting_order_equals_the_cli(tmp_path):
    # The UR5's URDF states joint speed limits: by default the poses are
    # ordered by time, as the CLI orders them without --order.
    r = activecal.Robot.from_urdf(UR5_URDF, tip="tool0")
    d = activecal.select(r, 20, count=512)
    out = tmp_path / "cli.json"
    want = cli("select", "--robot", UR5_URDF, "--tip", "tool0", "--pool", "random",
               "--count", 512, "--n", 20, "--out", out)
    assert "tour" in want and d.report["tour"] == want["tour"]
    assert d.ids == [c["id"] for c in want["configurations"]]
    assert np.array_equal(d.q, np.array([c["q"] for c in want["configurations"]]))
    assert sorted(d.ids) == sorted(want["poses"])
    mine = tmp_path / "py.json"
    d.write(mine)
    assert json.loads(mine.read_text()) == json.loads(out.read_text())
    # The tour is shorter than selection order (or as short).
    t = d.report["tour"]
    assert t["visiting_order"]["time_s"] <= t["selection_order"]["time_s"]
    # order="none" keeps selection order, as --order none.
    n = activecal.select(r, 20, count=512, order="none")
    want = cli("select", "--robot", UR5_URDF, "--tip", "tool0", "--pool", "random",
               "--count", 512, "--n", 20, "--order", "none")
    assert n.ids == want["poses"] == [c["id"] for c in want["configurations"]]
    assert n.report["tour"] == want["tour"]
    with pytest.raises(activecal.InputError, match="order: unknown order 'fast'"):
        activecal.select(r, 20, count=512, order="fast")


def test_order_with_collision_filters_checks_moves_as_the_cli():
    ur10 = FIXTURES / "example-robot-data" / "ur10_robot.urdf"
    r = activecal.Robot.from_urdf(ur10, tip="tool0")
    p = activecal.pool(
        r, "random", count=150, self_collision=True, floor=0.0, package_dirs=[FIXTURES]
    )
    d = activecal.select(r, 30, pool=p)
    want = cli(
        "select", "--robot", ur10, "--tip", "tool0", "--pool", "random", "--count", 150,
        "--self-collision", "--floor", 0, "--package-dir", FIXTURES, "--n", 30,
    )
    assert "moves" in want and d.report["moves"] == want["moves"]
    assert d.report["tour"] == want["tour"]
    assert d.report.get("swapped") == want.get("swapped")
    assert d.ids == [c["id"] for c in want["configurations"]]
    assert np.array_equal(d.q, np.array([c["q"] for c in want["configurations"]]))
    assert d.ln_oid == want["ln_oid"]


def test_compliance_equals_the_cli():
    path, joints, q, points, rot = figaroh_ur10()
    urdf = FIXTURES / "figaroh" / "ur10_robot.urdf"
    want = cli("calibrate", "--robot", f"{urdf}:pose", "--tip", "wrist_3_link",
               "--measurements", path, "--compliance")
    r = activecal.Robot.from_urdf(urdf, tip="wrist_3_link", pose=True)
    cal = activecal.calibrate(r, q, points, orientations=rot, compliance=True)
    assert_same_fit(cal, want)
    assert_close(cal.report["compliance"], want["compliance"])
    plain = activecal.calibrate(r, q, points, orientations=rot)
    assert "compliance" not in plain.report
    with pytest.raises(activecal.InputError, match="compliance:.*URDF"):
        activecal.calibrate(activecal.Robot.builtin("puma560"), q[:, :6], points, compliance=True)


pd = pytest.importorskip("pandas")


def test_dataframes_with_named_columns_equal_arrays():
    path, joints, q, points, rot = figaroh_ur10()
    urdf = FIXTURES / "figaroh" / "ur10_robot.urdf"
    r = activecal.Robot.from_urdf(urdf, tip="ur10e_tooltip_link", pose=True)
    # Columns in another order than the robot's joints, and an extra one.
    qdf = pd.DataFrame(q, columns=joints)[list(reversed(joints))].assign(note="x")
    pdf = pd.DataFrame(points, columns=["x", "y", "z"])
    a = activecal.calibrate(r, q, points, orientations=rot)
    b = activecal.calibrate(r, qdf, pdf, orientations=rot)
    assert a.estimate == b.estimate
    want = cli("calibrate", "--robot", f"{urdf}:pose", "--tip", "ur10e_tooltip_link",
               "--measurements", path)
    assert_same_fit(b, want)
    with pytest.raises(activecal.InputError, match="q: a DataFrame needs a column per joint .*no column 'elbow_joint'"):
        activecal.calibrate(r, qdf.drop(columns="elbow_joint"), pdf, orientations=rot)
    with pytest.raises(activecal.InputError, match="points: .*no column 'z'"):
        activecal.calibrate(r, qdf, pdf.rename(columns={"z": "Z"}), orientations=rot)


def test_dataframe_pool_and_existing():
    r = activecal.Robot.builtin("puma560")
    cand = activecal.pool(r, source="sobol", count=300).q
    names = r.joint_names
    df = pd.DataFrame(cand, columns=names)
    a = activecal.select(r, 12, pool=cand, existing=cand[:3])
    b = activecal.select(r, 12, pool=df, existing=df.iloc[:3])
    assert a.ids == b.ids and a.ln_oid == b.ln_oid
    assert math.isfinite(b.ln_oid)
