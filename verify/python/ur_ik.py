"""Closed-form inverse kinematics of the Universal Robots family, written
from the published geometry (Hawkins, "Analytic Inverse Kinematics for the
Universal Robots UR-5/UR-10 Arms", 2013), independent of activecal: the
check that a calibrated model keeping its axis relations
(`calibrate --keep-axis-relations`, issue #53) still has the UR solver's
eight closed-form solutions.

Everything is derived from the URDF by Pinocchio: the six joint axes as
lines at q = 0 (from the joint Jacobian in the world frame), DH frames
built on them (common normals; a parallel pair's normal through the
previous frame's origin), and the flange. The solver then assumes only
what the UR family's design gives: axes 1 ⟂ 2 meeting, 2 ∥ 3 ∥ 4, 4 ⟂ 5
meeting, 5 ⟂ 6 meeting. How far a model is from that structure is
reported (`structure`), so a model that breaks it shows both its
deviations and the solver's error.

Usage (project venv's python; prints one JSON object):

  ur_ik.py ik --urdf U --tip LINK [--base LINK] [--n 200] [--seed S]
      The chain's poses at N random configurations solved back: the
      largest distance between the target and the nearest of the eight
      solutions' flange positions (metres) and orientations (radians), the
      largest joint difference of the nearest solution (radians), and the
      extracted DH table.
  ur_ik.py relations --urdf U --nominal N --tip LINK [--base LINK]
      Angle (radians) and distance (metres) of each pair of consecutive
      joint axes at q = 0, in both URDFs.
"""

import argparse
import json
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import truth  # noqa: E402  (the Chain of the truth gate)


def axis_lines(chain):
    """Each chain joint's axis at q = 0 in the base frame: (point, unit
    direction), from the joint Jacobian's world-frame column."""
    p = truth.pin()
    m, d = chain.model, chain.data
    x = p.neutral(m)
    p.computeJointJacobians(m, d, x)
    p.framesForwardKinematics(m, d, x)
    base = d.oMf[chain.bf]
    out = []
    for j in chain.ids:
        jac = p.getJointJacobian(m, d, j, p.ReferenceFrame.WORLD)
        col = jac[:, m.joints[j].idx_v]
        v, w = col[:3], col[3:]
        point = np.cross(w, v) / np.dot(w, w)
        rot = base.rotation.T
        out.append((rot @ (point - base.translation), rot @ (w / np.linalg.norm(w))))
    return out


def foot(p1, z1, p2, z2):
    """Closest points of two non-parallel lines: (on line 1, on line 2)."""
    w = p1 - p2
    b = np.dot(z1, z2)
    den = 1.0 - b * b
    s = (b * np.dot(z2, w) - np.dot(z1, w)) / den
    t = (np.dot(z2, w) - b * np.dot(z1, w)) / den
    return p1 + s * z1, p2 + t * z2


def frame(origin, x, z):
    m = np.eye(4)
    y = np.cross(z, x)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = x, y, z, origin
    return m


def dh_frames(lines):
    """F_0..F_5: F_{i-1} on axis i (z along it), x along the common normal
    to axis i+1 (F_0's x is F_1's)."""
    frames = []
    prev_origin = None
    for i in range(len(lines) - 1):
        (p1, z1), (p2, z2) = lines[i], lines[i + 1]
        n = np.cross(z1, z2)
        if np.linalg.norm(n) > 1e-12:
            on1, on2 = foot(p1, z1, p2, z2)
            x = n / np.linalg.norm(n)
            if np.linalg.norm(on2 - on1) > 1e-12 and np.dot(on2 - on1, x) < 0:
                x = -x
            origin = on2
            if prev_origin is None:
                prev_origin = on1
        else:
            start = prev_origin if prev_origin is not None else p1
            origin = p2 + np.dot(start - p2, z2) * z2
            x = origin - start
            x = x - np.dot(x, z2) * z2
            x /= np.linalg.norm(x)
        frames.append((origin, x, z2))
        prev_origin = origin if prev_origin is not None else origin
    first = (foot(*lines[0], *lines[1])[0], frames[0][1], lines[0][1])
    return [frame(*first)] + [frame(*f) for f in frames]


def decompose(m):
    """M = Rz(γ) Tz(d) Tx(a) Rx(α) for a DH-form transform."""
    x, z, t = m[:3, 0], m[:3, 2], m[:3, 3]
    gamma = math.atan2(x[1], x[0])
    alpha = math.atan2(np.dot(np.cross([0.0, 0.0, 1.0], z), x), z[2])
    return {"gamma": gamma, "d": float(t[2]), "a": float(np.dot(t[:2], x[:2])),
            "alpha": alpha, "x_z": float(x[2]), "t_off": float(np.dot(t[:2], [-x[1], x[0]]))}


def rz(t):
    c, s = math.cos(t), math.sin(t)
    m = np.eye(4)
    m[:2, :2] = [[c, -s], [s, c]]
    return m


def dh(theta, d, a, alpha):
    ca, sa = math.cos(alpha), math.sin(alpha)
    tx = np.eye(4)
    tx[:3, 3] = [a, 0.0, d]
    rx = np.eye(4)
    rx[1:3, 1:3] = [[ca, -sa], [sa, ca]]
    return rz(theta) @ tx @ rx


class Model:
    """The chain as F_0 · Π Rz(q_i) M_i, M_i = F_{i-1}^-1 F_i (F_6 the flange)."""

    def __init__(self, chain):
        self.chain = chain
        lines = axis_lines(chain)
        if len(lines) != 6:
            raise SystemExit("a UR arm has 6 joints, the chain %d" % len(lines))
        fs = dh_frames(lines)
        x0 = chain.relative(np.zeros(6)).homogeneous
        fs.append(np.asarray(x0))
        self.base = fs[0]
        self.m = [np.linalg.inv(fs[i]) @ fs[i + 1] for i in range(6)]
        self.dh = [decompose(self.m[i]) for i in range(5)]

    def fk(self, q):
        t = self.base.copy()
        for qi, mi in zip(q, self.m):
            t = t @ rz(qi) @ mi
        return t

    def structure(self):
        """Deviations from the UR family's design (radians, metres)."""
        d = self.dh
        half = math.pi / 2
        return {
            "alpha_1_off_90": abs(abs(d[0]["alpha"]) - half),
            "a_1": abs(d[0]["a"]),
            "alpha_2": abs(d[1]["alpha"]),
            "alpha_3": abs(d[2]["alpha"]),
            "alpha_4_off_90": abs(abs(d[3]["alpha"]) - half),
            "a_4": abs(d[3]["a"]),
            "alpha_5_off_90": abs(abs(d[4]["alpha"]) - half),
            "a_5": abs(d[4]["a"]),
            "dh_form": max(max(abs(e["x_z"]), abs(e["t_off"])) for e in d),
        }

    def solve(self, target):
        """The eight closed-form solutions (joint values) for a flange pose
        in the base frame."""
        d = self.dh
        g = [e["gamma"] for e in d]
        s1, s4, s5 = (math.sin(d[k]["alpha"]) for k in (0, 3, 4))
        t = np.linalg.inv(self.base) @ target @ np.linalg.inv(self.m[5])
        o5, w = t[:3, 3], t[:3, 2]
        depth = d[1]["d"] + d[2]["d"] + d[3]["d"]
        r = math.hypot(o5[0], o5[1])
        phi = math.atan2(o5[1], o5[0])
        ratio = max(-1.0, min(1.0, depth / (r * s1)))
        out = []
        for th1 in (phi + math.asin(ratio), phi + math.pi - math.asin(ratio)):
            a1 = dh(th1, d[0]["d"], d[0]["a"], d[0]["alpha"])
            r1 = a1[:3, :3]
            w1 = r1.T @ w
            c5 = max(-1.0, min(1.0, -w1[2] / (s4 * s5)))
            for th5 in (math.acos(c5), -math.acos(c5)):
                v = t[:3, :3].T @ (r1 @ np.array([0.0, 0.0, 1.0]))
                k = s4 * math.sin(th5)
                th6 = math.atan2(-v[1] / k, v[0] / k) if abs(k) > 1e-12 else 0.0
                a5 = dh(th5, d[4]["d"], d[4]["a"], d[4]["alpha"])
                t14 = np.linalg.inv(a1) @ t @ np.linalg.inv(rz(th6)) @ np.linalg.inv(a5)
                # Frame 4 sits d4 along the parallel axes from frame 3.
                o3 = t14[:3, 3] - d[3]["d"] * np.array([0.0, 0.0, 1.0])
                a2, a3 = d[1]["a"], d[2]["a"]
                c3 = (o3[0] ** 2 + o3[1] ** 2 - a2 * a2 - a3 * a3) / (2 * a2 * a3)
                c3 = max(-1.0, min(1.0, c3))
                for th3 in (math.acos(c3), -math.acos(c3)):
                    th2 = math.atan2(o3[1], o3[0]) - math.atan2(a3 * math.sin(th3), a2 + a3 * math.cos(th3))
                    th4 = math.atan2(t14[1, 0], t14[0, 0]) - th2 - th3
                    th = [th1, th2, th3, th4, th5, th6]
                    out.append([th[i] - (g[i] if i < 5 else 0.0) for i in range(6)])
        return out


def wrap(x):
    return (x + math.pi) % (2 * math.pi) - math.pi


def cmd_ik(a):
    chain = truth.Chain(a.urdf, a.base, a.tip)
    model = Model(chain)
    rng = np.random.default_rng(a.seed)
    qs = chain.random_configurations(a.n, rng)
    worst_fk = 0.0
    worst_p, worst_r, worst_q = 0.0, 0.0, 0.0
    for q in qs:
        target = np.asarray(chain.relative(q).homogeneous)
        worst_fk = max(worst_fk, float(np.linalg.norm(model.fk(q)[:3, 3] - target[:3, 3])))
        best = None
        for sol in model.solve(target):
            dq = max(abs(wrap(x - y)) for x, y in zip(sol, q))
            if best is None or dq < best[0]:
                best = (dq, sol)
        got = np.asarray(chain.relative(best[1]).homogeneous)
        worst_p = max(worst_p, float(np.linalg.norm(got[:3, 3] - target[:3, 3])))
        rel = got[:3, :3].T @ target[:3, :3]
        worst_r = max(worst_r, float(np.linalg.norm(truth.log3(rel))))
        worst_q = max(worst_q, best[0])
    print(json.dumps({
        "n": a.n,
        "max_position_m": worst_p,
        "max_rotation_rad": worst_r,
        "max_joint_rad": worst_q,
        "model_fk_m": worst_fk,
        "structure": model.structure(),
        "dh": model.dh,
    }))


def relations(lines):
    out = []
    for (p1, z1), (p2, z2) in zip(lines, lines[1:]):
        n = np.cross(z1, z2)
        angle = math.atan2(np.linalg.norm(n), abs(np.dot(z1, z2)))
        w = p2 - p1
        if np.linalg.norm(n) > 1e-12:
            dist = abs(np.dot(w, n)) / np.linalg.norm(n)
        else:
            dist = float(np.linalg.norm(w - z1 * np.dot(w, z1)))
        out.append({"angle_rad": angle, "distance_m": dist})
    return out


def cmd_relations(a):
    got = relations(axis_lines(truth.Chain(a.urdf, a.base, a.tip)))
    nominal = relations(axis_lines(truth.Chain(a.nominal, a.base, a.tip)))
    print(json.dumps({"calibrated": got, "nominal": nominal}))


def main(argv=None):
    p = argparse.ArgumentParser()
    sub = p.add_subparsers(dest="cmd", required=True)
    x = sub.add_parser("ik")
    x.add_argument("--urdf", required=True)
    x.add_argument("--base")
    x.add_argument("--tip", required=True)
    x.add_argument("--n", type=int, default=200)
    x.add_argument("--seed", type=int, default=0)
    x.set_defaults(run=cmd_ik)
    r = sub.add_parser("relations")
    r.add_argument("--urdf", required=True)
    r.add_argument("--nominal", required=True)
    r.add_argument("--base")
    r.add_argument("--tip", required=True)
    r.set_defaults(run=cmd_relations)
    a = p.parse_args(argv)
    a.run(a)


if __name__ == "__main__":
    main()
