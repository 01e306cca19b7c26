"""Robot, Pool, Design, Calibration, CameraCalibration and
ContactCalibration pickle (by the call that made them, made again on
loading): the copy gives the same poses, ids, estimates and reports,
through pickle and through a multiprocessing worker."""

import multiprocessing
import pickle

import numpy as np
import activecal
from conftest import FIXTURES, UR5_URDF


def ur5():
    return activecal.Robot.from_urdf(UR5_URDF, tip="tool0")


def test_round_trips_through_pickle():
    r = ur5()
    r2 = pickle.loads(pickle.dumps(r))
    assert (r2.name, r2.dof, r2.unknowns) == (r.name, r.dof, r.unknowns)
    q = np.zeros(6)
    for a, b in zip(r2.fk(q), r.fk(q)):  # (R, p)
        assert np.array_equal(a, b)
    b = activecal.Robot.builtin("puma560")
    assert pickle.loads(pickle.dumps(b)).unknowns == b.unknowns

    p = activecal.pool(r, "sobol", count=300)
    p2 = pickle.loads(pickle.dumps(p))
    assert p2.ids == p.ids and np.array_equal(p2.q, p.q)

    # A Design made from a Pool object and from an array: both replay.
    d = activecal.select(r, 30, pool=p, noise=5e-5)
    d2 = pickle.loads(pickle.dumps(d))
    assert d2.ids == d.ids and d2.ln_oid == d.ln_oid
    assert np.array_equal(d2.q, d.q)
    assert d2.predicted == d.predicted
    q_pool = p.q.copy()
    d = activecal.select(r, 30, pool=q_pool)
    blob = pickle.dumps(d)
    q_pool[:] = 0.0  # a later change to the caller's array changes no copy
    assert pickle.loads(blob).ids == d.ids

    # The nominal robot's own points, slightly perturbed: a fit that moves.
    rng = np.random.default_rng(0)
    pts = np.array([r.fk(qi)[1] for qi in d.q]) + rng.normal(0.0, 5e-5, (30, 3))
    cal = activecal.calibrate(r, d.q, pts)
    cal2 = pickle.loads(pickle.dumps(cal))
    assert np.array_equal(cal2.estimate, cal.estimate)
    assert cal2.residuals == cal.residuals


def design_ids(design):
    return design.ids, design.ln_oid


def test_a_design_crosses_to_a_multiprocessing_worker():
    r = activecal.Robot.builtin("puma560")
    d = activecal.select(r, 30, pool="lattice", levels=3)
    ctx = multiprocessing.get_context("spawn")
    with ctx.Pool(1) as workers:
        ids, ln_oid = workers.apply(design_ids, (d,))
        back = workers.apply(activecal.select, (r, 30), {"pool": "lattice", "levels": 3})
    assert (ids, ln_oid) == (d.ids, d.ln_oid)
    assert back.ids == d.ids


def test_camera_and_contact_calibrations_round_trip():
    """The camera's and the contacts' results pickle equal (estimate, σ,
    report), with their inputs given as files, dicts and DataFrames: the
    copy is the same call made again, and every fit is deterministic."""
    import csv

    import pandas as pd

    cam = FIXTURES / "camera"
    pixels = pd.read_csv(cam / "ur5_eye_to_hand.csv")
    c = activecal.calibrate_camera(
        activecal.Robot.from_urdf(FIXTURES / "ur5.urdf"), pixels, cam / "camera_info.yaml", cam / "board.yaml",
        mounting="eye-to-hand", camera_pose=[1.1761, 0.6096, 0.9079, -2.0681, 0.0317, 2.0826],
        target_pose=[-0.1047, 0.0411, 0.0301, 3.1111, -0.0192, 0.0556], outliers="keep",
    )
    blob = pickle.dumps(c)
    pixels.loc[:, "u"] = 0.0  # a later change to the caller's DataFrame changes no copy
    c2 = pickle.loads(blob)
    assert type(c2) is activecal.CameraCalibration
    assert c2.estimate == c.estimate and c2.sigma == c.sigma
    assert c2.report == c.report

    with open(FIXTURES / "mukca" / "panda_2.csv") as f:
        body = list(csv.reader(f))[1:]
    q = np.array([[float(x) for x in row[:-1]] for row in body])
    touched = [row[-1] for row in body]
    distances = {(f"{b}/0", f"{b}/1"): 0.05 for b in sorted({t.split("/")[0] for t in touched})}
    r = activecal.Robot.from_urdf(FIXTURES / "mukca" / "panda.urdf", tip="ball_link")
    k = activecal.calibrate_contacts(r, q, touched, distances, max_iterations=150)
    k2 = pickle.loads(pickle.dumps(k))
    assert type(k2) is activecal.ContactCalibration
    assert k2.estimate == k.estimate and k2.sigma == k.sigma
    assert k2.report == k.report
