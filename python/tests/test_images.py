"""activecal.detect on the committed images (fixtures/camera/images/: a
camera on a true UR5's flange looking at a 6 x 9 checkerboard, rendered by
verify/python/camera_images.py with --noise 0; their true corners in
fixtures/camera/images_truth.csv), and the observations it returns
calibrated by calibrate_camera."""

import csv
import math

import pytest

import activecal
from conftest import FIXTURES

CAM = FIXTURES / "camera"
IMAGES = CAM / "images"


def ur5():
    return activecal.Robot.from_urdf(FIXTURES / "ur5.urdf", tip="target")


def detected():
    return activecal.detect(IMAGES, CAM / "board_6x9.yaml", CAM / "small_camera_info.yaml",
                            robot=ur5(), joints=IMAGES / "joints.csv")


def test_detect_returns_the_observations_of_every_image_with_the_true_corners():
    df = detected()
    r = ur5()
    assert list(df.columns) == ["pose", *r.joint_names, "feature", "u", "v"]
    images = df.attrs["images"]
    assert len(images) == 12 and all(i["status"] == "found" for i in images), images
    assert sorted(set(df["pose"])) == list(range(12))
    truth = {(int(row["pose"]), int(row["feature"])): (float(row["u"]), float(row["v"]))
             for row in csv.DictReader(open(CAM / "images_truth.csv"))}
    errors = sorted(math.hypot(u - truth[(p, f)][0], v - truth[(p, f)][1])
                    for p, f, u, v in zip(df["pose"], df["feature"], df["u"], df["v"]))
    # Every corner labelled as the truth (another id is a square, >= 6 px,
    # away) and refined (the bounds of tests/camera_images.rs: the
    # detector's corners within 0.5 px, refined ones 0.1 px in the median).
    assert len(errors) == 12 * 54
    assert errors[len(errors) // 2] < 0.1 and errors[-1] < 0.5, errors[-5:]


def test_the_detected_observations_calibrate_as_the_command_line_does():
    cal = activecal.calibrate_camera(ur5(), detected(), CAM / "small_camera_info.yaml",
                                     CAM / "board_6x9.yaml", mounting="eye-in-hand")
    assert cal.converged
    # Noise-free renders: the corners' errors are the refinement's
    # (under 0.1 px in the median), the fit's pixel σ of the same order.
    assert cal.report["sigma_px"] < 0.2, cal.report["sigma_px"]


def test_a_missing_folder_and_a_target_without_a_detector_are_refused_naming_them(tmp_path):
    with pytest.raises(activecal.InputError, match="^images: "):
        activecal.detect(tmp_path / "nowhere", CAM / "board_6x9.yaml",
                         CAM / "small_camera_info.yaml", robot=ur5(), joints=IMAGES / "joints.csv")
    points = {"points": [{"id": i, "xyz": [0.1 * (i % 2), 0.1 * (i // 2), 0.0]} for i in range(4)]}
    with pytest.raises(activecal.InputError, match="^images: .*a point list is not detected"):
        activecal.detect(IMAGES, points, CAM / "small_camera_info.yaml", robot=ur5(),
                         joints=IMAGES / "joints.csv")


def test_detect_finds_kalibrs_aprilgrid_with_its_ids():
    """fixtures/camera/aprilgrid/: 8 noise-free renders (640 x 480) of a
    Kalibr aprilgrid of 3 x 4 tags of 30 mm (tagSpacing 0.3), the true
    pixel of each tag corner in fixtures/camera/aprilgrid_truth.csv."""
    d = CAM / "aprilgrid"
    df = activecal.detect(d, CAM / "aprilgrid_3x4.yaml", CAM / "charuco_camera_info.yaml",
                          robot=ur5(), joints=d / "joints.csv")
    images = df.attrs["images"]
    assert len(images) == 8 and all(i["status"] == "found" for i in images), images
    truth = {(int(row["pose"]), int(row["feature"])): (float(row["u"]), float(row["v"]))
             for row in csv.DictReader(open(CAM / "aprilgrid_truth.csv"))}
    errors = sorted(math.hypot(u - truth[(p, f)][0], v - truth[(p, f)][1])
                    for p, f, u, v in zip(df["pose"], df["feature"], df["u"], df["v"]))
    # Every tag corner found with its true id (another id is at least the
    # 9 mm gap, >= 14 px, away) within the bounds of tests/camera_images.rs.
    assert len(errors) == 8 * 48
    assert errors[len(errors) // 2] < 0.1 and errors[-1] < 0.5, errors[-5:]
    cal = activecal.calibrate_camera(ur5(), camera_info=CAM / "charuco_camera_info.yaml",
                                     target=CAM / "aprilgrid_3x4.yaml", images=d,
                                     joints=d / "joints.csv", mounting="eye-in-hand")
    assert cal.report["images"] == images


def test_calibrate_camera_from_images_equals_the_command_line():
    from conftest import cli
    want = cli("calibrate", "--robot", f"{FIXTURES / 'ur5.urdf'}#tip=target", "--images", IMAGES,
               "--joints", IMAGES / "joints.csv", "--camera-info", CAM / "small_camera_info.yaml",
               "--target", CAM / "board_6x9.yaml", "--mounting", "eye-in-hand")
    got = activecal.calibrate_camera(ur5(), camera_info=CAM / "small_camera_info.yaml",
                                     target=CAM / "board_6x9.yaml", images=IMAGES,
                                     joints=IMAGES / "joints.csv", mounting="eye-in-hand")
    # The same library code on the same images: the reports equal bit for
    # bit, the images' list (found, figures) included.
    assert set(got.report) == set(want)
    for k in sorted(set(want) - {"out"}):
        assert got.report[k] == want[k], k
    assert len(got.report["images"]) == 12
    # The images as a list of files and the joints as a DataFrame: the same.
    import pandas as pd
    files = sorted(IMAGES.glob("img_*.png"))
    again = activecal.calibrate_camera(ur5(), camera_info=CAM / "small_camera_info.yaml",
                                       target=CAM / "board_6x9.yaml", images=[str(f) for f in files],
                                       joints=pd.read_csv(IMAGES / "joints.csv"),
                                       mounting="eye-in-hand")
    assert again.report["estimate"] == want["estimate"]
    assert again.report["images"] == want["images"]


def test_calibrate_camera_refuses_images_without_joints_or_with_observations():
    info, board = CAM / "small_camera_info.yaml", CAM / "board_6x9.yaml"
    with pytest.raises(ValueError, match="^joints: none given"):
        activecal.calibrate_camera(ur5(), camera_info=info, target=board, images=IMAGES,
                                   mounting="eye-in-hand")
    with pytest.raises(ValueError, match="^images: give the pixels"):
        activecal.calibrate_camera(ur5(), detected(), info, board, images=IMAGES,
                                   joints=IMAGES / "joints.csv", mounting="eye-in-hand")
    with pytest.raises(ValueError, match="^images: an empty list"):
        activecal.calibrate_camera(ur5(), camera_info=info, target=board, images=[],
                                   joints=IMAGES / "joints.csv", mounting="eye-in-hand")
