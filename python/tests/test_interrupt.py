"""Ctrl-C stops a long call within 0.5 s: a child process runs `select`
(and `Design.how_many`) on a pool large enough to take many seconds, the
parent sends SIGINT once the work is under way, and the child must raise
KeyboardInterrupt out of the call soon after."""

import os
import signal
import subprocess
import sys
import time

import pytest

from conftest import REPO

# The child: starts the long call, says when its work has started (the
# first progress report), and reports how the call ended.
CHILD = r"""
import sys, time
import activecal

r = activecal.Robot.builtin("puma560")
what = sys.argv[1]
started = []

def progress(task, done, total, note):
    if not started:
        started.append(True)
        print("started", flush=True)

try:
    if what == "select":
        activecal.select(r, 40, pool="sobol", count=60000, starts=64, ils=20, progress=progress)
    else:
        d = activecal.select(r, 30, pool="lattice", levels=3)
        print("designed", flush=True)
        d.how_many(noise=5e-5, progress=progress)
    print("finished", flush=True)
except KeyboardInterrupt:
    print("interrupted", time.monotonic(), flush=True)
"""

# Longest time from SIGINT to the call's KeyboardInterrupt: the issue's
# requirement. The call checks for signals every 50 ms, and the work stops
# at its next progress advance (throttled to 0.1 s only for the callback).
LIMIT_S = 0.5


@pytest.mark.parametrize("what", ["select", "how_many"])
def test_ctrl_c_stops_a_long_call(what):
    child = subprocess.Popen(
        [sys.executable, "-c", CHILD, what],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=REPO,
        env={**os.environ, "OPENBLAS_NUM_THREADS": "1"},
    )
    try:
        line = child.stdout.readline().strip()
        if line == "designed":
            line = child.stdout.readline().strip()
        assert line == "started", (line, child.stderr.read())
        # Well inside the work (which takes tens of seconds uninterrupted).
        time.sleep(1.0)
        sent = time.monotonic()
        child.send_signal(signal.SIGINT)
        out = child.stdout.readline().split()
        assert out and out[0] == "interrupted", (out, child.stderr.read())
        took = float(out[1]) - sent
        assert took < LIMIT_S, f"{what}: KeyboardInterrupt {took:.3f} s after SIGINT"
        assert child.wait(timeout=30) == 0
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()
