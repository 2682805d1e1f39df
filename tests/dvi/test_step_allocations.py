"""System.step's work arrays are kept on the System (audit e, finding 2): a step allocates
(almost) nothing on its Python side, whatever the number of bodies, and what the scene lacks is
not run; the results are bitwise those of the allocating step it replaced (tools: the
before/after comparison of the hunt; here: reuse of the kept arrays and of a kept state).

The Python side of a step is measured with tracemalloc: the traced peak of the step less the
largest peak of the compiled kernels it calls (their own temporaries: the solver's vectors,
the narrow phase's), i.e. what the step's Python code keeps alive.  The old step allocated
F, T, the imposed velocities, vel6, v_out, six load arrays, the SMC forces, the contacts'
arrays ...: 114 kB for 200 free bodies, 12 kB for 20 hinged bodies, 46 kB for 20 boxes
resting on a plane (80 contacts); now 0.3, 0.3 and 3 kB (the contacts' warm-start cache, which
get_state copies, is a new pair of arrays each step)."""
import sys
import tracemalloc

import numpy as np
import pytest
from numba.core.registry import CPUDispatcher

import sphdvi.dvi.system as SY
from sphdvi.dvi.system import System

G = 9.81


def _free(n):
    s = System(gravity=(0, 0, -G))
    for i in range(n):
        s.add_body(1.0, (0.01, 0.02, 0.03), pos=(i, 0, 0), omega=(1, 2, 3))
    return s


def _hinged(n):
    s = System(gravity=(0, 0, -G))
    for i in range(n):
        b = s.add_body(1.0, (0.01, 0.01, 0.01), pos=(0.3 * i + 0.1, 0, 0.5))
        s.add_link("hinge", b, -1, point=(0.3 * i, 0, 0.5), axis=(0, 1, 0), stiffness=1.0, damping=0.1)
    return s


def _boxes(n):
    s = System(gravity=(0, 0, -G), solver="psor", max_iter=30, envelope=0.005)
    m = s.add_material("m", friction=0.4)
    s.add_plane(material=m)
    for i in range(n):
        b = s.add_body(1.0, (0.01,) * 3, pos=(0.3 * i, 0, 0.1), vel=(1.0, 0.2, 0))
        s.add_box(b, (0.1, 0.1, 0.1), material=m)
    return s


@pytest.fixture
def traced_kernels(monkeypatch):
    """Wrap every compiled kernel the step calls (system.py's names, rows.*, collision.*,
    solvers.*: solve_iterative calls solve_ccp) to note the largest traced peak of one call;
    returns the dict holding it."""
    inner = {"peak": 0, "outer": 0}
    for mod in (SY, SY.rw, SY.col, sys.modules["sphdvi.dvi.solvers"]):
        for name, fn in list(vars(mod).items()):
            if not isinstance(fn, CPUDispatcher):
                continue

            def wrapper(*a, _fn=fn, **k):
                cur, peak = tracemalloc.get_traced_memory()
                tracemalloc.reset_peak()
                out = _fn(*a, **k)
                after = tracemalloc.get_traced_memory()[1]
                inner["peak"] = max(inner["peak"], after - cur)
                inner["outer"] = max(inner["outer"], peak, after)
                return out
            monkeypatch.setattr(mod, name, wrapper)
    return inner


def _python_side(s, inner, steps=100, passes=3):
    """Largest Python-side traced memory of a step over ``steps`` steps (see the module's
    docstring), and the traced memory left after them: the smallest of ``passes`` passes.
    tracemalloc traces every thread of the process, and under pytest-xdist the worker's
    message thread allocates whenever the controller sends it work, at any moment of a pass;
    what the step itself allocates shows in every pass."""
    F = np.full((s.nb, 3), 0.1)
    T = np.full((s.nb, 3), 0.01)
    for _ in range(3):
        s.advance(1e-3, F, T)
    return min(_traced_pass(s, inner, steps, F, T) for _ in range(passes))


def _traced_pass(s, inner, steps, F, T):
    worst = 0
    tracemalloc.start()
    try:
        start = tracemalloc.get_traced_memory()[0]
        for _ in range(steps):
            inner["peak"] = inner["outer"] = 0
            tracemalloc.reset_peak()
            base = tracemalloc.get_traced_memory()[0]
            s.advance(1e-3, F, T)
            peak = max(inner["outer"], tracemalloc.get_traced_memory()[1]) - base
            worst = max(worst, peak - inner["peak"])
        left = tracemalloc.get_traced_memory()[0] - start
    finally:
        tracemalloc.stop()
    return worst, left


def test_free_bodies_step_allocates_nothing(traced_kernels):
    """200 free bodies (no links, no shapes): no row building, no collision pass, no solve;
    the step's Python side keeps no array alive (it was 114 kB)."""
    s = _free(200)
    worst, left = _python_side(s, traced_kernels)
    assert worst < 1024, worst
    assert s.n_rows == 0 and s.n_contacts == 0


def test_hinged_bodies_step_allocates_nothing(traced_kernels):
    """20 bodies on hinges with stiffness and damping (a floating flap's <chrono> link_hinge):
    nothing beyond the solver's own vectors (it was 12 kB); nothing kept from step to step
    but the solver's (numba's string argument, ~0.4 kB a step, is not the step's)."""
    s = _hinged(20)
    worst, left = _python_side(s, traced_kernels)
    assert worst < 1024, worst
    assert s.n_rows > 0


def test_contact_step_allocates_only_the_warm_start_cache(traced_kernels):
    """20 boxes sliding on a plane (80 frictional contacts): the collision and the contact
    rows use kept arrays; what is left is the warm-start cache (sorted keys and impulses, new
    arrays each step: get_state copies them), under 64 bytes a contact (it was 580)."""
    s = _boxes(20)
    worst, left = _python_side(s, traced_kernels)
    assert s.n_contacts >= 40
    assert worst < 64 * s.n_contacts, (worst, s.n_contacts)


def test_kept_arrays_same_results_as_fresh_systems():
    """Steps on the kept arrays (a system stepped before, its state put back) give bitwise
    the results of a fresh system: nothing of a step leaks into the next through them."""
    def run(s, n):
        for _ in range(n):
            s.advance(1e-3)
        return [a.copy() for a in (s.pos, s.quat, s.vel, s.omega_b, s.total_force, s.total_torque,
                                   s.contact_force, s.link_force, s.link_torque)]

    for make in (lambda: _hinged(3), lambda: _boxes(3)):
        a = make()
        st = a.get_state()
        run(a, 30)
        a.set_state(st)
        got = run(a, 30)
        want = run(make(), 30)
        for x, y in zip(got, want):
            assert np.array_equal(x, y)


def test_get_state_into_a_kept_state():
    """get_state(out) refills an earlier state in place (the Symplectic predictor's kept copy)
    and gives what a fresh get_state gives; set_state copies it (the kept state stays the
    caller's)."""
    s = _boxes(2)
    for _ in range(20):
        s.advance(1e-3)
    kept = s.get_state()
    ids = {k: id(v) for k, v in kept.items() if isinstance(v, np.ndarray)}
    for _ in range(5):
        s.advance(1e-3)
    fresh = s.get_state()
    again = s.get_state(kept)
    assert again is kept
    assert {k: id(v) for k, v in kept.items() if isinstance(v, np.ndarray) and v.size} == \
        {k: i for k, i in ids.items() if kept[k].size and kept[k].shape == fresh[k].shape}
    for k, v in fresh.items():
        assert np.array_equal(kept[k], v) if isinstance(v, np.ndarray) else kept[k] == v
    s.advance(1e-3)
    s.set_state(kept)
    assert all(s.pos[i, k] == fresh["pos"][i, k] for i in range(2) for k in range(3))
    s.advance(1e-3)
    assert np.array_equal(kept["pos"], fresh["pos"]) and np.array_equal(kept["prev_g3"], fresh["prev_g3"])


def test_step_returns_what_advance_leaves():
    """step = advance + (pos, quat, vel, omega_world)."""
    a, b = _hinged(2), _hinged(2)
    for _ in range(10):
        pos, quat, vel, om = a.step(1e-3)
        b.advance(1e-3)
    assert np.array_equal(pos, b.pos) and np.array_equal(quat, b.quat) and np.array_equal(vel, b.vel)
    assert np.array_equal(om, b.omega_world)
