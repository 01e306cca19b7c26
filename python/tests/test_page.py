"""show() and write_report(): the report folder and 3D page the command
line writes (`select --report`, `calibrate --report`), byte for byte, made
by the library's renderer; the page shown inline by Jupyter."""

import html
import json

import pytest

import activecal
from conftest import UR5_URDF, cli

MARKER = "tool0@0.031,-0.024,0.097"
UR5_ARGS = ["--robot", UR5_URDF, "--tip", "tool0", "--marker", MARKER]


def ur5():
    return activecal.Robot.from_urdf(UR5_URDF, tip="tool0", marker=MARKER)


@pytest.fixture(scope="module")
def selected(tmp_path_factory):
    """The same UR5 design from the CLI (with its report folder) and from
    Python."""
    tmp = tmp_path_factory.mktemp("select")
    cli("select", *UR5_ARGS, "--pool", "random", "--count", 300, "--n", 12, "--order", "none",
        "--report", tmp / "cli", "--out", tmp / "d.json")
    d = activecal.select(ur5(), 12, count=300, order="none")
    return tmp, d


def test_design_page_and_folder_equal_the_clis(selected):
    tmp, d = selected
    want = tmp / "cli"
    d.write_report(tmp / "py")
    names = sorted(p.name for p in want.iterdir())
    assert sorted(p.name for p in (tmp / "py").iterdir()) == names
    assert "index.html" in names
    for name in names:
        if name != "report.json":
            assert (tmp / "py" / name).read_bytes() == (want / name).read_bytes(), name
    # report.json: the same but for the selection's measured run time.
    a, b = (json.loads((p / "report.json").read_text()) for p in (tmp / "py", want))
    for r in (a, b):
        r["selection"].pop("seconds")
    assert a == b
    page = d.show()
    assert isinstance(page, activecal.Page)
    assert page.html.encode() == (want / "index.html").read_bytes()
    assert repr(page) == f"Page({len(page.html.encode())} bytes of HTML)"


def test_page_displays_inline_and_writes(selected, tmp_path):
    _, d = selected
    page = d.show()
    frame = page._repr_html_()
    assert frame.startswith("<iframe srcdoc=\"") and frame.endswith("</iframe>")
    doc = frame[len("<iframe srcdoc=\""):frame.index("\" style=")]
    assert '"' not in doc
    assert html.unescape(doc) == page.html
    page.write(tmp_path / "p.html")
    assert (tmp_path / "p.html").read_text() == page.html
    with pytest.raises(activecal.FileError, match="exists"):
        page.write(tmp_path / "p.html", overwrite=False)


def test_write_report_overwrites_by_default_and_refuses_when_asked(selected, tmp_path):
    _, d = selected
    out = tmp_path / "r"
    out.mkdir()
    (out / "old.txt").write_text("x")
    with pytest.raises(activecal.FileError, match="exists"):
        d.write_report(out, overwrite=False)
    assert (out / "old.txt").exists()
    d.write_report(out)
    assert not (out / "old.txt").exists() and (out / "index.html").is_file()
    with pytest.raises(activecal.FileError, match="does not exist"):
        d.write_report(tmp_path / "no" / "such")
    (tmp_path / "f").write_text("x")
    with pytest.raises(activecal.FileError, match="not a directory"):
        d.write_report(tmp_path / "f")
    with pytest.raises(activecal.InputError, match="^noise"):
        d.show(noise=-1.0)
    with pytest.raises(TypeError):
        d.show(target_error=1.0)
    with pytest.raises(activecal.InputError, match="^target_error"):
        d.write_report(out, target_error=0.0)


def test_calibration_page_and_folder_equal_the_clis(tmp_path):
    design = tmp_path / "d.json"
    cli("select", *UR5_ARGS, "--pool", "random", "--count", 1000, "--n", 20, "--order", "none",
        "--out", design)
    meas = tmp_path / "m.json"
    cli("calibrate", *UR5_ARGS, "--design", design, "--save-measurements", meas,
        "--noise", 1e-4, "--seed", 3)
    cli("calibrate", *UR5_ARGS, "--measurements", meas, "--report", tmp_path / "cli")
    m = json.loads(meas.read_text())
    cal = activecal.calibrate(ur5(), m["qs"], m["points"])
    cal.write_report(tmp_path / "py")
    want = tmp_path / "cli"
    names = sorted(p.name for p in want.iterdir())
    assert sorted(p.name for p in (tmp_path / "py").iterdir()) == names
    # The figures and the page: byte for byte (report.md names the data's
    # source, report.json the run time).
    for name in names:
        if name not in ("report.json", "report.md"):
            assert (tmp_path / "py" / name).read_bytes() == (want / name).read_bytes(), name
    page = cal.show().html
    assert page.encode() == (want / "index.html").read_bytes()
    assert "Calibration of" in page and "measured" in page
