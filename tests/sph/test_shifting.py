"""Particle shifting (Lind et al. 2012, DualSPHysics form)."""
import numpy as np

from sphdvi.sph import SPHSolver
from sphdvi.sph.scenes import lattice_2d
from sphdvi.sph.state import FluidState

from _helpers import constants


def _block(dp=0.01, n=20):
    pos = lattice_2d(0.0, (n - 1) * dp, 0.0, (n - 1) * dp, dp)
    return FluidState(pos, mass=1000 * dp * dp), constants(dp, True, g=0.0)


def test_free_surface_detector_and_lattice_gradient():
    """On a regular lattice: div r ~ 2 inside (2D), < 1.5 on the free surface, and
    grad C ~ 0 inside."""
    st, c = _block()
    sol = SPHSolver(st, c, {"Shifting": 3, "ShiftTFS": 1.5})
    sol.compute_rates()
    x, z = sol.state.pos[:, 0], sol.state.pos[:, 2]
    inner = (x > 0.04) & (x < 0.15) & (z > 0.04) & (z < 0.15)
    edge = (x < 1e-9) | (z < 1e-9)
    assert np.allclose(sol.shiftdet[inner], 2.0, atol=0.03)
    assert (sol.shiftdet[edge] < 1.5).all()
    assert np.abs(sol.shiftpos[inner]).max() < 1e-8 * np.abs(sol.shiftpos).max() + 1e-9


def test_shift_moves_a_displaced_particle_back():
    """A particle pushed towards its +x neighbour is shifted towards -x."""
    st, c = _block()
    x, z = st.pos[:, 0], st.pos[:, 2]
    k = int(np.argmin((x - 0.1) ** 2 + (z - 0.1) ** 2))
    st.pos[k, 0] += 0.3 * 0.01
    st.vel[:, 0] = 0.1                      # |v| > 0 so that the shift is non-zero
    sol = SPHSolver(st, c, {"Shifting": 3, "ShiftCoef": -2.0, "ShiftTFS": 1.5,
                            "DtFixed": 1e-4})
    x0 = sol.state.pos[sol.state.idp == st.idp[k], 0][0]
    sol.step()
    m = sol.state.idp == st.idp[k]
    moved = sol.state.pos[m, 0][0] - x0 - 0.1 * 1e-4      # minus the advection
    assert moved < 0


def test_shifting_off_costs_nothing_and_changes_nothing():
    """Shifting 0 gives the same motion as a run without the keys."""
    st, c = _block()
    st.vel[:, 0] = np.linspace(0, 0.1, st.n)
    a = SPHSolver(st.copy(), c, {})
    b = SPHSolver(st.copy(), c, {"Shifting": 0, "ShiftCoef": -5.0})
    for _ in range(5):
        a.step()
        b.step()
    assert np.array_equal(a.state.pos, b.state.pos)
