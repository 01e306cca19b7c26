"""Rendered camera images of a known truth (issue #51): what a camera on a
true robot records when it looks at a checkerboard, with the true pixel
of every inner corner saved beside the images.

Usage (run with the project venv's python; the truth is camera_truth.py
make's truth.json):

  camera_images.py render --truth truth.json --camera-info cam.yaml
                          --board ROWS,COLS,SQUARE --count N --seed S
                          --out DIR [--far K] [--behind]
                          [--blur PX] [--noise DN] [--gamma G]
                          [--near-range A,B] [--far-range A,B]
      N configurations drawn uniformly within the joint limits (numpy
      default_rng(S)) at which the TRUE robot shows the whole printed board
      (its inner corners and the quiet zone of one square around the
      outer squares, 10 px inside the image) from 0.3-0.9 m (--near-range)
      with the board's normal within 60 deg of the line of sight; the last
      K of them (--far) from 0.9-1.4 m (--far-range) and 60-75 deg
      (squares foreshortened to a few pixels). Eye-to-hand (the truth's
      mounting: the camera fixed, the board on the flange) is rendered
      the same way, the camera <- board transform being then the truth's
      measured frame itself. The board's printed face is seen when its z axis
      points away from the camera; --behind keeps only configurations
      that see it from behind (a see-through or back-lit board: the same
      pattern, mirrored).

      Each image is rendered exactly: for each of 4 x 4 sub-pixels of a
      pixel (OpenCV's convention: (0, 0) is the centre of the top-left
      pixel) the camera_info's plumb_bob distortion is inverted (fixed
      point iteration to 1e-10 of a normalised coordinate), the ray is
      cast and intersected with the board's plane, and the sub-pixel
      takes the colour of the square it hits (black 0.08, white 0.92,
      the background outside the board 0.45); the 16 sub-pixels are
      averaged (anti-aliasing), then blurred (Gaussian of --blur px,
      default 0.6), encoded with the gamma 1/G (default 2.2), given
      Gaussian noise of --noise grey levels (default 2.0 of 255) and
      written as 8-bit grayscale PNG.

      --charuco ROWS,COLS,SQUARE,MARKER --dictionary NAME [--legacy]
      (instead of --board): an OpenCV ChArUco board of ROWS x COLS
      squares (cv2.aruco.CharucoBoard((COLS, ROWS), SQUARE, MARKER,
      getPredefinedDictionary(NAME)), setLegacyPattern with --legacy)
      and half a square of white paper around it, its texture
      generateImage's at 100 px per square (its squares' edges on whole
      texture pixels), each sub-pixel taking the texel it hits; the truth
      is its inner corners with OpenCV's ids (i*(COLS-1)+j at
      ((j+1)*SQUARE, (i+1)*SQUARE, 0)).

      --draws D (default 1): the same configurations and renders with D
      draws of the noise (numpy default_rng((S, 1 + d))), in DIR/draw_d/
      each (the files below in each).

      Written in DIR: img_NNN.png; joints.csv (image, then one column per
      joint: the configuration of each image, the file `activecal
      calibrate --images DIR --joints joints.csv` reads); truth.csv (the
      true pixel of every inner corner, cv2.projectPoints of the true
      camera <- board transform with the same distortion, as the
      observations CSV `activecal calibrate --observations` reads: pose
      = the image's index); and render.json (per image: distance m,
      view angle deg, the smallest square side in px, seen from behind).
"""
import argparse
import json
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import camera_truth  # noqa: E402
import truth  # noqa: E402

SUPERSAMPLE = 4
BLACK, WHITE, BACKGROUND = 0.08, 0.92, 0.45


def undistort(xd, yd, dist):
    """The normalised coordinates whose plumb_bob distortion is (xd, yd):
    fixed-point iteration x = (xd - tangential(x)) / radial(x), checked by
    distorting the result back."""
    k1, k2, p1, p2, k3 = dist
    x, y = xd.copy(), yd.copy()
    for _ in range(100):
        r2 = x * x + y * y
        radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3))
        dx = 2 * p1 * x * y + p2 * (r2 + 2 * x * x)
        dy = p1 * (r2 + 2 * y * y) + 2 * p2 * x * y
        nx, ny = (xd - dx) / radial, (yd - dy) / radial
        step = max(float(np.max(np.abs(nx - x))), float(np.max(np.abs(ny - y))))
        x, y = nx, ny
        if step < 1e-13:
            break
    r2 = x * x + y * y
    radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3))
    ex = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x) - xd
    ey = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y - yd
    err = max(float(np.max(np.abs(ex))), float(np.max(np.abs(ey))))
    if err > 1e-10:
        raise SystemExit("undistortion did not converge (%.3g)" % err)
    return x, y


def camera_from_board(t, q):
    """The true camera <- board transform at q (rotation, translation)."""
    m = t.measured(q)  # fixed <- moving
    if t.j.get("mounting", "eye-to-hand") == "eye-in-hand":
        m = m.inverse()
    return np.asarray(m.rotation), np.asarray(m.translation)


def board_outline(rows, cols, sq):
    """Points along the edge of the printed board's quiet zone (one square
    around the outer squares), board frame."""
    return rect_outline(-2 * sq, (cols + 1) * sq, -2 * sq, (rows + 1) * sq)


def rect_outline(x0, x1, y0, y1, n=40):
    """Points along the rectangle [x0, x1] x [y0, y1] of the board's plane."""
    s = np.linspace(0, 1, n)
    xs = np.concatenate([x0 + (x1 - x0) * s, np.full(n, x1), x1 - (x1 - x0) * s, np.full(n, x0)])
    ys = np.concatenate([np.full(n, y0), y0 + (y1 - y0) * s, np.full(n, y1), y1 - (y1 - y0) * s])
    return np.stack([xs, ys, np.zeros_like(xs)], axis=1)


def project(pts, r, tv, k, dist):
    import cv2
    img, _ = cv2.projectPoints(pts.reshape(-1, 1, 3), cv2.Rodrigues(r)[0], tv, k, dist)
    return img.reshape(-1, 2)


def view(r, tv, pts, outline, k, dist, w, h):
    """(distance m, view angle deg, behind, smallest square px, in image)."""
    cam = pts @ r.T + tv
    if np.any(cam[:, 2] <= 0.05) or np.any((outline @ r.T + tv)[:, 2] <= 0.05):
        return None
    centre = cam.mean(axis=0)
    dist_m = float(np.linalg.norm(centre))
    n = r[:, 2]
    cosang = float(np.dot(n, centre) / dist_m)
    angle = math.degrees(math.acos(min(1.0, abs(cosang))))
    o = project(outline, r, tv, k, dist)
    inside = bool(np.all((o[:, 0] >= 10) & (o[:, 0] <= w - 11) & (o[:, 1] >= 10) & (o[:, 1] <= h - 11)))
    return dist_m, angle, cosang < 0, inside


def smallest_square(px, rows, cols):
    g = px.reshape(rows, cols, 2)
    a = np.linalg.norm(np.diff(g, axis=1), axis=2).min() if cols > 1 else np.inf
    b = np.linalg.norm(np.diff(g, axis=0), axis=2).min() if rows > 1 else np.inf
    return float(min(a, b))


def rays_of(box, k, dist):
    """The normalised rays of the sub-pixels of `box` (pixel bounds)."""
    u0, v0, u1, v1 = box
    s = SUPERSAMPLE
    us = (np.arange(u0 * s, u1 * s) + 0.5) / s - 0.5
    vs = (np.arange(v0 * s, v1 * s) + 0.5) / s - 0.5
    xd = np.broadcast_to((us - k[0, 2]) / k[0, 0], (len(vs), len(us)))
    yd = np.broadcast_to(((vs - k[1, 2]) / k[1, 1])[:, None], (len(vs), len(us)))
    return undistort(np.array(xd), np.array(yd), dist)


class Checkerboard:
    """A checkerboard of rows x cols inner corners (OpenCV's ids), a quiet
    zone of one square around its outer squares."""

    def __init__(self, rows, cols, sq):
        self.rows, self.cols, self.sq = rows, cols, sq
        self.pts = np.array([[(i % cols) * sq, (i // cols) * sq, 0.0] for i in range(rows * cols)])
        self.grid = (rows, cols)
        self.outline = board_outline(rows, cols, sq)

    def colour(self, bx, by):
        rows, cols, sq = self.rows, self.cols, self.sq
        cx, cy = np.floor(bx / sq), np.floor(by / sq)
        square = (cx >= -1) & (cx <= cols - 1) & (cy >= -1) & (cy <= rows - 1)
        quiet = (bx >= -2 * sq) & (bx <= (cols + 1) * sq) & (by >= -2 * sq) & (by <= (rows + 1) * sq)
        sub = np.where(quiet, WHITE, BACKGROUND)
        return np.where(square & ((cx + cy) % 2 == 0), BLACK, sub)


TEXEL = 100  # texture pixels per ChArUco square


class Charuco:
    """OpenCV's ChArUco board of rows x cols squares (its inner corners with
    OpenCV's ids), half a square of white paper around it."""

    def __init__(self, rows, cols, sq, marker, dictionary, legacy):
        import cv2
        b = cv2.aruco.CharucoBoard((cols, rows), sq, marker,
                                   cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, dictionary)))
        b.setLegacyPattern(legacy)
        self.board = b
        self.rows, self.cols, self.sq = rows, cols, sq
        self.tex = b.generateImage((cols * TEXEL, rows * TEXEL), marginSize=0, borderBits=1)
        self.pts = np.asarray(b.getChessboardCorners(), dtype=float).reshape(-1, 3)
        self.grid = (rows - 1, cols - 1)
        self.outline = rect_outline(-0.5 * sq, (cols + 0.5) * sq, -0.5 * sq, (rows + 0.5) * sq)

    def colour(self, bx, by):
        rows, cols, sq = self.rows, self.cols, self.sq
        tx, ty = np.floor(bx / sq * TEXEL), np.floor(by / sq * TEXEL)
        on = (tx >= 0) & (tx < cols * TEXEL) & (ty >= 0) & (ty < rows * TEXEL)
        texel = self.tex[np.clip(ty, 0, rows * TEXEL - 1).astype(int),
                         np.clip(tx, 0, cols * TEXEL - 1).astype(int)]
        level = np.where(texel > 127, WHITE, BLACK)
        paper = (bx >= -0.5 * sq) & (bx <= (cols + 0.5) * sq) & (by >= -0.5 * sq) & (by <= (rows + 0.5) * sq)
        return np.where(on, level, np.where(paper, WHITE, BACKGROUND))


def render(r, tv, k, dist, box, board, w, h):
    """The image (floats in [0, 1], linear) of `board` at camera <- board
    (r, tv): sub-pixels inside `box` (pixel bounds) cast, the rest background."""
    out = np.full((h, w), BACKGROUND)
    u0, v0, u1, v1 = box
    s = SUPERSAMPLE
    xs, ys = rays_of(box, k, dist)
    n = r[:, 2]
    denom = n[0] * xs + n[1] * ys + n[2]
    with np.errstate(divide="ignore", invalid="ignore"):
        depth = float(np.dot(n, tv)) / denom
    px, py, pz = depth * xs - tv[0], depth * ys - tv[1], depth - tv[2]
    bx = r[0, 0] * px + r[1, 0] * py + r[2, 0] * pz
    by = r[0, 1] * px + r[1, 1] * py + r[2, 1] * pz
    sub = board.colour(bx, by)
    sub = np.where(np.isfinite(depth) & (depth > 0), sub, BACKGROUND)
    out[v0:v1, u0:u1] = sub.reshape(v1 - v0, s, u1 - u0, s).mean(axis=(1, 3))
    return out


def develop(img, blur, gamma):
    """Blurred and gamma-encoded grey levels (0-255, floats)."""
    import cv2
    if blur > 0:
        img = cv2.GaussianBlur(img, (0, 0), blur)
    return 255.0 * np.clip(img, 0, 1) ** (1.0 / gamma)


def with_noise(img, noise, rng):
    """8-bit levels of `img` with Gaussian noise of `noise` levels."""
    if noise > 0:
        img = img + rng.normal(scale=noise, size=img.shape)
    return np.clip(np.rint(img), 0, 255).astype(np.uint8)


def choose(t, a, pts, outline, k, dist, w, h, rng):
    """The configurations to render: (q, r, tv, stats) per image."""
    near_n = a.count - a.far
    found = {"near": [], "far": []}
    tries = 0
    while len(found["near"]) < near_n or len(found["far"]) < a.far:
        tries += 1
        if tries > 400:
            raise SystemExit("fewer than %d configurations show the board in 400,000 draws" % a.count)
        for q in t.chain.random_configurations(1000, rng):
            r, tv = camera_from_board(t, q)
            v = view(r, tv, pts, outline, k, dist, w, h)
            if v is None or not v[3] or v[2] != a.behind:
                continue
            d, ang = v[0], v[1]
            kind = "near" if a.near_range[0] <= d <= a.near_range[1] and ang <= 60 else (
                "far" if a.far_range[0] < d <= a.far_range[1] and 60 < ang <= 75 else None)
            want = near_n if kind == "near" else a.far
            if kind and len(found[kind]) < want:
                found[kind].append((q, r, tv, {"distance_m": d, "view_angle_deg": ang,
                                               "behind": v[2], "far": kind == "far"}))
    return found["near"] + found["far"]


def cmd_render(a):
    import cv2
    t = truth.Truth(a.truth)
    k, dist, w, h = camera_truth.camera_info(a.camera_info)
    if (a.board is None) == (a.charuco is None):
        raise SystemExit("give one of --board and --charuco")
    if a.board is not None:
        rows, cols, sq = camera_truth.numbers(a.board, 3, "--board")
        board = Checkerboard(int(rows), int(cols), sq)
    else:
        rows, cols, sq, marker = camera_truth.numbers(a.charuco, 4, "--charuco")
        board = Charuco(int(rows), int(cols), sq, marker, a.dictionary, a.legacy)
    pts, outline = board.pts, board.outline
    rng = np.random.default_rng(a.seed)
    chosen = choose(t, a, pts, outline, k, dist, w, h, rng)
    outs = [a.out] if a.draws == 1 else [os.path.join(a.out, "draw_%d" % d) for d in range(a.draws)]
    rngs = [np.random.default_rng((a.seed, 1 + d)) for d in range(a.draws)]
    for o in outs:
        os.makedirs(o, exist_ok=True)
    names = t.chain.names
    joints = ["image," + ",".join(names)]
    obs = ["pose," + ",".join(names) + ",feature,u,v"]
    stats = []
    for n, (q, r, tv, st) in enumerate(chosen):
        o = project(outline, r, tv, k, dist)
        box = (max(0, int(o[:, 0].min()) - 3), max(0, int(o[:, 1].min()) - 3),
               min(w, int(o[:, 0].max()) + 4), min(h, int(o[:, 1].max()) + 4))
        img = develop(render(r, tv, k, dist, box, board, w, h), a.blur, a.gamma)
        name = "img_%03d.png" % n
        for o, g in zip(outs, rngs):
            cv2.imwrite(os.path.join(o, name), with_noise(img, a.noise, g))
        qs = ",".join(repr(float(v)) for v in q)
        joints.append("%s,%s" % (name, qs))
        px = project(pts, r, tv, k, dist)
        obs += ["%d,%s,%d,%r,%r" % (n, qs, i, float(px[i, 0]), float(px[i, 1])) for i in range(len(pts))]
        st = dict(st, image=name, smallest_square_px=smallest_square(px, *board.grid))
        stats.append(st)
    for o in outs:
        with open(os.path.join(o, "joints.csv"), "w") as f:
            f.write("\n".join(joints) + "\n")
        with open(os.path.join(o, "truth.csv"), "w") as f:
            f.write("\n".join(obs) + "\n")
        with open(os.path.join(o, "render.json"), "w") as f:
            json.dump({"board": [board.rows, board.cols, sq], "images": stats}, f, indent=1)
    print(json.dumps({"out": a.out, "images": len(chosen),
                      "smallest_square_px": min(s["smallest_square_px"] for s in stats)}))


def read_truth(d):
    """{image name: {feature: (u, v)}} of DIR's truth.csv and joints.csv."""
    names = [l.split(",")[0] for l in open(os.path.join(d, "joints.csv")).read().split()[1:]]
    lines = open(os.path.join(d, "truth.csv")).read().split()
    head = lines[0].split(",")
    out = {n: {} for n in names}
    for l in lines[1:]:
        row = dict(zip(head, l.split(",")))
        out[names[int(row["pose"])]][int(row["feature"])] = (float(row["u"]), float(row["v"]))
    return out


def cmd_opencv(a):
    """OpenCV's detectors on DIR's images, as a user would run them:
    findChessboardCorners + cornerSubPix with a fixed (W, W) window (the
    tutorial's 11), or findChessboardCornersSB with its defaults; or, for
    a ChArUco board (--method charuco), cv2.aruco.CharucoDetector with its
    default parameters (its corners' ids). Written as detections CSV:
    image, feature (OpenCV's order or id), u, v."""
    import cv2
    lines = ["image,feature,u,v"]
    crit = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 30, 0.001)
    if a.method == "charuco":
        rows, cols, sq, marker = camera_truth.numbers(a.charuco, 4, "--charuco")
        detector = cv2.aruco.CharucoDetector(
            Charuco(int(rows), int(cols), sq, marker, a.dictionary, a.legacy).board)
    else:
        rows, cols = (int(v) for v in a.pattern.split(","))
    for name in sorted(read_truth(a.dir)):
        img = cv2.imread(os.path.join(a.dir, name), cv2.IMREAD_GRAYSCALE)
        if a.method == "charuco":
            c, ids, _, _ = detector.detectBoard(img)
            if ids is None or len(ids) == 0:
                continue
            lines += ["%s,%d,%r,%r" % (name, int(i), float(p[0][0]), float(p[0][1]))
                      for i, p in zip(ids.ravel(), c)]
            continue
        if a.method == "sb":
            ok, c = cv2.findChessboardCornersSB(img, (cols, rows))
        else:
            ok, c = cv2.findChessboardCorners(img, (cols, rows))
            if ok:
                c = cv2.cornerSubPix(img, c, (a.window, a.window), (-1, -1), crit)
        if not ok:
            continue
        lines += ["%s,%d,%r,%r" % (name, i, float(p[0][0]), float(p[0][1])) for i, p in enumerate(c)]
    with open(a.out, "w") as f:
        f.write("\n".join(lines) + "\n")


def cmd_score(a):
    """Detections (image, feature, u, v; or an observations CSV whose pose
    is the image's index in DIR) against DIR's truth: per image the
    error of each detected point against the nearest true corner (so that
    a flipped order does not count as an error), whether the order is the
    truth's, and the summary (detection rate, median, 95th percentile and
    max error, px)."""
    t = read_truth(a.dir)
    det = {}
    lines = open(a.detections).read().split()
    head = lines[0].split(",")
    names = list(t)  # an observations CSV's pose is the image's index
    for l in lines[1:]:
        row = dict(zip(head, l.split(",")))
        name = row["image"] if "image" in row else names[int(row["pose"])]
        det.setdefault(name, {})[int(row["feature"])] = (float(row["u"]), float(row["v"]))
    errs, per, reordered = [], {}, 0
    for name, true in t.items():
        if name not in det:
            per[name] = None
            continue
        ids = sorted(true)
        tp = np.array([true[i] for i in ids])
        e, same = [], True
        for f, p in det[name].items():
            d = np.linalg.norm(tp - np.asarray(p), axis=1)
            j = int(np.argmin(d))
            e.append(float(d[j]))
            same &= ids[j] == f
        reordered += not same
        errs += e
        per[name] = {"max_px": max(e), "points": len(e), "order_as_truth": bool(same)}
    errs = np.array(errs)
    found = sum(v is not None for v in per.values())
    out = {"detected": found, "images": len(t), "reordered": reordered,
           "median_px": float(np.median(errs)) if len(errs) else None,
           "p95_px": float(np.percentile(errs, 95)) if len(errs) else None,
           "max_px": float(errs.max()) if len(errs) else None, "per_image": per}
    print(json.dumps(out if a.per_image else {k: v for k, v in out.items() if k != "per_image"}))


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("render")
    r.add_argument("--truth", required=True)
    r.add_argument("--camera-info", required=True)
    r.add_argument("--board")
    r.add_argument("--charuco", help="ROWS,COLS,SQUARE,MARKER: a ChArUco board's squares")
    r.add_argument("--dictionary", default="DICT_4X4_50")
    r.add_argument("--legacy", action="store_true")
    r.add_argument("--count", type=int, default=25)
    r.add_argument("--far", type=int, default=4)
    r.add_argument("--behind", action="store_true")
    r.add_argument("--seed", type=int, default=0)
    r.add_argument("--blur", type=float, default=0.6)
    r.add_argument("--noise", type=float, default=2.0)
    r.add_argument("--gamma", type=float, default=2.2)
    r.add_argument("--draws", type=int, default=1)
    r.add_argument("--near-range", type=lambda v: camera_truth.numbers(v, 2, "--near-range"),
                   default=(0.3, 0.9), help="A,B: the near images' distance, m")
    r.add_argument("--far-range", type=lambda v: camera_truth.numbers(v, 2, "--far-range"),
                   default=(0.9, 1.4), help="A,B: the far images' distance, m")
    r.add_argument("--out", required=True)
    o = sub.add_parser("opencv")
    o.add_argument("--dir", required=True)
    o.add_argument("--pattern", help="ROWS,COLS of inner corners")
    o.add_argument("--method", choices=["classic", "sb", "charuco"], default="classic")
    o.add_argument("--charuco", help="ROWS,COLS,SQUARE,MARKER: a ChArUco board's squares")
    o.add_argument("--dictionary", default="DICT_4X4_50")
    o.add_argument("--legacy", action="store_true")
    o.add_argument("--window", type=int, default=11)
    o.add_argument("--out", required=True)
    c = sub.add_parser("score")
    c.add_argument("--dir", required=True)
    c.add_argument("--detections", required=True)
    c.add_argument("--per-image", action="store_true")
    a = p.parse_args(argv)
    if a.cmd != "render":
        {"opencv": cmd_opencv, "score": cmd_score}[a.cmd](a)
        return
    if a.far > a.count:
        raise SystemExit("--far %d is more than --count %d" % (a.far, a.count))
    {"render": cmd_render}[a.cmd](a)


if __name__ == "__main__":
    main()
