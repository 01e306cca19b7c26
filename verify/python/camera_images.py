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

      --aprilgrid ROWS,COLS,TAG,SPACING (instead of --board): Kalibr's
      aprilgrid (tagRows, tagCols, tagSize in m, tagSpacing the gap over
      the tag's side) as kalibr_create_target_pdf draws it (class
      Aprilgrid: 36h11 tags with a 2-bit border, the black squares at
      their corners), half a tag of white paper around the corner squares;
      its face is seen when its z axis points towards the camera (Kalibr's
      frame), which --behind turns around; the truth is the tags' corners
      with Kalibr's ids (4k ... 4k+3: lower left, lower right, upper right,
      upper left of tag k), the smallest square is the shortest tag side.

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


def view(r, tv, pts, outline, k, dist, w, h, face=1.0):
    """(distance m, view angle deg, behind, in image); `face` is +1 for a
    board whose printed face is seen when its z axis points away from the
    camera (OpenCV's), -1 when it points towards it (Kalibr's aprilgrid)."""
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
    return dist_m, angle, face * cosang < 0, inside


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
        self.face = 1.0

    def smallest(self, px):
        return smallest_square(px, *self.grid)

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
        self.face = 1.0

    def smallest(self, px):
        return smallest_square(px, *self.grid)

    def colour(self, bx, by):
        rows, cols, sq = self.rows, self.cols, self.sq
        tx, ty = np.floor(bx / sq * TEXEL), np.floor(by / sq * TEXEL)
        on = (tx >= 0) & (tx < cols * TEXEL) & (ty >= 0) & (ty < rows * TEXEL)
        texel = self.tex[np.clip(ty, 0, rows * TEXEL - 1).astype(int),
                         np.clip(tx, 0, cols * TEXEL - 1).astype(int)]
        level = np.where(texel > 127, WHITE, BLACK)
        paper = (bx >= -0.5 * sq) & (bx <= (cols + 0.5) * sq) & (by >= -0.5 * sq) & (by <= (rows + 0.5) * sq)
        return np.where(on, level, np.where(paper, WHITE, BACKGROUND))


# Tag 0 of the AprilTag family 36h11 (AprilTag's tag36h11 table, the code
# Kalibr's kalibr_create_target_pdf draws): its 36 bits, the most
# significant first, row by row from the top-left of the printed tag,
# white = 1 (Kalibr's generateAprilTag: bit 6i+j of the code, turned 180
# degrees by np.rot90(., 2), drawn with row 0 at the top).
TAG36H11_0 = 0xD5D628584


def kalibr_tag(dictionary, tag_id):
    """Kalibr's printed tag `tag_id` (36h11, a 2-bit black border) as 10 x 10
    booleans (True: black), row 0 at the top of the printed face: OpenCV's
    generateImageMarker(DICT_APRILTAG_36h11, id, borderBits=2) turned 180
    degrees (OpenCV draws the same code with its first bit at the other
    corner), checked on tag 0 against the family's code."""
    import cv2
    m = cv2.aruco.generateImageMarker(dictionary, tag_id, 10, borderBits=2)
    black = np.rot90(m < 128, 2)
    if tag_id == 0:
        want = [(TAG36H11_0 >> (35 - n)) & 1 == 0 for n in range(36)]
        if list(black[2:8, 2:8].ravel()) != want:
            raise SystemExit("OpenCV's DICT_APRILTAG_36h11 tag 0 is not Kalibr's")
    return black


class Aprilgrid:
    """Kalibr's aprilgrid of rows x cols tags (36h11, ids 0 ... rows*cols - 1
    row by row from the bottom-left) of side `size` (m), `spacing * size`
    apart, as kalibr_create_target_pdf draws it: each tag a 10 x 10 bit
    square with a 2-bit black border, a black square of side spacing*size
    diagonally outside each of its corners (touching the tag's corner:
    X-junctions), white paper half a tag around that. The board's frame is
    Kalibr's: x right, y up on the printed face, z out of it (the face is
    seen when z points towards the camera). The truth is the tags' corners
    with Kalibr's ids (4k ... 4k+3: lower left, lower right, upper right,
    upper left; activecal's aprilgrid target). Not drawn: the PDF's axis
    arrows and caption below the grid (outside the paper here)."""

    def __init__(self, rows, cols, size, spacing):
        import cv2
        d = cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_APRILTAG_36h11)
        self.rows, self.cols, self.sq = rows, cols, size
        self.size, self.spacing = size, spacing
        self.pitch = (1 + spacing) * size
        self.tags = np.stack([kalibr_tag(d, i) for i in range(rows * cols)])
        pts = []
        for i in range(rows * cols):
            x0, y0 = (i % cols) * self.pitch, (i // cols) * self.pitch
            pts += [[x0, y0, 0], [x0 + size, y0, 0], [x0 + size, y0 + size, 0], [x0, y0 + size, 0]]
        self.pts = np.array(pts, dtype=float)
        m = spacing * size + 0.5 * size
        # the corner squares reach spacing*size past the outer tags
        self.paper = (-m, (cols - 1) * self.pitch + size + m, -m, (rows - 1) * self.pitch + size + m)
        self.outline = rect_outline(*self.paper)
        self.face = -1.0

    def smallest(self, px):
        """The shortest tag side, px."""
        q = px.reshape(-1, 4, 2)
        return float(np.linalg.norm(q - np.roll(q, 1, axis=1), axis=2).min())

    def colour(self, bx, by):
        p, t = self.pitch, self.size
        cx, cy = np.floor(bx / p), np.floor(by / p)
        u, v = bx - cx * p, by - cy * p
        in_tag = (u < t) & (v < t) & (cx >= 0) & (cx < self.cols) & (cy >= 0) & (cy < self.rows)
        k = np.clip(cy * self.cols + cx, 0, self.rows * self.cols - 1).astype(int)
        b = t / 10
        row = np.clip(9 - np.floor(v / b), 0, 9).astype(int)
        col = np.clip(np.floor(u / b), 0, 9).astype(int)
        tag_black = self.tags[k, row, col]
        corner = (u >= t) & (v >= t) & (cx >= -1) & (cx <= self.cols - 1) & (cy >= -1) & (cy <= self.rows - 1)
        x0, x1, y0, y1 = self.paper
        paper = (bx >= x0) & (bx <= x1) & (by >= y0) & (by <= y1)
        black = (in_tag & tag_black) | corner
        return np.where(black, BLACK, np.where(paper, WHITE, BACKGROUND))


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


def choose(t, a, pts, outline, k, dist, w, h, rng, face=1.0):
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
            v = view(r, tv, pts, outline, k, dist, w, h, face)
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
    if sum(x is not None for x in (a.board, a.charuco, a.aprilgrid)) != 1:
        raise SystemExit("give one of --board, --charuco and --aprilgrid")
    if a.board is not None:
        rows, cols, sq = camera_truth.numbers(a.board, 3, "--board")
        board = Checkerboard(int(rows), int(cols), sq)
    elif a.aprilgrid is not None:
        rows, cols, sq, spacing = camera_truth.numbers(a.aprilgrid, 4, "--aprilgrid")
        board = Aprilgrid(int(rows), int(cols), sq, spacing)
    else:
        rows, cols, sq, marker = camera_truth.numbers(a.charuco, 4, "--charuco")
        board = Charuco(int(rows), int(cols), sq, marker, a.dictionary, a.legacy)
    pts, outline = board.pts, board.outline
    rng = np.random.default_rng(a.seed)
    chosen = choose(t, a, pts, outline, k, dist, w, h, rng, board.face)
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
        st = dict(st, image=name, smallest_square_px=board.smallest(px))
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


# OpenCV's marker corner c (clockwise from the top-left of its marker
# image) is Kalibr's corner KALIBR_OF_OPENCV[c] of the same tag: Kalibr
# prints OpenCV's marker image turned 180 degrees (kalibr_tag), so
# OpenCV's top-left, top-right, bottom-right, bottom-left are Kalibr's
# lower right, lower left, upper left, upper right.
KALIBR_OF_OPENCV = [1, 0, 3, 2]


def aprilgrid_detector(method):
    """OpenCV's ArucoDetector for Kalibr's tags (DICT_APRILTAG_36h11, a
    2-bit border), its other parameters the defaults but the corner
    refinement: 'aprilgrid-subpix' (CORNER_REFINE_SUBPIX, cornerSubPix
    with its documented defaults), 'aprilgrid-apriltag'
    (CORNER_REFINE_APRILTAG), 'aprilgrid' (none)."""
    import cv2
    p = cv2.aruco.DetectorParameters()
    p.markerBorderBits = 2
    p.cornerRefinementMethod = {
        "aprilgrid": cv2.aruco.CORNER_REFINE_NONE,
        "aprilgrid-subpix": cv2.aruco.CORNER_REFINE_SUBPIX,
        "aprilgrid-apriltag": cv2.aruco.CORNER_REFINE_APRILTAG}[method]
    d = cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_APRILTAG_36h11)
    return cv2.aruco.ArucoDetector(d, p)


def aprilgrid_lines(detector, img, name, ntags):
    """The detections CSV's rows of the aprilgrid's tags (ids below
    `ntags`) found by `detector` in `img`, with Kalibr's point ids."""
    corners, ids, _ = detector.detectMarkers(img)
    if ids is None:
        return []
    out = []
    for c, i in zip(corners, ids.ravel()):
        if i >= ntags:
            continue
        for k in range(4):
            f = 4 * int(i) + KALIBR_OF_OPENCV[k]
            out.append("%s,%d,%r,%r" % (name, f, float(c[0][k][0]), float(c[0][k][1])))
    return out


def cmd_opencv(a):
    """OpenCV's detectors on DIR's images, as a user would run them:
    findChessboardCorners + cornerSubPix with a fixed (W, W) window (the
    tutorial's 11), or findChessboardCornersSB with its defaults; or, for
    a ChArUco board (--method charuco), cv2.aruco.CharucoDetector with its
    default parameters (its corners' ids); or, for Kalibr's aprilgrid
    (--method aprilgrid[-subpix|-apriltag] --aprilgrid R,C,T,S; OpenCV has
    no aprilgrid detector), cv2.aruco.ArucoDetector on its tags
    (aprilgrid_detector), each tag's corners with Kalibr's ids. Written as detections CSV:
    image, feature (OpenCV's order or id), u, v."""
    import cv2
    lines = ["image,feature,u,v"]
    crit = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 30, 0.001)
    if a.method == "charuco":
        rows, cols, sq, marker = camera_truth.numbers(a.charuco, 4, "--charuco")
        detector = cv2.aruco.CharucoDetector(
            Charuco(int(rows), int(cols), sq, marker, a.dictionary, a.legacy).board)
    elif a.method.startswith("aprilgrid"):
        detector = aprilgrid_detector(a.method)
        ntags = int(np.prod(camera_truth.numbers(a.aprilgrid, 4, "--aprilgrid")[:2]))
    else:
        rows, cols = (int(v) for v in a.pattern.split(","))
    for name in sorted(read_truth(a.dir)):
        img = cv2.imread(os.path.join(a.dir, name), cv2.IMREAD_GRAYSCALE)
        if a.method.startswith("aprilgrid"):
            lines += aprilgrid_lines(detector, img, name, ntags)
            continue
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
    r.add_argument("--aprilgrid", help="ROWS,COLS,TAG,SPACING: Kalibr's aprilgrid (tagRows, tagCols, tagSize m, tagSpacing)")
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
    o.add_argument("--method", choices=["classic", "sb", "charuco", "aprilgrid", "aprilgrid-subpix",
                                        "aprilgrid-apriltag"], default="classic")
    o.add_argument("--aprilgrid", help="ROWS,COLS,TAG,SPACING: Kalibr's aprilgrid")
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
