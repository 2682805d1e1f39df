"""sphdvi measure points --trackmk in a run with periodic boundaries (audit hunt11/m finding 3): the run
wraps the tracked set particle by particle when it crosses a periodic end, so the rigid fit of the
split set went wrong ("--trackmk tracked motion does not unwrap bodies across periodic ends"). The set
is now made whole first (each particle at its periodic image nearest where the motion so far puts it,
Periodicity.min_image as `measure bodies` uses it) and the points are brought back into the periodic
box, where the run keeps the fluid. Without periodicity nothing changes (bitwise)."""
from dataclasses import replace

import numpy as np
import pytest

from _tank import lattice
from sphdvi.io.casefile import write_case_h5
from sphdvi.io.vtkhdf import VTKHDFParticleWriter
from sphdvi.measure.post import RunOutput, measure_points, rigid_fit, tracked_motion, tracked_points
from sphdvi.simulation import POINT_ARRAYS
from sphdvi.sph.periodic import Periodicity

from test_bodies import rot

DP = 0.05
# the floor spans x in [0, 0.95]: the x period is [0, 1) (extent + dp, as DualSPHysics)
FLOOR = lattice(np.array([-0.025, 0.0, -0.6]), np.array([0.975, 0.3, -0.55]), DP, False)
WATER = lattice(np.array([-0.025, 0.0, -0.5]), np.array([0.975, 0.3, -0.1]), DP, False)
BOX = lattice(np.array([0.3, 0.0, 0.0]), np.array([0.5, 0.3, 0.15]), DP, False)      # the moving object
C0 = BOX.mean(axis=0)
FLUID_VEL = np.array([0.5, 0.0, 0.1])
# (pitch [deg], displacement) of the box at t = 0, 0.1, ...: straddling x = 1 at 0.1 and 0.2, exactly
# half a period on at 0.3, past the end at 0.4, more than a period on at 0.5
MOTIONS = [(0.0, (0.0, 0.0, 0.0)), (3.0, (0.62, 0.0, 0.01)), (-4.0, (0.55, 0.0, -0.01)),
           (0.0, (0.5, 0.0, 0.0)), (5.0, (0.95, 0.0, 0.0)), (-2.0, (1.3, 0.0, 0.02))]
# points at the start, in the water below the box; the last one is carried past x = 1 + 2h
POINTS = np.array([[0.4, 0.15, -0.3], [0.25, 0.1, -0.2], [0.55, 0.2, -0.4], [0.7, 0.15, -0.3]])


def _run_folder(tmp_path, inc=0.0, periodic=True, motions=MOTIONS):
    """A run folder: floor (mk 11), water (mk 1, a uniform velocity) and a box moving as ``motions``
    (mk 12, mkbound 10); with ``periodic`` x is periodic (XPeriodicIncZ = ``inc``) and every particle
    is kept in the periodic box, as the run keeps them. Returns (folder, Periodicity or None)."""
    pos0 = np.vstack([WATER, FLOOR, BOX])
    nw, nf = WATER.shape[0], FLOOR.shape[0]
    n = pos0.shape[0]
    mk = np.r_[np.full(nw, 1), np.full(nf, 11), np.full(n - nw - nf, 12)].astype(np.int32)
    ptype = np.r_[np.full(nw, 3), np.zeros(nf), np.ones(n - nw - nf)].astype(np.uint8)
    parts = {"pos": pos0, "vel": np.zeros((n, 3)), "rhop": np.full(n, 1000.0), "mass": np.full(n, 0.125),
             "type": ptype, "mk": mk, "idp": np.arange(n, dtype=np.int64)}
    consts = {"dp": DP, "h": 1.2 * DP, "b": 1e5, "cs0": 10.0, "rhop0": 1000.0, "gamma": 7.0,
              "gravity": [0, 0, -9.81], "massfluid": 0.125, "massbound": 0.125, "is2d": False, "posy2d": 0.0}
    params = {"Kernel": 2, "TimeOut": 0.1}
    if periodic:
        params["XPeriodicIncZ"] = inc
    out = tmp_path / "run"
    out.mkdir()
    write_case_h5(str(out / "Box.h5"), casename="Box", source_file="x", source_xml="<case/>", version="t",
                  particles=parts, constants=consts, parameters=params,
                  domain={"posmin": [-1, -1, -1], "posmax": [3, 2, 2]}, bodies=[],
                  json_items={"mkconfig": {"fluidcount": 1},
                              "parameters_set": ["XPeriodicIncZ"] if periodic else []})
    per = Periodicity(["x"], pos0, DP, {"XPeriodicIncZ": inc}) if periodic else None
    w = VTKHDFParticleWriter(str(out / "particles.vtkhdf"), POINT_ARRAYS)
    order = np.random.default_rng(1).permutation(n)                 # file order is not idp order
    vel = np.zeros((n, 3))
    vel[:nw] = FLUID_VEL
    for k, (pitch, disp) in enumerate(motions):
        pos = pos0.copy()
        pos[nw + nf:] = C0 + np.asarray(disp) + (BOX - C0) @ rot(0.0, pitch, 0.0).T
        if per is not None:
            per.wrap(pos)
        w.append(0.1 * k, pos[order], {"Idp": parts["idp"][order], "Vel": vel[order], "Rhop": parts["rhop"],
                                        "Press": np.zeros(n), "Type": ptype[order], "Mk": mk[order]})
    w.close()
    return out, per


def _expected_points(pitch, disp, per):
    """The points carried by the box's motion, in the periodic box (x past 1: x - 1, z + inc)."""
    q = C0 + np.asarray(disp) + (POINTS - C0) @ rot(0.0, pitch, 0.0).T
    while per is not None and ((q[:, 0] < 0.0) | (q[:, 0] >= 1.0)).any():
        per.wrap(q)                                     # one period at a time, as the run
    return q


@pytest.mark.parametrize("inc", [0.0, 0.1])
@pytest.mark.parametrize("track", [([12], False), ([10], True)])
def test_tracked_points_ride_across_the_periodic_end(tmp_path, inc, track):
    """The points ride with the box to round-off at every output: while it straddles x = 1, exactly
    half a period on, past the end and more than a period on (before: the fit of the split set put
    them up to ~0.5 m off)."""
    out, per = _run_folder(tmp_path, inc)
    run = RunOutput(str(out))
    assert run.periodicity is not None and run.periodicity.length[0] == pytest.approx(1.0, abs=1e-12)
    motion = tracked_motion(run, *track)
    snaps = list(run.snapshots())
    straddles = [np.ptp(s.pos[s.mk == 12][:, 0]) > 0.5 for s in snaps]
    assert straddles == [False, True, True, False, False, False]
    for snap, (pitch, disp) in zip(snaps, MOTIONS):
        R, t = motion(snap)
        got = tracked_points(POINTS, R, t, run.periodicity)
        np.testing.assert_allclose(got, _expected_points(pitch, disp, per), rtol=0, atol=1e-12,
                                   err_msg=f"t {snap.time}")


def test_tracking_may_start_at_any_output(tmp_path):
    """The first output measured may be a late one (--first): the set is made whole about where its
    particle nearest the centroid went, whatever the travel (here while it straddles x = 1, and more
    than a period on)."""
    out, per = _run_folder(tmp_path, 0.1)
    run = RunOutput(str(out))
    for k in (1, 2, 5):
        motion = tracked_motion(run, [12])
        snap = next(run.snapshots(first=k, last=k))
        got = tracked_points(POINTS, *motion(snap), run.periodicity)
        np.testing.assert_allclose(got, _expected_points(*MOTIONS[k], per), rtol=0, atol=1e-12)


def test_measured_values_follow_the_object(tmp_path):
    """measure_points --trackmk end to end: the water's velocity at the carried points at every output
    (float32 in the file: 1e-6), the kernel sum that of points inside the water (before: the points
    carried past x = 1 + 2h, beyond the periodic copies, read empty values)."""
    out, _ = _run_folder(tmp_path)
    table, _ = measure_points(RunOutput(str(out)), POINTS, variables=["vel", "kcorr"], track=([12], False))
    assert table.time.tolist() == pytest.approx([0.1 * k for k in range(len(MOTIONS))])
    for i in range(POINTS.shape[0]):
        vel = np.stack([table.column(f"vel{c}_{i}") for c in "xyz"], axis=1)
        np.testing.assert_allclose(vel, np.tile(FLUID_VEL, (len(MOTIONS), 1)), atol=1e-6, err_msg=f"point {i}")
        assert (table.column(f"kcorr_{i}") > 0.9).all()


def test_without_periodicity_nothing_changes(tmp_path):
    """No periodic axis: the fit is the plain Kabsch fit of the positions as they are, bit for bit, and
    the points are not moved into any box (the box here moves within x < 2)."""
    motions = [(0.0, (0.0, 0.0, 0.0)), (3.0, (0.62, 0.0, 0.01)), (-2.0, (1.3, 0.0, 0.02))]
    out, per = _run_folder(tmp_path, periodic=False, motions=motions)
    run = RunOutput(str(out))
    assert run.periodicity is None and per is None
    motion = tracked_motion(run, [12])
    p = run.data["particles"]
    ref_by_idp = dict(zip(np.asarray(p["idp"]).tolist(), np.asarray(p["pos"], float)))
    for snap, (pitch, disp) in zip(run.snapshots(), motions):
        R, t = motion(snap)
        sel = (snap.mk == 12) & (snap.ptype != 3)
        R0, t0 = rigid_fit(np.array([ref_by_idp[i] for i in snap.idp[sel].tolist()]),
                           np.asarray(snap.pos[sel], float))
        assert np.array_equal(R, R0) and np.array_equal(t, t0)
        got = tracked_points(POINTS, R, t)
        assert np.array_equal(got, POINTS @ R.T + t)
        np.testing.assert_allclose(got, _expected_points(pitch, disp, None), atol=1e-6)     # float32 positions


def test_a_set_longer_than_half_a_period(tmp_path):
    """A tracked set spanning the whole periodic length (the floor of a periodic channel, sliding along
    x by up to 1.6 periods, every particle wrapped): made whole particle by particle about where the
    motion puts it, so the fit is the translation and the points ride with it (a set made whole about
    one particle would break where offsets reach half a period)."""
    out, per = _run_folder(tmp_path)
    run = RunOutput(str(out))
    p = run.data["particles"]
    floor = np.flatnonzero(np.asarray(p["mk"]) == 11)
    assert np.ptp(np.asarray(p["pos"])[floor, 0]) > 0.9                 # 0.95 of the 1 m period
    motion = tracked_motion(run, [11])
    snap0 = next(run.snapshots(first=0, last=0))
    for d in (0.0, 0.3, 0.5, 0.73, 1.6, 1.9):
        pos = np.asarray(p["pos"], float) + [d, 0.0, 0.0]
        while ((pos[:, 0] < 0.0) | (pos[:, 0] >= 1.0)).any():
            per.wrap(pos)
        snap = replace(snap0, pos=pos, idp=np.asarray(p["idp"], np.int64), ptype=np.asarray(p["type"]),
                       mk=np.asarray(p["mk"]))
        R, t = motion(snap)
        np.testing.assert_allclose(R, np.eye(3), atol=1e-12)
        got = tracked_points(POINTS, R, t, run.periodicity)
        np.testing.assert_allclose(got, _expected_points(0.0, (d, 0.0, 0.0), per), rtol=0, atol=1e-12,
                                   err_msg=f"d {d}")
