"""progress callbacks: every task the work starts reports to the caller,
done never exceeds total and ends at it, and the callback's exception is
raised by the call."""

import pytest

import activecal


def test_select_and_bound_report_their_progress():
    r = activecal.Robot.builtin("puma560")
    calls = []
    d = activecal.select(r, 30, pool="lattice", levels=3, progress=lambda *a: calls.append(a))
    tasks = {c[0] for c in calls}
    assert any(t.startswith("select") for t in tasks), tasks
    for task, done, total, note in calls:
        assert isinstance(task, str) and done >= 0
        assert total is None or done <= total
    ends = [c for c in calls if c[3] == "done"]
    assert ends and all(c[2] is None or c[1] == c[2] for c in ends), ends
    calls.clear()
    d.bound(progress=lambda *a: calls.append(a))
    assert any(c[0].startswith("bound") for c in calls), calls[:3]
    # The same design without a callback: progress changes nothing.
    assert activecal.select(r, 30, pool="lattice", levels=3).ids == d.ids


def test_the_callbacks_exception_is_raised_and_a_non_callable_refused():
    r = activecal.Robot.builtin("puma560")

    def stop(*_):
        raise KeyError("stop")

    with pytest.raises(KeyError, match="stop"):
        activecal.select(r, 30, pool="lattice", levels=3, progress=stop)
    with pytest.raises(activecal.InputError, match="^progress"):
        activecal.select(r, 30, pool="lattice", levels=3, progress=3)
