"""calibrate: the same estimate as `activecal calibrate --measurements FILE`
on the same values, the same calibrated files, errors, threads."""

import json
import threading

import numpy as np
import pytest

import activecal
from conftest import FIXTURES, UR5_URDF, cli

MARKER = "tool0@0.031,-0.024,0.097"


def simulated(tmp_path, robot_args, n=30, seed=3):
    """Measurements of a robot's `real` table at a selected design, written
    by the CLI (--save-measurements), and the CLI's calibration of them."""
    design = tmp_path / "d.json"
    cli("select", *robot_args, "--pool", "random", "--count", 1000, "--n", n,
        "--order", "none", "--out", design)
    meas = tmp_path / "m.json"
    cli("calibrate", *robot_args, "--design", design, "--save-measurements", meas,
        "--noise", 1e-4, "--seed", seed)
    m = json.loads(meas.read_text())
    return meas, m


def assert_same_fit(cal, want):
    assert set(cal.estimate) == set(want["estimate"])
    for k, v in want["estimate"].items():
        assert cal.estimate[k] == pytest.approx(v, abs=1e-12, rel=0), k
    for k, v in want["std"].items():
        assert cal.sigma[k] == pytest.approx(v, abs=1e-12, rel=1e-9), k
    assert cal.residuals["position_rms_mm"] == pytest.approx(want["residuals"]["position_rms_mm"], abs=1e-12)
    report = cal.report
    for k in ("status", "converged", "iterations", "rank", "unidentifiable", "parameters", "fixed", "notes"):
        assert report[k] == want[k], k


def test_puma_points_equal_the_cli(tmp_path):
    meas, m = simulated(tmp_path, ["--robot", "puma560"])
    want = cli("calibrate", "--robot", "puma560", "--measurements", meas)
    r = activecal.Robot.builtin("puma560")
    cal = activecal.calibrate(r, np.array(m["qs"]), np.array(m["points"]))
    assert cal.converged
    assert_same_fit(cal, want)


def test_ur5_marker_urdf_and_frames_equal_the_clis(tmp_path):
    args = ["--robot", UR5_URDF, "--tip", "tool0", "--marker", MARKER]
    meas, m = simulated(tmp_path, args)
    urdf, frames = tmp_path / "cli.urdf", tmp_path / "cli.yaml"
    want = cli("calibrate", *args, "--measurements", meas, "--out", urdf, "--out", frames)
    r = activecal.Robot.from_urdf(UR5_URDF, tip="tool0", marker=MARKER)
    cal = activecal.calibrate(r, m["qs"], m["points"])
    assert_same_fit(cal, want)
    assert cal.report["frames"] == want["frames"]
    cal.write_urdf(tmp_path / "py.urdf")
    cal.write_frames(tmp_path / "py.yaml")
    assert (tmp_path / "py.urdf").read_text() == urdf.read_text()
    assert (tmp_path / "py.yaml").read_text() == frames.read_text()


def test_full_pose_equals_the_cli(tmp_path):
    args = ["--robot", f"{UR5_URDF}:pose", "--tip", "tool0"]
    meas, m = simulated(tmp_path, args)
    want = cli("calibrate", *args, "--measurements", meas)
    r = activecal.Robot.from_urdf(UR5_URDF, tip="tool0", pose=True)
    assert r.measures_orientation
    cal = activecal.calibrate(r, m["qs"], m["points"], orientations=m["orientations"])
    assert_same_fit(cal, want)


def test_two_calibrations_at_once_from_threads(tmp_path):
    meas, m = simulated(tmp_path, ["--robot", "puma560"])
    r = activecal.Robot.builtin("puma560")
    alone = activecal.calibrate(r, m["qs"], m["points"]).estimate
    out = [None, None]

    def run(k):
        out[k] = activecal.calibrate(r, m["qs"], m["points"]).estimate

    ts = [threading.Thread(target=run, args=(k,)) for k in range(2)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    assert out[0] == alone and out[1] == alone


@pytest.fixture(scope="module")
def puma_data(tmp_path_factory):
    _, m = simulated(tmp_path_factory.mktemp("data"), ["--robot", "puma560"])
    return np.array(m["qs"]), np.array(m["points"])


def errors_of(call):
    with pytest.raises(activecal.Error) as e:
        call()
    return str(e.value)


def test_calibrate_errors_name_the_argument(puma_data):
    qs, pts = puma_data
    r = activecal.Robot.builtin("puma560")
    msg = errors_of(lambda: activecal.calibrate(r, qs[:, :5], pts))
    assert msg.startswith("q: expected shape (n, 6)"), msg
    msg = errors_of(lambda: activecal.calibrate(r, qs, pts[:-1]))
    assert msg.startswith("points: expected shape (30, 3)"), msg
    bad = pts.copy()
    bad[4, 1] = np.nan
    msg = errors_of(lambda: activecal.calibrate(r, qs, bad))
    assert msg.startswith("points: points[4, 1] is NaN"), msg
    deg = np.degrees(qs)
    msg = errors_of(lambda: activecal.calibrate(r, deg, pts))
    assert msg.startswith("q") and "degree" in msg, msg
    msg = errors_of(lambda: activecal.calibrate(r, qs, pts, orientations=np.zeros((30, 3, 3))))
    assert msg.startswith("orientations: "), msg
    msg = errors_of(lambda: activecal.calibrate(r, qs, pts, fix=["nope_9"]))
    assert "nope_9" in msg, msg
    msg = errors_of(lambda: activecal.calibrate(r, qs, pts, loss="huber"))
    assert msg.startswith("loss_scale: "), msg


def test_unconverged_fits_are_not_written(tmp_path, puma_data):
    qs, pts = puma_data
    r = activecal.Robot.builtin("puma560")
    cal = activecal.calibrate(r, qs, pts, max_iterations=1)
    assert not cal.converged
    with pytest.raises(activecal.Error, match="not written"):
        cal.write_urdf(tmp_path / "x.urdf")


def rpy_matrix(roll, pitch, yaw):
    """R = Rz(yaw) Ry(pitch) Rx(roll), as the measurement files' phix/phiy/
    phiz are read (nalgebra's Rotation3::from_euler_angles, term by term)."""
    import math

    sr, cr = math.sin(roll), math.cos(roll)
    sp, cp = math.sin(pitch), math.cos(pitch)
    sy, cy = math.sin(yaw), math.cos(yaw)
    return [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]


def figaroh_ur10():
    """FIGAROH's UR10 full-pose data as arrays: q, points, orientations."""
    from conftest import FIXTURES

    path = FIXTURES / "figaroh" / "ur10_full_pose.csv"
    head = path.read_text().splitlines()[0].split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    col = {c: k for k, c in enumerate(head)}
    joints = [c for c in head if c.endswith("_joint")]
    q = data[:, [col[j] for j in joints]]
    points = data[:, [col["x1"], col["y1"], col["z1"]]]
    rot = np.array([rpy_matrix(*row) for row in data[:, [col["phix1"], col["phiy1"], col["phiz1"]]]])
    return path, joints, q, points, rot


def test_figaroh_ur10_full_pose_equals_the_cli():
    from conftest import FIXTURES

    path, joints, q, points, rot = figaroh_ur10()
    urdf = FIXTURES / "figaroh" / "ur10_robot.urdf"
    want = cli("calibrate", "--robot", f"{urdf}:pose", "--tip", "ur10e_tooltip_link", "--measurements", path)
    r = activecal.Robot.from_urdf(urdf, tip="ur10e_tooltip_link", pose=True)
    assert r.joint_names == joints
    cal = activecal.calibrate(r, q, points, orientations=rot)
    assert_same_fit(cal, want)


def test_holdout_and_weights_equal_the_cli(tmp_path):
    args = ["--robot", f"{UR5_URDF}:pose", "--tip", "tool0"]
    meas, m = simulated(tmp_path, args)
    r = activecal.Robot.from_urdf(UR5_URDF, tip="tool0", pose=True)
    for extra, kw in [
        (["--holdout", 0.25, "--splits", 3, "--seed", 5], dict(holdout=0.25, splits=3, seed=5)),
        (["--weights", "fixed"], dict(weights="fixed")),
        (["--orientation-scale", 0.2], dict(orientation_scale=0.2)),
    ]:
        want = cli("calibrate", *args, "--measurements", meas, *extra)
        cal = activecal.calibrate(r, m["qs"], m["points"], orientations=m["orientations"], **kw)
        assert_same_fit(cal, want)
        assert cal.noise == want["noise"]
        got = cal.holdout
        if "holdout" in kw:
            # The same splits and fits: the same numbers, bit for bit.
            assert got == want["holdout"] and len(got["splits"]) == 3
        else:
            assert got is None and "holdout" not in want
    assert cal.frames == want["frames"]
    for kw, words in [
        (dict(weights="estimated", orientation_scale=0.2), "orientation_scale: fixes"),
        (dict(weights="robust"), "weights: unknown"),
        (dict(orientation_scale=-1.0), "orientation_scale: -1"),
        (dict(holdout=1.5), "holdout: 1.5"),
        (dict(holdout=0.2, splits=0), "splits:"),
    ]:
        with pytest.raises(activecal.Error, match=words):
            activecal.calibrate(r, m["qs"], m["points"], orientations=m["orientations"], **kw)


def test_evaluate_on_poses_the_fit_did_not_see_equals_the_cli(tmp_path):
    args = ["--robot", UR5_URDF, "--tip", "tool0", "--marker", MARKER]
    meas, m = simulated(tmp_path, args)
    r = activecal.Robot.from_urdf(UR5_URDF, tip="tool0", marker=MARKER)
    q, p = np.array(m["qs"]), np.array(m["points"])
    cal = activecal.calibrate(r, q[:22], p[:22])
    got = activecal.evaluate(cal, q[22:], p[22:])
    cal.write_urdf(tmp_path / "cal.urdf")
    cal.write_frames(tmp_path / "cal.yaml")
    test = tmp_path / "test.csv"
    np.savetxt(
        test, np.hstack([p[22:], q[22:]]), delimiter=",", comments="", fmt="%.17g",
        header=",".join(["x", "y", "z", *r.joint_names]),
    )
    want = cli(
        "evaluate", "--robot", tmp_path / "cal.urdf", "--tip", "tool0", "--frames",
        tmp_path / "cal.yaml", "--measurements", test,
    )["residuals"]
    assert got["position_rms_mm"] == pytest.approx(want["position_rms_mm"], abs=1e-9)
    assert len(got["per_sample"]) == 8
    # The nominal model is far worse on the same poses (the truth's origins
    # are off by millimetres).
    nominal = activecal.evaluate(r, q[22:], p[22:])
    assert nominal["position_rms_mm"] > 10 * got["position_rms_mm"]
    with pytest.raises(activecal.InputError, match="^model"):
        activecal.evaluate("ur5", q, p)


def test_glitches_are_left_out_as_the_cli_leaves_them_out(tmp_path):
    """Two tracker glitches of 4 mm: the library's test leaves both out in
    Python as on the command line, and `outliers="keep"` keeps them."""
    args = ["--robot", UR5_URDF, "--tip", "tool0", "--marker", MARKER]
    meas, m = simulated(tmp_path, args)
    pts = np.array(m["points"])
    pts[4, 0] += 4e-3
    pts[17, 2] -= 4e-3
    m["points"] = pts.tolist()
    glitched = tmp_path / "g.json"
    glitched.write_text(json.dumps(m))
    want = cli("calibrate", *args, "--measurements", glitched)
    r = activecal.Robot.from_urdf(UR5_URDF, tip="tool0", marker=MARKER)
    cal = activecal.calibrate(r, m["qs"], pts)
    assert sorted(o["pose"] for o in cal.report["outliers"]["left_out"]) == [4, 17]
    assert cal.report["outliers"] == want["outliers"]
    assert_same_fit(cal, want)
    kept = activecal.calibrate(r, m["qs"], pts, outliers="keep")
    assert kept.report["outliers"]["left_out"] == []
    # The glitches pull the kept fit: its residual is far above the other's.
    assert kept.residuals["position_rms_mm"] > 5 * cal.residuals["position_rms_mm"]
    with pytest.raises(ValueError, match="outliers"):
        activecal.calibrate(r, m["qs"], pts, outliers="maybe")


def test_a_shuffled_points_frame_is_aligned_on_its_index(tmp_path):
    pd = pytest.importorskip("pandas")
    args = ["--robot", UR5_URDF, "--tip", "tool0", "--marker", MARKER]
    meas, m = simulated(tmp_path, args)
    r = activecal.Robot.from_urdf(UR5_URDF, tip="tool0", marker=MARKER)
    q = pd.DataFrame(m["qs"], columns=r.joint_names)
    pts = pd.DataFrame(m["points"], columns=["x", "y", "z"])
    ref = activecal.calibrate(r, q, pts.to_numpy())
    shuffled = pts.sample(frac=1.0, random_state=1)
    assert not shuffled.index.equals(q.index)
    cal = activecal.calibrate(r, q, shuffled)
    assert cal.residuals["position_rms_mm"] == pytest.approx(ref.residuals["position_rms_mm"], rel=1e-12)
    # Labels that are not q's are refused, naming the argument.
    other = pts.set_axis(pts.index + 1000)
    with pytest.raises(ValueError, match="points: its index"):
        activecal.calibrate(r, q, other)


def test_a_stated_noise_the_data_reject_warns_in_python(tmp_path):
    """The simulated σ is 0.1 mm; stated as 0.02 mm, the χ² test rejects it
    and Python gets the command line's warning as a UserWarning."""
    args = ["--robot", UR5_URDF, "--tip", "tool0", "--marker", MARKER]
    meas, m = simulated(tmp_path, args)
    r = activecal.Robot.from_urdf(UR5_URDF, tip="tool0", marker=MARKER)
    with pytest.warns(UserWarning, match="noisier than stated"):
        cal = activecal.calibrate(r, m["qs"], m["points"], noise=2e-5)
    want = cli("calibrate", *args, "--measurements", meas, "--noise", 2e-5)
    assert cal.report["warnings"] == want["warnings"]
    assert cal.report["noise_test"]["rejected"]
    assert cal.report["predicted"] == want["predicted"]


def test_too_few_poses_are_refused_as_the_cli_refuses_them(tmp_path):
    """3 poses (9 rows) for 27 unknowns converge on the 9 the rows determine:
    the library's verdict refuses to write it, in Python as on the command
    line (exit 3, the same reason)."""
    import subprocess

    from conftest import cli_path

    args = ["--robot", UR5_URDF, "--tip", "tool0", "--marker", MARKER]
    meas, m = simulated(tmp_path, args)
    m["qs"], m["points"] = m["qs"][:3], m["points"][:3]
    few = tmp_path / "few.json"
    few.write_text(json.dumps(m))
    r = activecal.Robot.from_urdf(UR5_URDF, tip="tool0", marker=MARKER)
    cal = activecal.calibrate(r, m["qs"], m["points"])
    assert cal.report["exit_status"] == 3
    with pytest.raises(activecal.Error, match="3 poses give 9 measurement rows for 27 unknowns"):
        cal.write_urdf(tmp_path / "x.urdf")
    assert not (tmp_path / "x.urdf").exists()
    out = subprocess.run([str(cli_path()), "calibrate", *args, "--measurements", str(few), "--out", str(tmp_path / "y.urdf")],
                         capture_output=True, text=True)
    assert out.returncode == 3
    assert "3 poses give 9 measurement rows for 27 unknowns" in out.stderr
    assert not (tmp_path / "y.urdf").exists()


def test_kinematics_files_equal_the_clis_and_read_back(tmp_path):
    """write_ur_kinematics / write_joint_origins write what `calibrate --out
    *kinematics.yaml / *origins.yaml` writes, and Robot.from_urdf(...,
    kinematics=FILE) reads either back to the calibrated URDF's model."""
    ur5 = FIXTURES / "ur5.urdf"
    factory = FIXTURES / "xacro" / "ur5_factory_kinematics.yaml"
    args = ["--robot", ur5, "--kinematics", factory]
    meas, m = simulated(tmp_path, args)
    kin, ori, urdf = tmp_path / "cli_kinematics.yaml", tmp_path / "cli_origins.yaml", tmp_path / "cli.urdf"
    cli("calibrate", *args, "--measurements", meas, "--out", kin, "--out", ori, "--out", urdf)
    r = activecal.Robot.from_urdf(ur5, kinematics=factory)
    cal = activecal.calibrate(r, m["qs"], m["points"])
    assert cal.converged
    cal.write_ur_kinematics(tmp_path / "py_kinematics.yaml")
    cal.write_joint_origins(tmp_path / "py_origins.yaml")
    assert (tmp_path / "py_kinematics.yaml").read_text() == kin.read_text()
    assert (tmp_path / "py_origins.yaml").read_text() == ori.read_text()
    q = np.array([0.3, -1.2, 1.1, 0.4, -0.8, 0.5])
    want = np.asarray(activecal.Robot.from_urdf(urdf).fk(q)[1])
    bare = np.asarray(activecal.Robot.from_urdf(ur5).fk(q)[1])
    # The calibration moved the model by more than the comparison's bar.
    assert np.linalg.norm(want - bare) > 1e-5
    for f in (kin, ori):
        got = np.asarray(activecal.Robot.from_urdf(ur5, kinematics=f).fk(q)[1])
        # The same decimals on both sides: rpy rounding only.
        assert np.linalg.norm(got - want) < 1e-12, f


def test_kinematics_file_errors_name_the_file(tmp_path):
    with pytest.raises(activecal.FileError, match="kinematics: .*nope.yaml: no such file"):
        activecal.Robot.from_urdf(FIXTURES / "ur5.urdf", kinematics=tmp_path / "nope.yaml")
    bad = tmp_path / "bad_origins.yaml"
    bad.write_text("elbow_joint: {xyz: [0, 0], rpy: [0, 0, 0]}\n")
    with pytest.raises(activecal.Error, match="bad_origins.yaml"):
        activecal.Robot.from_urdf(FIXTURES / "ur5.urdf", kinematics=bad)


def test_offsets_only_equals_the_cli(tmp_path):
    """unknowns="offsets" estimates what `--unknowns offsets` does: only
    offsets, measurement frame and tool (no link length or twist)."""
    args = ["--robot", FIXTURES / "ur5.urdf"]
    meas, m = simulated(tmp_path, args)
    want = cli("calibrate", *args, "--measurements", meas, "--unknowns", "offsets")
    r = activecal.Robot.from_urdf(FIXTURES / "ur5.urdf")
    cal = activecal.calibrate(r, m["qs"], m["points"], unknowns="offsets")
    assert_same_fit(cal, want)
    full = activecal.calibrate(r, m["qs"], m["points"])
    links = [k for k in full.estimate if k.startswith(("a_", "alpha_")) and not k.endswith("_base")]
    assert links and not any(k in cal.estimate for k in links)
    with pytest.raises(activecal.Error, match="unknowns"):
        activecal.calibrate(r, m["qs"], m["points"], unknowns="some")
    # The offsets as a driver takes them, as the command line writes them.
    off = tmp_path / "cli_joint_offsets.yaml"
    cli("calibrate", *args, "--measurements", meas, "--unknowns", "offsets", "--out", off,
        "--offset-unit", "deg", "--offset-sign", "subtract")
    cal.write_joint_offsets(tmp_path / "py_joint_offsets.yaml", unit="deg", sign="subtract")
    assert (tmp_path / "py_joint_offsets.yaml").read_text() == off.read_text()
    with pytest.raises(activecal.Error, match="sign"):
        cal.write_joint_offsets(tmp_path / "x_joint_offsets.yaml", sign="plus")
    # The full model's fit of the same data beside it, as the CLI reports it.
    assert cal.report["full_model_gain"] == want["full_model_gain"]
    assert cal.report["full_model_gain"]["restricted"] == "offsets"


def test_keeping_axis_relations_equals_the_cli(tmp_path):
    """keep_axis_relations=True holds what `--keep-axis-relations` holds
    (the UR5's five relations: 10 unknowns) and reports the same cost
    against the full model."""
    args = ["--robot", FIXTURES / "ur5.urdf"]
    meas, m = simulated(tmp_path, args)
    want = cli("calibrate", *args, "--measurements", meas, "--keep-axis-relations")
    r = activecal.Robot.from_urdf(FIXTURES / "ur5.urdf")
    cal = activecal.calibrate(r, m["qs"], m["points"], keep_axis_relations=True)
    assert_same_fit(cal, want)
    g = cal.report["full_model_gain"]
    assert g == want["full_model_gain"]
    held = [n for h in g["relations_held"] for n in h["held"]]
    assert len(g["relations_held"]) == 5 and len(held) == 10
    assert not any(n in cal.estimate for n in held)
    # The restricted model is never better than the full one it is compared with.
    assert g["restricted_predicted_rms_mm"] >= g["full_predicted_rms_mm"]
    with pytest.raises(activecal.Error, match="keep_axis_relations"):
        activecal.calibrate(r, m["qs"], m["points"], unknowns="offsets", keep_axis_relations=True)
