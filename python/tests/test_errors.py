"""Every error is an activecal.Error subclass that says what kind of
failure it is, with the library's message, and is also the built-in
exception that fits (ValueError, OSError, RuntimeError). Writers replace
an existing file, as pandas and NumPy do; overwrite=False refuses."""

import pickle

import numpy as np
import pytest

import activecal


def test_error_classes_say_what_failed(tmp_path):
    r = activecal.Robot.builtin("puma560")
    for cls, builtin in (
        (activecal.InputError, ValueError),
        (activecal.FileError, OSError),
        (activecal.ResourceError, RuntimeError),
        (activecal.ComputationError, RuntimeError),
        (activecal.InternalError, RuntimeError),
    ):
        assert issubclass(cls, activecal.Error) and issubclass(cls, builtin)
        assert cls.__module__ == "activecal" and cls.__doc__
    with pytest.raises(activecal.InputError, match=r"^q: expected shape \(6,\)"):
        r.fk(np.zeros(5))
    with pytest.raises(ValueError, match="fewer than the 27 unknowns"):
        activecal.select(r, 3, pool="lattice", levels=2)
    with pytest.raises(activecal.FileError, match="^path: .*no such file") as e:
        activecal.Robot.from_urdf(tmp_path / "missing.urdf", tip="tool0")
    assert isinstance(e.value, OSError) and str(e.value).startswith("path: ")
    # An error pickles (multiprocessing sends them back from workers).
    again = pickle.loads(pickle.dumps(e.value))
    assert type(again) is activecal.FileError and str(again) == str(e.value)


def test_writers_overwrite_unless_told_not_to(tmp_path):
    r = activecal.Robot.builtin("puma560")
    d = activecal.select(r, 30, pool="lattice", levels=3)
    out = tmp_path / "d.json"
    out.write_text("old")
    d.write(out)  # replaced, as DataFrame.to_csv does
    assert out.read_text().startswith("{")
    before = out.read_text()
    with pytest.raises(activecal.FileError, match="exists") as e:
        d.write(out, overwrite=False)
    assert isinstance(e.value, OSError)
    assert out.read_text() == before
    fresh = tmp_path / "new.csv"
    d.write(fresh, overwrite=False)
    assert fresh.is_file()
