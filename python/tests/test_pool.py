"""pool and the new arguments of select: the same pools, designs, existing
poses and bound as the command line on the same inputs."""

import numpy as np
import pytest

import activecal
from conftest import FIXTURES, cli


def test_pool_equals_the_cli_pool_and_selects_the_same_design():
    r = activecal.Robot.builtin("puma560")
    p = activecal.pool(r, "lattice", levels=3)
    assert len(p) == 3**6 and p.q.shape == (729, 6) and p.q.dtype == np.float64
    assert p.ids == list(range(729))
    assert p.stats["candidates"] == 729 and p.stats["kept"] == 729
    d = activecal.select(r, 15, pool=p)
    want = cli("select", "--robot", "puma560", "--levels", 3, "--n", 15, "--order", "none")
    assert d.ids == want["poses"] and d.ln_oid == want["ln_oid"]
    with pytest.raises(activecal.Error, match="count: is the pool's own"):
        activecal.select(r, 15, pool=p, count=10)


def test_own_candidates_equal_a_cli_pool_file(tmp_path):
    r = activecal.Robot.builtin("puma560")
    rng = np.random.default_rng(3)
    lo, hi = r.limits[:, 0], r.limits[:, 1]
    q = lo + (hi - lo) * rng.random((400, 6))
    f = tmp_path / "candidates.csv"
    header = ",".join(r.joint_names)
    np.savetxt(f, q, delimiter=",", header=header, comments="", fmt="%.17g")
    d = activecal.select(r, 20, pool=q)
    want = cli("select", "--robot", "puma560", "--pool", f"file:{f}", "--n", 20, "--order", "none")
    assert d.ids == want["poses"]
    assert abs(d.ln_oid - want["ln_oid"]) < 1e-12
    with pytest.raises(activecal.Error, match=r"^source"):
        activecal.pool(r, q[:, :5])
    bad = q.copy()
    bad[7, 2] = np.nan
    with pytest.raises(activecal.Error, match=r"^source"):
        activecal.pool(r, bad)


def test_existing_poses_and_the_bound_equal_the_cli(tmp_path):
    r = activecal.Robot.builtin("puma560")
    first = activecal.select(r, 12, pool="lattice", levels=3)
    f = tmp_path / "first.csv"
    first.write(str(f))
    d = activecal.select(r, 10, pool="lattice", levels=3, existing=first.q)
    want = cli(
        "select", "--robot", "puma560", "--levels", 3, "--n", 10, "--existing", f, "--order", "none",
    )
    assert d.ids == want["poses"]
    assert abs(d.ln_oid - want["ln_oid"]) < 1e-9 * abs(want["ln_oid"])
    out = tmp_path / "d.json"
    d.write(str(out))
    g = d.bound()
    gap = cli("gap", "--design", out)
    assert abs(g["ln_bound"] - gap["ln_bound"]) < 1e-9 * abs(gap["ln_bound"])
    assert abs(g["d_efficiency"] - gap["d_efficiency"]) < 1e-9
    assert 0.0 < g["d_efficiency"] <= 1.0


def test_the_bound_and_gap_functions_equal_the_cli(tmp_path):
    r = activecal.Robot.builtin("puma560")
    b = activecal.bound(r, 30, pool="lattice", levels=3, weights=True)
    want = cli("bound", "--robot", "puma560", "--levels", 3, "--n", 30, "--weights")
    # The same bound to rounding (one solve, the same pool); every key the
    # command prints, with the same support poses.
    assert abs(b["ln_bound"] - want["ln_bound"]) < 1e-9 * abs(want["ln_bound"])
    assert set(b) == set(want)
    assert [w["pose"] for w in b["support"]] == [w["pose"] for w in want["support"]]
    # Existing poses raise the bound of the poses to add, as --existing does.
    first = activecal.select(r, 12, pool="lattice", levels=3)
    f = tmp_path / "first.csv"
    first.write(str(f))
    with_prior = activecal.bound(r, 10, pool="lattice", levels=3, existing=first.q)
    want = cli("bound", "--robot", "puma560", "--levels", 3, "--n", 10, "--existing", f)
    assert abs(with_prior["ln_bound"] - want["ln_bound"]) < 1e-9 * abs(want["ln_bound"])
    # gap(design) is design.bound(), and the dict `gap --json` prints for
    # the design's file: the same keys, the same values (to rounding, one
    # solve each; the solver's timing aside).
    d = activecal.select(r, 30, pool="lattice", levels=3)
    g = activecal.gap(d)
    assert g == d.bound() or _without_seconds(g) == _without_seconds(d.bound())
    d.write(tmp_path / "d30.json")
    _same_report(g, cli("gap", "--design", tmp_path / "d30.json"))
    with pytest.raises(activecal.InputError, match="n"):
        activecal.bound(r, 0, pool="lattice", levels=3)


def test_collision_filters_equal_the_cli():
    ur10 = FIXTURES / "example-robot-data" / "ur10_robot.urdf"
    r = activecal.Robot.from_urdf(ur10, tip="tool0")
    p = activecal.pool(
        r, "random", count=150, self_collision=True, floor=0.0, package_dirs=[FIXTURES]
    )
    want = cli(
        "select", "--robot", ur10, "--tip", "tool0", "--pool", "random", "--count", 150,
        "--self-collision", "--floor", 0, "--package-dir", FIXTURES, "--n", 30, "--order", "none",
    )
    assert p.stats == want["pool_stats"]
    assert len(p) == want["pool_stats"]["kept"] < 150
    with pytest.raises(activecal.Error, match="^srdf: lists pairs"):
        activecal.pool(r, "random", count=10, srdf=str(ur10))
    with pytest.raises(activecal.Error, match="^floor"):
        activecal.pool(r, "random", count=10, floor=float("nan"))
    puma = activecal.Robot.builtin("puma560")
    with pytest.raises(activecal.Error, match="^self_collision: collision checks need"):
        activecal.pool(puma, "random", count=10, self_collision=True)


def _without_seconds(v):
    """A report without its timings (keys ending in `seconds`)."""
    if isinstance(v, dict):
        return {k: _without_seconds(x) for k, x in v.items() if not k.endswith("seconds")}
    if isinstance(v, list):
        return [_without_seconds(x) for x in v]
    return v


def _same_report(got, want, where="gap"):
    """The same keys at every level and the same values, floats to 1e-9
    relative (two solves of the same problem), timings aside."""
    if isinstance(want, dict):
        assert isinstance(got, dict) and set(got) == set(want), (where, set(got) ^ set(want))
        for k in want:
            if not k.endswith("seconds"):
                _same_report(got[k], want[k], f"{where}.{k}")
    elif isinstance(want, list):
        assert isinstance(got, list) and len(got) == len(want), where
        for i, (a, b) in enumerate(zip(got, want)):
            _same_report(a, b, f"{where}[{i}]")
    elif isinstance(want, float) and not isinstance(want, bool):
        assert got == pytest.approx(want, rel=1e-9, abs=1e-12), where
    else:
        assert got == want, where
