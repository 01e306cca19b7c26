"""Python refuses what the command line refuses: every keyword argument of
the calibrate functions acts on the sensor of the data given, or is refused
with a ValueError naming the argument and the sensor (the library's table,
`activecal::experiment::acts_on`, which the command line's `acts_on.rs`
uses too); and the writers never write over an input of the call."""

import inspect
import shutil

import pytest

import activecal
from conftest import FIXTURES, UR5_URDF
from test_calibrate import simulated

# A value of each keyword argument that is not its default, and the sensors
# it acts on (the command line's table, restated here so that a change of
# the library's is a change of this test).
MEASURED = {"points", "poses", "bag_points", "bag_poses"}
POSES = {"poses", "bag_poses"}
BAG = {"bag_points", "bag_poses"}
CALIBRATE = {
    "fix": (["d_shoulder_lift_joint"], MEASURED),
    "free": (["d_shoulder_lift_joint"], MEASURED),
    "max_iterations": (150, MEASURED),
    "loss": ("huber", MEASURED),
    "loss_scale": (1e-3, MEASURED),
    "weights": ("fixed", POSES),
    "orientation_scale": (0.2, POSES),
    "holdout": (0.25, MEASURED),
    "splits": (3, MEASURED),
    "seed": (5, MEASURED),
    "compliance": (True, MEASURED),
    "outliers": ("keep", MEASURED),
    "outlier_rate": (0.05, MEASURED),
    "noise": (1e-4, MEASURED),
    "orientation_noise": (1e-3, POSES),
    "unknowns": ("offsets", MEASURED),
    "keep_axis_relations": (True, MEASURED),
    # A ROS 2 bag's (`bag` itself chooses the sensor: see below).
    "bag": (None, BAG),
    "joints": ("/js", BAG),
    "poses": ("/mocap", {"bag_poses"}),
    "tf": ("world:tool0", {"bag_poses"}),
    "time_offset": (0.01, BAG),
    "max_offset": (2.0, BAG),
    "rest_speed": (0.01, BAG),
    "rest_min": (0.4, BAG),
    "settle": (0.1, BAG),
    "design": ("d.json", BAG),
    "design_tolerance": (0.02, BAG),
}
# Arguments a keyword needs beside it (the command line's `requires`).
NEEDS = {"loss_scale": {"loss": "huber"}, "loss": {"loss_scale": 1e-3}, "splits": {"holdout": 0.25}, "seed": {"holdout": 0.25}}
WORDS = {"points": "measured points", "poses": "measured full poses",
         "bag_points": "points read from a ROS 2 bag", "bag_poses": "full poses read from a ROS 2 bag"}
DATA = {"robot", "q", "points", "orientations", "progress"}


def keywords(f):
    return [p for p in inspect.signature(f).parameters if p not in DATA]


def test_every_keyword_of_calibrate_is_decided():
    assert sorted(keywords(activecal.calibrate)) == sorted(CALIBRATE)


@pytest.mark.parametrize("sensor", ["points", "poses"])
def test_every_keyword_of_calibrate_acts_or_is_refused_naming_it(tmp_path, sensor):
    pose = sensor == "poses"
    args = ["--robot", f"{UR5_URDF}:pose" if pose else UR5_URDF, "--tip", "tool0"]
    if not pose:
        args += ["--marker", "tool0@0.031,-0.024,0.097"]
    _, m = simulated(tmp_path, args)
    r = (activecal.Robot.from_urdf(UR5_URDF, tip="tool0", pose=True) if pose
         else activecal.Robot.from_urdf(UR5_URDF, tip="tool0", marker="tool0@0.031,-0.024,0.097"))
    extra = {"orientations": m["orientations"]} if pose else {}
    base = activecal.calibrate(r, m["qs"], m["points"], **extra)
    # Names of this robot's: an unknown to fix, a fixed parameter to free.
    names = {"fix": [list(base.estimate)[2]],
             "free": [f["name"] for f in base.report["fixed"]][:1] or None}
    acting = refused = 0
    for k, (value, on) in CALIBRATE.items():
        value = names.get(k, value)
        if value is None:
            continue
        kw = {k: value, **NEEDS.get(k, {})}
        if sensor in on:
            cal = activecal.calibrate(r, m["qs"], m["points"], **extra, **kw)
            assert cal.report is not None, k
            acting += 1
        else:
            with pytest.raises(ValueError) as e:
                activecal.calibrate(r, m["qs"], m["points"], **extra, **kw)
            msg = str(e.value)
            assert msg.startswith(f"{k}: not used with {WORDS[sensor]}"), msg
            refused += 1
    assert acting > 5 and (refused > 0 or pose)


TINY = FIXTURES / "bags" / "tiny.mcap"


@pytest.mark.parametrize("sensor", ["bag_points", "bag_poses"])
def test_every_keyword_of_calibrate_from_a_bag_acts_or_is_refused_naming_it(sensor):
    """With bag=, the same table: each keyword that acts on a bag's sensor
    is not refused (the call may still fail for another reason: the tiny
    bag's three rests, or for bag_poses its point topic read as poses), and
    each other one is refused naming it and the bag's sensor."""
    pose = sensor == "bag_poses"
    ur5 = FIXTURES / "ur5.urdf"
    r = activecal.Robot.from_urdf(ur5, pose=pose)
    source = {"poses": "/tracker"} if pose else {"points": "/tracker"}
    base = activecal.calibrate(activecal.Robot.from_urdf(ur5), bag=TINY, points="/tracker")
    names = {"fix": [list(base.estimate)[2]],
             "free": [f["name"] for f in base.report["fixed"]][:1] or None}
    acting = refused = 0
    for k, (value, on) in CALIBRATE.items():
        value = names.get(k, value)
        if value is None or k in source:
            continue
        kw = {k: value, **NEEDS.get(k, {})}
        if k in ("poses", "tf") and not pose:
            # A pose topic with a point topic: the bag's sensor is poses,
            # and the point topic is the one refused.
            with pytest.raises(ValueError, match=f"^points: not used with {WORDS['bag_poses']}"):
                activecal.calibrate(r, bag=TINY, **source, **kw)
            continue
        if sensor in on:
            try:
                activecal.calibrate(r, bag=TINY, **source, **kw)
            except (activecal.Error, ValueError) as e:
                assert not str(e).startswith(f"{k}: not used"), (k, str(e))
            acting += 1
        else:
            with pytest.raises(ValueError) as e:
                activecal.calibrate(r, bag=TINY, **source, **kw)
            msg = str(e.value)
            assert msg.startswith(f"{k}: not used with {WORDS[sensor]}"), msg
            refused += 1
    assert acting > 15 and (refused > 0 or pose), (acting, refused)


def test_contact_and_camera_keywords_act_on_their_sensor():
    """Every keyword of calibrate_contacts and calibrate_camera is one the
    table has acting on contacts or pixels: the refusal is never raised by
    a keyword of their own signatures (checked through the table's words:
    a keyword the table does not decide would be refused)."""
    for f in (activecal.calibrate_contacts, activecal.calibrate_camera):
        ks = keywords(f)
        assert "outliers" in ks and "outlier_rate" in ks, ks
    assert "pixel_noise" in keywords(activecal.calibrate_camera)


def test_detect_takes_the_robot_and_the_joints_by_keyword():
    """detect's keywords: the robot and the joints file its observations
    need (the command line's --robot and --joints), nothing else."""
    sig = inspect.signature(activecal.detect)
    kw = [n for n, p in sig.parameters.items() if p.kind == p.KEYWORD_ONLY]
    assert kw == ["robot", "joints"], kw


def test_calibrate_camera_takes_images_and_joints_by_keyword():
    """calibrate_camera's images and joints (the command line's --images
    and --joints): keyword-only, None by default (the pixels are then the
    observations)."""
    sig = inspect.signature(activecal.calibrate_camera)
    for k in ("images", "joints"):
        p = sig.parameters[k]
        assert p.kind == p.KEYWORD_ONLY and p.default is None, (k, p)
    assert sig.parameters["observations"].default is None


CAM = FIXTURES / "camera"
CAMERA_POSE = [1.1761, 0.6096, 0.9079, -2.0681, 0.0317, 2.0826]
TARGET_POSE = [-0.1047, 0.0411, 0.0301, 3.1111, -0.0192, 0.0556]


def camera_fit(pixels, **kw):
    r = activecal.Robot.from_urdf(FIXTURES / "ur5.urdf")
    return activecal.calibrate_camera(
        r, pixels, CAM / "camera_info.yaml", CAM / "board.yaml", mounting="eye-to-hand",
        camera_pose=CAMERA_POSE, target_pose=TARGET_POSE, **kw,
    )


def test_camera_keywords_act(tmp_path):
    pixels = CAM / "ur5_eye_to_hand.csv"
    kept = camera_fit(pixels, outliers="keep")
    assert kept.report["outliers"] == {"choice": {"kind": "keep"}, "left_out": []}
    # A stated pixel noise far below the fit's σ̂ is rejected, with the
    # command line's warning.
    with pytest.warns(UserWarning, match="noisier than stated"):
        c = camera_fit(pixels, pixel_noise=0.01)
    assert c.report["noise_test"]["rejected"] and c.report["noise_test"]["unit"] == "px"
    for kw, words in [
        (dict(pixel_noise=-1.0), "pixel_noise=-1"),
        (dict(outliers="maybe"), "outliers"),
        (dict(outlier_rate=2.0), "outlier_rate=2"),
    ]:
        with pytest.raises(ValueError, match=words):
            camera_fit(pixels, **kw)


def test_writers_refuse_to_write_over_an_input(tmp_path):
    pixels = tmp_path / "pixels.csv"
    shutil.copy(CAM / "ur5_eye_to_hand.csv", pixels)
    before = pixels.read_bytes()
    c = camera_fit(pixels)
    for write in (c.write_urdf, c.write_frames):
        with pytest.raises(activecal.Error, match="pixels.csv"):
            write(pixels, overwrite=True)
    assert pixels.read_bytes() == before
    # The robot's own URDF, for a tracker's calibration too.
    urdf = tmp_path / "ur5.urdf"
    shutil.copy(UR5_URDF, urdf)
    marker = "tool0@0.031,-0.024,0.097"
    _, m = simulated(tmp_path, ["--robot", urdf, "--tip", "tool0", "--marker", marker])
    r = activecal.Robot.from_urdf(urdf, tip="tool0", marker=marker)
    cal = activecal.calibrate(r, m["qs"], m["points"])
    text = urdf.read_bytes()
    with pytest.raises(activecal.Error, match="ur5.urdf"):
        cal.write_urdf(urdf, overwrite=True)
    assert urdf.read_bytes() == text
    # A report folder is replaced whole: never one holding the robot's
    # description, even with overwrite.
    with pytest.raises(activecal.FileError, match="holds an input"):
        cal.write_report(tmp_path, overwrite=True)
    assert urdf.read_bytes() == text


def test_every_keyword_of_the_report_folder_acts(tmp_path):
    """Design.show and write_report: noise changes the "how many poses"
    curve the folder and its page show, target_error the size report.md
    recommends (progress is called)."""
    d = activecal.select(activecal.Robot.builtin("puma560"), 12, count=400, order="none")
    assert keywords(d.show) == ["noise"]
    assert keywords(d.write_report) == ["path", "overwrite", "noise", "target_error"]
    calls = []
    base = d.show(progress=lambda *a: calls.append(a)).html
    assert calls
    assert d.show(noise=3e-3).html != base
    # target_error: the size the folder's report.md recommends.
    target = d.how_many()["points"][0]["predicted"]["position_rms_mm"]
    d.write_report(tmp_path / "a")
    d.write_report(tmp_path / "b", target_error=target * 1.5)
    a, b = ((tmp_path / x / "report.md").read_text() for x in "ab")
    assert "recommended, the fewest predicted to reach" in b and a != b
    assert keywords(activecal.Calibration.show) == ["self"]
    assert keywords(activecal.Calibration.write_report) == ["self", "path", "overwrite"]


# activecal.extract's keywords and the flags of `activecal extract` they are
# (a bag's options, the same on `calibrate --bag`).
EXTRACT = {
    "joints": "--joints",
    "points": "--points",
    "poses": "--poses",
    "tf": "--tf",
    "time_offset": "--time-offset",
    "max_offset": "--max-offset",
    "rest_speed": "--rest-speed",
    "rest_min": "--rest-min",
    "settle": "--settle",
    "design": "--design",
    "design_tolerance": "--design-tolerance",
}


def test_every_keyword_of_extract_is_a_flag_of_the_command_line():
    import subprocess

    from conftest import cli_path

    given = inspect.signature(activecal.extract).parameters
    assert sorted(p for p in given if p not in {"bag", "robot", "progress"}) == sorted(EXTRACT)
    help_text = subprocess.run([str(cli_path()), "extract", "--help"], capture_output=True, text=True).stdout
    for flag in EXTRACT.values():
        assert flag + " " in help_text, flag
