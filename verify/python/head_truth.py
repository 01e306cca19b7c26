"""Head-camera truth (issue #41): Pinocchio plays the real robot (the whole
URDF tree, both branches), OpenCV the real camera on one of its links;
activecal calibrates the chain from the camera's link to the tip
(`--camera-link`) from the pixels; this script compares.

Usage (the project venv's python; outputs are JSON or CSV):

  head_truth.py make --urdf U --camera-link L --tip T --seed S
                     --camera x,y,z,r,p,y --target x,y,z,r,p,y --out truth.json
      A true robot: every moving joint on the paths from the root to L and
      to T (the torso's too) gets its placement composed with 0.5-2 mm and
      0.05-0.3 deg in random directions (numpy default_rng(S)); the
      camera's optical frame in L and the target's frame in T (metres,
      radians, rpy as in URDF) are true as given.

  head_truth.py observe --truth truth.json --camera-info cam.yaml
                        --board ROWS,COLS,SQUARE --configs q.csv
                        --noise SIGMA_PX --seed S --out obs.csv
      The board's inner corners (ids row by row at (j*square, i*square,
      0)) projected by cv2.projectPoints (K and plumb_bob of the
      camera_info) at each configuration of q.csv (a header of joint
      names: every joint it names is set, the others are 0), Gaussian
      noise of SIGMA_PX per coordinate; a corner kept when in front of
      the camera and inside the image, a configuration with fewer than 4
      left out. Written as `activecal calibrate --observations` reads it.

  head_truth.py compare --truth truth.json --urdf cal.urdf --frames cal.yaml
                        [--n 1000] --seed S
      The true error of the target's origin in the camera's frame at N
      random configurations of every joint on both paths (uniform within
      the limits): the truth against the calibrated URDF (Pinocchio, the
      whole tree) with the frames file's `camera` block (the camera's
      placement in L, the target's in T). Prints {"rms_mm", "max_mm"}.
"""
import argparse
import json
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import truth  # noqa: E402
import camera_truth  # noqa: E402


class Tree:
    """Pinocchio's model of a whole URDF; the moving joints on the paths
    from the root to two links."""

    def __init__(self, urdf, links):
        p = truth.pin()
        self.model = p.buildModelFromUrdf(os.path.abspath(urdf))
        self.frames = {l: self.model.getFrameId(l, p.FrameType.BODY) for l in links}
        ids = set()
        for f in self.frames.values():
            j = self.model.frames[f].parentJoint
            while j != 0:
                ids.add(j)
                j = self.model.parents[j]
        self.ids = sorted(ids)
        self.names = [self.model.names[j] for j in self.ids]
        self.data = self.model.createData()

    def perturb(self, deltas):
        p = truth.pin()
        by = {self.model.names[j]: j for j in self.ids}
        for d in deltas:
            j = by[d["name"]]
            delta = p.SE3(truth.exp3(d["w"]), np.asarray(d["t"], dtype=float))
            self.model.jointPlacements[j] = self.model.jointPlacements[j] * delta
        self.data = self.model.createData()

    def relative(self, q, a, b):
        """oMf(a)^-1 oMf(b) at joint values q ({name: value})."""
        p = truth.pin()
        x = p.neutral(self.model)
        for name, v in q.items():
            jm = self.model.joints[self.model.getJointId(name)]
            x[jm.idx_q] = v
        p.framesForwardKinematics(self.model, self.data, x)
        return self.data.oMf[self.frames[a]].actInv(self.data.oMf[self.frames[b]])

    def random(self, n, rng):
        out = []
        for _ in range(n):
            q = {}
            for j, name in zip(self.ids, self.names):
                jm = self.model.joints[j]
                lo = float(self.model.lowerPositionLimit[jm.idx_q])
                hi = float(self.model.upperPositionLimit[jm.idx_q])
                q[name] = rng.uniform(max(lo, -math.pi), min(hi, math.pi))
            out.append(q)
        return out


def load(path):
    with open(path) as f:
        t = json.load(f)
    tree = Tree(t["urdf"], [t["camera_link"], t["tip"]])
    tree.perturb(t["joints"])
    return t, tree, truth.iso_from_json(t["camera"]), truth.iso_from_json(t["target"])


def cmd_make(a):
    rng = np.random.default_rng(a.seed)
    tree = Tree(a.urdf, [a.camera_link, a.tip])
    joints = []
    for name in tree.names:
        t = truth.unit(rng) * rng.uniform(0.5e-3, 2e-3)
        w = truth.unit(rng) * math.radians(rng.uniform(0.05, 0.3))
        joints.append({"name": name, "t": t.tolist(), "w": w.tolist()})
    out = {"urdf": os.path.abspath(a.urdf), "camera_link": a.camera_link, "tip": a.tip,
           "seed": a.seed, "joints": joints,
           "camera": truth.iso_json(camera_truth.placement(a.camera, "--camera")),
           "target": truth.iso_json(camera_truth.placement(a.target, "--target"))}
    with open(a.out, "w") as f:
        json.dump(out, f, indent=1)
    print(json.dumps({"out": a.out, "joints": tree.names}))


def cmd_observe(a):
    import cv2
    t, tree, cam, tgt = load(a.truth)
    k, dist, w, h = camera_truth.camera_info(a.camera_info)
    rows_, cols_, sq = camera_truth.numbers(a.board, 3, "--board")
    rows_, cols_ = int(rows_), int(cols_)
    pts = np.array([[(i % cols_) * sq, (i // cols_) * sq, 0.0] for i in range(rows_ * cols_)])
    lines = [l.strip() for l in open(a.configs) if l.strip()]
    names = lines[0].split(",")
    rng = np.random.default_rng(a.seed)
    out = ["pose," + ",".join(names) + ",feature,u,v"]
    poses = 0
    for n, l in enumerate(lines[1:]):
        vals = [float(v) for v in l.split(",")]
        m = cam.inverse() * tree.relative(dict(zip(names, vals)), t["camera_link"], t["tip"]) * tgt
        r, tv = np.asarray(m.rotation), np.asarray(m.translation)
        z = (pts @ r.T + tv)[:, 2]
        img, _ = cv2.projectPoints(pts.reshape(-1, 1, 3), cv2.Rodrigues(r)[0], tv, k, dist)
        img = img.reshape(-1, 2) + (rng.normal(scale=a.noise, size=(len(pts), 2)) if a.noise > 0 else 0.0)
        keep = [i for i in range(len(pts)) if z[i] > 0 and -0.5 <= img[i, 0] <= w - 0.5
                and -0.5 <= img[i, 1] <= h - 0.5]
        if len(keep) < 4:
            continue
        poses += 1
        joints = ",".join(repr(v) for v in vals)
        out += ["%d,%s,%d,%r,%r" % (n, joints, i, float(img[i, 0]), float(img[i, 1])) for i in keep]
    with open(a.out, "w") as f:
        f.write("\n".join(out) + "\n")
    print(json.dumps({"out": a.out, "poses": poses, "rows": len(out) - 1}))


def cmd_compare(a):
    t, tree, cam, tgt = load(a.truth)
    cal = Tree(a.urdf, [t["camera_link"], t["tip"]])
    _, _, _, _, _, y = truth.read_frames(a.frames)
    block = y["camera"]
    c_cam = truth.se3(truth.rpy_matrix(block["camera"]["rpy"]), block["camera"]["xyz"])
    c_tgt = truth.se3(truth.rpy_matrix(block["target"]["rpy"]), block["target"]["xyz"])
    rng = np.random.default_rng(a.seed)
    errs = []
    for q in tree.random(a.n, rng):
        want = cam.inverse() * tree.relative(q, t["camera_link"], t["tip"]) * tgt
        got = c_cam.inverse() * cal.relative(q, t["camera_link"], t["tip"]) * c_tgt
        errs.append(float(np.linalg.norm(np.asarray(want.translation) - np.asarray(got.translation))))
    e = np.asarray(errs) * 1e3
    print(json.dumps({"rms_mm": float(np.sqrt(np.mean(e ** 2))), "max_mm": float(e.max()), "n": a.n}))


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    m = sub.add_parser("make")
    for f in ["--urdf", "--camera-link", "--tip", "--camera", "--target", "--out"]:
        m.add_argument(f, required=True)
    m.add_argument("--seed", type=int, required=True)
    o = sub.add_parser("observe")
    for f in ["--truth", "--camera-info", "--board", "--configs", "--out"]:
        o.add_argument(f, required=True)
    o.add_argument("--noise", type=float, default=0.0)
    o.add_argument("--seed", type=int, default=0)
    c = sub.add_parser("compare")
    for f in ["--truth", "--urdf", "--frames"]:
        c.add_argument(f, required=True)
    c.add_argument("--n", type=int, default=1000)
    c.add_argument("--seed", type=int, default=1)
    a = p.parse_args(argv)
    {"make": cmd_make, "observe": cmd_observe, "compare": cmd_compare}[a.cmd](a)


if __name__ == "__main__":
    main()
