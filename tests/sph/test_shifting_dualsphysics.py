"""Shifting as DualSPHysics applies it: the ShiftTFS ramp and the 0.1 dp limit of modes 1-3
(JSphShifting::RunCpu), the shifting zones (JSphShifting::InitCpu) and the moment plain
Shifting 4 is computed (JSphCpuSingle::PreLoopProcedure: Symplectic predictor, Nstep != 0)."""
import copy
import math

import numpy as np
import pytest

from sphdvi.sph import integrators as _int
from sphdvi.sph.solver import SPHSolver
from sphdvi.sph.state import FluidState

from _helpers import constants, jittered_block, random_state

DP = 0.01
H = 0.012


def _ip(dt, tfs, is2d=True):
    ip = np.zeros(17)               # ip[16] = 0: no movement limit (exclusion) here
    ip[0], ip[1], ip[2], ip[3] = dt, 1000.0, 0.0, 1e9
    ip[4] = -2.0 * H                 # ShiftCoef * h
    ip[5] = tfs
    ip[14] = 0.1 * DP
    ip[15] = (2.0 if is2d else 3.0) - tfs
    return ip


def _verlet_shift(det, gradc, vel, dt, tfs):
    """The shifting displacement one Verlet step (mode 1) gives particles with this div r,
    grad C and velocity (no acceleration; the advection v dt taken off)."""
    n = len(det)
    pos = np.zeros((n, 3))
    v = np.array(vel, float).reshape(n, 3)
    z1, z3 = np.zeros(n), np.zeros((n, 3))
    _int.verlet_serial(1, False, pos, v.copy(), np.full(n, 1000.0), v.copy(), np.full(n, 1000.0), z3.copy(), z1.copy(),
                       np.full(n, 3, np.int8), np.array(gradc, float).reshape(n, 3), np.array(det, float),
                       _ip(dt, tfs), np.zeros(n, np.int8))
    return pos - v * dt


def test_tfs_ramp_from_the_threshold_to_the_bulk():
    """umagn *= (div r - TFS)/(dim - TFS) above ShiftTFS, 0 below it; no cut with ShiftTFS 0."""
    dt, speed = 1e-4, 2.0
    det = [1.4, 1.5, 1.7, 1.9, 2.0]
    g = [[1.0, 0.0, -0.5]] * 5
    d = _verlet_shift(det, g, [[speed, 0, 0]] * 5, dt, 1.5)
    full = -2.0 * H * speed * dt * np.array(g[0])
    ramp = [0.0, 0.0, 0.4, 0.8, 1.0]
    np.testing.assert_allclose(d, np.outer(ramp, full), rtol=1e-12, atol=1e-18)
    d0 = _verlet_shift(det, g, [[speed, 0, 0]] * 5, dt, 0.0)
    np.testing.assert_allclose(d0, np.outer(np.ones(5), full), rtol=1e-12)


def test_each_component_is_limited_to_a_tenth_of_dp_both_ways():
    d = _verlet_shift([2.0, 2.0], [[50.0, 0.0, -50.0], [0.5, 0.0, -50.0]], [[2.0, 0, 0]] * 2, 5e-3, 0.0)
    np.testing.assert_allclose(d[0], [-0.1 * DP, 0.0, 0.1 * DP], rtol=1e-12)
    assert d[1, 0] == pytest.approx(-2.0 * H * 2.0 * 5e-3 * 0.5)        # under the limit: unchanged
    assert d[1, 2] == pytest.approx(0.1 * DP)


# --------------------------------------------------------------------------- zones
def _zone_solver(zones, mode=3):
    rng = np.random.default_rng(4)
    pos = jittered_block(16, DP, True, rng, jitter=0.2)
    s = random_state(pos, DP, True, rng)
    return SPHSolver(s, constants(DP, True), {"Shifting": mode}, shift_zones=zones)


def _box(p0, size):
    return {"posref": list(p0), "vecs": np.diag(size).tolist()}


def test_particles_outside_every_zone_are_not_shifted():
    ref = _zone_solver(None)
    ref.compute_rates()
    assert np.abs(ref.shiftpos).max() > 0
    far = _zone_solver([_box((5, -1, 5), (1, 2, 1))])
    far.compute_rates()
    assert not far.shiftpos.any()
    x = ref.state.pos[:, 0]
    half = _zone_solver([_box((-1, -1, -1), (1.0 + x.min() + 0.5 * np.ptp(x), 2, 3))])
    half.compute_rates()
    inside = half.state.pos[:, 0] <= x.min() + 0.5 * np.ptp(x)
    o_ref, o_half = np.argsort(ref.state.idp), np.argsort(half.state.idp)
    np.testing.assert_array_equal(half.shiftpos[o_half][inside[o_half]], ref.shiftpos[o_ref][inside[o_half]])
    assert not half.shiftpos[~inside].any() and inside.sum() > 50 and (~inside).sum() > 50


def test_oblique_zone_of_edge_vectors():
    """A zone turned 45 degrees about y: a particle is shifted where posref + a vecx + c vecz,
    0 <= a, c <= 1, reaches it."""
    c, s = math.cos(math.pi / 4), math.sin(math.pi / 4)
    side = 0.12
    zone = {"posref": [0.0, -1.0, 0.0], "vecs": [[side * c, 0, -side * s], [0, 2.0, 0], [side * s, 0, side * c]]}
    sol = _zone_solver([zone])
    sol.compute_rates()
    ref = _zone_solver(None)
    ref.compute_rates()
    p = sol.state.pos
    a = (p[:, 0] * c - p[:, 2] * s) / side
    b = (p[:, 0] * s + p[:, 2] * c) / side
    inside = (a >= 0) & (a <= 1) & (b >= 0) & (b <= 1)
    assert inside.sum() > 20 and (~inside).sum() > 20
    assert not sol.shiftpos[~inside].any()
    o, r = np.argsort(sol.state.idp), np.argsort(ref.state.idp)
    np.testing.assert_array_equal(sol.shiftpos[o][inside[o]], ref.shiftpos[r][inside[o]])


def test_zones_cost_nothing_without_classic_shifting():
    assert _zone_solver([_box((5, -1, 5), (1, 2, 1))], mode=0).shift_zones is None


# --------------------------------------------------------------------------- Shifting 4
def _adv_block(periodic=None):
    rng = np.random.default_rng(9)
    dp = 0.02
    n = 14
    pos = jittered_block(n, dp, True, rng, jitter=0.15)
    pos -= pos.min(0)
    c0 = 20.0
    consts = {"dp": dp, "h": math.sqrt(2) * dp, "b": c0 * c0 * 1000 / 7, "cs0": c0, "rhop0": 1000.0,
              "gamma": 7.0, "gravity": [0, 0, 0], "is2d": True, "cflnumber": 0.2}
    m = pos.shape[0]
    vel = np.zeros((m, 3))
    vel[:, 0] = 0.3 * np.sin(pos[:, 2] * 7.0)
    st = FluidState(pos, vel, np.full(m, 1000.0), np.full(m, 1000.0 * dp * dp), np.full(m, 3, np.int8))
    return SPHSolver(st, consts, {"Shifting": 4, "StepAlgorithm": 2}, periodic=periodic)


@pytest.mark.parametrize("periodic", [None, "x"])
def test_plain_shifting4_is_computed_in_the_predictor_from_the_positions_at_tn(periodic):
    sol = _adv_block(periodic)
    sol.step()                       # step 0: nothing shifted (DualSPHysics: Nstep != 0)
    assert not sol.shiftpos.any()
    ref = copy.deepcopy(sol)
    ref._need_shift_adv = True
    ref.compute_rates()              # the shift from the positions at t^n of step 1
    assert np.abs(ref.shiftpos).max() > 1e-6
    sol.step()
    np.testing.assert_array_equal(sol.shiftpos, ref.shiftpos)
