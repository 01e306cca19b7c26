"""select: the same design as `activecal select --order none` on the same
pool and seed (test_api_more.py: the visiting order); the design files it
writes are read back by the CLI."""

import json

import numpy as np
import pytest

import activecal
from conftest import UR5_URDF, cli

# What differs between two runs: the clock.
VOLATILE = {"seconds"}


def same_report(py, cl):
    keys = (set(py) | set(cl)) - VOLATILE
    for k in sorted(keys):
        assert py.get(k) == cl.get(k), k


def test_puma_random_pool_equals_the_cli():
    r = activecal.Robot.builtin("puma560")
    d = activecal.select(r, 20, pool="random", count=1500, pool_seed=4, seed=7, noise=1e-4)
    want = cli(
        "select", "--robot", "puma560", "--pool", "random", "--count", 1500, "--pool-seed", 4,
        "--n", 20, "--seed", 7, "--noise", 1e-4, "--order", "none",
    )
    assert d.ids == want["poses"]
    assert d.q.shape == (20, 6) and d.q.dtype == np.float64
    assert np.array_equal(d.q, np.array([c["q"] for c in want["configurations"]]))
    assert d.ln_oid == want["ln_oid"]
    assert d.predicted == want["predicted"]
    same_report(d.report, want)


def test_lattice_and_sobol_equal_the_cli():
    r = activecal.Robot.builtin("puma560")
    d = activecal.select(r, 15, pool="lattice", levels=3)
    want = cli("select", "--robot", "puma560", "--levels", 3, "--n", 15, "--order", "none")
    assert d.ids == want["poses"] and d.ln_oid == want["ln_oid"]
    d = activecal.select(r, 15, pool="sobol", count=512)
    want = cli("select", "--robot", "puma560", "--pool", "sobol", "--count", 512, "--n", 15, "--order", "none")
    assert d.ids == want["poses"] and d.ln_oid == want["ln_oid"]
    assert d.predicted is None


def test_urdf_with_marker_equals_the_cli():
    r = activecal.Robot.from_urdf(UR5_URDF, tip="tool0", marker="tool0@0.031,-0.024,0.097")
    d = activecal.select(r, 30, count=1024, order="none")
    want = cli(
        "select", "--robot", UR5_URDF, "--tip", "tool0", "--marker", "tool0@0.031,-0.024,0.097",
        "--pool", "random", "--count", 1024, "--n", 30, "--order", "none",
    )
    assert d.ids == want["poses"]
    assert np.array_equal(d.q, np.array([c["q"] for c in want["configurations"]]))
    assert d.ln_oid == want["ln_oid"]


@pytest.mark.parametrize("ext", ["json", "csv", "yaml"])
def test_written_designs_equal_the_clis_and_read_back(tmp_path, ext):
    r = activecal.Robot.builtin("puma560")
    d = activecal.select(r, 12, pool="random", count=800)
    mine = tmp_path / f"py.{ext}"
    d.write(mine)
    theirs = tmp_path / f"cli.{ext}"
    cli("select", "--robot", "puma560", "--pool", "random", "--count", 800, "--n", 12,
        "--order", "none", "--out", theirs)
    if ext == "json":
        a, b = json.loads(mine.read_text()), json.loads(theirs.read_text())
        assert a == b
    else:
        assert mine.read_text() == theirs.read_text()
    # The CLI scores the file Python wrote: the same ln OI_D.
    if ext == "csv":
        score = cli("score", "--robot", "puma560", "--pool", f"file:{mine}")
    else:
        score = cli("score", "--design", mine)
    assert score["ln_oid"] == pytest.approx(d.ln_oid, abs=1e-9)
    with pytest.raises(activecal.FileError, match="exists"):
        d.write(mine, overwrite=False)
    d.write(mine)


@pytest.mark.parametrize(
    "kwargs, words",
    [
        (dict(n=0), ["n:", ">= 1"]),
        (dict(n=10, pool="grid"), ["pool:", "unknown pool 'grid'"]),
        (dict(n=10, pool="lattice", count=100), ["count:", "random"]),
        (dict(n=10, levels=3), ["levels:", "lattice"]),
        (dict(n=10, seed=-1), ["seed:"]),
        (dict(n=10, noise=float("nan")), ["noise:"]),
        (dict(n=10, margin=-1.0), ["margin:"]),
        (dict(n=10, algorithm="best"), ["algorithm:", "eae"]),
        (dict(n=5000, count=100), ["100"]),
    ],
)
def test_select_errors(kwargs, words):
    r = activecal.Robot.builtin("puma560")
    with pytest.raises(activecal.Error) as e:
        activecal.select(r, **kwargs)
    for w in words:
        assert w in str(e.value), str(e.value)
