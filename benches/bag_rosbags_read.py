"""The reference side of benches/bag_throughput.sh: what `activecal extract
BAG --points TOPIC --time-offset 0` does, written with rosbags (PyPI, pure
Python) and NumPy as a user's own script would: read every message of the
joint topic and the point topic, find the rests (every joint slower than
SPEED rad/s for MIN s or longer, the speed over a 0.1 s window) and
average the points of each rest after SETTLE s. Prints JSON: the message
counts and the rests' averaged points (m).

Usage: bag_rosbags_read.py BAG [--joints /joint_states] [--points /tracker]
       [--speed 0.005] [--min 0.5] [--settle 0.2]
"""

import argparse
import json
from pathlib import Path

import numpy as np
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore


def stamp(h):
    return h.stamp.sec + 1e-9 * h.stamp.nanosec


def read(bag, joints, points):
    tq, q, tp, p = [], [], [], []
    with AnyReader([Path(bag)], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as r:
        conns = [c for c in r.connections if c.topic in (joints, points)]
        for c, _, raw in r.messages(connections=conns):
            m = r.deserialize(raw, c.msgtype)
            if c.topic == joints:
                tq.append(stamp(m.header))
                q.append(m.position)
            else:
                tp.append(stamp(m.header))
                p.append((m.point.x, m.point.y, m.point.z))
    return np.array(tq), np.array(q), np.array(tp), np.array(p)


def rests(t, q, speed, min_s, window=0.1):
    """(start, end) times of the runs where every joint is slower than
    speed, each joint's speed its change over a centred window (s) as
    activecal's (a window of samples keeps the encoders' noise out)."""
    a = np.searchsorted(t, t - window / 2, "left")
    b = np.searchsorted(t, t + window / 2, "right") - 1
    dt = t[b] - t[a]
    v = np.abs(q[b] - q[a]).max(axis=1) / np.where(dt > 0, dt, np.inf)
    still = np.concatenate([[False], v < speed, [False]])
    edges = np.flatnonzero(np.diff(still.astype(np.int8)))
    out = []
    for i, j in zip(edges[::2], edges[1::2]):
        t0, t1 = t[i], t[j - 1]
        if t1 - t0 >= min_s:
            out.append((t0, t1))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("bag")
    ap.add_argument("--joints", default="/joint_states")
    ap.add_argument("--points", default="/tracker")
    ap.add_argument("--speed", type=float, default=0.005)
    ap.add_argument("--min", type=float, default=0.5)
    ap.add_argument("--settle", type=float, default=0.2)
    a = ap.parse_args()
    tq, q, tp, p = read(a.bag, a.joints, a.points)
    order = np.argsort(tq)
    tq, q = tq[order], q[:, :6][order]
    found = rests(tq, q, a.speed, a.min)
    means = []
    for t0, t1 in found:
        inside = (tp >= t0 + a.settle) & (tp <= t1)
        means.append(p[inside].mean(axis=0).tolist() if inside.any() else None)
    print(json.dumps({"joint_messages": len(tq), "point_messages": len(tp), "rests": len(found), "points": means}))


if __name__ == "__main__":
    main()
