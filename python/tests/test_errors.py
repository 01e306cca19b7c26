"""Every error is an activecal.Error subclass that says what kind of
failure it is, with the library's message."""

import numpy as np
import pytest

import activecal


def test_error_classes_say_what_failed(tmp_path):
    r = activecal.Robot.builtin("puma560")
    for cls in (
        activecal.InputError,
        activecal.FileError,
        activecal.ResourceError,
        activecal.ComputationError,
        activecal.InternalError,
    ):
        assert issubclass(cls, activecal.Error)
    with pytest.raises(activecal.InputError, match=r"^q: expected shape \(6,\)"):
        r.fk(np.zeros(5))
    with pytest.raises(activecal.InputError, match="fewer than the 27 unknowns"):
        activecal.select(r, 3, pool="lattice", levels=2)
    with pytest.raises(activecal.FileError, match="^path: .*no such file"):
        activecal.Robot.from_urdf(tmp_path / "missing.urdf", tip="tool0")
    d = activecal.select(r, 30, pool="lattice", levels=3)
    d.write(tmp_path / "d.json")
    with pytest.raises(activecal.FileError, match="exists"):
        d.write(tmp_path / "d.json")
    d.write(tmp_path / "d.json", overwrite=True)
