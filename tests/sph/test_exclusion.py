"""Exclusion helpers (masks and counts)."""
import numpy as np

from sphdvi.sph.exclusion import (count_reasons, domain_out_mask, not_finite_mask,
                                  rhop_out_mask)


def test_masks_and_counts():
    pos = np.array([[0.0, 0, 0], [2.0, 0, 0], [0.5, 0, 0.5], [0.5, 0, 0.5], [np.nan, 0, 0]])
    vel = np.zeros_like(pos)
    rhop = np.array([1000.0, 1000.0, 650.0, 1350.0, 1000.0])
    ptype = np.array([3, 3, 3, 0, 3], np.int8)
    assert rhop_out_mask(rhop, ptype, 700, 1300).tolist() == [False, False, True, False, False]
    assert domain_out_mask(pos[:4], ptype[:4], [-1, -1, -1], [1, 1, 1]).tolist() == \
        [False, True, False, False]
    assert not_finite_mask(pos, vel, rhop).tolist() == [False, False, False, False, True]
    assert count_reasons([0, 1, 2, 2, 3, 4]) == {"rhop": 1, "position": 2, "not finite": 1, "movement": 1}


# -- exclusion in the integrators (hunt6/c finding 7) ------------------------------------------
import pytest  # noqa: E402

from sphdvi.sph import SPHSolver  # noqa: E402
from sphdvi.sph.scenes import tank_2d  # noqa: E402
from sphdvi.sph.state import FluidState  # noqa: E402

from _helpers import constants  # noqa: E402


@pytest.mark.parametrize("alg", [1, 2])
def test_a_particle_moving_more_than_movlimit_in_a_step_is_excluded(alg):
    """DualSPHysics's UpdatePos: a fluid particle displaced more than MovLimit = 0.9 Scell
    (Scell = 2h, CellMode full) in one update is excluded (CODE_OUTMOV), domain or not; sphdvi
    kept it.  A lone particle at 80 m/s over DtFixed 1 ms: 0.04 m in the Symplectic predictor
    (< 1.8 h = 0.051 m), 0.08 m in the full step; one at 40 m/s stays."""
    c = constants(0.02, True, g=9.81)
    pos = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 1.0]])
    vel = np.array([[0.0, 0.0, 0.0], [80.0, 0.0, 0.0], [40.0, 0.0, 0.0]])
    st = FluidState(pos, vel, np.full(3, 1000.0), np.full(3, 0.4), np.array([0, 3, 3], np.int8))
    sol = SPHSolver(st, c, {"StepAlgorithm": alg, "DtFixed": 1e-3})
    assert sol.movlimit == pytest.approx(1.8 * c["h"])
    idp, slow = int(st.idp[1]), int(st.idp[2])
    sol.step()
    assert sol.state.n == 2 and slow in sol.state.idp
    ev = {int(k): r for e in sol.excluded for k, r in zip(e["idp"], e["reason"])}
    assert ev.get(idp) == "movement" and sol.n_excluded["movement"] >= 1
    assert idp not in sol.state.idp


def test_out_of_the_domain_is_the_reason_before_the_density():
    """UpdatePos labels a particle out of the domain and of the density window "position"
    (if(out) SetOutPos; else if(outrho) SetOutRho)."""
    st, c = tank_2d(0.4, 0.4, 0.2, 0.3, 0.02)
    i = np.flatnonzero(st.ptype == 3)[0]
    st.rhop[i] = 1400.0
    st.pos[i] = [0.2, 0.0, 0.6]
    st.vel[i] = [0.0, 0.0, 50.0]
    dom = (np.array([-0.1, -1.0, -0.1]), np.array([0.5, 1.0, 0.6005]))
    sol = SPHSolver(st, c, {"RhopOutMax": 1300.0}, domain=dom)
    sol.step()
    assert sol.excluded[0]["reason"] == ["position"] and sol.n_excluded["rhop"] == 0


def test_the_symplectic_predictor_excludes_at_the_half_step():
    """ComputeSymplecticPre checks density and position at t + dt/2 and the particle leaves
    before the corrector: a lone particle rising out of the domain is excluded where the
    predictor put it, r + dt/2 v (sphdvi found it after the corrector, at r + dt v)."""
    c = constants(0.02, True, g=9.81)
    pos = np.array([[0.0, 0.0, 0.0], [0.5, 0.0, 0.59]])
    vel = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 10.0]])
    st = FluidState(pos, vel, np.full(2, 1000.0), np.full(2, 0.4), np.array([0, 3], np.int8))
    dom = (np.array([-1.0, -1.0, -1.0]), np.array([1.0, 1.0, 0.5925]))
    sol = SPHSolver(st, c, {"StepAlgorithm": 2, "DtFixed": 1e-3}, domain=dom)
    sol.step()
    ev = sol.excluded[0]
    assert ev["reason"] == ["position"] and ev["time"] == sol.time
    assert ev["pos"][0, 2] == pytest.approx(0.59 + 0.5e-3 * 10.0, abs=1e-12)
    assert sol.state.n == 1 and np.isfinite(sol.state.pos).all()
