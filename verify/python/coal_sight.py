"""Reference line-of-sight verdicts of Pinocchio + Coal for activecal's
camera pool filter (issue #41, item 4).

Usage: coal_sight.py URDF PACKAGE_DIR JOINTS(comma) BASE CARRIER_JOINTS(comma) RAYS.json OUT.json

RAYS.json: [{"q": [...], "eye": [x, y, z], "points": [[x, y, z], ...]}],
positions in the BASE link's frame (metres), q the values of JOINTS (the
URDF's other joints at 0). Each segment from the eye to a point, stopped
STOP = 1 mm short of the point, is a Coal capsule of radius RADIUS = 1e-6 m
along it; it is blocked when it collides (coal.collide) with a collision
geometry of the URDF (Pinocchio's COLLISION model: meshes as BVH triangle
surfaces) whose parent joint is none of CARRIER_JOINTS (the rigid bodies the
target and, for a camera on the robot's own link, the camera are fixed to).
BASE is the frame of the rays: the chain's base link, or the camera's link. OUT.json: per configuration, per point, blocked or not, and
the least Coal distance from the segment to the checked geometries.
"""
import json
import sys

import coal
import numpy as np
import pinocchio as pin

STOP = 1e-3
RADIUS = 1e-6


def segment(a, b):
    """A thin capsule from a to b (3-vectors) and its placement."""
    d = b - a
    length = np.linalg.norm(d)
    z = d / length
    x = np.cross(z, [1.0, 0.0, 0.0])
    if np.linalg.norm(x) < 1e-6:
        x = np.cross(z, [0.0, 1.0, 0.0])
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    R = np.column_stack([x, y, z])
    return coal.Capsule(RADIUS, length), pin.SE3(R, (a + b) / 2)


def main():
    urdf, pkg, joints, base, carrier, rays, out = sys.argv[1:8]
    joints = joints.split(",")
    model, gmodel = pin.buildModelsFromUrdf(urdf, package_dirs=[pkg], geometry_types=pin.GeometryType.COLLISION)
    idx = [model.joints[model.getJointId(j)].idx_q for j in joints]
    skip = {model.getJointId(c) for c in carrier.split(",")}
    checked = [k for k, g in enumerate(gmodel.geometryObjects) if g.parentJoint not in skip]
    data, gdata = model.createData(), gmodel.createData()
    with open(rays) as f:
        cases = json.load(f)
    res = {"blocked": [], "distance": []}
    for case in cases:
        q = pin.neutral(model)
        for k, i in enumerate(idx):
            q[i] = case["q"][k]
        pin.framesForwardKinematics(model, data, q)
        pin.updateGeometryPlacements(model, data, gmodel, gdata, q)
        oMb = data.oMf[model.getFrameId(base)]
        eye = oMb.act(np.array(case["eye"], dtype=float))
        blocked, dist = [], []
        for p in case["points"]:
            p = oMb.act(np.array(p, dtype=float))
            d = p - eye
            end = p - STOP * d / np.linalg.norm(d)
            cap, pose = segment(eye, end)
            hit, dmin = False, float("inf")
            for g in checked:
                geom, gp = gmodel.geometryObjects[g].geometry, gdata.oMg[g]
                req, r = coal.CollisionRequest(), coal.CollisionResult()
                if coal.collide(cap, pose, geom, gp, req, r):
                    hit = True
                dreq, dres = coal.DistanceRequest(), coal.DistanceResult()
                dmin = min(dmin, coal.distance(cap, pose, geom, gp, dreq, dres) + RADIUS)
            blocked.append(hit)
            dist.append(float(dmin))
        res["blocked"].append(blocked)
        res["distance"].append(dist)
    res.update(
        reference=f"Pinocchio {pin.__version__} + Coal {coal.__version__}: buildModelsFromUrdf(COLLISION), "
        f"segments as capsules of radius {RADIUS} m stopped {STOP} m short, collide per geometry, "
        f"geometries on joints {carrier} skipped",
        checked=len(checked),
    )
    with open(out, "w") as f:
        json.dump(res, f, separators=(",", ":"))


if __name__ == "__main__":
    main()
