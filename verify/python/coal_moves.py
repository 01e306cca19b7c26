"""Reference verdicts of Pinocchio + Coal (hpp-fcl) on straight joint-space
moves, for activecal's tour check (issue #27).

Usage: coal_moves.py SPEC.json OUT.json

SPEC holds `urdf`, `srdf` (or null), `package_dir`, `joints` (the moving
joints, in the order of a configuration's values; every other joint sits at
0), `base` (the link whose frame the obstacles are given in, or null for
the root), `floor` (z of the floor in that frame, or null), `boxes`
([cx, cy, cz, sx, sy, sz] each), `resolution` (metres) and `moves`
([[qa, qb], ...]). Each move's verdict in OUT: `collides`, `at` (s of the
first check in contact), `pair` (the two geometries, or a geometry and
`box K` / `floor`), `checks`, `least_distance` (the least Coal distance
taken) and `resolution_s` (the step in s that moves the fastest point
`resolution` metres).

Pairs are built as activecal builds them: every pair of collision
geometries (Pinocchio's `buildModelsFromUrdf`, meshes as Coal BVH triangle
surfaces), less the SRDF's `disable_collisions`, less geometries on the same
joint or on two joints joined by one joint; every obstacle against every
geometry not welded to the base link. The floor is a 20 m x 20 m x 10 m box
whose top face is at `floor` (the half-space as far as an arm reaches).

Each move q(s) = qa + s (qb - qa), s in [0, 1], is checked by conservative
advancement on Coal's distances, independently of activecal's check (no
convex hulls; Coal's own BVH distances of the meshes): a
point of geometry g moves, per unit of s, at most sum_j |dq_j| R_jg
relative to any body above joint j, where R_jg bounds the distance from
joint j's origin to any point of g whatever the configuration (the sum of
the joint offsets from j down to g's joint, g's offset and its local
bounding box's half-diagonal: the triangle inequality). Two geometries whose
deepest common body is c approach each other at most at the sum of those
rates over the joints between c and each of them (an obstacle is fixed to
the base). The next step is the least over the pairs of distance / rate,
so no pair can meet between checks (a pair's last distance less what the
steps since can have closed bounds it until it could limit the step), but
never less than `resolution`
metres of the fastest point's motion: near contact, the move is checked at
that resolution. A check whose least distance is at most 0, or where
`computeCollisions` finds a contact, is a collision. Revolute joints only
(a prismatic joint would move its origin).
"""
import json
import sys

import coal
import numpy as np
import pinocchio as pin


def load(spec):
    model, gmodel = pin.buildModelsFromUrdf(
        spec["urdf"], package_dirs=[spec["package_dir"]], geometry_types=pin.GeometryType.COLLISION
    )
    base_frame = model.getFrameId(spec["base"]) if spec.get("base") else 0
    data = model.createData()
    pin.forwardKinematics(model, data, pin.neutral(model))
    pin.updateFramePlacements(model, data)
    base_pose = data.oMf[base_frame]
    base_joint = model.frames[base_frame].parentJoint
    n_links = gmodel.ngeoms
    obstacles = []
    for k, (cx, cy, cz, sx, sy, sz) in enumerate(spec.get("boxes") or []):
        obstacles.append((f"box {k + 1}", coal.Box(sx, sy, sz), pin.SE3(np.eye(3), np.array([cx, cy, cz]))))
    if spec.get("floor") is not None:
        z = spec["floor"]
        obstacles.append(("floor", coal.Box(20.0, 20.0, 10.0), pin.SE3(np.eye(3), np.array([0.0, 0.0, z - 5.0]))))
    for name, shape, placement in obstacles:
        # Fixed in the base link's frame, placed once at rest (the joints
        # above the base do not move).
        go = pin.GeometryObject(name, 0, 0, base_pose * placement, shape)
        gmodel.addGeometryObject(go)
    # Self pairs, as activecal: SRDF removed, same and adjacent joints dropped.
    for a in range(n_links):
        for b in range(a + 1, n_links):
            gmodel.addCollisionPair(pin.CollisionPair(a, b))
    if spec.get("srdf"):
        pin.removeCollisionPairs(model, gmodel, spec["srdf"])
    par = model.parents
    keep = []
    for cp in gmodel.collisionPairs:
        ja = gmodel.geometryObjects[cp.first].parentJoint
        jb = gmodel.geometryObjects[cp.second].parentJoint
        if ja == jb or par[ja] == jb or par[jb] == ja:
            continue
        keep.append((cp.first, cp.second))
    for o in range(n_links, gmodel.ngeoms):
        for g in range(n_links):
            if gmodel.geometryObjects[g].parentJoint != base_joint:
                keep.append((g, o))
    gmodel.removeAllCollisionPairs()
    for a, b in keep:
        gmodel.addCollisionPair(pin.CollisionPair(a, b))
    return model, gmodel, n_links


def ancestors(model, j):
    out = []
    while j != 0:
        out.append(j)
        j = model.parents[j]
    return out


def reach(model, gmodel, g):
    """{joint j: a bound on the distance from j's origin to any point of g}."""
    obj = gmodel.geometryObjects[g]
    geom = obj.geometry
    geom.computeLocalAABB()
    box = geom.aabb_local
    centre = obj.placement.translation + obj.placement.rotation @ np.asarray(box.center())
    half = 0.5 * np.linalg.norm(np.asarray(box.max_) - np.asarray(box.min_))
    out, below = {}, np.linalg.norm(centre) + half
    for j in ancestors(model, obj.parentJoint):
        out[j] = below
        below += np.linalg.norm(model.jointPlacements[j].translation)
    return out


def rates(model, gmodel, n_links, idx_of, dq):
    """Per pair, the most its gap can shrink per unit of s; and the fastest
    point's speed."""
    reaches = [reach(model, gmodel, g) if g < n_links else {} for g in range(gmodel.ngeoms)]

    def speed(g, joints):
        return sum(abs(dq[idx_of[j]]) * reaches[g][j] for j in joints if j in idx_of)

    anc = [set(reaches[g]) for g in range(gmodel.ngeoms)]
    pair_rates = []
    for cp in gmodel.collisionPairs:
        a, b = cp.first, cp.second
        pair_rates.append(speed(a, anc[a] - anc[b]) + speed(b, anc[b] - anc[a]))
    fastest = max(speed(g, anc[g]) for g in range(n_links))
    return np.array(pair_rates), fastest


def check_move(model, gmodel, n_links, idx_of, q_index, qa, qb, resolution):
    data, gdata = model.createData(), gmodel.createData()
    qa, qb = np.asarray(qa, dtype=float), np.asarray(qb, dtype=float)
    dq = qb - qa
    pair_rates, fastest = rates(model, gmodel, n_links, idx_of, dq)
    floor_ds = resolution / fastest if fastest > 0 else 1.0
    # A lower bound on each pair's distance, carried from step to step (the
    # last Coal distance less what the steps since can have closed): Coal
    # is asked again only for the pairs whose bound could limit the step.
    lower = np.full(len(pair_rates), -np.inf)
    s, checks, least = 0.0, 0, float("inf")
    q = pin.neutral(model)

    def allowed(bound, rate):
        if bound <= 0.0:
            return 0.0
        return bound / rate if rate > 0 else np.inf

    while True:
        q[q_index] = qa + s * dq
        checks += 1
        pin.updateGeometryPlacements(model, data, gmodel, gdata, q)
        step = np.inf
        for k in sorted(range(len(lower)), key=lambda k: allowed(lower[k], pair_rates[k])):
            cheap = allowed(lower[k], pair_rates[k])
            if cheap > 0.0 and cheap >= min(max(step, floor_ds), 1.0 - s):
                break
            d = pin.computeDistance(gmodel, gdata, k).min_distance
            least = min(least, d)
            hit = d <= 0.0 or (d < 2.0 * resolution and pin.computeCollision(gmodel, gdata, k))
            if hit:
                cp = gmodel.collisionPairs[k]
                names = [gmodel.geometryObjects[cp.first].name, gmodel.geometryObjects[cp.second].name]
                return {"collides": True, "at": s, "pair": names, "checks": checks, "least_distance": least,
                        "resolution_s": floor_ds}
            lower[k] = d
            step = min(step, allowed(d, pair_rates[k]))
        if s >= 1.0:
            return {"collides": False, "at": None, "pair": None, "checks": checks, "least_distance": least,
                    "resolution_s": floor_ds}
        ds = max(step, floor_ds)
        lower = lower - pair_rates * ds
        s = min(1.0, s + ds)


def main():
    spec_path, out = sys.argv[1:3]
    with open(spec_path) as f:
        spec = json.load(f)
    model, gmodel, n_links = load(spec)
    joint_ids = [model.getJointId(j) for j in spec["joints"]]
    for j in joint_ids:
        if model.joints[j].nq != 1 or "Prismatic" in model.joints[j].shortname():
            sys.exit(f"coal_moves.py: joint {model.names[j]} is not revolute")
    q_index = [model.joints[j].idx_q for j in joint_ids]
    idx_of = {j: k for k, j in enumerate(joint_ids)}
    res = spec["resolution"]
    moves = [check_move(model, gmodel, n_links, idx_of, q_index, a, b, res) for a, b in spec["moves"]]
    result = {
        "format": 1,
        "reference": f"Pinocchio {pin.__version__} + Coal {coal.__version__}: conservative advancement on "
        f"computeDistances, at most {res} m of link-point motion per step near contact",
        "pairs": len(gmodel.collisionPairs),
        "moves": moves,
    }
    with open(out, "w") as f:
        json.dump(result, f, separators=(",", ":"))


if __name__ == "__main__":
    main()
