"""Pinocchio and MuJoCo side of activecal's verify crate.

Loaded by verify/src/bridge.rs with PyModule::from_code into an interpreter
embedded by pyo3. That interpreter is not in venv mode, so `init` first makes
the project venv's site-packages importable (see shared/notes/python-bridge.md):
site.addsitedir (which runs the .pth files Pinocchio relies on), those entries
moved to the front of sys.path, sys.executable set to the venv's python, and
MUJOCO_GL=disable (importing mujoco pulls in glfw, which spawns sys.executable).

Every evaluation takes a list of joint configurations and returns, per
configuration, the end point position [x, y, z] and the 3 x dof positional
joint Jacobian flattened row-major (d position_r / d q_j at r * dof + j), both
in the measurement (world) frame.
"""

import os
import platform
import site
import sys

pin = None
mujoco = None
np = None


def init(site_packages, python_exe):
    """Makes the venv importable, imports the libraries, returns their versions."""
    global pin, mujoco, np
    if pin is None:
        os.environ["MUJOCO_GL"] = "disable"
        before = list(sys.path)
        site.addsitedir(site_packages)
        added = [p for p in sys.path if p not in before]
        sys.path[:] = added + before
        sys.executable = python_exe
        import numpy as _np
        import pinocchio as _pin
        import mujoco as _mujoco

        np, pin, mujoco = _np, _pin, _mujoco
    return {
        "python": platform.python_version(),
        "numpy": np.__version__,
        "pinocchio": pin.__version__,
        "mujoco": mujoco.__version__,
    }


# Joint models by activecal's joint kind (built on use: pin is imported by init).
JOINT_MODELS = {
    "revolute": lambda: pin.JointModelRZ(),
    "prismatic": lambda: pin.JointModelPZ(),
}


def pinocchio_model(placements, kinds, tool):
    """A Pinocchio model: after each fixed placement (R as a row-major 3x3
    list, t as a 3-list) a joint about ("revolute") or along ("prismatic") its
    z axis, and an operational frame "ee" at `tool` on the last joint."""
    model = pin.Model()
    parent = 0  # the universe: activecal's measurement frame
    for k, ((rot, trans), kind) in enumerate(zip(placements, kinds)):
        placement = pin.SE3(np.array(rot, dtype=float), np.array(trans, dtype=float))
        parent = model.addJoint(parent, JOINT_MODELS[kind](), placement, "q%d" % (k + 1))
    rot, trans = tool
    ee = pin.SE3(np.array(rot, dtype=float), np.array(trans, dtype=float))
    model.addFrame(pin.Frame("ee", parent, ee, pin.FrameType.OP_FRAME))
    return model


def pinocchio_eval(placements, kinds, tool, qs):
    """End point positions and joint Jacobians from Pinocchio: forwardKinematics +
    updateFramePlacements for the position, computeFrameJacobian in
    LOCAL_WORLD_ALIGNED (origin at the frame, axes of the world) for the
    Jacobian, whose top 3 rows are d position / d q."""
    model = pinocchio_model(placements, kinds, tool)
    data = model.createData()
    fid = model.getFrameId("ee")
    positions, jacobians = [], []
    for q in qs:
        q = np.array(q, dtype=float)
        pin.forwardKinematics(model, data, q)
        pin.updateFramePlacements(model, data)
        positions.append(data.oMf[fid].translation.tolist())
        jac = pin.computeFrameJacobian(model, data, q, fid, pin.LOCAL_WORLD_ALIGNED)
        jacobians.append(jac[:3, :].reshape(-1).tolist())
    return positions, jacobians


def mujoco_eval(mjcf, qs):
    """End point positions and joint Jacobians from MuJoCo: site_xpos after
    mj_kinematics, and mj_jacSite after mj_comPos (mj_jacSite needs the
    com-based quantities; after mj_kinematics alone it is wrong)."""
    model = mujoco.MjModel.from_xml_string(mjcf)
    data = mujoco.MjData(model)
    sid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "ee")
    if sid < 0:
        raise ValueError("the MJCF has no site named 'ee'")
    if model.nq != model.nv:
        raise ValueError("expected hinge and slide joints only (nq == nv)")
    # Map activecal's joint k to MuJoCo's qpos and dof addresses through the
    # joint names "q1".."qn" rather than assuming MuJoCo's ordering.
    jids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "q%d" % (k + 1))
            for k in range(model.njnt)]
    if min(jids) < 0:
        raise ValueError("the MJCF's joints must be named q1..qn")
    qadr = [int(model.jnt_qposadr[j]) for j in jids]
    vadr = [int(model.jnt_dofadr[j]) for j in jids]
    jacp = np.zeros((3, model.nv))
    positions, jacobians = [], []
    for q in qs:
        data.qpos[qadr] = q
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        positions.append(data.site_xpos[sid].tolist())
        mujoco.mj_jacSite(model, data, jacp, None, sid)
        jacobians.append(jacp[:, vadr].reshape(-1).tolist())
    return positions, jacobians


def urdf_leaf_link(path):
    """The URDF's one leaf link (a child of some joint, parent of none), read
    with the standard library's XML parser, independently of activecal."""
    import xml.etree.ElementTree as ET

    root = ET.parse(path).getroot()
    parents = {j.find("parent").get("link") for j in root.iter("joint")}
    children = [j.find("child").get("link") for j in root.iter("joint")]
    leaves = [c for c in children if c not in parents]
    if len(leaves) != 1:
        raise ValueError("%s: expected one leaf link, found %s" % (path, leaves))
    return leaves[0]


def pinocchio_urdf_eval(path, qs):
    """Pinocchio loading a URDF file itself (buildModelFromUrdf): the leaf
    link's placement in the root frame at each joint vector (actuated joints
    in chain order; a continuous joint's q enters as (cos q, sin q)).
    Returns the leaf's name and, per q, (rotation row-major 3x3, position)."""
    model = pin.buildModelFromUrdf(path)
    data = model.createData()
    tip = urdf_leaf_link(path)
    fid = model.getFrameId(tip)
    if fid >= len(model.frames):
        raise ValueError("Pinocchio has no frame for link %s" % tip)
    joints = list(model.joints)[1:]
    out = []
    for q in qs:
        if len(q) != len(joints):
            raise ValueError("%d joint values for %d joints" % (len(q), len(joints)))
        x = np.zeros(model.nq)
        for j, v in zip(joints, q):
            if j.nq == 1:
                x[j.idx_q] = v
            elif j.nq == 2:
                x[j.idx_q] = np.cos(v)
                x[j.idx_q + 1] = np.sin(v)
            else:
                raise ValueError("unsupported joint with nq = %d" % j.nq)
        pin.forwardKinematics(model, data, x)
        pin.updateFramePlacements(model, data)
        m = data.oMf[fid]
        out.append((m.rotation.tolist(), m.translation.tolist()))
    return tip, out


# --- URDF chains of example-robot-data (verify/src/erd_fk.rs).


def erd_location():
    """The installed example-robot-data's version and robots/ directory (the
    wheel installs its data under cmeel.prefix/share/, no Python module)."""
    from importlib import metadata

    dist = metadata.distribution("example-robot-data")
    robots = dist.locate_file("cmeel.prefix/share/example-robot-data/robots")
    if not os.path.isdir(str(robots)):
        raise ValueError("example-robot-data %s has no %s" % (dist.version, robots))
    return dist.version, str(robots)


_URDF_MODELS = {}


def _urdf_model(path):
    """buildModelFromUrdf(path), once per file."""
    model = _URDF_MODELS.get(path)
    if model is None:
        model = pin.buildModelFromUrdf(path)
        _URDF_MODELS[path] = model
    return model


def _body_frame(model, link):
    if not model.existFrame(link, pin.FrameType.BODY):
        raise ValueError("Pinocchio's model has no link %s" % link)
    return model.getFrameId(link, pin.FrameType.BODY)


def _chain_joints(model, base, tip):
    """The joint ids from the base link (None: the root, Pinocchio's universe)
    down to the tip link, in order; an error if the tip is not below the base."""
    stop = model.frames[_body_frame(model, base)].parentJoint if base is not None else 0
    j = model.frames[_body_frame(model, tip)].parentJoint
    path = []
    while j != stop:
        if j == 0:
            raise ValueError("the link %s is not below %s" % (tip, base))
        path.append(j)
        j = model.parents[j]
    return path[::-1]


def urdf_chain(path, base, tip):
    """The moving joints of Pinocchio's model of a URDF from the link `base`
    (None: the root) to the link `tip`, in order: (name, nq, limits), limits
    (lower, upper) for nq == 1 and None for a continuous joint (nq == 2,
    stored as cos, sin)."""
    model = _urdf_model(path)
    out = []
    for j in _chain_joints(model, base, tip):
        joint = model.joints[j]
        if joint.nq == 1:
            limits = (float(model.lowerPositionLimit[joint.idx_q]),
                      float(model.upperPositionLimit[joint.idx_q]))
        elif joint.nq == 2:
            limits = None
        else:
            raise ValueError("joint %s has nq = %d" % (model.names[j], joint.nq))
        out.append((model.names[j], joint.nq, limits))
    return out


def urdf_relative_poses(path, base, tip, names, qs):
    """The tip link's placement in the base link's frame (base None: the
    root's), oMf(base)^-1 * oMf(tip) after framesForwardKinematics, at each
    joint vector: qs[k][i] is the value of the joint names[i] (a continuous
    joint's angle enters as cos, sin), every other joint at neutral.
    Returns, per vector, (rotation row-major 3x3, position)."""
    model = _urdf_model(path)
    data = model.createData()
    tf = _body_frame(model, tip)
    bf = _body_frame(model, base) if base is not None else None
    joints = []
    for n in names:
        if not model.existJointName(n):
            raise ValueError("Pinocchio's model has no joint %s" % n)
        joints.append(model.joints[model.getJointId(n)])
    out = []
    for q in qs:
        if len(q) != len(joints):
            raise ValueError("%d values for %d joints" % (len(q), len(joints)))
        x = pin.neutral(model)
        for joint, v in zip(joints, q):
            if joint.nq == 1:
                x[joint.idx_q] = v
            elif joint.nq == 2:
                x[joint.idx_q] = np.cos(v)
                x[joint.idx_q + 1] = np.sin(v)
            else:
                raise ValueError("unsupported joint with nq = %d" % joint.nq)
        pin.framesForwardKinematics(model, data, x)
        m = data.oMf[tf] if bf is None else data.oMf[bf].actInv(data.oMf[tf])
        out.append((m.rotation.tolist(), m.translation.tolist()))
    return out


def urdf_gravity(path, names, qs):
    """Pinocchio's generalized gravity of the URDF at `path` (fixed base,
    buildModelFromUrdf): computeGeneralizedGravity at each joint vector,
    qs[k][i] the value of the joint names[i] (a continuous joint's angle
    enters as cos, sin), every other joint at neutral. Returns, per vector,
    the torques of the joints `names` (their idx_v entries)."""
    model = _urdf_model(path)
    data = model.createData()
    joints = []
    for n in names:
        if not model.existJointName(n):
            raise ValueError("Pinocchio's model has no joint %s" % n)
        joints.append(model.joints[model.getJointId(n)])
    out = []
    for q in qs:
        if len(q) != len(joints):
            raise ValueError("%d values for %d joints" % (len(q), len(joints)))
        x = pin.neutral(model)
        for joint, v in zip(joints, q):
            if joint.nq == 1:
                x[joint.idx_q] = v
            elif joint.nq == 2:
                x[joint.idx_q] = np.cos(v)
                x[joint.idx_q + 1] = np.sin(v)
            else:
                raise ValueError("unsupported joint with nq = %d" % joint.nq)
        g = pin.computeGeneralizedGravity(model, data, x)
        out.append([float(g[joint.idx_v]) for joint in joints])
    return out


def pinocchio_end_frames(model, qs):
    """The "ee" frame's placement (rotation 3x3, translation 3) at each q."""
    data = model.createData()
    fid = model.getFrameId("ee")
    out = []
    for q in qs:
        pin.forwardKinematics(model, data, np.array(q, dtype=float))
        pin.updateFramePlacements(model, data)
        m = data.oMf[fid]
        out.append((m.rotation.copy(), m.translation.copy()))
    return out


def pinocchio_central_differences(pairs, kinds, qs, h):
    """Central differences of the end frame over model parameters.

    `pairs[c]` holds the models of parameter c at theta + h and theta - h, each
    as (placements, tool) in the form of `pinocchio_model`. Per configuration
    and parameter, 6 numbers: the position rows (p(+h) - p(-h)) / 2h and the
    orientation rows pin.log3(R(+h) R(-h)^T) / 2h, an angular velocity in the
    world (measurement) frame. Returns a list over q of lists over c."""
    n = len(qs)
    out = np.zeros((n, len(pairs), 6))
    for c, ((pl_p, tool_p), (pl_m, tool_m)) in enumerate(pairs):
        plus = pinocchio_end_frames(pinocchio_model(pl_p, kinds, tool_p), qs)
        minus = pinocchio_end_frames(pinocchio_model(pl_m, kinds, tool_m), qs)
        for k, ((rp, tp), (rm, tm)) in enumerate(zip(plus, minus)):
            out[k, c, :3] = (tp - tm) / (2.0 * h)
            out[k, c, 3:] = pin.log3(rp @ rm.T) / (2.0 * h)
    return out.tolist()


# --- The relaxation (R) of activecal's bound, solved and certified from outside.
#
#   maximise ln det M(w),  M(w) = sum_i w_i X_i^T X_i,  0 <= w_i <= 1,  sum w = N
#
# X is the stacked Jacobian (m poses of t rows, p columns). Both functions scale
# the columns to a common size first, X~ = X S^-1 with s_j = |X[:, j]| / sqrt(m):
# ln det M(w) = ln det M~(w) + 2 sum_j ln s_j exactly, and the variances d_i are
# unchanged, so the scaling only helps conditioning (the PUMA's columns differ
# by the 20 m tracker distance).


def _scaled(x, t, p):
    X = np.array(x, dtype=float).reshape(-1, p)
    if X.shape[0] % t:
        raise ValueError("%d rows are not a multiple of t = %d" % (X.shape[0], t))
    m = X.shape[0] // t
    s = np.linalg.norm(X, axis=0) / np.sqrt(m)
    return X / s, m, 2.0 * np.sum(np.log(s))


def relaxation_cvxpy(x, t, p, n_design, solver, eps):
    """Solves (R) with cvxpy's log_det and the named solver ("CLARABEL" or
    "SCS") at tolerance eps. Returns (status, ln det objective unscaled,
    weights clipped to [0, 1], solve seconds as cvxpy reports them, wall
    seconds including cvxpy's compilation)."""
    import time

    import cvxpy as cp

    Xs, m, ln_scale = _scaled(x, t, p)
    B = Xs.reshape(m, t, p)
    G = np.einsum("itp,itq->ipq", B, B).reshape(m, p * p)
    w = cp.Variable(m)
    M = cp.reshape(G.T @ w, (p, p), order="C")
    M = (M + M.T) / 2
    prob = cp.Problem(cp.Maximize(cp.log_det(M)), [w >= 0, w <= 1, cp.sum(w) == n_design])
    start = time.perf_counter()
    if solver == "CLARABEL":
        prob.solve(solver=cp.CLARABEL, tol_gap_abs=eps, tol_gap_rel=eps, tol_feas=eps,
                   max_iter=500)
    elif solver == "SCS":
        prob.solve(solver=cp.SCS, eps_abs=eps, eps_rel=eps, max_iters=200000)
    else:
        raise ValueError("unknown solver %s" % solver)
    wall = time.perf_counter() - start
    solve_time = prob.solver_stats.solve_time
    value = prob.value + ln_scale if prob.value is not None else float("nan")
    wv = np.clip(np.asarray(w.value, dtype=float), 0.0, 1.0)
    return (prob.status, float(value), wv.tolist(),
            float(solve_time if solve_time is not None else float("nan")), wall)


def relaxation_certificate(x, t, p, weights, n_design):
    """The certificate (activecal's eq. C), recomputed in numpy: with
    M = M(w), d_i = tr(X_i M^-1 X_i^T) and S_N the sum of the N largest d_i,
    every feasible w* has ln det M(w*) <= ln det M + p ln(S_N / p) (AM-GM on
    the eigenvalues of M^-1 M(w*), whose sum is sum_i w*_i d_i <= S_N).
    Returns (ln det M(w), S_N, the bound, sum of w)."""
    Xs, m, ln_scale = _scaled(x, t, p)
    w = np.asarray(weights, dtype=float)
    if w.shape != (m,):
        raise ValueError("%d weights for %d poses" % (w.size, m))
    M = Xs.T @ (np.repeat(w, t)[:, None] * Xs)
    L = np.linalg.cholesky(M)
    ln_det = 2.0 * np.sum(np.log(np.diag(L))) + ln_scale
    Y = np.linalg.solve(L, Xs.T)  # L^-1 X~^T: d_i = squared norm of pose i's columns
    d = (Y * Y).T.reshape(m, t, p).sum(axis=(1, 2))
    s_n = float(np.sort(d)[::-1][:n_design].sum())
    return float(ln_det), s_n, float(ln_det + p * np.log(s_n / p)), float(w.sum())
