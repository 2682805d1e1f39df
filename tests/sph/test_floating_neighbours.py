"""What a floating neighbour switches off for a fluid particle, as DualSPHysics's
InteractionForcesFluid: Molteni's DDT (DensityDT 1) next to a body no heavier than 1.2
fluid particles (DELTA_HEAVYFLOATING), and shifting with ShiftMode 1 (SHIFT_NoBound), as a
wall does.  (The rates themselves, floating-wall pairs included, are checked against a
reference in test_interaction.py.)"""
import numpy as np
import pytest

from sphdvi.sph import SPHSolver
from sphdvi.sph.scenes import lattice_2d
from sphdvi.sph.state import FluidState

from _helpers import constants

DP = 0.01


def _block_with_floating(relative_mass):
    """A 2D fluid lattice with one floating particle at its centre of ``relative_mass`` fluid
    particles, a density perturbation around it (so that the DDT is not zero) and a velocity
    field (so that the shift is not zero); the index of the floating particle."""
    pos = lattice_2d(0.0, 19 * DP, 0.0, 19 * DP, DP)
    n = pos.shape[0]
    rng = np.random.default_rng(3)
    pos[:, [0, 2]] += rng.uniform(-0.1, 0.1, (n, 2)) * DP
    k = int(np.argmin(np.sum((pos - [0.1, 0.0, 0.1]) ** 2, axis=1)))
    ptype = np.full(n, 3, np.int8)
    ptype[k] = 2
    mass = np.full(n, 1000.0 * DP * DP)
    mass[k] *= relative_mass
    rhop = 1000.0 + rng.uniform(-3.0, 3.0, n)
    vel = np.zeros((n, 3))
    vel[:, 0] = 0.1
    return FluidState(pos, vel, rhop, mass, ptype), k


def _near(state, k):
    """Fluid particles within 2h of particle k (h = sqrt(2) dp here)."""
    d = np.linalg.norm(state.pos - state.pos[k], axis=1)
    return (d < 2.0 * np.sqrt(2.0) * DP) & (state.ptype == 3)


@pytest.mark.parametrize("relative_mass,off", [(1.0, True), (1.19, True), (1.5, False)])
def test_molteni_ddt_off_next_to_a_light_floating_body(relative_mass, off):
    """DensityDT 1: a fluid particle with a floating neighbour of mass <= 1.2 m_fluid gets no
    DDT (its density rate equals the one without DDT); a heavier one enters the sum."""
    st, k = _block_with_floating(relative_mass)
    c = constants(DP, True)
    rates = {}
    for ddt in (0, 1):
        sol = SPHSolver(st.copy(), c, {"DensityDT": ddt, "DensityDTvalue": 0.1})
        sol.compute_rates()
        rates[ddt] = sol.ar.copy()
    near = _near(st, k)
    far = ~near & (st.ptype == 3)
    assert near.sum() >= 8
    diff = np.abs(rates[1] - rates[0])
    assert (diff[far] > 0).mean() > 0.9           # the DDT works away from the body
    if off:
        assert np.array_equal(rates[1][near], rates[0][near])
    else:
        assert (diff[near] > 0).all()


@pytest.mark.parametrize("mode,off", [(1, True), (2, False), (3, False)])
def test_shifting_mode_1_is_off_next_to_a_floating_body(mode, off):
    """Shifting 1 (no shifting next to boundaries) treats a floating neighbour as a boundary
    one; modes 2 (off near fixed walls only) and 3 (everywhere) keep shifting it."""
    st, k = _block_with_floating(1.0)
    sol = SPHSolver(st, constants(DP, True), {"Shifting": mode, "ShiftTFS": 0.0})
    sol.compute_rates()
    near = _near(sol.state, int(np.flatnonzero(sol.state.ptype == 2)[0]))
    shifted = np.abs(sol.shiftpos[near]).max(axis=1) > 0
    assert near.sum() >= 8
    assert (not shifted.any()) if off else shifted.all()
