"""show() and write_report() of a camera design and a contact calibration:
the report folder the command line writes (`select --camera-info ...
--report`, `calibrate --measurements contacts.csv --report`), made by the
library's renderer, and its 3D page with the lines of sight checked (camera)
and the fitted sockets and planes (contacts)."""

import json

import pytest

import activecal
from conftest import FIXTURES, cli

CAM = FIXTURES / "camera"
INFO, BOARD = CAM / "camera_info.yaml", CAM / "board.yaml"
PANDA = FIXTURES / "example-robot-data" / "panda.urdf"
# The Panda eye-to-hand scene of test_camera's line-of-sight test: its own
# links hide the board from some configurations.
CP = [1.2, 0.6, 0.9, -2.0985, 0.0, 2.0779]
TP = [-0.0853, 0.0568, 0.02, 3.141592653589793, 0.0, 0.03]


def csv6(v):
    return ",".join(repr(float(x)) for x in v)


def page_data(html):
    """The page's embedded data (the JSON its script draws)."""
    start = html.index('id="page-data">') + len('id="page-data">')
    return json.loads(html[start:html.index("</script>", start)])


@pytest.fixture(scope="module")
def camera(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("camera")
    cli(
        "select", "--robot", f"{PANDA}#tip=panda_hand_tcp", "--camera-info", INFO,
        "--target", BOARD, "--mounting", "eye-to-hand", f"--camera-pose={csv6(CP)}",
        f"--target-pose={csv6(TP)}", "--image-margin", 20, "--distance", "0.3,2.0",
        "--n", 14, "--count", 1500, "--line-of-sight", "--report", tmp / "cli",
    )
    r = activecal.Robot.from_urdf(PANDA, tip="panda_hand_tcp")
    d = activecal.select_camera(
        r, INFO, BOARD, n=14, mounting="eye-to-hand", camera_pose=CP, target_pose=TP,
        count=1500, image_margin=20, distance=(0.3, 2.0), line_of_sight=True,
    )
    return tmp, d


def test_camera_design_folder_and_page_equal_the_clis(camera):
    """Every file of the folder, report.json and the page included, byte for
    byte: the same library code on the same design (no run time in a
    camera design's report)."""
    tmp, d = camera
    want = tmp / "cli"
    d.write_report(tmp / "py")
    names = sorted(p.name for p in want.iterdir())
    assert sorted(p.name for p in (tmp / "py").iterdir()) == names
    assert {"index.html", "report.md", "report.json", "how_many_poses.png"} <= set(names)
    for name in names:
        assert (tmp / "py" / name).read_bytes() == (want / name).read_bytes(), name
    page = d.show()
    assert isinstance(page, activecal.Page)
    assert page.html.encode() == (want / "index.html").read_bytes()


def test_camera_page_holds_the_lines_of_sight_the_design_counted(camera):
    """One list of rays per pose; the clear ones to points inside the image
    are the points the design says each pose sees (`points_seen`, counted
    by the line-of-sight check when the design was chosen), and every ray
    leaves from the camera the page draws."""
    _, d = camera
    s = page_data(d.show().html)["sensor"]
    assert s["kind"] == "camera"
    assert len(s["rays"]) == len(d.points_seen) == 14
    for rays, seen, cam in zip(s["rays"], d.points_seen, s["placements"]):
        assert sum(r["clear"] for r in rays) == seen
        for r in rays:
            assert r["from"] == pytest.approx(cam[12:15], abs=1e-9)


def test_camera_report_keywords_act(camera, tmp_path):
    _, d = camera
    base = d.show().html
    assert d.show(pixel_noise=1.0).html != base
    calls = []
    d.write_report(tmp_path / "a", progress=lambda *a: calls.append(a))
    assert calls
    d.write_report(tmp_path / "b", target_error=1e-6)
    a, b = ((tmp_path / x / "report.md").read_text() for x in "ab")
    assert "no N of the curve is predicted to reach 0.000001 mm" in b and a != b
    with pytest.raises(activecal.FileError, match="exists"):
        d.write_report(tmp_path / "a", overwrite=False)
    with pytest.raises(activecal.InputError, match="^pixel_noise"):
        d.show(pixel_noise=0.0)
    with pytest.raises(activecal.InputError, match="^target_error"):
        d.write_report(tmp_path / "c", target_error=-1.0)


MUKCA = FIXTURES / "mukca"
CONTACT_PANDA, CONTACTS = MUKCA / "panda.urdf", MUKCA / "panda_2.csv"


def contact_rows():
    import csv

    with open(CONTACTS) as f:
        r = list(csv.reader(f))
    return [[float(x) for x in row[:-1]] for row in r[1:]], [row[-1] for row in r[1:]]


def test_contact_folder_and_page_equal_the_clis(tmp_path):
    """The same folder as the command line's but for how the rows are
    named: the CSV's path and file lines for the command line, "the arrays
    given" and row numbers (from 1) for Python. So the consistency figure
    is equal byte for byte, report.md once the source is replaced (no row
    is named in it without a robust loss), and the page's data once the
    rows' numbers are taken out of the pose labels; the row-distance
    figure names its five largest rows by number, so it differs. The page
    draws every fitted socket where the fit puts it (MUKCa's base link is
    its URDF's root: the page's frame is the fit's)."""
    import re

    q, touched = contact_rows()
    blocks = sorted({t.split("/")[0] for t in touched})
    args = ["--robot", CONTACT_PANDA, "--tip", "ball_link", "--measurements", CONTACTS]
    for b in blocks:
        args += ["--point-distance", f"{b}/0,{b}/1=0.05"]
    cli("calibrate", *args, "--report", tmp_path / "cli")
    r = activecal.Robot.from_urdf(CONTACT_PANDA, tip="ball_link")
    c = activecal.calibrate_contacts(r, q, touched, {(f"{b}/0", f"{b}/1"): 0.05 for b in blocks})
    c.write_report(tmp_path / "py")
    py, want = tmp_path / "py", tmp_path / "cli"
    names = sorted(p.name for p in want.iterdir())
    assert sorted(p.name for p in py.iterdir()) == names
    assert {"index.html", "report.md", "report.json", "row_distances.png"} <= set(names)
    for name in ("consistency_by_placement.png", "consistency_by_placement.svg"):
        assert (py / name).read_bytes() == (want / name).read_bytes(), name
    source = str(CONTACTS)
    md = (want / "report.md").read_text()
    assert source in md
    assert (py / "report.md").read_text().replace("the arrays given", source) == md
    page = c.show().html
    assert page.encode() == (py / "index.html").read_bytes()
    got, exp = page_data(page), page_data((want / "index.html").read_text())
    rows = [p["label"] for p in got["poses"]]
    assert rows[0].startswith("line 1: ") and exp["poses"][0]["label"].startswith("line 2: ")
    for d in (got, exp):
        for p in d["poses"]:
            p["label"] = re.sub(r"^line \d+: ", "", p["label"])
    assert got == exp
    s = got["sensor"]
    assert s["kind"] == "contacts" and s["planes"] == []
    drawn = {p["name"]: p["position"] for p in s["sockets"]}
    assert set(drawn) == set(touched)
    for name, x in c.points.items():
        assert drawn[name] == pytest.approx(list(x), abs=1e-12)
