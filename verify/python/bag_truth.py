"""ROS 2 bags of a simulated calibration run (issue #52), written by
`rosbags` (pure Python, PyPI; a library nobody here wrote), for
`activecal extract`.

Usage (run with the project venv's python):

  bag_truth.py write --truth truth.json --design D --out BAG
                     [--storage mcap|sqlite3] [--kind points|poses|tf]
                     [--noise M] [--orientation-noise RAD] [--joint-noise RAD]
                     [--rate HZ] [--offset S] [--latency S]
                     [--gap-pose K] [--glitch-pose K] [--seed S]
                     [--joint-rate HZ] [--image-mb M]
      The true robot of truth.json (verify/python/truth.py: Pinocchio,
      perturbed joint origins, a tracker 2.6 m away) driven through the
      design's poses in order: at each pose a rest of 1.6-2.4 s, then a
      move to the next with a quintic (smooth) profile, at most 1 rad/s.
      /joint_states (sensor_msgs/JointState) at 500 Hz (--joint-rate) with Gaussian encoder
      noise (--joint-noise, default 2e-6 rad) and one joint that is not the
      robot's (a gripper's, always 0). The measurement at --rate Hz with
      --noise metres per axis (default 5e-5): --kind points on /tracker
      (geometry_msgs/PointStamped), poses on /mocap (PoseStamped, also
      --orientation-noise rad per axis, default 1e-4), tf on /tf (a
      TFMessage tracker -> marker) plus a static world -> tracker on
      /tf_static. Its header stamps are the true time + --offset (the
      tracker's clock ahead of the joints') + --latency. --gap-pose K: the
      measurement drops out for 0.8 s in the middle of rest K (0-based);
      --glitch-pose K: 15 samples of rest K off by 3-5 mm. --image-mb M:
      also M megabytes of raw images (zeros) on /camera/image_raw at 30 Hz,
      to check that reading streams. Prints JSON:
      the rests' true times (joint clock), the expected offset (offset +
      latency), the rest count.

  bag_truth.py images --dir DIR --camera-info YAML --out BAG
                      [--storage mcap|sqlite3] [--encoding png|mono8|rgb8|bgr8]
                      [--joint-noise RAD] [--per-rest N] [--seed S]
      A camera's run (issue #52's camera topics): the images of DIR (as
      camera_images.py render writes them: img_NNN.png and joints.csv, the
      true robot's configuration of each) in the order of joints.csv, the
      arm resting at each image's configuration 1.6-2.4 s and moving to
      the next with the quintic profile above. /joint_states at 500 Hz
      (UR5 names from joints.csv's header, Gaussian --joint-noise, default
      2e-6 rad); the camera on /camera/image at 30 Hz during the rests
      only (a camera at rest sees the same scene: each frame is the
      rendered image itself, --per-rest N frames evenly over the rest, all
      of them by default), as sensor_msgs/CompressedImage (--encoding png:
      the PNG file's bytes, format 'png') or sensor_msgs/Image (mono8,
      rgb8, bgr8: the PNG decoded by OpenCV and converted); and one
      CameraInfo on /camera/camera_info from the YAML (K, D, plumb_bob).
      Prints JSON: the rests' true times, the image files in order.

  bag_truth.py tiny --out DIR
      The small committed bags of fixtures/bags/ (the UR5 of
      fixtures/ur5.urdf; no Pinocchio): tiny.mcap (3 rests of 0.8 s, joints
      at 20 Hz, a point at 10 Hz, a CameraInfo), tiny_db3/ (the same in
      SQLite 3 with its metadata.yaml) and moving.mcap (the arm never
      stops).

  bag_truth.py tiny-images --out DIR
      fixtures/bags/camera.mcap: the first six committed renders of
      fixtures/camera/images/ (joints.csv's configurations; joints at
      20 Hz, no noise, rests of 0.6 s), one frame per rest on
      /camera/image (CompressedImage, png), the first rest's frame
      also raw on /camera/image_raw (Image, mono8), a 16 x 8 frame per
      rest in encoding yuv422 on /camera/image_yuv; on /camera/image_jpeg
      (CompressedImage, format 'jpeg') the first two rests' images as the
      JPEG files fixtures/camera/jpeg/img_000.jpg and img_001.jpg (the
      renders at quality 90) and a 16 x 8 JPEG frame on the other rests,
      /camera/camera_info (the CameraInfo of
      fixtures/camera/small_camera_info.yaml) and /camera/no_info (a
      CameraInfo topic without messages).
"""

import argparse
import json
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

T0 = 1_700_000_000.0  # the epoch of the recording's clock (s)
UR5_JOINTS = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
              "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"]


def rosbags_api():
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore
    return Writer, StoragePlugin, get_typestore(Stores.ROS2_JAZZY)


class Out:
    """A rosbag2 writer with the few message kinds a run records."""

    def __init__(self, path, storage):
        Writer, Plugin, ts = rosbags_api()
        plugin = Plugin.MCAP if storage == "mcap" else Plugin.SQLITE3
        self.ts = ts
        self.w = Writer(path, version=9, storage_plugin=plugin)
        self.w.open()
        self.conns = {}
        self.T = ts.types

    def conn(self, topic, msgtype):
        if topic not in self.conns:
            self.conns[topic] = (self.w.add_connection(topic, msgtype, typestore=self.ts), msgtype)
        return self.conns[topic]

    def header(self, stamp, frame):
        sec = math.floor(stamp)
        nsec = min(int(round((stamp - sec) * 1e9)), 999_999_999)
        return self.T["std_msgs/msg/Header"](
            stamp=self.T["builtin_interfaces/msg/Time"](sec=int(sec), nanosec=nsec), frame_id=frame)

    def put(self, topic, msgtype, msg, log_time):
        c, t = self.conn(topic, msgtype)
        self.w.write(c, int(round(log_time * 1e9)), self.ts.serialize_cdr(msg, t))

    def joints(self, stamp, names, q, log_time):
        m = self.T["sensor_msgs/msg/JointState"](
            header=self.header(stamp, ""), name=list(names),
            position=np.asarray(q, dtype=float), velocity=np.zeros(0), effort=np.zeros(0))
        self.put("/joint_states", "sensor_msgs/msg/JointState", m, log_time)

    def point(self, topic, stamp, p, log_time):
        m = self.T["geometry_msgs/msg/PointStamped"](
            header=self.header(stamp, "tracker"),
            point=self.T["geometry_msgs/msg/Point"](x=p[0], y=p[1], z=p[2]))
        self.put(topic, "geometry_msgs/msg/PointStamped", m, log_time)

    def quat(self, q):
        return self.T["geometry_msgs/msg/Quaternion"](x=q[1], y=q[2], z=q[3], w=q[0])

    def pose(self, topic, stamp, p, q, log_time):
        P = self.T["geometry_msgs/msg/Pose"](
            position=self.T["geometry_msgs/msg/Point"](x=p[0], y=p[1], z=p[2]), orientation=self.quat(q))
        m = self.T["geometry_msgs/msg/PoseStamped"](header=self.header(stamp, "tracker"), pose=P)
        self.put(topic, "geometry_msgs/msg/PoseStamped", m, log_time)

    def transform(self, stamp, parent, child, p, q):
        tr = self.T["geometry_msgs/msg/Transform"](
            translation=self.T["geometry_msgs/msg/Vector3"](x=p[0], y=p[1], z=p[2]), rotation=self.quat(q))
        return self.T["geometry_msgs/msg/TransformStamped"](
            header=self.header(stamp, parent), child_frame_id=child, transform=tr)

    def tf(self, topic, transforms, log_time):
        m = self.T["tf2_msgs/msg/TFMessage"](transforms=transforms)
        self.put(topic, "tf2_msgs/msg/TFMessage", m, log_time)

    def camera_info(self, stamp, log_time):
        roi = self.T["sensor_msgs/msg/RegionOfInterest"](x_offset=0, y_offset=0, height=0, width=0,
                                                          do_rectify=False)
        m = self.T["sensor_msgs/msg/CameraInfo"](
            header=self.header(stamp, "camera"), height=480, width=640, distortion_model="plumb_bob",
            d=np.array([0.1, -0.05, 0.0, 0.0, 0.0]),
            k=np.array([500.0, 0, 320, 0, 500, 240, 0, 0, 1]), r=np.eye(3).ravel(),
            p=np.array([500.0, 0, 320, 0, 0, 500, 240, 0, 0, 0, 1, 0]), binning_x=0, binning_y=0, roi=roi)
        self.put("/camera_info", "sensor_msgs/msg/CameraInfo", m, log_time)

    def close(self):
        self.w.close()


def matrix_quat(r):
    """[w, x, y, z] of a rotation matrix."""
    from scipy.spatial.transform import Rotation
    x, y, z, w = Rotation.from_matrix(r).as_quat()
    return [w, x, y, z]


def timeline(qs, rng, vmax=1.0, rest=(1.6, 2.4), lead=0.5):
    """Segments (kind, t0, t1, qa, qb) through the poses qs: a rest at each,
    a quintic move between; the rests' (t0, t1)."""
    segs, rests = [], []
    t = 0.0
    segs.append(("rest", t, t + lead, qs[0], qs[0]))
    t += lead
    for k, q in enumerate(qs):
        d = rng.uniform(*rest)
        segs.append(("rest", t, t + d, q, q))
        rests.append((t, t + d))
        t += d
        if k + 1 < len(qs):
            dq = np.max(np.abs(qs[k + 1] - q))
            dur = max(1.2, 1.875 * dq / vmax)
            segs.append(("move", t, t + dur, q, qs[k + 1]))
            t += dur
    segs.append(("rest", t, t + lead, qs[-1], qs[-1]))
    return segs, rests, t + lead


def q_at(segs, t):
    for kind, a, b, qa, qb in segs:
        if t <= b:
            if kind == "rest":
                return qa
            s = (t - a) / (b - a)
            s = 10 * s ** 3 - 15 * s ** 4 + 6 * s ** 5
            return qa + (qb - qa) * s
    return segs[-1][4]


def cmd_write(a):
    from truth import Truth, exp3, read_design
    t = Truth(a.truth)
    rng = np.random.default_rng(a.seed)
    qs = read_design(a.design, t.chain.names)
    segs, rests, end = timeline(qs, rng)
    out = Out(a.out, a.storage)
    names = list(t.chain.names) + ["gripper_finger_joint"]
    for k in range(int(end * a.joint_rate) + 1):
        tk = k / a.joint_rate
        q = q_at(segs, tk) + rng.normal(scale=a.joint_noise, size=len(t.chain.names))
        out.joints(T0 + tk, names, list(q) + [0.0], T0 + tk + 0.001)
    glitch, gap = set(), None
    if a.glitch_pose is not None:
        r0, r1 = rests[a.glitch_pose]
        glitch = {round(r0 + 0.5 * (r1 - r0) + j / a.rate, 6) for j in range(15)}
    if a.gap_pose is not None:
        r0, r1 = rests[a.gap_pose]
        gap = (0.5 * (r0 + r1) - 0.4, 0.5 * (r0 + r1) + 0.4)
    static_sent = False
    phase = 0.0037  # the tracker's samples fall between the joints'
    for k in range(int(end * a.rate)):
        tk = phase + k / a.rate
        if gap and gap[0] <= tk <= gap[1]:
            continue
        m = t.measured(q_at(segs, tk))
        p = m.translation + rng.normal(scale=a.noise, size=3)
        if any(abs(tk - g) < 0.5 / a.rate for g in glitch):
            d = rng.normal(size=3)
            p = p + d / np.linalg.norm(d) * rng.uniform(3e-3, 5e-3)
        stamp = T0 + tk + a.offset + a.latency
        log_time = T0 + tk + a.latency + 0.002
        if a.kind == "points":
            out.point("/tracker", stamp, p, log_time)
            continue
        r = m.rotation @ exp3(rng.normal(scale=a.orientation_noise, size=3))
        qq = matrix_quat(r)
        if a.kind == "poses":
            out.pose("/mocap", stamp, p, qq, log_time)
        else:
            if not static_sent:
                # world -> tracker, static: the chain world -> marker is the
                # tracker's measurement seen from the world.
                out.tf("/tf_static", [out.transform(stamp, "world", "tracker", [0.5, -0.2, 1.0],
                                                    [math.cos(0.3), 0, 0, math.sin(0.3)])], log_time)
                static_sent = True
            out.tf("/tf", [out.transform(stamp, "tracker", "marker", p, qq)], log_time)
    out.camera_info(T0, T0)
    if a.image_mb > 0:
        # A camera's raw images (zeros, 640x480 rgb8, 30 Hz): bulk that a
        # reader of the other topics must stream past.
        frame = np.zeros(480 * 640 * 3, dtype=np.uint8)
        for k in range(int(a.image_mb * 1e6 / frame.size) + 1):
            tk = k / 30.0
            m = out.T["sensor_msgs/msg/Image"](header=out.header(T0 + tk, "camera"), height=480, width=640,
                                               encoding="rgb8", is_bigendian=0, step=640 * 3, data=frame)
            out.put("/camera/image_raw", "sensor_msgs/msg/Image", m, T0 + tk)
    out.close()
    print(json.dumps({"rests": [[r0, r1] for r0, r1 in rests], "poses": len(qs),
                      "offset": a.offset + a.latency, "duration": end, "joints": list(t.chain.names)}))


def cmd_tiny(a):
    os.makedirs(a.out, exist_ok=True)
    rng = np.random.default_rng(52)
    qs = np.array([[0.0, -1.2, 1.4, -1.7, -1.57, 0.0],
                   [0.4, -1.0, 1.2, -1.5, -1.4, 0.3],
                   [-0.3, -1.4, 1.6, -1.9, -1.7, -0.4]])
    for name, storage in [("tiny.mcap", "mcap"), ("tiny_db3", "sqlite3")]:
        segs, rests, end = timeline(qs, np.random.default_rng(1), vmax=2.0, rest=(0.8, 0.8), lead=0.1)
        tmp = os.path.join(a.out, name + ".d" if storage == "mcap" else name)
        remove(os.path.join(a.out, name))
        out = Out(tmp, storage)
        for k in range(int(end * 20) + 1):
            tk = k / 20.0
            out.joints(T0 + tk, UR5_JOINTS, list(q_at(segs, tk)), T0 + tk)
        for k in range(int(end * 10)):
            tk = k / 10.0
            q = q_at(segs, tk)
            p = [0.5 + 0.1 * q[0], 0.2 * q[1], 0.3 + 0.1 * q[2]] + rng.normal(scale=1e-5, size=3)
            out.point("/tracker", T0 + tk, p, T0 + tk)
        out.camera_info(T0, T0)
        out.close()
        if storage == "mcap":
            finish(tmp, os.path.join(a.out, name))
    segs = [("move", 0.0, 2.0, qs[0], qs[1])]
    tmp = os.path.join(a.out, "moving.mcap.d")
    out = Out(tmp, "mcap")
    for k in range(41):
        out.joints(T0 + k / 20.0, UR5_JOINTS, list(q_at(segs, k / 20.0 * 0.999)), T0 + k / 20.0)
        out.point("/tracker", T0 + k / 20.0, [0.5, 0.0, 0.3], T0 + k / 20.0)
    out.close()
    finish(tmp, os.path.join(a.out, "moving.mcap"))


def camera_info_msg(out, path, stamp, topic):
    """The CameraInfo of a camera_info YAML, on topic."""
    from camera_truth import camera_info
    k, d, w, h = camera_info(path)
    roi = out.T["sensor_msgs/msg/RegionOfInterest"](x_offset=0, y_offset=0, height=0, width=0,
                                                     do_rectify=False)
    p = np.hstack([k, np.zeros((3, 1))]).ravel()
    m = out.T["sensor_msgs/msg/CameraInfo"](
        header=out.header(stamp, "camera"), height=h, width=w, distortion_model="plumb_bob",
        d=np.asarray(d, dtype=float), k=k.ravel().astype(float), r=np.eye(3).ravel(), p=p,
        binning_x=0, binning_y=0, roi=roi)
    out.put(topic, "sensor_msgs/msg/CameraInfo", m, stamp)


def image_msg(out, topic, stamp, png_bytes, encoding):
    """One frame: the PNG as a CompressedImage, or decoded as a raw Image."""
    if encoding == "png":
        m = out.T["sensor_msgs/msg/CompressedImage"](
            header=out.header(stamp, "camera"), format="png",
            data=np.frombuffer(png_bytes, dtype=np.uint8))
        out.put(topic, "sensor_msgs/msg/CompressedImage", m, stamp)
        return
    import cv2
    g = cv2.imdecode(np.frombuffer(png_bytes, dtype=np.uint8), cv2.IMREAD_UNCHANGED)
    raw_image(out, topic, stamp, g, encoding)


def raw_image(out, topic, stamp, g, encoding):
    import cv2
    if encoding in ("rgb8", "bgr8") and g.ndim == 2:
        g = cv2.cvtColor(g, cv2.COLOR_GRAY2RGB if encoding == "rgb8" else cv2.COLOR_GRAY2BGR)
    h, w = g.shape[:2]
    step = g.strides[0]
    m = out.T["sensor_msgs/msg/Image"](
        header=out.header(stamp, "camera"), height=h, width=w, encoding=encoding, is_bigendian=0,
        step=step, data=np.ascontiguousarray(g).ravel().view(np.uint8))
    out.put(topic, "sensor_msgs/msg/Image", m, stamp)


def read_images_dir(d):
    """The joints.csv of DIR: joint names, [(file, q)]."""
    lines = open(os.path.join(d, "joints.csv")).read().split()
    names = lines[0].split(",")[1:]
    rows = [(l.split(",")[0], np.array([float(v) for v in l.split(",")[1:]])) for l in lines[1:]]
    return names, rows


def cmd_images(a):
    names, rows = read_images_dir(a.dir)
    rng = np.random.default_rng(a.seed)
    qs = [q for _, q in rows]
    segs, rests, end = timeline(qs, rng)
    out = Out(a.out, a.storage)
    for k in range(int(end * 500) + 1):
        tk = k / 500.0
        q = q_at(segs, tk) + rng.normal(scale=a.joint_noise, size=len(names))
        out.joints(T0 + tk, names, list(q), T0 + tk + 0.001)
    camera_info_msg(out, a.camera_info, T0, "/camera/camera_info")
    for (f, _), (r0, r1) in zip(rows, rests):
        data = open(os.path.join(a.dir, f), "rb").read()
        frames = [r0 + j / 30.0 for j in range(int((r1 - r0) * 30) + 1)]
        if a.per_rest:
            frames = list(np.linspace(r0, r1, a.per_rest + 2)[1:-1])
        for tk in frames:
            image_msg(out, "/camera/image", T0 + tk, data, a.encoding)
    out.close()
    print(json.dumps({"rests": [[r0, r1] for r0, r1 in rests], "images": [f for f, _ in rows]}))


def cmd_tiny_images(a):
    import cv2
    root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
    d = os.path.join(root, "fixtures", "camera", "images")
    names, rows = read_images_dir(d)
    rows = rows[:6]
    segs, rests, end = timeline([q for _, q in rows], np.random.default_rng(1), vmax=2.0,
                                rest=(0.6, 0.6), lead=0.1)
    tmp = os.path.join(a.out, "camera.mcap.d")
    remove(tmp)
    out = Out(tmp, "mcap")
    for k in range(int(end * 20) + 1):
        tk = k / 20.0
        out.joints(T0 + tk, names, list(q_at(segs, tk)), T0 + tk)
    info = os.path.join(root, "fixtures", "camera", "small_camera_info.yaml")
    camera_info_msg(out, info, T0, "/camera/camera_info")
    out.conn("/camera/no_info", "sensor_msgs/msg/CameraInfo")
    small = np.full((8, 16), 128, dtype=np.uint8)
    jpeg = cv2.imencode(".jpg", small)[1].tobytes()
    for n, ((f, _), (r0, r1)) in enumerate(zip(rows, rests)):
        data = open(os.path.join(d, f), "rb").read()
        tk = T0 + 0.5 * (r0 + r1)
        image_msg(out, "/camera/image", tk, data, "png")
        if n == 0:
            image_msg(out, "/camera/image_raw", tk, data, "mono8")
        m = out.T["sensor_msgs/msg/Image"](
            header=out.header(tk, "camera"), height=8, width=8, encoding="yuv422", is_bigendian=0,
            step=16, data=small.ravel())
        out.put("/camera/image_yuv", "sensor_msgs/msg/Image", m, tk)
        frame = jpeg
        if n < 2:
            frame = open(os.path.join(root, "fixtures", "camera", "jpeg", f"img_{n:03}.jpg"), "rb").read()
        m = out.T["sensor_msgs/msg/CompressedImage"](
            header=out.header(tk, "camera"), format="jpeg", data=np.frombuffer(frame, dtype=np.uint8))
        out.put("/camera/image_jpeg", "sensor_msgs/msg/CompressedImage", m, tk)
    out.close()
    finish(tmp, os.path.join(a.out, "camera.mcap"))


def remove(path):
    import shutil
    if os.path.isdir(path):
        shutil.rmtree(path)
    elif os.path.exists(path):
        os.remove(path)


def finish(tmp, dest):
    """The .mcap file of the bag folder tmp, alone at dest."""
    import shutil
    remove(dest)
    f = [x for x in os.listdir(tmp) if x.endswith(".mcap")][0]
    os.replace(os.path.join(tmp, f), dest)
    shutil.rmtree(tmp)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    p = sub.add_parser("write")
    p.add_argument("--truth", required=True)
    p.add_argument("--design", required=True)
    p.add_argument("--out", required=True)
    p.add_argument("--storage", choices=["mcap", "sqlite3"], default="mcap")
    p.add_argument("--kind", choices=["points", "poses", "tf"], default="points")
    p.add_argument("--noise", type=float, default=5e-5)
    p.add_argument("--orientation-noise", type=float, default=1e-4)
    p.add_argument("--joint-noise", type=float, default=2e-6)
    p.add_argument("--rate", type=float, default=100.0)
    p.add_argument("--offset", type=float, default=0.0)
    p.add_argument("--latency", type=float, default=0.0)
    p.add_argument("--gap-pose", type=int)
    p.add_argument("--glitch-pose", type=int)
    p.add_argument("--image-mb", type=float, default=0.0)
    p.add_argument("--joint-rate", type=float, default=500.0)
    p.add_argument("--seed", type=int, default=1)
    p = sub.add_parser("images")
    p.add_argument("--dir", required=True)
    p.add_argument("--camera-info", required=True)
    p.add_argument("--out", required=True)
    p.add_argument("--storage", choices=["mcap", "sqlite3"], default="mcap")
    p.add_argument("--encoding", choices=["png", "mono8", "rgb8", "bgr8"], default="png")
    p.add_argument("--joint-noise", type=float, default=2e-6)
    p.add_argument("--per-rest", type=int, default=0)
    p.add_argument("--seed", type=int, default=1)
    p = sub.add_parser("tiny-images")
    p.add_argument("--out", required=True)
    p = sub.add_parser("tiny")
    p.add_argument("--out", required=True)
    a = ap.parse_args(argv)
    {"write": cmd_write, "tiny": cmd_tiny, "images": cmd_images, "tiny-images": cmd_tiny_images}[a.cmd](a)


if __name__ == "__main__":
    main()
