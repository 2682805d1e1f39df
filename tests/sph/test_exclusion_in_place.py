"""Excluding particles compacts the solver's arrays in place (audit e, finding 8): the kept rows move
down, every array becomes a view of its first rows, nothing is reallocated, and the run goes on
bitwise as when every work array was allocated anew."""
import tracemalloc

import numpy as np
import pytest

from sphdvi.sph import SPHSolver
from sphdvi.sph.scenes import tank_2d
from sphdvi.sph.state import FluidState
from sphdvi.sph.exclusion import REASON_NAMES


def _reallocating_exclude(self, t_end, carry=()):
    """The exclusion as it was: the state and aux arrays copied less the excluded rows, every work
    array allocated anew (the reference the in-place one must match bitwise)."""
    s = self.state
    codes = self.out.copy()
    bad = codes != 0
    for code, name in REASON_NAMES.items():
        self.n_excluded[name] += int(np.count_nonzero(codes == code))
    self.excluded.append({"time": t_end, "idp": s.idp[bad].copy(), "pos": s.pos[bad].copy(),
                          "vel": s.vel[bad].copy(), "rhop": s.rhop[bad].copy(),
                          "reason": [REASON_NAMES[int(c)] for c in codes[bad]]})
    keep = ~bad
    s.select(keep)
    for name in self._aux_names():
        a = getattr(self, name)
        if a.shape[0] == keep.shape[0]:
            setattr(self, name, np.ascontiguousarray(a[keep]))
    kept = {name: np.ascontiguousarray(getattr(self, name)[keep]) for name in carry
            if getattr(self, name).shape[0] == keep.shape[0]}
    self._alloc()
    for name, a in kept.items():
        setattr(self, name, a)


def _leaking_tank(seed=0):
    """A tank whose fluid particles leave the domain one after the other (fast upward ones)."""
    st, c = tank_2d(0.4, 0.4, 0.2, 0.3, 0.02)
    rng = np.random.default_rng(seed)
    top = np.flatnonzero((st.ptype == 3) & (st.pos[:, 2] > 0.25))
    pick = rng.choice(top, 12, replace=False)
    st.vel[pick, 2] = np.linspace(2.0, 6.0, pick.size)
    dom = (np.array([-0.1, -1.0, -0.1]), np.array([0.5, 1.0, 0.32]))
    return st, c, dom


PARAMS = [{"StepAlgorithm": 1}, {"StepAlgorithm": 2},
          {"StepAlgorithm": 2, "Shifting": 4, "ShiftCoef": -2.0, "ShiftTFS": 1.5},
          {"StepAlgorithm": 1, "ViscoTreatment": 2, "DensityDT": 2},
          {"StepAlgorithm": 2, "Boundary": 2, "SlipMode": 1}]


@pytest.mark.parametrize("params", PARAMS)
def test_in_place_exclusion_runs_bitwise_as_reallocation(params, monkeypatch):
    runs = []
    for ref in (False, True):
        st, c, dom = _leaking_tank()
        kw = {}
        if params.get("Boundary") == 2:
            kw["normals"] = np.where((st.ptype == 3)[:, None], 0.0, np.array([0.0, 0.0, 1.0]))
        sol = SPHSolver(st, c, params, domain=dom, **kw)
        if ref:
            monkeypatch.setattr(sol, "_exclude", _reallocating_exclude.__get__(sol))
        n0 = sol.state.n
        for _ in range(120):
            sol.step()
        assert sol.state.n < n0 - 2           # several exclusion events
        runs.append(sol)
    a, b = runs
    assert sum(a.n_excluded.values()) == sum(b.n_excluded.values())
    for name in FluidState.FIELDS:
        assert np.array_equal(getattr(a.state, name), getattr(b.state, name)), name
    for name in a._aux_names():
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert a.time == b.time and np.array_equal(a.ace, b.ace) and np.array_equal(a.ar, b.ar)


def test_exclusion_allocates_no_per_particle_array():
    """One excluded particle: the state and the work arrays are views of the memory they held, and
    the exclusion allocates a few hundred bytes (the event), not the ~40 arrays of N rows."""
    st, c, dom = _leaking_tank()
    sol = SPHSolver(st, c, {"StepAlgorithm": 2}, domain=dom)
    for _ in range(3):
        sol.step()
    for _ in range(2):          # the compaction's kernels loaded (float, int8, int32, int64 rows)
        sol.out[:] = 0
        sol.out[int(np.flatnonzero(sol.state.ptype == 3)[-1])] = 1
        sol._exclude(sol.time)
    n = sol.state.n
    i = int(np.flatnonzero(sol.state.ptype == 3)[0])
    sol.out[:] = 0
    sol.out[i] = 1
    before = {name: getattr(sol, name) for name in ("nb", "ace", "ar", "out", "pos_pre", "dtmax")}
    state = {name: getattr(sol.state, name) for name in FluidState.FIELDS}
    tracemalloc.start()
    sol._exclude(sol.time)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert sol.state.n == n - 1
    for name, a in before.items():
        assert np.shares_memory(getattr(sol, name), a), name
    for name, a in state.items():
        assert np.shares_memory(getattr(sol.state, name), a), name
    assert peak < 24 * n, peak         # bytes: less than one (N, 3) array (a copy of ``out``, the event)
    sol.step()
