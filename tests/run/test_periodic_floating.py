"""A floating body across a periodic boundary: its particles are wrapped into the periodic box,
its centre is not; the moment takes the particle-to-centre distance as its shortest periodic
image (DualSPHysics's FtPeriodicDist in FtPartsSumAce / FtPartsUpdate)."""
import numpy as np
import pytest

from sphdvi.coupling import FloatingBodies
from sphdvi.motion import MotionSet
from sphdvi.sph.periodic import Periodicity

from test_coupling import _coupling, _solver, case_data  # noqa: F401 (case_data: the gencased floatingbox2d)


def _setup(data, periodicity):
    fb, sol = _coupling(data), _solver(data)
    sol.periodicity = periodicity
    sel = np.flatnonzero(sol.state.ptype == 2)
    return fb, sol, sel, fb.body_of_idp[sol.state.idp[sel]]


def _edge_through_the_body(data, inc=0.0):
    """x periodic with its high end through the body's centre (period = centre x + 0.013)."""
    p = data["particles"]
    per = Periodicity(["x"], p["pos"], 0.01, {"XPeriodicIncZ": inc})
    per.lo[0] = 0.0
    fb = FloatingBodies(data, MotionSet([], []), int(data["json"]["mkconfig"]["fluidcount"]))
    per.length[0] = per.shift[0, 0] = fb.system.pos[0][0] + 0.013
    return per


@pytest.mark.parametrize("inc", [0.0, 0.05])
def test_moment_of_a_body_split_by_the_periodic_edge(case_data, inc):
    per = _edge_through_the_body(case_data, inc)
    fb, sol, sel, body = _setup(case_data, None)
    s = sol.state
    R = fb.system.pos[0]
    alpha, a0 = np.array([0.0, 3.7, 0.0]), np.array([0.4, 0.0, -1.3])
    sol.ace[sel] = np.cross(alpha, s.pos[sel] - R) + a0
    F0, T0 = fb.loads(sol, sel, body)
    assert abs(T0[0, 1]) > 1e-3
    pw = s.pos.copy()
    per.wrap(pw)
    moved = (pw != s.pos).any(axis=1)
    assert 0 < moved[sel].sum() < sel.size          # the edge cuts the body
    fb2, sol2, sel2, body2 = _setup(case_data, per)
    sol2.state.pos[:] = pw
    sol2.ace[:] = sol.ace
    F1, T1 = fb2.loads(sol2, sel2, body2)
    np.testing.assert_allclose(F1, F0, rtol=1e-12)
    np.testing.assert_allclose(T1, T0, rtol=1e-10, atol=1e-12)


def test_carried_particles_stay_in_the_periodic_box(case_data):
    per = _edge_through_the_body(case_data)
    fb, sol, sel, body = _setup(case_data, per)
    fb.system.vel[0] = [0.2, 0.0, 0.0]
    fb.carry_particles(sol, sel, body)
    x = sol.state.pos[sel, 0]
    assert x.max() < per.length[0] and (x < 0.1).any()      # the part past the edge is at the low end
    v = sol.state.vel[sel]
    np.testing.assert_allclose(v, np.tile([0.2, 0.0, 0.0], (sel.size, 1)), atol=1e-12)
