"""Robot, Pool, Design and Calibration pickle (by the call that made
them, made again on loading): the copy gives the same poses, ids and
estimates, through pickle and through a multiprocessing worker."""

import multiprocessing
import pickle

import numpy as np
import activecal
from conftest import UR5_URDF


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
