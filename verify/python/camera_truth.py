"""Camera truth (issue #41): Pinocchio plays the real robot, OpenCV the real
camera; activecal calibrates from the pixels; truth.py compares.

Usage (run with the project venv's python; outputs are JSON or CSV):

  camera_truth.py make --urdf U --base LINK --tip LINK --seed S
                       --camera x,y,z,r,p,y --target x,y,z,r,p,y --out truth.json
      A true robot as truth.py make perturbs it (every chain joint's
      <origin> composed with 0.5-2 mm and 0.05-0.3 deg, seeded), the
      camera's optical frame and the target's frame (metres and radians,
      rpy as in URDF): eye-to-hand (--mounting, the default), the camera in
      the base link and the target on the tip link; eye-in-hand, the
      camera on the tip link and the target in the base link. truth.json
      is truth.py's format: `tracker` is the base link's pose in the fixed
      one's frame and `tool` the moving one's frame in the tip link, so
      that `truth.py compare` measures the true error of the moving one's
      origin in the fixed one's frame (and its orientation: `pose` is
      true), as activecal's frames file places them. --exact: no
      perturbation (the URDF is the truth).

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

  camera_truth.py handeye --truth truth.json --camera-info cam.yaml
                          --board ROWS,COLS,SQUARE --observations obs.csv
                          [--frames cal.yaml] [--n 1000] --seed S
      OpenCV's hand-eye calibration from the same pixels (eye-to-hand):
      cv2.solvePnP per pose (camera <- target), the gripper poses from
      the NOMINAL robot (Pinocchio, the URDF as given: what a hand-eye
      tool assumes), cv2.calibrateHandEye with each of its five methods
      (base <- camera), the target on the tip link as the mean over poses
      of tip <- base <- camera <- target; and cv2.calibrateRobotWorldHandEye
      (Shah, Li: camera and target placements together, from the same
      solvePnP poses and nominal gripper poses). For each method, and for
      activecal's frames file (--frames: its measurement_frame is the base
      link in the camera's frame), against the truth: the camera
      placement's error (mm, deg) and the true error of the target's
      origin in the camera's frame at N random configurations (mm RMS;
      activecal with its calibrated URDF given as --urdf).
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
        if a.exact:
            t, w = 0.0 * t, 0.0 * w
        joints.append({"name": name, "t": t.tolist(), "w": w.tolist()})
    camera = placement(a.camera, "--camera")
    target = placement(a.target, "--target")
    # The fixed one's frame is the sensor's: the base link in it is the
    # "tracker", the moving one on the tip link the "tool".
    fixed, moving = (camera, target) if a.mounting == "eye-to-hand" else (target, camera)
    out = {
        "format": 1,
        "urdf": os.path.abspath(a.urdf),
        "base": chain.base,
        "tip": a.tip,
        "seed": a.seed,
        "pose": True,
        "joint_names": chain.names,
        "joints": joints,
        "mounting": a.mounting,
        "tracker": truth.iso_json(fixed.inverse()),
        "tool": truth.iso_json(moving),
        "nominal_tool": truth.iso_json(moving),
        "note": "camera truth: tracker = the base link in the fixed one's frame (the camera's "
                "optical frame for eye-to-hand, the target's for eye-in-hand); tool = the "
                "moving one's frame in the tip link",
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
        m = t.measured(q)  # fixed <- moving
        if t.j.get("mounting", "eye-to-hand") == "eye-in-hand":
            m = m.inverse()  # camera <- target
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


def read_observations(path, names):
    """{pose: (q, {feature: (u, v)})} of an observation CSV."""
    lines = [l.strip() for l in open(path) if l.strip()]
    head = lines[0].split(",")
    out = {}
    for l in lines[1:]:
        row = dict(zip(head, l.split(",")))
        p = int(row["pose"])
        q = [float(row[n]) for n in names]
        out.setdefault(p, (q, {}))[1][int(row["feature"])] = (float(row["u"]), float(row["v"]))
    return out


def mean_se3(ms):
    """The mean of rigid transforms: translations averaged, rotation the
    projection of the mean matrix onto SO(3)."""
    t = np.mean([np.asarray(m.translation) for m in ms], axis=0)
    u, _, vt = np.linalg.svd(np.mean([np.asarray(m.rotation) for m in ms], axis=0))
    r = u @ vt
    if np.linalg.det(r) < 0:
        r = u @ np.diag([1, 1, -1]) @ vt
    return truth.se3(r, t)


def placement_error(est, want):
    d = want.inverse() * est
    return float(np.linalg.norm(d.translation) * 1e3), float(np.degrees(np.linalg.norm(truth.log3(d.rotation))))


def cmd_handeye(a):
    import cv2
    t = truth.Truth(a.truth)
    k, dist, _, _ = camera_info(a.camera_info)
    rows_, cols_, sq = numbers(a.board, 3, "--board")
    cols_ = int(cols_)
    obs = read_observations(a.observations, t.chain.names)
    r_t2c, t_t2c, r_b2g, t_b2g, tips = [], [], [], [], []
    for p, (q, feats) in sorted(obs.items()):
        ids = sorted(feats)
        obj = np.array([[(i % cols_) * sq, (i // cols_) * sq, 0.0] for i in ids])
        img = np.array([feats[i] for i in ids])
        ok, rvec, tvec = cv2.solvePnP(obj, img, k, dist, flags=cv2.SOLVEPNP_ITERATIVE)
        if not ok:
            continue
        r_t2c.append(cv2.Rodrigues(rvec)[0])
        t_t2c.append(tvec.reshape(3))
        g = t.nominal.relative(q)  # base <- tip, nominal
        gi = g.inverse()
        r_b2g.append(np.asarray(gi.rotation))
        t_b2g.append(np.asarray(gi.translation))
        tips.append((g, truth.se3(r_t2c[-1], t_t2c[-1])))
    cam_true = t.tracker.inverse()  # base <- camera
    rng = np.random.default_rng(a.seed)
    qs = t.chain.random_configurations(a.n, rng)
    out = {}
    methods = {"tsai": cv2.CALIB_HAND_EYE_TSAI, "park": cv2.CALIB_HAND_EYE_PARK,
               "horaud": cv2.CALIB_HAND_EYE_HORAUD, "andreff": cv2.CALIB_HAND_EYE_ANDREFF,
               "daniilidis": cv2.CALIB_HAND_EYE_DANIILIDIS}
    for name, m in methods.items():
        r, tt = cv2.calibrateHandEye(r_b2g, t_b2g, r_t2c, t_t2c, method=m)
        cam = truth.se3(r, tt.reshape(3))  # base <- camera (eye-to-hand)
        target = mean_se3([g.inverse() * cam * c for g, c in tips])  # tip <- target
        e_t, e_r = placement_error(cam, cam_true)
        out[name] = {"camera_mm": e_t, "camera_deg": e_r,
                     "true": truth.errors(t, t.nominal, cam.inverse(), target, qs)}
    # cv2.calibrateRobotWorldHandEye solves cTw wTb = cTg gTb for a camera
    # on the gripper and a fixed "world"; eye-to-hand maps onto it with the
    # target as the world, the tip-in-base pose (bTg) as "base2gripper",
    # so that "gripper2cam" is the camera <- base and "base2world" the
    # target <- tip: cTt = cTb bTg gTt.
    r_g = [np.asarray(g.rotation) for g, _ in tips]
    t_g = [np.asarray(g.translation) for g, _ in tips]
    for name, m in {"shah": cv2.CALIB_ROBOT_WORLD_HAND_EYE_SHAH,
                    "li": cv2.CALIB_ROBOT_WORLD_HAND_EYE_LI}.items():
        r_w, t_w, r_c, t_c = cv2.calibrateRobotWorldHandEye(r_t2c, t_t2c, r_g, t_g, method=m)
        cam = truth.se3(r_c, t_c.reshape(3)).inverse()  # base <- camera
        target = truth.se3(r_w, t_w.reshape(3)).inverse()  # tip <- target
        e_t, e_r = placement_error(cam, cam_true)
        out[name] = {"camera_mm": e_t, "camera_deg": e_r,
                     "true": truth.errors(t, t.nominal, cam.inverse(), target, qs),
                     "camera": np.asarray(cam.homogeneous).tolist(),
                     "target": np.asarray(target.homogeneous).tolist()}
    if a.frames:
        m, tool, _, base, tip, _ = truth.read_frames(a.frames)
        e_t, e_r = placement_error(m.inverse(), cam_true)
        cal = truth.Chain(a.urdf, base or t.chain.base, tip or t.chain.tip)
        out["activecal"] = {"camera_mm": e_t, "camera_deg": e_r, "true": truth.errors(t, cal, m, tool, qs)}
    print(json.dumps(out))


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
    m.add_argument("--exact", action="store_true", help="no perturbation: the URDF is the truth")
    m.add_argument("--mounting", choices=["eye-to-hand", "eye-in-hand"], default="eye-to-hand")
    o = sub.add_parser("observe")
    o.add_argument("--truth", required=True)
    o.add_argument("--camera-info", required=True)
    o.add_argument("--board", required=True)
    o.add_argument("--configs", required=True)
    o.add_argument("--noise", type=float, default=0.0)
    o.add_argument("--seed", type=int, default=0)
    o.add_argument("--out", required=True)
    h = sub.add_parser("handeye")
    h.add_argument("--truth", required=True)
    h.add_argument("--camera-info", required=True)
    h.add_argument("--board", required=True)
    h.add_argument("--observations", required=True)
    h.add_argument("--frames")
    h.add_argument("--urdf")
    h.add_argument("--n", type=int, default=1000)
    h.add_argument("--seed", type=int, default=1)
    a = p.parse_args(argv)
    {"make": cmd_make, "observe": cmd_observe, "handeye": cmd_handeye}[a.cmd](a)


if __name__ == "__main__":
    main()
