"""Contacts of a known true robot, and a contact calibration's true error.

The true robot is `truth.py make`'s (Pinocchio, every chain joint's origin
perturbed, the tool point off its nominal). A socket is a fixed point in
the tracker's frame (any fixed frame: contacts do not see it). A contact
row is a configuration at which the true tool point sits in its socket, up
to a seating error (Gaussian, `--noise` metres per axis): found by damped
Gauss-Newton on Pinocchio's forward kinematics from a configuration near
the placement's, to 1e-12 m.

    contacts --truth T --placements N --rows R --noise S --seed K
             --draws D --glitched G --glitch-size M --out STEM
        N placements of two sockets 50 mm apart, R rows per socket. The
        configurations are drawn once (seed K); draw d (d < D) seats each
        row with its own noise and is written to STEM<d>.csv; for d < G the
        same draw again with two rows seated M metres off (the ball beside
        its socket) to STEMg<d>.csv. Prints the glitched rows of each draw.

    compare --truth T --urdf U... --frames F... --n N --seed K
        The true error of each calibration (a URDF and its frames file: the
        measured point on the tip) at N random configurations, after the
        rigid motion of the calibrated points onto the true ones that fits
        best (Kabsch): contacts leave the setup's placement free, so only
        the robot's shape is compared. RMS mm per calibration.
"""

import argparse
import json
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import truth  # noqa: E402


def point(t, q):
    return np.asarray(t.measured(q).translation, dtype=float)


def seat(t, target, q0, lims):
    """A configuration near q0 putting the true tool point at target."""
    q = np.array(q0, dtype=float)
    for _ in range(100):
        e = point(t, q) - target
        if np.linalg.norm(e) < 1e-12:
            return q
        jac = np.empty((3, len(q)))
        for k in range(len(q)):
            dq = np.zeros(len(q))
            dq[k] = 1e-7
            jac[:, k] = (point(t, q + dq) - point(t, q - dq)) / 2e-7
        lam = 1e-9
        q = q - jac.T @ np.linalg.solve(jac @ jac.T + lam * np.eye(3), e)
    if np.linalg.norm(point(t, q) - target) < 1e-12 and all(
            lim is None or lim[0] <= v <= lim[1] for v, lim in zip(q, lims)):
        return q
    return None


def cmd_contacts(a):
    t = truth.Truth(a.truth)
    rng = np.random.default_rng(a.seed)
    lims = t.chain.limits
    names = t.chain.names
    sockets, seeds = [], []
    for p in range(a.placements):
        q = t.chain.random_configurations(1, rng)[0]
        s = point(t, q)
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        sockets += [("p%d/0" % p, s), ("p%d/1" % p, s + 0.05 * d)]
        seeds += [q, q]
    # The configurations, each near its placement's (seated exactly).
    rows = []
    for (name, s), q in zip(sockets, seeds):
        got = 0
        while got < a.rows:
            q0 = seat(t, s, q + rng.normal(scale=0.35, size=len(q)), lims)
            if q0 is None:
                continue
            rows.append((name, s, q0))
            got += 1
    glitches = []
    for d in range(a.draws):
        nr = np.random.default_rng((a.seed, d))
        noise = nr.normal(scale=a.noise, size=(len(rows), 3))
        bad = sorted(nr.choice(len(rows), size=2, replace=False).tolist())
        dirs = nr.normal(size=(2, 3))
        outs = [("%s%d.csv" % (a.out, d), {})]
        if d < a.glitched:
            off = {b: a.glitch_size * v / np.linalg.norm(v) for b, v in zip(bad, dirs)}
            outs.append(("%sg%d.csv" % (a.out, d), off))
            glitches.append(bad)
        for path, off in outs:
            lines = [",".join(names) + ",point"]
            for k, (name, s, q0) in enumerate(rows):
                target = s + noise[k] + off.get(k, 0.0)
                q = seat(t, target, q0, [None] * len(q0))
                if q is None:
                    raise SystemExit("row %d: not seated" % k)
                lines.append(",".join(repr(float(v)) for v in q) + "," + name)
            with open(path, "w") as f:
                f.write("\n".join(lines) + "\n")
    print(json.dumps({"rows": len(rows), "sockets": [n for n, _ in sockets],
                      "glitched_rows": glitches}))


def kabsch(src, dst):
    """R, t minimising sum |R src_i + t - dst_i|^2."""
    cs, cd = src.mean(axis=0), dst.mean(axis=0)
    h = (src - cs).T @ (dst - cd)
    u, _, vt = np.linalg.svd(h)
    d = np.sign(np.linalg.det(vt.T @ u.T))
    r = vt.T @ np.diag([1.0, 1.0, d]) @ u.T
    return r, cd - r @ cs


def cmd_compare(a):
    t = truth.Truth(a.truth)
    rng = np.random.default_rng(a.seed)
    qs = t.chain.random_configurations(a.n, rng)
    want = np.array([point(t, q) for q in qs])
    out = []
    for u, fr in zip(a.urdf, a.frames):
        m, tool, markers, base, tip, _ = truth.read_frames(fr)
        cal = truth.Chain(u, base or t.chain.base, tip or t.chain.tip)
        got = np.array([np.asarray((m * cal.relative(q) * tool).translation, dtype=float) for q in qs])
        r, tv = kabsch(got, want)
        e = np.linalg.norm(got @ r.T + tv - want, axis=1) * 1e3
        out.append(float(math.sqrt(np.mean(e ** 2))))
    print(json.dumps(out))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    p = sub.add_parser("contacts")
    p.add_argument("--truth", required=True)
    p.add_argument("--placements", type=int, default=4)
    p.add_argument("--rows", type=int, default=12)
    p.add_argument("--noise", type=float, required=True)
    p.add_argument("--seed", type=int, required=True)
    p.add_argument("--draws", type=int, default=1)
    p.add_argument("--glitched", type=int, default=0)
    p.add_argument("--glitch-size", type=float, default=2e-3)
    p.add_argument("--out", required=True)
    p = sub.add_parser("compare")
    p.add_argument("--truth", required=True)
    p.add_argument("--urdf", nargs="+", required=True)
    p.add_argument("--frames", nargs="+", required=True)
    p.add_argument("--n", type=int, default=1000)
    p.add_argument("--seed", type=int, default=0)
    a = ap.parse_args(argv)
    {"contacts": cmd_contacts, "compare": cmd_compare}[a.cmd](a)


if __name__ == "__main__":
    main()
