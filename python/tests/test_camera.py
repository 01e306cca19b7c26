"""calibrate_camera and select_camera: the same reports as `activecal
calibrate --observations FILE --json` and `activecal select --camera-info
... --json` on the example files (UR5 eye-to-hand, TIAGo's head camera),
the same written files, DataFrame input equal to CSV input, and the
refusals."""

import json
import math

import numpy as np
import pandas as pd
import pytest

import activecal
from conftest import FIXTURES, cli

CAM = FIXTURES / "camera"
UR5 = FIXTURES / "ur5.urdf"
INFO, BOARD, PIXELS = CAM / "camera_info.yaml", CAM / "board.yaml", CAM / "ur5_eye_to_hand.csv"
CAMERA_POSE = [1.1761, 0.6096, 0.9079, -2.0681, 0.0317, 2.0826]
TARGET_POSE = [-0.1047, 0.0411, 0.0301, 3.1111, -0.0192, 0.0556]

TIAGO = FIXTURES / "figaroh" / "tiago.urdf"
XTION, TIAGO_BOARD = CAM / "tiago_xtion.yaml", CAM / "tiago_board.yaml"


def csv6(v):
    return ",".join(repr(float(x)) for x in v)


def ur5_args(pixels=PIXELS):
    return [
        "--robot", UR5, "--mounting", "eye-to-hand", "--camera-info", INFO, "--target", BOARD,
        "--observations", pixels, f"--camera-pose={csv6(CAMERA_POSE)}",
        f"--target-pose={csv6(TARGET_POSE)}",
    ]


def ur5_fit(observations=PIXELS, **kw):
    kw.setdefault("mounting", "eye-to-hand")
    r = activecal.Robot.from_urdf(UR5)
    return activecal.calibrate_camera(
        r, observations, kw.pop("camera_info", INFO), kw.pop("target", BOARD),
        camera_pose=CAMERA_POSE, target_pose=TARGET_POSE, **kw,
    )


def same(got, want, skip=("out",)):
    """Equal reports: every key but `skip`, bit for bit (the same library
    code on the same inputs in one thread)."""
    assert set(got) == set(want)
    for k in sorted(set(want) - set(skip)):
        assert got[k] == want[k], k


def test_ur5_eye_to_hand_equals_the_cli(tmp_path):
    urdf, frames = tmp_path / "cli.urdf", tmp_path / "cli.yaml"
    want = cli("calibrate", *ur5_args(), "--out", urdf, "--out", frames)
    c = ur5_fit()
    same(c.report, want)
    assert c.report["out"] == [] and c.converged
    assert list(c.estimate) == sorted(want["names"])
    assert c.estimate == dict(zip(want["names"], want["estimate"]))
    assert c.sigma == dict(zip(want["names"], want["std"]))
    assert c.sigma_px == want["sigma_px"] and c.rms_px == want["rms_px"]
    # The placements as matrices: the frames block's xyz, and a rotation
    # whose rpy is the block's (to rounding of the rpy's round trip).
    for m, block in ((c.camera, want["camera"]["camera"]), (c.target, want["camera"]["target"])):
        assert m.shape == (4, 4)
        assert np.array_equal(m[:3, 3], block["xyz"])
        assert np.allclose(m[:3, :3].T @ m[:3, :3], np.eye(3), atol=1e-15)
        # Roll about x last: R[2, 1] = cos(pitch) sin(roll).
        roll, pitch, yaw = block["rpy"]
        assert m[2, 1] == pytest.approx(np.cos(pitch) * np.sin(roll), abs=1e-15)
        assert m[1, 0] == pytest.approx(np.sin(yaw) * np.cos(pitch), abs=1e-15)
    c.write_urdf(tmp_path / "py.urdf")
    c.write_frames(tmp_path / "py.yaml")
    assert (tmp_path / "py.urdf").read_bytes() == urdf.read_bytes()
    assert (tmp_path / "py.yaml").read_bytes() == frames.read_bytes()
    with pytest.raises(activecal.FileError, match="exists"):
        c.write_urdf(tmp_path / "py.urdf", overwrite=False)
    c.write_urdf(tmp_path / "py.urdf")
    with pytest.raises(activecal.InputError, match="^path: .*not refined"):
        c.write_camera_info(tmp_path / "refined.yaml")


def test_refined_intrinsics_and_camera_info_equal_the_clis(tmp_path):
    (tmp_path / "cli").mkdir()
    refined = tmp_path / "cli" / "refined.yaml"
    want = cli("calibrate", *ur5_args(), "--refine-intrinsics", "--out-camera-info", refined)
    c = ur5_fit(refine_intrinsics=True)
    same(c.report, want)
    assert len(want["names"]) == 39 and c.report["intrinsics"] == want["intrinsics"]
    c.write_camera_info(tmp_path / "refined.yaml")
    assert (tmp_path / "refined.yaml").read_bytes() == refined.read_bytes()
    with pytest.raises(activecal.InputError, match=r"^path .*: the refined intrinsics are written as a ROS camera_info \.yaml"):
        c.write_camera_info(tmp_path / "refined.txt")


def test_dataframe_and_dicts_equal_the_files():
    from_files = ur5_fit().report
    df = pd.read_csv(PIXELS)
    # Columns in another order: read by name.
    df = df[["u", "v", "feature", *df.columns[:7]]]
    c = ur5_fit(
        df,
        camera_info={
            "image_width": 1280, "image_height": 960, "camera_name": "cell_camera",
            "camera_matrix": {"rows": 3, "cols": 3, "data": [1000.0, 0.0, 640.0, 0.0, 1000.0, 480.0, 0.0, 0.0, 1.0]},
            "distortion_model": "plumb_bob",
            "distortion_coefficients": {"rows": 1, "cols": 5, "data": [-0.08, 0.04, 0.0005, -0.0003, -0.01]},
        },
        target={"checkerboard": {"rows": 6, "cols": 8, "square": 0.025}},
    )
    assert c.report["observations"] == "observations"
    same(c.report, from_files, skip=("out", "observations"))


def test_tiago_head_camera_equals_the_cli(tmp_path):
    cp = [0.1008, 0.0950, -0.0020, -2.2154, -1.5388, -0.8959]
    tp = [0.0699, -0.0248, 0.0798, -2.2457, 1.5388, -2.2154]
    urdf, frames = tmp_path / "cli.urdf", tmp_path / "cli.yaml"
    want = cli(
        "calibrate", "--robot", f"{TIAGO}#tip=arm_tool_link", "--camera-link", "head_2_link",
        "--camera-info", XTION, "--target", TIAGO_BOARD, "--observations", CAM / "tiago_head.csv",
        f"--camera-pose={csv6(cp)}", f"--target-pose={csv6(tp)}", "--out", urdf, "--out", frames,
    )
    r = activecal.Robot.from_urdf(TIAGO, tip="arm_tool_link")
    c = activecal.calibrate_camera(
        r, CAM / "tiago_head.csv", XTION, TIAGO_BOARD, camera_link="head_2_link",
        camera_pose=cp, target_pose=tp,
    )
    same(c.report, want)
    assert c.report["camera_link"] == "head_2_link" and len(want["names"]) == 42
    c.write_urdf(tmp_path / "py.urdf")
    c.write_frames(tmp_path / "py.yaml")
    assert (tmp_path / "py.urdf").read_bytes() == urdf.read_bytes()
    assert (tmp_path / "py.yaml").read_bytes() == frames.read_bytes()


def refused(call, words):
    with pytest.raises(activecal.InputError) as e:
        call()
    assert e.match(words), str(e.value)
    return str(e.value)


def test_refusals_name_the_input(tmp_path):
    df = pd.read_csv(PIXELS)
    out = df.copy()
    out.loc[5, "u"] = 1500.0
    # Row 5 of the frame is line 7 of its CSV (line 1 the header).
    refused(lambda: ur5_fit(out), r"^observations: line 7, column 9 \('u'\): pixel \(1500, .*lies outside the 1280×960 image")
    path = tmp_path / "pixels.csv"
    out.to_csv(path, index=False)
    msg = refused(lambda: ur5_fit(path), "^observations: .*pixels.csv: line 7, column 9")
    want = cli_error(["calibrate", *ur5_args(path)])
    assert msg.split("pixels.csv: ", 1)[1] in want
    lacks = df.copy()
    lacks.loc[3, "feature"] = 48
    refused(lambda: ur5_fit(lacks), r"^observations: line 5, column 8 \('feature'\): .*48")
    refused(lambda: ur5_fit(mounting=None), "^mounting: none given")
    refused(lambda: ur5_fit(mounting="on-the-wall"), "^mounting: unknown mounting 'on-the-wall'")
    refused(lambda: ur5_fit(camera_link="head_2_link"), "^camera_link: .*not both")
    refused(lambda: ur5_fit(target={"checkerboard": {"rows": 6}}), "^target: ")
    refused(lambda: ur5_fit(target=42), "^target: expected a path")
    r = activecal.Robot.from_urdf(UR5)
    refused(
        lambda: activecal.calibrate_camera(r, PIXELS, INFO, BOARD, mounting="eye-to-hand",
                                           camera_pose=CAMERA_POSE[:5], target_pose=TARGET_POSE),
        r"^camera_pose: expected shape \(6,\)",
    )
    with pytest.raises(activecal.FileError, match="^camera_info: .*nowhere.yaml"):
        ur5_fit(camera_info=tmp_path / "nowhere.yaml")


def cli_error(args):
    """The CLI's stderr for a command that must fail."""
    import subprocess

    from conftest import cli_path

    out = subprocess.run([str(cli_path()), *map(str, args)], capture_output=True, text=True)
    assert out.returncode != 0
    return out.stderr


def select_args(extra=()):
    return [
        "select", "--robot", UR5, "--mounting", "eye-to-hand", "--camera-info", INFO,
        "--target", BOARD, f"--camera-pose={csv6(CAMERA_POSE)}", f"--target-pose={csv6(TARGET_POSE)}",
        "--image-margin", 20, "--distance", "0.3,2.0", "--n", 14, "--count", 1500, *extra,
    ]


def test_select_camera_equals_the_cli(tmp_path):
    design = tmp_path / "d.csv"
    want = cli(*select_args(), "--out", design)
    r = activecal.Robot.from_urdf(UR5)
    d = activecal.select_camera(
        r, INFO, BOARD, n=14, mounting="eye-to-hand", camera_pose=CAMERA_POSE,
        target_pose=TARGET_POSE, count=1500, image_margin=20, distance=(0.3, 2.0),
    )
    same(d.report, want)
    assert d.report["out"] == []
    assert d.candidates == want["chosen_candidates"]
    assert np.array_equal(d.q, np.array(want["poses"]))
    poses = d.poses
    from_csv = pd.read_csv(design)
    assert list(poses.columns) == list(from_csv.columns)
    assert np.array_equal(poses["candidate"], from_csv["candidate"])
    assert np.array_equal(poses["points_seen"], from_csv["points_seen"])
    # The CSV's joints are written with 17 digits after the point.
    assert np.allclose(poses[d.joint_names], from_csv[d.joint_names], rtol=0, atol=1e-16)


def test_select_camera_gap_equals_the_cli():
    args = select_args()
    args[args.index("--count") + 1] = 600
    want = cli(*args, "--gap")
    r = activecal.Robot.from_urdf(UR5)
    d = activecal.select_camera(
        r, INFO, BOARD, n=14, mounting="eye-to-hand", camera_pose=CAMERA_POSE,
        target_pose=TARGET_POSE, count=600, image_margin=20, distance=(0.3, 2.0), gap=True,
    )
    same(d.report, want, skip=("out", "gap"))
    volatile = {"seconds", "elapsed_seconds"}
    assert {k: v for k, v in d.report["gap"].items() if k not in volatile} == {
        k: v for k, v in want["gap"].items() if k not in volatile
    }
    assert 0 < d.report["d_efficiency"] <= 1


def test_select_camera_how_many_equals_the_clis_report(tmp_path):
    """design.how_many() is the curve `select --report` writes (the same
    library code on the same pool: bit for bit); it starts at ⌈p / 6⌉
    poses (a pose's pixels move with the target's 6-DOF placement alone)
    and at the design's own size predicts what the report's
    `predicted_error_mm` says at the same pixel noise."""
    args = select_args()
    args[args.index("--count") + 1] = 600
    report = tmp_path / "report"
    want = cli(*args, "--gap", "--pixel-noise", 0.25, "--target-error", 0.3, "--report", report)
    curve = json.loads((report / "report.json").read_text())["how_many_poses"]
    r = activecal.Robot.from_urdf(UR5)
    d = activecal.select_camera(
        r, INFO, BOARD, n=14, mounting="eye-to-hand", camera_pose=CAMERA_POSE,
        target_pose=TARGET_POSE, count=600, image_margin=20, distance=(0.3, 2.0), gap=True,
        pixel_noise=0.25,
    )
    same(d.report, want, skip=("out", "gap"))
    got = d.how_many(target_error=0.3)
    assert got == curve
    assert got["noise_px"] == 0.25 and "noise_m" not in got
    assert got["n_min"] == math.ceil(len(want["unknowns"]) / 6)
    at = next(p for p in got["points"] if p["n"] == 14)
    assert at["predicted"]["position_rms_mm"] == pytest.approx(want["predicted_error_mm"], rel=1e-9)
    refused(lambda: d.how_many(pixel_noise=-1.0), "^pixel_noise: -1")
    refused(lambda: d.how_many(target_error=0.0), "^target_error: 0")


def test_select_camera_with_line_of_sight_equals_the_cli():
    """line_of_sight=True is `select --line-of-sight`: the Panda's own
    links hide the board from some configurations the view keeps
    (`out_of_sight` > 0), and the design is the command's, value for
    value; floor= adds the collision filter (`collision_removed`)."""
    panda = FIXTURES / "example-robot-data" / "panda.urdf"
    cp = [1.2, 0.6, 0.9, -2.0985, 0.0, 2.0779]
    tp = [-0.0853, 0.0568, 0.02, 3.141592653589793, 0.0, 0.03]
    args = [
        "select", "--robot", f"{panda}#tip=panda_hand_tcp", "--camera-info", INFO,
        "--target", BOARD, "--mounting", "eye-to-hand", f"--camera-pose={csv6(cp)}",
        f"--target-pose={csv6(tp)}", "--image-margin", 20, "--distance", "0.3,2.0",
        "--n", 14, "--count", 1500, "--line-of-sight", "--floor", 0.0,
    ]
    want = cli(*args)
    assert want["out_of_sight"] > 0 and want["collision_removed"] is not None
    r = activecal.Robot.from_urdf(panda, tip="panda_hand_tcp")
    d = activecal.select_camera(
        r, INFO, BOARD, n=14, mounting="eye-to-hand", camera_pose=cp, target_pose=tp,
        count=1500, image_margin=20, distance=(0.3, 2.0), line_of_sight=True, floor=0.0,
    )
    same(d.report, want)
    with pytest.raises(activecal.FileError, match="^package_dirs: /no/such/dir"):
        activecal.select_camera(
            r, INFO, BOARD, n=14, mounting="eye-to-hand", camera_pose=cp, target_pose=tp,
            line_of_sight=True, package_dirs=["/no/such/dir"],
        )


def test_select_camera_on_the_head_equals_the_cli():
    cp = [0.0908, 0.0800, -0.0220, -3.1416, -1.5708, 0.0]
    tp = [0.0800, -0.0400, 0.0600, 0.0, 1.5708, 0.0]
    want = cli(
        "select", "--robot", f"{TIAGO}#tip=arm_tool_link", "--camera-link", "head_2_link",
        "--camera-info", XTION, "--target", TIAGO_BOARD, f"--camera-pose={csv6(cp)}",
        f"--target-pose={csv6(tp)}", "--image-margin", 20, "--distance", "0.25,1.5",
        "--n", 14, "--count", 2000, "--pool-seed", 3, "--seed", 2,
    )
    r = activecal.Robot.from_urdf(TIAGO, tip="arm_tool_link")
    d = activecal.select_camera(
        r, XTION, TIAGO_BOARD, n=14, camera_link="head_2_link", camera_pose=cp, target_pose=tp,
        count=2000, pool_seed=3, seed=2, image_margin=20, distance=(0.25, 1.5),
    )
    same(d.report, want)
    assert want["chain"] == {"tip": "arm_tool_link"}


def test_select_camera_refusals():
    r = activecal.Robot.from_urdf(UR5)
    kw = dict(n=14, camera_pose=CAMERA_POSE, target_pose=TARGET_POSE, count=300)
    refused(lambda: activecal.select_camera(r, INFO, BOARD, **kw), "^mounting: none given")
    refused(
        lambda: activecal.select_camera(r, INFO, BOARD, mounting="eye-to-hand", distance=(2.0, 1.0), **kw),
        r"^camera view: distance range \[2, 1\] m",
    )
    refused(
        lambda: activecal.select_camera(r, INFO, BOARD, mounting="eye-to-hand", camera_link="x", **kw),
        "^camera_link: ",
    )


def test_the_docs_camera_block_runs_and_says_what_it_prints(tmp_path, monkeypatch, capsys):
    from conftest import REPO

    text = (REPO / "docs" / "python.md").read_text()
    section = text[text.index("\n## A camera\n"):]
    block = section.split("```python\n", 1)[1].split("```", 1)[0]
    monkeypatch.chdir(tmp_path)
    ns = {}
    exec(block.replace('"fixtures/', f'"{REPO}/fixtures/'), ns)
    # The figures the prose after the block gives.
    after = section.split("```python\n", 1)[1].split("```", 1)[1]
    d, cal = ns["design"], ns["cal"]
    assert f"predicts {d.report['predicted_error_mm_per_px']:.2f} mm" in after
    assert f"{cal.rms_px:.3f} px RMS, σ̂ {cal.sigma_px:.3f} px" in after
    assert "({:.3f}, {:.3f}, {:.3f}) m".format(*cal.camera[:3, 3]) in after
    for f in ("cal.urdf", "cal.yaml", "refined.yaml"):
        assert (tmp_path / f).is_file()


def test_a_board_ten_times_too_large_is_refused_as_by_the_cli(tmp_path):
    """Squares of 0.25 m for the example's 0.025 m: the library refuses
    the fit (issue 49, item 4) with the same reason the command line exits
    3 with, and nothing is written."""
    board = tmp_path / "board.yaml"
    board.write_text("checkerboard: {rows: 6, cols: 8, square: 0.25}\n")
    import subprocess
    from conftest import cli_path
    args = ["calibrate", "--robot", UR5, "--mounting", "eye-to-hand", "--camera-info", INFO,
            "--target", board, "--observations", PIXELS, "--json"]
    out = subprocess.run([str(cli_path()), *map(str, args)], capture_output=True, text=True)
    assert out.returncode == 3, out.stderr
    want = json.loads(out.stdout)["refused"]
    assert "likely 10× too large" in want
    c = activecal.calibrate_camera(activecal.Robot.from_urdf(UR5), PIXELS, INFO, board,
                                   mounting="eye-to-hand")
    assert c.refused == want
    urdf = tmp_path / "cal.urdf"
    with pytest.raises(activecal.ComputationError, match="not written"):
        c.write_urdf(urdf)
    assert not urdf.exists()
