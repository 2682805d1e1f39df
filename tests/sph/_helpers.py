"""Shared builders for the SPH tests."""
import math

import numpy as np

from sphdvi.sph.state import FluidState


def jittered_block(n_side, dp, is2d, rng, jitter=0.15):
    """Fluid lattice of n_side^d particles with random displacements."""
    g = np.arange(n_side) * dp
    if is2d:
        X, Z = np.meshgrid(g, g)
        pos = np.zeros((X.size, 3))
        pos[:, 0] = X.ravel()
        pos[:, 2] = Z.ravel()
        pos[:, [0, 2]] += rng.uniform(-jitter, jitter, (X.size, 2)) * dp
    else:
        X, Y, Z = np.meshgrid(g, g, g)
        pos = np.stack([X.ravel(), Y.ravel(), Z.ravel()], 1)
        pos += rng.uniform(-jitter, jitter, pos.shape) * dp
    return pos


def constants(dp, is2d, g=0.0, cs0=10.0, coefh=1.0):
    h = coefh * math.sqrt(2.0 if is2d else 3.0) * dp
    return {"dp": dp, "h": h, "cs0": cs0, "rhop0": 1000.0, "gamma": 7.0,
            "b": cs0 ** 2 * 1000.0 / 7.0, "gravity": [0.0, 0.0, -g], "is2d": is2d,
            "cflnumber": 0.2}


def random_state(pos, dp, is2d, rng, ptype=None, vscale=0.5, drho=5.0):
    n = pos.shape[0]
    vel = rng.normal(0.0, vscale, (n, 3))
    if is2d:
        vel[:, 1] = 0.0
    rho = 1000.0 + rng.uniform(-drho, drho, n)
    vol = dp ** 2 if is2d else dp ** 3
    return FluidState(pos, vel, rho, 1000.0 * vol * rng.uniform(0.9, 1.1, n), ptype)


def assert_threaded_equals_serial(state, consts, params, steps=30):
    """Run the same scene with the serial and the threaded kernels (two numba threads; the
    light ones, cell indices, packing and integrators, threaded too) and assert bitwise equal
    step results, positions, velocities and densities."""
    import numba
    from sphdvi.sph import SPHSolver
    ser = SPHSolver(state.copy(), consts, params, parallel_threshold=10 ** 9)
    par = SPHSolver(state.copy(), consts, params, parallel_threshold=0, light_threshold=0)
    old = numba.get_num_threads()
    numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
    try:
        for _ in range(steps):
            assert ser.step() == par.step()
    finally:
        numba.set_num_threads(old)
    a, b = ser.state.sorted_by_idp(), par.state.sorted_by_idp()
    assert np.array_equal(a.pos, b.pos) and np.array_equal(a.vel, b.vel)
    assert np.array_equal(a.rhop, b.rhop)
