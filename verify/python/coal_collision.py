"""Reference self-collision verdicts of Pinocchio + Coal (hpp-fcl) for
activecal's collision filter (issue #15).

Usage: coal_collision.py URDF SRDF PACKAGE_DIR JOINTS(comma) N SEED OUT.json
       (N = file:CONFIGS.json checks the configurations of that JSON list
       instead of sampling)

The URDF's collision geometry is loaded by Pinocchio (meshes as Coal BVH
triangle surfaces, boxes as boxes); every collision pair is added, the SRDF's
disabled pairs removed (pinocchio.removeCollisionPairs), and pairs on the
same or adjacent joints dropped (activecal's rule: bodies joined by one joint
touch by design). N configurations are drawn uniformly within the URDF's
limits of JOINTS (numpy default_rng(SEED)); other joints sit at 0. For each:
whether any pair collides (security margin 0 and +1 mm), the smallest Coal
distance over the pairs, and the largest penetration depth of the contacts
Coal reports when it collides.
"""
import json
import sys

import coal
import numpy as np
import pinocchio as pin


def main():
    urdf, srdf, pkg, joints, n, seed, out = sys.argv[1:8]
    joints = joints.split(",")
    model, gmodel = pin.buildModelsFromUrdf(urdf, package_dirs=[pkg], geometry_types=pin.GeometryType.COLLISION)
    gmodel.addAllCollisionPairs()
    pin.removeCollisionPairs(model, gmodel, srdf)
    par = model.parents
    pairs = []
    for cp in gmodel.collisionPairs:
        a = gmodel.geometryObjects[cp.first].parentJoint
        b = gmodel.geometryObjects[cp.second].parentJoint
        if a == b or par[a] == b or par[b] == a:
            continue
        pairs.append((cp.first, cp.second))
    idx = [model.joints[model.getJointId(j)].idx_q for j in joints]
    lo = np.array([model.lowerPositionLimit[i] for i in idx])
    hi = np.array([model.upperPositionLimit[i] for i in idx])
    rng = np.random.default_rng(int(seed))
    if n.startswith("file:"):
        with open(n[5:]) as f:
            given = [np.array(c, dtype=float) for c in json.load(f)]
    else:
        given = [rng.uniform(lo, hi) for _ in range(int(n))]
    data, gdata = model.createData(), gmodel.createData()
    res = {"configs": [], "collides": [], "collides_1mm": [], "distance": [], "depth": []}
    for qc in given:
        q = pin.neutral(model)
        for k, i in enumerate(idx):
            q[i] = qc[k]
        pin.updateGeometryPlacements(model, data, gmodel, gdata, q)
        hit = {0.0: False, 1e-3: False}
        depth = 0.0
        dmin = float("inf")
        for a, b in pairs:
            ga, gb = gmodel.geometryObjects[a].geometry, gmodel.geometryObjects[b].geometry
            pa, pb = gdata.oMg[a], gdata.oMg[b]
            for m in hit:
                req = coal.CollisionRequest()
                req.security_margin = m
                req.num_max_contacts = 100
                req.enable_contact = True
                r = coal.CollisionResult()
                if coal.collide(ga, pa, gb, pb, req, r):
                    hit[m] = True
                    if m == 0.0:
                        for c in r.getContacts():
                            depth = max(depth, abs(c.penetration_depth))
            dreq, dres = coal.DistanceRequest(), coal.DistanceResult()
            dmin = min(dmin, coal.distance(ga, pa, gb, pb, dreq, dres))
        res["configs"].append([float(x) for x in qc])
        res["collides"].append(hit[0.0])
        res["collides_1mm"].append(hit[1e-3])
        res["distance"].append(float(dmin))
        res["depth"].append(float(depth))
    res.update(
        format=1,
        reference=f"Pinocchio {pin.__version__} + Coal {coal.__version__}: buildModelsFromUrdf(COLLISION), "
        "addAllCollisionPairs, removeCollisionPairs(SRDF), same/adjacent joints dropped; collide and distance per pair",
        joints=joints,
        seed=int(seed),
        pairs=len(pairs),
    )
    with open(out, "w") as f:
        json.dump(res, f, separators=(",", ":"))


if __name__ == "__main__":
    main()
