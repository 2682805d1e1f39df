"""sphdvi measure bodies on a floating body split by a periodic boundary (audit hunt10/b2 finding 4):
the run wraps each particle into the periodic box, so a body across the end has particles at both
ends; the rigid fit first makes it whole (each particle's offset from the one nearest the centre
taken as its shortest periodic image, as DualSPHysics's FtPeriodicDist) and gives the centre in the
periodic box, as bodies.csv does (FtUpdateFloatings: center = UpdatePeriodicPos(fcenter))."""
from types import SimpleNamespace

import numpy as np
import pytest

from _tank import lattice
from sphdvi.io.casefile import write_case_h5
from sphdvi.io.vtkhdf import VTKHDFParticleWriter
from sphdvi.measure.post import measure_bodies, unwrap_rigid
from sphdvi.simulation import POINT_ARRAYS
from sphdvi.sph.periodic import Periodicity

from test_bodies import rot

DP = 0.05
# the fixed floor's particles span x in [0, 0.95]: the x period is [0, 1) (extent + dp, as DualSPHysics)
FLOOR = lattice(np.array([-0.025, 0.0, -0.55]), np.array([0.975, 0.3, -0.5]), DP, False)
BOX = lattice(np.array([0.3, 0.0, 0.0]), np.array([0.5, 0.2, 0.15]), DP, False)
C0 = BOX.mean(axis=0) + np.array([0.01, 0.0, 0.0])       # body centre need not be the particle mean
# (roll, pitch, yaw), displacement, velocity, angular velocity at t = 0, 0.1, 0.2, 0.3: at 0.1 the
# body straddles x = 1, at 0.2 its centre is past it (most particles at the low end), at 0.3 it is
# wholly past it
MOTIONS = [((0, 0, 0), (0, 0, 0), (0, 0, 0), (0, 0, 0)),
           ((3.0, -5.0, 10.0), (0.6, 0.02, 0.1), (0.5, 0.0, -0.2), (0.1, 0.2, -0.3)),
           ((-20.0, 30.0, 45.0), (0.7, -0.03, 0.05), (1.0, 0.1, 0.0), (1.0, 0.0, 0.5)),
           ((10.0, -10.0, 80.0), (0.95, 0.0, 0.0), (0.2, 0.0, 0.1), (0.0, -0.5, 0.2))]


def _run_folder(tmp_path, inc):
    """A run folder: the case (floor + box, x periodic with XPeriodicIncZ = ``inc``) and snapshots
    of the box moved by MOTIONS, every particle wrapped into the periodic box as the run keeps them."""
    pos0 = np.vstack([FLOOR, BOX])
    nf, n = FLOOR.shape[0], pos0.shape[0]
    mk = np.r_[np.full(nf, 11), np.full(n - nf, 12)].astype(np.int32)
    ptype = np.r_[np.zeros(nf), np.full(n - nf, 2)].astype(np.uint8)
    parts = {"pos": pos0, "vel": np.zeros((n, 3)), "rhop": np.full(n, 1000.0), "mass": np.full(n, 0.1),
             "type": ptype, "mk": mk, "idp": np.arange(n, dtype=np.int64)}
    nb = n - nf
    body = SimpleNamespace(mkbound=10, mk=12, begin=nf, count=nb, mass=0.1 * nb, masspart=0.1, center=C0.tolist(),
                           inertia=np.eye(3).tolist(), translation_dof=[1, 1, 1], rotation_dof=[1, 1, 1],
                           linearvelini=[0, 0, 0], angularvelini=[0, 0, 0])
    consts = {"dp": DP, "h": 1.2 * DP, "b": 1e5, "cs0": 10.0, "rhop0": 1000.0, "gamma": 7.0,
              "gravity": [0, 0, -9.81], "massfluid": 0.125, "massbound": 0.125, "is2d": False, "posy2d": 0.0}
    out = tmp_path / "run"
    out.mkdir()
    write_case_h5(str(out / "Body.h5"), casename="Body", source_file="x", source_xml="<case/>", version="t",
                  particles=parts, constants=consts,
                  parameters={"Kernel": 2, "TimeOut": 0.1, "XPeriodicIncZ": inc},
                  domain={"posmin": [-1, -1, -1], "posmax": [2, 2, 2]}, bodies=[body],
                  json_items={"mkconfig": {"fluidcount": 1}, "parameters_set": ["XPeriodicIncZ"],
                              "bodies_extra": [{"mkbound": 10, "mass": 0.1 * nb, "inertia": np.eye(3).tolist(),
                                                "center": C0.tolist(), "linearvelini": [0, 0, 0],
                                                "angularvelini": [0, 0, 0], "translation_dof": [1, 1, 1],
                                                "rotation_dof": [1, 1, 1]}]})
    per = Periodicity(["x"], pos0, DP, {"XPeriodicIncZ": inc})
    assert per.lo[0] == 0.0 and per.length[0] == pytest.approx(1.0, abs=1e-12)
    w = VTKHDFParticleWriter(str(out / "particles.vtkhdf"), POINT_ARRAYS)
    order = np.random.default_rng(0).permutation(n)                 # file order is not idp order
    split = []
    for k, (ang, disp, v, w_) in enumerate(MOTIONS):
        R = rot(*ang)
        c = C0 + np.asarray(disp)
        pos = pos0.copy()
        pos[nf:] = c + (BOX - C0) @ R.T
        vel = np.zeros((n, 3))
        vel[nf:] = np.asarray(v) + np.cross(np.asarray(w_), pos[nf:] - c)
        per.wrap(pos)
        split.append(np.ptp(pos[nf:, 0]) > 0.5)                        # particles at both ends
        w.append(0.1 * k, pos[order], {"Idp": parts["idp"][order], "Vel": vel[order], "Rhop": parts["rhop"],
                                        "Press": np.zeros(n), "Type": ptype[order], "Mk": mk[order]})
    w.close()
    assert split == [False, True, True, False]
    return out, per


@pytest.mark.parametrize("inc", [0.0, 0.1])
def test_body_across_the_periodic_end(tmp_path, inc):
    """Centre, angles and velocities of the box as it crosses x = 1, recovered to round-off (float32
    velocities in the file: 1e-6), the centre in the periodic box (past x = 1: x - 1 and z + inc, as
    the run wraps it); surge/sway/heave are that centre minus the initial one (as from bodies.csv).
    Before: the fit of the split body gave a centre near the box's middle (x 0.5 off) and wrong
    angles and angular velocities."""
    out, per = _run_folder(tmp_path, inc)
    t = measure_bodies(str(out))
    assert t.time.tolist() == pytest.approx([0.0, 0.1, 0.2, 0.3])
    for k, (ang, disp, v, w_) in enumerate(MOTIONS):
        col = lambda name: t.column(f"mkbound10_{name}")[k]  # noqa: E731
        c = C0 + np.asarray(disp)
        if c[0] >= per.length[0]:
            c += [-per.length[0], 0.0, inc]
        np.testing.assert_allclose([col("cx"), col("cy"), col("cz")], c, atol=1e-12, err_msg=f"t {0.1 * k}")
        np.testing.assert_allclose([col("surge"), col("sway"), col("heave")], c - C0, atol=1e-12)
        np.testing.assert_allclose([col("roll"), col("pitch"), col("yaw")], ang, atol=1e-9)
        np.testing.assert_allclose([col("vx"), col("vy"), col("vz")], v, atol=1e-6)
        np.testing.assert_allclose([col("wx"), col("wy"), col("wz")], w_, atol=1e-6)
        np.testing.assert_allclose([col("ffx"), col("ffy"), col("ffz")], 0.0)     # no fluid


def test_unwrap_rigid():
    """The positions made whole about the anchor (each offset a minimum image, with the increment);
    without periodicity they are returned as they are."""
    per = Periodicity(["x"], np.array([[0.0, 0, 0], [0.95, 0, 0]]), DP, {"XPeriodicIncZ": 0.1})
    whole = np.array([[0.9, 0.0, 0.0], [0.98, 0.0, 0.0], [1.05, 0.0, 0.02], [1.1, 0.1, 0.0]])
    wrapped = whole.copy()
    per.wrap(wrapped)
    assert (wrapped[:, 0] < 1.0).all() and (wrapped[2:, 2] > 0.05).all()
    np.testing.assert_allclose(unwrap_rigid(wrapped, 0, per), whole, atol=1e-15)
    np.testing.assert_allclose(unwrap_rigid(wrapped, 3, per), whole + [-1.0, 0.0, 0.1], atol=1e-15)
    assert unwrap_rigid(wrapped, 0, None) is not None and np.array_equal(unwrap_rigid(wrapped, 0, None), wrapped)
