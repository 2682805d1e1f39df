"""mDBC with periodic boundaries: the periodic copies of the wall particles carry their
real particle's correction (DualSPHysics wraps the ghost node into the domain,
UpdatePeriodicPos in InteractionMdbcCorrectionT2 / InteractionMdbc2CorrectionT2)."""
import numpy as np
import pytest

from sphdvi.sph import SPHSolver, mdbc
from sphdvi.sph.scenes import constants_2d, lattice_2d
from sphdvi.sph.state import FluidState

DP = 0.01
L = 0.12


def _channel(shift_cells=0):
    """x-periodic channel, 3 wall layers, disturbed hydrostatic water 0.1 m deep; the
    whole scene moved by ``shift_cells`` dp along x (wrapped)."""
    fl = lattice_2d(0.0, L - DP, DP, 0.1, DP)
    bd = np.concatenate([lattice_2d(0.0, L - DP, -k * DP, -k * DP, DP) for k in range(3)])
    c = constants_2d(DP, hswl=0.1)
    pos = np.concatenate([bd, fl])
    n, nb = len(pos), len(bd)
    ptype = np.full(n, 3, np.int8)
    ptype[:nb] = 0
    f = ptype == 3
    rng = np.random.default_rng(3)
    pos[f, 0] += 0.2 * DP * rng.uniform(-1, 1, f.sum())
    pos[f, 2] += 0.2 * DP * rng.uniform(-1, 1, f.sum())
    top = 0.1 + 0.5 * DP
    rho = np.full(n, c["rhop0"])
    rho[f] = c["rhop0"] * (1 + c["rhop0"] * 9.81 * (top - pos[f, 2]) / c["b"]) ** (1 / c["gamma"])
    rho[f] *= 1 + 0.003 * rng.uniform(-1, 1, f.sum())
    vel = np.zeros((n, 3))
    vel[f, 0] = rng.uniform(-0.1, 0.1, f.sum())
    pos[:, 0] = np.mod(pos[:, 0] + shift_cells * DP, L)
    mass = np.where(f, c["massfluid"], c["massbound"])
    st = FluidState(pos, vel=vel, rhop=rho, mass=mass, ptype=ptype,
                    mk=np.where(f, 1, 11).astype(np.int32))
    normals = np.zeros((n, 3))
    normals[:nb, 2] = 0.5 * DP - pos[:nb, 2]
    return st, c, normals


def _solver(slip, shift_cells=0):
    st, c, normals = _channel(shift_cells)
    sol = SPHSolver(st, c, {"Boundary": 2, "SlipMode": slip, "MdbcGhostVelocity": 0,
                            "XPeriodicIncZ": 0.0}, normals=normals, periodic=["x"])
    per = sol.periodicity           # the period is [0, L) whatever the disturbed fluid's extent
    per.lo[0], per.length[0], per.shift[0, 0] = 0.0, L, L
    return sol


@pytest.mark.parametrize("slip", [1, 2])
def test_periodic_wall_copies_equal_their_sources(monkeypatch, slip):
    """Packed density/pressure/mass/1/rho (and mDBC2 tangential velocity) of every wall
    copy equal its real particle's after the correction."""
    seen = {}
    real = mdbc.mdbc_serial

    def spy(kern, is2d, nb, ptype, *rest):
        real(kern, is2d, nb, ptype, *rest)
        seen["nb"], seen["ptype"], seen["tvel"] = nb, ptype, rest[-2]

    monkeypatch.setattr(mdbc, "mdbc_serial", spy)
    monkeypatch.setattr(mdbc, "mdbc_parallel", spy)
    sol = _solver(slip)
    sol.compute_rates()
    nb, pe = seen["nb"], seen["ptype"]
    pos, s = sol.state.pos, sol.state
    wall = np.flatnonzero(s.ptype != 3)
    copies = np.flatnonzero((pe != 3) & ((nb[:, 0] < -1e-9) | (nb[:, 0] > L - DP + 1e-9)))
    assert len(copies) >= 12
    for r in copies:
        i = wall[np.argmin(np.abs(pos[wall, 0] - nb[r, 0] % L) + np.abs(pos[wall, 2] - nb[r, 1]))]
        src = np.flatnonzero((np.abs(nb[:, 0] - pos[i, 0]) < 1e-9) & (np.abs(nb[:, 1] - pos[i, 2]) < 1e-9))
        assert len(src) == 1
        np.testing.assert_allclose(nb[r, 4:8], nb[src[0], 4:8], rtol=1e-13, atol=0.0)
        np.testing.assert_allclose(nb[r, 4], s.rhop[i], rtol=1e-13)
        if slip > 1:
            np.testing.assert_allclose(seen["tvel"][r], seen["tvel"][src[0]], rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("slip", [1, 2])
def test_periodic_mdbc_is_translation_invariant(slip):
    """Moving the whole periodic scene along x by a few dp leaves every particle's density
    rate, acceleration and wall density as they were: the fluid next to the periodic end
    sees the same wall as elsewhere."""
    a = _solver(slip)
    a.compute_rates()
    b = _solver(slip, shift_cells=5)
    b.compute_rates()
    np.testing.assert_allclose(b.state.rhop, a.state.rhop, rtol=1e-12)
    f = a.state.ptype == 3
    scale = np.abs(a.ar[f]).max()
    np.testing.assert_allclose(b.ar[f], a.ar[f], rtol=0, atol=1e-8 * scale)
    np.testing.assert_allclose(b.ace[f], a.ace[f], rtol=0, atol=1e-8 * np.abs(a.ace[f]).max())


def test_periodic_mdbc2_sets_floating_densities():
    """SlipMode 2 with periodic boundaries: the floating particles with a normal get their
    mDBC density in the state, as without periodic boundaries (the same as a wall particle
    in their place)."""
    walls = _solver(2)
    walls.compute_rates()
    sol = _solver(2)
    s = sol.state
    top = np.flatnonzero((s.ptype == 0) & (np.abs(s.pos[:, 2]) < 1e-9) & (s.pos[:, 0] > 0.04) & (s.pos[:, 0] < 0.08))
    s.ptype[top] = 2
    sol.compute_rates()
    assert np.all(np.abs(walls.state.rhop[top] - 1000.0) > 0.1)
    np.testing.assert_allclose(s.rhop[top], walls.state.rhop[top], rtol=1e-12)
