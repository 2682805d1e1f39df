"""mDBC2 (SlipMode 2, 3) with moving walls: the wall acceleration (v^{n+1} − v^n)/dt of the moving
particles is found in two compiled passes over their rows, without the boolean mask and the three
indexed copies per step (audit e, finding 5), to the bit as before."""
import math
import tracemalloc

import numpy as np
import pytest

from sphdvi.sph.mdbc import keep_moving_velocity, moving_wall_ace

from test_mdbc_slip import MOVING, tank


def _swaying(solver, t, dt):
    """A hook moving the walls with a velocity that is no polynomial of t (in place)."""
    m = solver.state.ptype == MOVING
    solver.state.vel[m, 0] = 0.2 * math.sin(7.0 * t)
    solver.state.vel[m, 2] = 0.1 * math.cos(5.0 * t) + solver.state.pos[m, 0] * 1e-3


@pytest.mark.parametrize("slip", [2, 3])
@pytest.mark.parametrize("alg", [1, 2])
def test_wall_acceleration_bitwise_as_numpy(slip, alg):
    sol = tank(0.05, slip=slip, moving=True, params={"StepAlgorithm": alg})
    seen = []

    def hook(solver, t, dt):
        moving = solver.state.ptype == MOVING
        v0 = solver.state.vel[moving]
        _swaying(solver, t, dt)
        seen.append((solver.state.vel[moving] - v0) / dt)
    sol.motion_hook = hook
    for _ in range(12):
        sol.step()
        moving = sol.state.ptype == MOVING
        assert sol.wall_ace[moving].tobytes() == seen[-1].tobytes()
        assert not np.any(sol.wall_ace[~moving])


def test_wall_acceleration_allocates_nothing():
    """The wall acceleration's passes allocate nothing (the mask and copies were 4 arrays of N or
    of the moving rows per step)."""
    sol = tank(0.05, slip=2, moving=True)
    sol.motion_hook = lambda solver, t, dt: None
    sol.step()
    s = sol.state
    v0 = sol._wall_v0[:s.n]
    tracemalloc.start()
    for _ in range(10):
        keep_moving_velocity(s.ptype, s.vel, v0)
        moving_wall_ace(s.ptype, s.vel, v0, 1e-4, sol.wall_ace)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert peak < 2000, peak
