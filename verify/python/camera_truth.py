"""Camera truth (issue #41): Pinocchio plays the real robot, OpenCV the real
camera; activecal calibrates from the pixels; truth.py compares.

Usage (run with the project venv's python; outputs are JSON or CSV):

  camera_truth.py make --urdf U --base LINK --tip LINK --seed S
                       --camera x,y,z,r,p,y --target x,y,z,r,p,y --out truth.json
      A true robot as truth.py make perturbs it (every chain joint's
      <origin> composed with 0.5-2 mm and 0.05-0.3 deg, seeded), a fixed
      camera (eye-to-hand: its optical frame in the base link, metres and
      radians, rpy as in URDF) and a target on the tip link. truth.json is
      truth.py's format: `tracker` is the base link's pose in the camera's
      optical frame and `tool` the target's frame in the tip link, so that
      `truth.py compare` measures the true error of the target's origin in
      the camera's frame (and its orientation: `pose` is true).

  camera_truth.py observe --truth truth.json --camera-info cam.yaml
                          --board ROWS,COLS,SQUARE --configs q.csv
                          --noise SIGMA_PX --seed S --out obs.csv
      The board's inner corners (ids row by row, at (j*square, i*square,
      0)) projected by cv2.projectPoints with the camera_info's K and
      plumb_bob distortion at each configuration of q.csv (a header of
      joint names), Gaussian noise of SIGMA_PX per pixel coordinate
      (numpy default_rng(S)); a corner is kept when it is in front of the
      camera and inside the image; a configuration with fewer than 4 is
      left out. Written as `activecal calibrate --observations` reads it:
      pose, joints, feature, u, v.
"""
import argparse
import json
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import truth  # noqa: E402


def numbers(s, n, what):
    v = [float(x) for x in s.split(",")]
    if len(v) != n:
        raise SystemExit("%s: %d numbers, expected %d" % (what, len(v), n))
    return v


def placement(s, what):
    v = numbers(s, 6, what)
    return truth.se3(truth.rpy_matrix(v[3:]), v[:3])


def cmd_make(a):
    rng = np.random.default_rng(a.seed)
    chain = truth.Chain(a.urdf, a.base, a.tip)
    joints = []
    for name in chain.names:
        t = truth.unit(rng) * rng.uniform(0.5e-3, 2e-3)
        w = truth.unit(rng) * math.radians(rng.uniform(0.05, 0.3))
        joints.append({"name": name, "t": t.tolist(), "w": w.tolist()})
    camera = placement(a.camera, "--camera")
    target = placement(a.target, "--target")
    out = {
        "format": 1,
        "urdf": os.path.abspath(a.urdf),
        "base": chain.base,
        "tip": a.tip,
        "seed": a.seed,
        "pose": True,
        "joint_names": chain.names,
        "joints": joints,
        "tracker": truth.iso_json(camera.inverse()),
        "tool": truth.iso_json(target),
        "nominal_tool": truth.iso_json(target),
        "note": "camera truth: tracker = the base link in the camera's optical frame; "
                "tool = the target's frame in the tip link",
    }
    with open(a.out, "w") as f:
        json.dump(out, f, indent=1)
    print(json.dumps({"out": a.out, "joints": chain.names}))


def camera_info(path):
    """K (3x3), distortion (5), width, height of a ROS camera_info YAML."""
    y = truth.parse_yaml(open(path).read())
    k = np.array(y["camera_matrix"]["data"], dtype=float).reshape(3, 3)
    d = np.array(y["distortion_coefficients"]["data"], dtype=float)
    return k, d, int(y["image_width"]), int(y["image_height"])


def cmd_observe(a):
    import cv2
    t = truth.Truth(a.truth)
    k, dist, w, h = camera_info(a.camera_info)
    rows_, cols_, sq = numbers(a.board, 3, "--board")
    rows_, cols_ = int(rows_), int(cols_)
    pts = np.array([[(i % cols_) * sq, (i // cols_) * sq, 0.0] for i in range(rows_ * cols_)])
    qs = truth.read_design(a.configs, t.chain.names)
    rng = np.random.default_rng(a.seed)
    lines = ["pose," + ",".join(t.chain.names) + ",feature,u,v"]
    poses = 0
    for n, q in enumerate(qs):
        m = t.measured(q)  # camera <- target
        r, tv = np.asarray(m.rotation), np.asarray(m.translation)
        z = (pts @ r.T + tv)[:, 2]
        img, _ = cv2.projectPoints(pts.reshape(-1, 1, 3), cv2.Rodrigues(r)[0], tv, k, dist)
        img = img.reshape(-1, 2) + (rng.normal(scale=a.noise, size=(len(pts), 2)) if a.noise > 0 else 0.0)
        keep = [i for i in range(len(pts)) if z[i] > 0 and -0.5 <= img[i, 0] <= w - 0.5
                and -0.5 <= img[i, 1] <= h - 0.5]
        if len(keep) < 4:
            continue
        poses += 1
        joints = ",".join(repr(float(v)) for v in q)
        lines += ["%d,%s,%d,%r,%r" % (n, joints, i, float(img[i, 0]), float(img[i, 1])) for i in keep]
    with open(a.out, "w") as f:
        f.write("\n".join(lines) + "\n")
    print(json.dumps({"out": a.out, "poses": poses, "rows": len(lines) - 1, "noise_px": a.noise}))


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    m = sub.add_parser("make")
    m.add_argument("--urdf", required=True)
    m.add_argument("--base")
    m.add_argument("--tip", required=True)
    m.add_argument("--seed", type=int, required=True)
    m.add_argument("--camera", required=True)
    m.add_argument("--target", required=True)
    m.add_argument("--out", required=True)
    o = sub.add_parser("observe")
    o.add_argument("--truth", required=True)
    o.add_argument("--camera-info", required=True)
    o.add_argument("--board", required=True)
    o.add_argument("--configs", required=True)
    o.add_argument("--noise", type=float, default=0.0)
    o.add_argument("--seed", type=int, default=0)
    o.add_argument("--out", required=True)
    a = p.parse_args(argv)
    {"make": cmd_make, "observe": cmd_observe}[a.cmd](a)


if __name__ == "__main__":
    main()
