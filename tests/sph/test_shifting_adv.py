"""Shifting 4 (advanced): free-surface detection, normals, the interior displacement
(sphdvi.sph.shifting_adv) and its wiring in the solver."""
import math

import numpy as np
import pytest

from sphdvi.sph.kernels import kernel_alpha, kernel_fac
from sphdvi.sph.solver import SPHSolver
from sphdvi.sph.state import FluidState

# these tests run Shifting 4 under Verlet on purpose (sphdvi supports it; the solver warns
# that DualSPHysics does not: tested in test_shifting_adv.py)
pytestmark = pytest.mark.filterwarnings("ignore:Shifting=4 with StepAlgorithm=1")

DP = 0.02


def block(nx, nz, ny=None, gravity=0.0, params=None, periodic=None):
    """A lattice block of fluid (2D, or 3D with ny), rho0 everywhere, no walls."""
    axes = [(np.arange(nx) + 0.5) * DP, (np.arange(ny) + 0.5) * DP if ny else np.zeros(1),
            (np.arange(nz) + 0.5) * DP]
    X, Y, Z = np.meshgrid(*axes, indexing="ij")
    pos = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    n = pos.shape[0]
    is2d = ny is None
    c0 = 20.0
    consts = {"dp": DP, "h": (math.sqrt(2) if is2d else math.sqrt(3)) * DP, "b": c0 * c0 * 1000 / 7,
              "cs0": c0, "rhop0": 1000.0, "gamma": 7.0, "gravity": [0, 0, -gravity], "is2d": is2d,
              "cflnumber": 0.2}
    p = {"Shifting": 4}
    p.update(params or {})
    mass = np.full(n, 1000.0 * DP ** (2 if is2d else 3))
    return SPHSolver(FluidState(pos, None, np.full(n, 1000.0), mass, np.full(n, 3, np.int8)), consts, p,
                     periodic=periodic)


def test_block_surface_near_surface_and_interior_2d():
    sol = block(30, 20)
    sol.compute_rates()
    t = sol.fstype.reshape(30, 20)
    edge = np.zeros((30, 20), bool)
    edge[0, :] = edge[-1, :] = edge[:, 0] = edge[:, -1] = True
    corner = np.zeros_like(edge)
    corner[[0, 0, -1, -1], [0, -1, 0, -1]] = True
    assert np.all(t[edge & ~corner] == 2)
    assert np.all(t[corner] == 3)                 # few neighbours, lambda < 1.1: isolated
    assert np.all(t[3:-3, 3:-3] == 0)             # farther than 2h (2.83 dp) from the surface
    ring = ~edge & (t != 0)
    assert np.all(t[ring] == 1) and ring.sum() == (28 * 18 - 24 * 14)
    n = sol.fsnormal.reshape(30, 20, 3)
    np.testing.assert_allclose(n[15, -1], [0, 0, 1], atol=1e-9)
    np.testing.assert_allclose(n[0, 10], [-1, 0, 0], atol=1e-9)
    np.testing.assert_allclose(n[15, 0], [0, 0, -1], atol=1e-9)
    assert np.abs(sol.shiftpos).max() < 1e-15    # a perfect lattice is not shifted


def test_block_faces_and_normals_3d():
    sol = block(10, 10, ny=10)
    sol.compute_rates()
    t = sol.fstype.reshape(10, 10, 10)
    n = sol.fsnormal.reshape(10, 10, 10, 3)
    assert t[5, 5, 9] == 2 and t[5, 5, 0] == 2 and t[0, 5, 5] == 2 and t[5, 9, 5] == 2
    np.testing.assert_allclose(n[5, 5, 9], [0, 0, 1], atol=1e-9)
    np.testing.assert_allclose(n[5, 9, 5], [0, 1, 0], atol=1e-9)
    np.testing.assert_allclose(n[0, 5, 5], [-1, 0, 0], atol=1e-9)
    assert np.all(t[4:6, 4:6, 4:6] == 0)        # 4 dp from every face, beyond 2h = 3.46 dp


def test_periodic_block_has_no_side_surface():
    """Periodic in x: the side columns see their neighbours across the boundary."""
    sol = block(30, 20, periodic=["x"])
    sol.compute_rates()
    t = sol.fstype.reshape(30, 20)
    assert np.all(t[:, -1] == 2) and np.all(t[:, 0] == 2)
    assert np.all(t[:, 3:-3] == 0)


def test_interior_particle_moves_away_from_crowding():
    """delta r = A h^2 grad C (A = ShiftAdvCoef < 0) against grad C summed here; capped at 0.1 dp."""
    sol = block(30, 20)
    s = sol.state
    i = 15 * 20 + 10
    s.pos[i, 0] += 0.2 * DP                     # towards its right-hand neighbour
    sol.compute_rates()
    h = sol.h
    alpha = kernel_alpha(2, h, True)
    d = s.pos[i] - s.pos
    r = np.linalg.norm(d, axis=1)
    sel = (r > 0) & (r < 2 * h)
    fac = np.array([kernel_fac(2, q, alpha / (h * h)) for q in r[sel] / h])
    grad_c = ((s.mass[sel] / s.rhop[sel] * fac)[:, None] * d[sel]).sum(axis=0)
    expect = np.clip(-0.01 * h * h * grad_c, -0.1 * DP, 0.1 * DP)
    assert sol.fstype[i] == 0
    assert sol.shiftpos[i, 0] < 0.0             # away from the crowded side
    np.testing.assert_allclose(sol.shiftpos[i], expect, rtol=1e-9, atol=1e-18)
    # a much larger coefficient hits the 0.1 dp cap
    sol2 = block(30, 20, params={"ShiftAdvCoef": -50.0})
    sol2.state.pos[i, 0] += 0.2 * DP
    sol2.compute_rates()
    assert sol2.shiftpos[i, 0] == pytest.approx(-0.1 * DP)


@pytest.mark.parametrize("algo", [1, 2])
def test_settling_block_keeps_its_surface_unshifted(algo):
    """Under gravity on a DBC floor: finite, nothing excluded, surface particles never shifted,
    the interior ones are (by up to 0.1 dp a step)."""
    nx, nz = 30, 20
    sol = block(nx, nz, gravity=9.81, params={"StepAlgorithm": algo, "DensityDT": 2})
    s = sol.state
    floor = np.column_stack([(np.arange(-3, nx + 3) + 0.5) * DP, np.zeros(nx + 6), np.full(nx + 6, -0.5 * DP)])
    n = s.n
    sol2 = SPHSolver(FluidState(np.vstack([s.pos, floor, floor - [0, 0, DP]]), None,
                                np.full(n + 2 * floor.shape[0], 1000.0), np.full(n + 2 * floor.shape[0], 0.4),
                                np.concatenate([s.ptype, np.zeros(2 * floor.shape[0], np.int8)])),
                     {"dp": DP, "h": math.sqrt(2) * DP, "b": sol.b, "cs0": sol.cs0, "rhop0": 1000.0,
                      "gamma": 7.0, "gravity": [0, 0, -9.81], "is2d": True, "cflnumber": 0.2},
                     {"Shifting": 4, "StepAlgorithm": algo, "DensityDT": 2})
    moved = 0
    for _ in range(150):
        sol2.step()
        f = sol2.state.ptype == 3
        surf = f & (sol2.fstype == 2)
        assert np.all(sol2.shiftpos[surf] == 0.0)
        assert np.all(np.abs(sol2.shiftpos) <= 0.1 * DP + 1e-15)
        moved += np.count_nonzero(np.abs(sol2.shiftpos[f & (sol2.fstype == 0)]).sum(axis=1) > 0)
    assert np.isfinite(sol2.state.pos).all()
    assert np.count_nonzero(sol2.state.ptype == 3) == n
    assert moved > 0



def test_shifting_4_with_verlet_is_warned_as_without_dualsphysics_counterpart():
    """DualSPHysics v5.4 refuses Shifting 4 under Verlet (JSph: 'Advanced shifting is not
    allowed with Verlet'); sphdvi runs it and says so.  Symplectic is not warned."""
    with pytest.warns(UserWarning, match="Advanced shifting is not allowed with Verlet"):
        block(4, 4, params={"StepAlgorithm": 1})
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        block(4, 4, params={"StepAlgorithm": 2})
