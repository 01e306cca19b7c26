"""End-to-end truth gate (issue #39, item 5): Pinocchio plays the real robot
and the tracker; activecal selects, calibrates and writes URDF + frames;
Pinocchio compares the calibrated model with the truth.

Usage (run with /work/main/.venv/bin/python; every output is JSON or CSV):

  truth.py make --urdf U --tip LINK --seed S --out truth.json
               [--marker x,y,z] [--pose] [--base LINK] [--offsets-only]
      A true robot: every moving joint of the chain base..tip has its
      <origin> composed with a small rigid motion (0.5-2 mm, 0.05-0.3 deg,
      random directions, seeded): origin_true = origin * Delta, Delta =
      (exp(w), t) in the joint's own frame (the URDF origin's xyz becomes
      xyz + R t, its rotation R exp(w)). A tracker 2.6 m from the base,
      turned 95 deg about a generic axis (the measurement frame: the base
      link's pose in the tracker's frame). A marker on the tip link at the
      nominal offset (default 0.031,-0.024,0.097: about 10 cm off the
      flange, off every axis) plus about 2 mm; with --pose the measured
      frame is also turned by about 0.3 deg from the tip link's axes.
      --offsets-only: each origin only turned about its joint's own axis
      (0.05-0.3 deg, either sign, t = 0): zero-offset errors alone.
      truth.json holds everything (perturbations, tracker, marker); a
      true.urdf is written beside it for people (not read back).

  truth.py measure --truth truth.json --design D --noise SIGMA_M
                   [--orientation-noise RAD] --seed S --out meas.csv
      The true marker position (and with --pose the orientation) in the
      tracker frame at the design's poses (a design file as `activecal
      select --out` writes it: .json, .csv or a pool file's .csv), Gaussian
      noise of SIGMA_M metres per axis (and RAD per axis of a small
      rotation), written as the CSV `activecal calibrate --measurements`
      reads (x1,y1,z1[,phix1,phiy1,phiz1], one column per joint).
      Several --design D1 D2 .. --out O1 O2 ..: one file each, the k-th
      (from 0) with the noise of default_rng((S, k)) (k = 0: of S).

  truth.py compare --truth truth.json --urdf cal.urdf --frames cal.yaml
                   [--design D] [--n 1000] --seed S
      The calibrated model (cal.urdf in Pinocchio, mounted with cal.yaml's
      measurement frame and tool or marker, as verify/tests/live_export.rs
      composes them: M * oMf(base)^-1 oMf(tip) * T) against the truth at N
      random configurations within the joint limits (a joint spanning more
      than a turn drawn over one turn about its range's centre) and at the
      design's poses: RMS (and max) of the 3-D distance, mm; orientation
      error angle (deg) for a full pose. Printed as one JSON object
      (`random`, `design`: rms_mm, max_mm, ...); several --urdf U1 U2 ..
      --frames F1 F2 .. print a list (--design applies to the first; the
      same configurations for all). --nominal compares the nominal URDF
      with the true tracker and the nominal marker: the error before
      calibration.

  truth.py rank --truth truth.json [--n 100] [--seed S]
      The rank of Pinocchio's identification Jacobian of a complete model
      (every chain joint origin 6, tracker 6, marker 3, tool rotation 3 for
      a pose) at N random configurations: what activecal's unknowns should
      number (27 for a UR with a marker, 31 for the xArm7, 30 for a UR
      full pose).

  truth.py sensor-frames --truth truth.json --out nominal.yaml
      A frames file giving activecal the chain's tip and the NOMINAL marker
      (or tool, --pose), no measurement frame: how `select`/`calibrate` are
      told about the sensor until `--marker` lands.

  truth.py random-design --pool pool.csv --n 30 --seed S --out d.csv
      N distinct rows of a pool file written by `activecal pool --out
      pool.csv` (the pool `select --pool file:pool.csv` chooses from),
      uniformly at random (numpy default_rng(S)), written in the same CSV
      form (several --out: one design each).

  truth.py optimum --urdf U --tip LINK [--base LINK] --measurements M.csv
      An independent least-squares fit of single measured points (x1,y1,z1
      and a column per chain joint): every chain joint's <origin> composed
      with a free rigid motion (6 unknowns each, more than the minimal
      parameters: the optimum is the same), the measurement frame (6) and
      the point on the tip link (3), by SciPy's Levenberg-Marquardt on
      Pinocchio's kinematics from the rigid start (Kabsch and the point's
      least squares, alternated). Prints the optimum's RMS position error
      (mm) over the samples: what any calibration of the same model class
      can reach on the data.

One arm end to end, printing predicted vs true:
  verify/python/truth_run.sh ur5 [SEED] [RANDOM_DESIGNS]
The live gate on 9 arms: verify/tests/live_truth.rs.
"""
import argparse
import json
import math
import os
import sys
import xml.etree.ElementTree as ET

import numpy as np

TWO_PI = 2.0 * math.pi
DEFAULT_MARKER = (0.031, -0.024, 0.097)


# ----------------------------------------------------------------- helpers

def pin():
    import pinocchio
    return pinocchio


def unit(rng):
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def exp3(w):
    return pin().exp3(np.asarray(w, dtype=float))


def log3(r):
    return pin().log3(np.asarray(r, dtype=float))


def rpy_matrix(rpy):
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return rz @ ry @ rx


def matrix_rpy(r):
    return [float(v) for v in pin().rpy.matrixToRpy(np.asarray(r))]


def root_link(urdf):
    root = ET.parse(urdf).getroot()
    links = [l.get("name") for l in root.findall("link")]
    children = {j.find("child").get("link") for j in root.findall("joint")}
    roots = [l for l in links if l not in children]
    if len(roots) != 1:
        raise SystemExit("%s: %d root links" % (urdf, len(roots)))
    return roots[0]


class Chain:
    """Pinocchio's model of a URDF and the chain base..tip in it."""

    def __init__(self, urdf, base, tip):
        p = pin()
        self.urdf = os.path.abspath(urdf)
        self.model = p.buildModelFromUrdf(self.urdf)
        self.base = base or root_link(self.urdf)
        self.tip = tip
        self.tf = self.frame(tip)
        self.bf = self.frame(self.base)
        stop = self.model.frames[self.bf].parentJoint
        j = self.model.frames[self.tf].parentJoint
        path = []
        while j != stop:
            if j == 0:
                raise SystemExit("%s is not below %s" % (tip, self.base))
            path.append(j)
            j = self.model.parents[j]
        self.ids = path[::-1]
        self.names = [self.model.names[j] for j in self.ids]
        self.limits = []
        for j in self.ids:
            jm = self.model.joints[j]
            if jm.nq == 1:
                self.limits.append((float(self.model.lowerPositionLimit[jm.idx_q]),
                                    float(self.model.upperPositionLimit[jm.idx_q])))
            elif jm.nq == 2:
                self.limits.append(None)
            else:
                raise SystemExit("joint %s has nq = %d" % (self.model.names[j], jm.nq))
        self.data = self.model.createData()

    def frame(self, link):
        p = pin()
        if not self.model.existFrame(link, p.FrameType.BODY):
            raise SystemExit("%s has no link %s" % (self.urdf, link))
        return self.model.getFrameId(link, p.FrameType.BODY)

    def perturb(self, deltas):
        """origin_true = origin * (exp(w), t) for each chain joint."""
        p = pin()
        for j, d in zip(self.ids, deltas):
            delta = p.SE3(exp3(d["w"]), np.asarray(d["t"], dtype=float))
            self.model.jointPlacements[j] = self.model.jointPlacements[j] * delta
        self.data = self.model.createData()

    def relative(self, q):
        """oMf(base)^-1 oMf(tip) at the chain's joint values q."""
        p = pin()
        x = p.neutral(self.model)
        for j, v in zip(self.ids, q):
            jm = self.model.joints[j]
            if jm.nq == 1:
                x[jm.idx_q] = v
            else:
                x[jm.idx_q] = math.cos(v)
                x[jm.idx_q + 1] = math.sin(v)
        p.framesForwardKinematics(self.model, self.data, x)
        return self.data.oMf[self.bf].actInv(self.data.oMf[self.tf])

    def random_configurations(self, n, rng):
        """Uniform within the limits; a joint spanning more than a turn (or
        continuous) over one turn about its range's centre."""
        qs = np.empty((n, len(self.ids)))
        for k, lim in enumerate(self.limits):
            if lim is None:
                lo, hi = -math.pi, math.pi
            else:
                lo, hi = lim
                if hi - lo > TWO_PI:
                    c = 0.5 * (lo + hi)
                    lo, hi = c - math.pi, c + math.pi
            qs[:, k] = rng.uniform(lo, hi, size=n)
        return qs


def se3(r, t):
    return pin().SE3(np.asarray(r, dtype=float), np.asarray(t, dtype=float))


def iso_json(m):
    return {"xyz": [float(v) for v in m.translation], "rpy": matrix_rpy(m.rotation),
            "rotation": np.asarray(m.rotation).tolist()}


def iso_from_json(e):
    r = np.asarray(e["rotation"]) if "rotation" in e else rpy_matrix(e["rpy"])
    return se3(r, e["xyz"])


class Truth:
    def __init__(self, path):
        with open(path) as f:
            self.j = json.load(f)
        t = self.j
        urdf = t["urdf"]
        if not os.path.isabs(urdf):
            urdf = os.path.join(os.path.dirname(os.path.abspath(path)), urdf)
            if not os.path.exists(urdf):
                urdf = os.path.abspath(t["urdf"])
        self.urdf = urdf
        self.chain = Chain(urdf, t["base"], t["tip"])
        self.chain.perturb(t["joints"])
        self.nominal = Chain(urdf, t["base"], t["tip"])
        self.tracker = iso_from_json(t["tracker"])
        self.tool = iso_from_json(t["tool"])
        self.pose = t["pose"]

    def measured(self, q):
        """The measured frame (marker and, for a pose, its axes) in the tracker's frame."""
        return self.tracker * self.chain.relative(q) * self.tool


def read_design(path, names):
    """Joint values (rows in `names` order) of a design: the JSON design
    file (`joint_names`, `q`), or a CSV with a header of joint names (an
    `id` column of `via` rows is skipped)."""
    if path.lower().endswith(".json"):
        with open(path) as f:
            d = json.load(f)
        cols = d.get("joint_names") or d.get("joints")
        qs = d.get("q") or d.get("qs")
        if cols is None or qs is None:
            raise SystemExit("%s: no joint_names/q" % path)
        rows = [dict(zip(cols, q)) for q in qs]
    else:
        with open(path) as f:
            lines = [l.strip() for l in f if l.strip() and not l.startswith("#")]
        head = [c.strip() for c in lines[0].split(",")]
        rows = []
        for l in lines[1:]:
            cells = [c.strip() for c in l.split(",")]
            row = dict(zip(head, cells))
            if row.get("id") == "via":
                continue
            rows.append({c: float(v) for c, v in row.items() if c in names})
    missing = [n for n in names if n not in rows[0]]
    if missing:
        raise SystemExit("%s: no column for joints %s" % (path, missing))
    return np.array([[r[n] for n in names] for r in rows], dtype=float)


# ------------------------------------------------------------ tiny YAML

def _scalar(s):
    s = s.strip()
    if s.startswith("[") and s.endswith("]"):
        inner = s[1:-1].strip()
        return [] if not inner else [_scalar(x) for x in inner.split(",")]
    if len(s) >= 2 and s[0] == s[-1] and s[0] in "'\"":
        return s[1:-1]
    if s in ("null", "~", ""):
        return None
    if s in ("true", "false"):
        return s == "true"
    try:
        return int(s)
    except ValueError:
        pass
    try:
        return float(s)
    except ValueError:
        return s


def parse_yaml(text):
    """The block YAML activecal writes (maps, sequences, flow lists of
    scalars, comments): enough for the frames file."""
    lines = []
    for raw in text.splitlines():
        s = raw.split(" #")[0].rstrip() if not raw.lstrip().startswith("#") else ""
        if s.strip():
            lines.append((len(s) - len(s.lstrip()), s.strip()))
    pos = [0]

    def block(indent):
        if pos[0] >= len(lines):
            return None
        ind, s = lines[pos[0]]
        if s.startswith("- ") or s == "-":
            out = []
            while pos[0] < len(lines):
                ind, s = lines[pos[0]]
                if ind != indent or not (s.startswith("- ") or s == "-"):
                    break
                rest = s[1:].strip()
                if not rest:
                    pos[0] += 1
                    out.append(block(lines[pos[0]][0]) if pos[0] < len(lines) and lines[pos[0]][0] > indent else None)
                elif ":" in rest and not rest.startswith("[") and not rest.startswith(("'", '"')):
                    # A map inside the sequence: its first key on the dash's line.
                    lines[pos[0]] = (indent + 2, rest)
                    out.append(block(indent + 2))
                else:
                    pos[0] += 1
                    out.append(_scalar(rest))
            return out
        out = {}
        while pos[0] < len(lines):
            ind, s = lines[pos[0]]
            if ind != indent or s.startswith("- "):
                break
            key, _, rest = s.partition(":")
            key = key.strip().strip("'\"")
            rest = rest.strip()
            pos[0] += 1
            if rest:
                out[key] = _scalar(rest)
            elif pos[0] < len(lines) and (lines[pos[0]][0] > indent or
                                          (lines[pos[0]][0] == indent and lines[pos[0]][1].startswith("- "))):
                out[key] = block(lines[pos[0]][0])
            else:
                out[key] = None
        return out

    return block(lines[0][0]) if lines else {}


def read_frames(path):
    """(measurement frame M, tool T, markers, base, tip) of a frames file,
    with the semantics of src/io/frames_file.rs: one marker is the tool's
    origin."""
    with open(path) as f:
        y = parse_yaml(f.read())
    ident = se3(np.eye(3), np.zeros(3))
    mf = y.get("measurement_frame")
    m = se3(rpy_matrix(mf["rpy"]), mf["xyz"]) if mf else ident
    tl = y.get("tool")
    tool = se3(rpy_matrix(tl["rpy"]), tl["xyz"]) if tl else ident
    markers = [mk["xyz"] for mk in (y.get("markers") or [])]
    if len(markers) == 1:
        tool = se3(np.eye(3), markers[0])
        markers = []
    chain = y.get("chain") or {}
    return m, tool, markers, chain.get("base"), chain.get("tip"), y


def matrix_quat(r):
    """A rotation matrix's unit quaternion [w, x, y, z] (Shepperd's method)."""
    import pinocchio
    q = pinocchio.Quaternion(np.asarray(r, dtype=float))
    q.normalize()
    return [q.w, q.x, q.y, q.z]


def write_yaml_frames(path, base, tip, tool, pose, mount=None, joints=()):
    """A frames file activecal reads: the chain (its driven joints), the
    measurement frame (identity unless given), no joint-origin changes, and
    the nominal marker (a point) or tool (a pose). activecal reads frames
    files strictly: every block present, rpy and quaternion agreeing."""
    def frame(iso):
        return ["  xyz: [%s]" % ", ".join(repr(float(v)) for v in iso.translation),
                "  rpy: [%s]" % ", ".join(repr(float(v)) for v in matrix_rpy(iso.rotation)),
                "  quaternion: [%s]" % ", ".join(repr(float(v)) for v in matrix_quat(iso.rotation))]
    lines = ["# written by verify/python/truth.py", "chain:", "  base: %s" % base, "  tip: %s" % tip,
             "  joints: [%s]" % ", ".join(joints)]
    lines += ["measurement_frame:"] + frame(mount if mount is not None else se3(np.eye(3), np.zeros(3)))
    lines += ["joints: {}"]
    if pose:
        lines += ["tool:"] + frame(tool)
    else:
        lines += ["markers:", "- xyz: [%s]" % ", ".join(repr(float(v)) for v in tool.translation)]
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


# ------------------------------------------------------------- commands

def cmd_make(a):
    rng = np.random.default_rng(a.seed)
    chain = Chain(a.urdf, a.base, a.tip)
    joints = []
    axes = joint_axes(a.urdf)
    for name in chain.names:
        t = unit(rng) * rng.uniform(0.5e-3, 2e-3)
        w = unit(rng) * math.radians(rng.uniform(0.05, 0.3))
        if getattr(a, "offsets_only", False):
            # Only a turn about the joint's own axis: a zero-offset error.
            t = np.zeros(3)
            w = axes[name] * math.radians(rng.uniform(0.05, 0.3)) * rng.choice([-1.0, 1.0])
        joints.append({"name": name, "t": t.tolist(), "w": w.tolist()})
    # The tracker: 2.6 m from the base, turned 95 degrees about a generic axis.
    tracker = se3(exp3(unit(rng) * math.radians(95.0)), unit(rng) * 2.6)
    nominal = np.array([float(v) for v in a.marker.split(",")]) if a.marker else np.array(DEFAULT_MARKER)
    true_marker = nominal + unit(rng) * 2e-3
    tool_r = exp3(unit(rng) * math.radians(0.3)) if a.pose else np.eye(3)
    os.makedirs(os.path.dirname(os.path.abspath(a.out)), exist_ok=True)
    truth = {
        "format": 1,
        "urdf": os.path.abspath(a.urdf),
        "base": chain.base,
        "tip": a.tip,
        "seed": a.seed,
        "pose": bool(a.pose),
        "joint_names": chain.names,
        "joints": joints,
        "tracker": iso_json(tracker),
        "tool": iso_json(se3(tool_r, true_marker)),
        "nominal_tool": iso_json(se3(np.eye(3), nominal)),
        "note": "origin_true = origin * (exp3(w), t) per joint (t m, w rad, the joint's frame); "
                "tracker: the base link's pose in the tracker's frame; tool: the measured frame "
                "(marker) in the tip link's frame",
    }
    with open(a.out, "w") as f:
        json.dump(truth, f, indent=1)
    # The true URDF, for people.
    true_urdf = os.path.join(os.path.dirname(os.path.abspath(a.out)), "true.urdf")
    write_true_urdf(a.urdf, joints, true_urdf)
    print(json.dumps({"out": a.out, "true_urdf": true_urdf, "joints": chain.names,
                      "base": chain.base, "tip": a.tip,
                      "marker_nominal": nominal.tolist(), "marker_true": true_marker.tolist()}))


def joint_axes(urdf):
    """Each joint's unit axis in its own frame (URDF <axis>, default x)."""
    axes = {}
    for j in ET.parse(urdf).getroot().findall("joint"):
        e = j.find("axis")
        v = np.array([float(x) for x in e.get("xyz").split()]) if e is not None else np.array([1.0, 0.0, 0.0])
        axes[j.get("name")] = v / np.linalg.norm(v)
    return axes


def write_true_urdf(urdf, joints, out):
    tree = ET.parse(urdf)
    by = {j["name"]: j for j in joints}
    for e in tree.getroot().findall("joint"):
        d = by.get(e.get("name"))
        if d is None:
            continue
        o = e.find("origin")
        if o is None:
            o = ET.SubElement(e, "origin")
        xyz = np.array([float(v) for v in (o.get("xyz") or "0 0 0").split()])
        rpy = [float(v) for v in (o.get("rpy") or "0 0 0").split()]
        r0 = rpy_matrix(rpy)
        o.set("xyz", " ".join(repr(float(v)) for v in xyz + r0 @ np.asarray(d["t"])))
        o.set("rpy", " ".join(repr(v) for v in matrix_rpy(r0 @ exp3(d["w"]))))
    tree.write(out)


def cmd_measure(a):
    if len(a.design) != len(a.out):
        raise SystemExit("measure: %d designs, %d outputs" % (len(a.design), len(a.out)))
    t = Truth(a.truth)
    # The k-th output's noise: default_rng(SEED) for the first, ((SEED, k))
    # for the others (independent draws; the same design may be repeated).
    done = [measure_one(t, d, o, a, np.random.default_rng(a.seed if k == 0 else (a.seed, k)))
            for k, (d, o) in enumerate(zip(a.design, a.out))]
    print(json.dumps(done[0] if len(done) == 1 else done))


def measure_one(t, design, out, a, rng):
    qs = read_design(design, t.chain.names)
    head = ["x1", "y1", "z1"]
    if t.pose:
        head += ["phix1", "phiy1", "phiz1"]
    head += t.chain.names
    rows = []
    for q in qs:
        m = t.measured(q)
        p = m.translation + rng.normal(scale=a.noise, size=3) if a.noise > 0 else m.translation
        row = list(p)
        if t.pose:
            r = m.rotation
            if a.orientation_noise > 0:
                r = r @ exp3(rng.normal(scale=a.orientation_noise, size=3))
            row += matrix_rpy(r)
        row += list(q)
        rows.append(row)
    with open(out, "w") as f:
        f.write(",".join(head) + "\n")
        for r in rows:
            f.write(",".join(repr(float(v)) for v in r) + "\n")
    return {"out": out, "poses": len(rows), "noise_m": a.noise,
            "orientation_noise_rad": a.orientation_noise if t.pose else None}


def errors(t, cal, m, tool, qs):
    dp, da = [], []
    for q in qs:
        want = t.measured(q)
        got = m * cal.relative(q) * tool
        dp.append(np.linalg.norm(got.translation - want.translation))
        if t.pose:
            da.append(np.linalg.norm(log3(want.rotation.T @ got.rotation)))
    dp = np.array(dp) * 1e3
    out = {"rms_mm": float(np.sqrt(np.mean(dp ** 2))), "max_mm": float(dp.max()),
           "mean_mm": float(dp.mean()), "n": len(dp)}
    if t.pose:
        da = np.degrees(np.array(da))
        out["orientation_rms_deg"] = float(np.sqrt(np.mean(da ** 2)))
        out["orientation_max_deg"] = float(da.max())
    return out


def cmd_compare(a):
    t = Truth(a.truth)
    rng = np.random.default_rng(a.seed)
    qs = t.chain.random_configurations(a.n, rng)
    if a.nominal:
        cals = [(t.nominal, t.tracker, iso_from_json(t.j["nominal_tool"]), None)]
    else:
        if len(a.urdf) != len(a.frames):
            raise SystemExit("compare: %d URDFs, %d frames files" % (len(a.urdf), len(a.frames)))
        cals = []
        for k, (u, fr) in enumerate(zip(a.urdf, a.frames)):
            m, tool, markers, base, tip, _ = read_frames(fr)
            if markers:
                raise SystemExit("%s: %d markers; the truth has one" % (fr, len(markers)))
            cal = Chain(u, base or t.chain.base, tip or t.chain.tip)
            if cal.names != t.chain.names:
                raise SystemExit("chains differ: %s vs %s" % (cal.names, t.chain.names))
            cals.append((cal, m, tool, a.design[k] if a.design and k < len(a.design) else None))
    outs = []
    for cal, m, tool, design in cals:
        out = {"random": errors(t, cal, m, tool, qs)}
        if design:
            out["design"] = errors(t, cal, m, tool, read_design(design, t.chain.names))
        outs.append(out)
    print(json.dumps(outs[0] if len(outs) == 1 else outs))


def cmd_rank(a):
    """The rank of the identification Jacobian of a complete model at random
    configurations: every chain joint's origin (6: origin * (exp(w), t)),
    the tracker (6: (exp(w), t) * tracker), the marker's offset (3) and, for
    a full pose, the tool's rotation (3), by central differences (h = 1e-6)
    at the truth. Singular values below 1e-8 of the largest are not counted
    (they are ~1e-14 for the structural null directions; the smallest
    counted are reported)."""
    p = pin()
    t = Truth(a.truth)
    rng = np.random.default_rng(a.seed)
    qs = t.chain.random_configurations(a.n, rng)
    model = t.chain.model
    base_placements = [model.jointPlacements[j].copy() for j in t.chain.ids]
    tracker0, tool0 = t.tracker.copy(), t.tool.copy()
    ncols = 6 * len(t.chain.ids) + 6 + 3 + (3 if t.pose else 0)

    def stack(delta):
        for k, j in enumerate(t.chain.ids):
            d = delta[6 * k:6 * k + 6]
            model.jointPlacements[j] = base_placements[k] * p.SE3(exp3(d[3:]), d[:3])
        o = 6 * len(t.chain.ids)
        t.tracker = p.SE3(exp3(delta[o + 3:o + 6]), delta[o:o + 3]) * tracker0
        r = tool0.rotation @ exp3(delta[o + 9:o + 12]) if t.pose else tool0.rotation
        t.tool = se3(r, tool0.translation + delta[o + 6:o + 9])
        rows = []
        for k, q in enumerate(qs):
            m = t.measured(q)
            rows.append(m.translation)
            if t.pose:
                # The rotation change in the measured frame (log3 of the
                # absolute rotation is not smooth near a half turn).
                rows.append(log3(r0[k].T @ m.rotation) if r0 else np.zeros(3))
        return np.concatenate(rows)

    r0 = [t.measured(q).rotation.copy() for q in qs]
    h = 1e-6
    jac = np.empty((len(stack(np.zeros(ncols))), ncols))
    for c in range(ncols):
        e = np.zeros(ncols)
        e[c] = h
        jac[:, c] = (stack(e) - stack(-e)) / (2 * h)
    stack(np.zeros(ncols))
    sv = np.linalg.svd(jac, compute_uv=False)
    rank = int(np.sum(sv > sv[0] * 1e-8))
    print(json.dumps({"rank": rank, "columns": ncols, "configurations": a.n,
                      "smallest_counted": float(sv[rank - 1] / sv[0]),
                      "largest_dropped": float(sv[rank] / sv[0]) if rank < len(sv) else None}))


def cmd_sensor_frames(a):
    t = Truth(a.truth)
    nominal = iso_from_json(t.j["nominal_tool"])
    write_yaml_frames(a.out, t.chain.base, t.chain.tip, nominal, t.pose, joints=t.chain.names)
    print(json.dumps({"out": a.out}))


def cmd_random_design(a):
    with open(a.pool) as f:
        lines = [l.rstrip("\n") for l in f if l.strip() and not l.startswith("#")]
    head, rows = lines[0], lines[1:]
    rng = np.random.default_rng(a.seed)
    done = []
    for out in a.out:
        pick = rng.choice(len(rows), size=a.n, replace=False)
        with open(out, "w") as f:
            f.write(head + "\n")
            for k in pick:
                f.write(rows[k] + "\n")
        done.append({"out": out, "rows": sorted(int(k) for k in pick), "pool": len(rows)})
    print(json.dumps(done[0] if len(done) == 1 else done))


def rigid(p, y):
    """The least-squares rigid motion (R, t) with y_i = R p_i + t (Kabsch)."""
    cp, cy = p.mean(axis=0), y.mean(axis=0)
    u, _, vt = np.linalg.svd((p - cp).T @ (y - cy))
    d = np.sign(np.linalg.det(vt.T @ u.T))
    r = vt.T @ np.diag([1.0, 1.0, d]) @ u.T
    return r, cy - r @ cp


def read_points(path, names):
    """Joint values (in the chain's order) and the points x1,y1,z1 of a CSV."""
    with open(path) as f:
        lines = [l.strip() for l in f if l.strip() and not l.startswith("#")]
    head = lines[0].split(",")
    rows = np.array([[float(v) for v in l.split(",")] for l in lines[1:]])
    qs = rows[:, [head.index(n) for n in names]]
    ys = rows[:, [head.index(c) for c in ("x1", "y1", "z1")]]
    return qs, ys


def cmd_optimum(a):
    from scipy.optimize import least_squares

    p = pin()
    chain = Chain(a.urdf, a.base, a.tip)
    qs, ys = read_points(a.measurements, chain.names)
    nominal = [chain.model.jointPlacements[j].copy() for j in chain.ids]
    ends = [chain.relative(q) for q in qs]
    # The rigid start: the measurement frame and the tip point, alternated.
    t = np.zeros(3)
    for _ in range(100):
        r, c = rigid(np.array([e.act(t) for e in ends]), ys)
        inv = np.array([r.T @ (y - c) for y in ys])
        t = np.mean([e.rotation.T @ (x - e.translation) for e, x in zip(ends, inv)], axis=0)
    m0 = p.SE3(r, c)
    nj = len(chain.ids)

    def residuals(x):
        for k, j in enumerate(chain.ids):
            chain.model.jointPlacements[j] = nominal[k] * p.exp6(p.Motion(x[6 * k:6 * k + 6]))
        m = p.exp6(p.Motion(x[6 * nj:6 * nj + 6])) * m0
        tool = t + x[6 * nj + 6:]
        pred = np.array([(m * chain.relative(q)).act(tool) for q in qs])
        return (pred - ys).ravel()

    x0 = np.zeros(6 * nj + 9)
    start = residuals(x0)
    sol = least_squares(residuals, x0, method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15,
                        max_nfev=200 * len(x0))
    e = sol.fun.reshape(-1, 3)
    rms = float(np.sqrt(np.mean(np.sum(e ** 2, axis=1)))) * 1e3
    rms0 = float(np.sqrt(np.mean(np.sum(start.reshape(-1, 3) ** 2, axis=1)))) * 1e3
    print(json.dumps({"rms_mm": rms, "start_rms_mm": rms0, "poses": len(qs),
                      "unknowns": len(x0), "evaluations": int(sol.nfev), "status": int(sol.status)}))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    p = sub.add_parser("make")
    p.add_argument("--urdf", required=True)
    p.add_argument("--tip", required=True)
    p.add_argument("--base")
    p.add_argument("--seed", type=int, required=True)
    p.add_argument("--out", required=True)
    p.add_argument("--marker")
    p.add_argument("--pose", action="store_true")
    p.add_argument("--offsets-only", action="store_true")
    p = sub.add_parser("measure")
    p.add_argument("--truth", required=True)
    p.add_argument("--design", required=True, nargs="+")
    p.add_argument("--noise", type=float, required=True)
    p.add_argument("--orientation-noise", type=float, default=0.0)
    p.add_argument("--seed", type=int, required=True)
    p.add_argument("--out", required=True, nargs="+")
    p = sub.add_parser("compare")
    p.add_argument("--truth", required=True)
    p.add_argument("--urdf", nargs="+")
    p.add_argument("--frames", nargs="+")
    p.add_argument("--design", nargs="+")
    p.add_argument("--n", type=int, default=1000)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--nominal", action="store_true")
    p = sub.add_parser("rank")
    p.add_argument("--truth", required=True)
    p.add_argument("--n", type=int, default=100)
    p.add_argument("--seed", type=int, default=0)
    p = sub.add_parser("sensor-frames")
    p.add_argument("--truth", required=True)
    p.add_argument("--out", required=True)
    p = sub.add_parser("random-design")
    p.add_argument("--pool", required=True)
    p.add_argument("--n", type=int, default=30)
    p.add_argument("--seed", type=int, required=True)
    p.add_argument("--out", required=True, nargs="+")
    p = sub.add_parser("optimum")
    p.add_argument("--urdf", required=True)
    p.add_argument("--tip", required=True)
    p.add_argument("--base")
    p.add_argument("--measurements", required=True)
    a = ap.parse_args(argv)
    if a.cmd == "compare" and not a.nominal and not (a.urdf and a.frames):
        ap.error("compare needs --urdf and --frames (or --nominal)")
    {"make": cmd_make, "measure": cmd_measure, "compare": cmd_compare,
     "sensor-frames": cmd_sensor_frames, "rank": cmd_rank, "random-design": cmd_random_design, "optimum": cmd_optimum}[a.cmd](a)


if __name__ == "__main__":
    main()
