"""sphdvi.tables.TimeTable: per-step look-ups in time tables, to the bit np.interp's, in O(1) with
a kept cursor (O(log n) elsewhere), without copying the table (audit e, finding 3)."""
import time

import numpy as np
import pytest

from sphdvi.tables import TimeTable, find_row


def _tables(rng):
    """Random tables: rising, with repeated times (steps), of 1 to 40 rows, values of all sizes."""
    for n in list(range(1, 12)) + [40] * 20:
        t = np.cumsum(rng.exponential(1.0, n)) - 3.0
        if n > 2:
            rep = rng.integers(0, n - 1, size=rng.integers(0, 3))
            t[rep + 1] = t[rep]                  # repeated times (a step in the table)
            t = np.maximum.accumulate(t)
        v = rng.normal(size=(n, 3)) * 10.0 ** rng.integers(-5, 5, size=3)
        yield t, v


def _times(rng, t):
    """Times inside, outside, at the table's times and repeated, forward and back."""
    span = t[-1] - t[0] + 1.0
    x = np.concatenate([rng.uniform(t[0] - span, t[-1] + span, 40), t, t, np.repeat(t[:3], 2),
                        np.sort(rng.uniform(t[0] - 0.1, t[-1] + 0.1, 40)),
                        [t[0] - 1e-300, t[-1] + 1e-12, -np.inf, np.inf]])
    return x


def test_lookups_are_bitwise_np_interp():
    rng = np.random.default_rng(7)
    for t, v in _tables(rng):
        # the table held as DualSPHysics's rows (n, 4) and looked up in a strided column, as before
        a = np.column_stack([t, v])
        tab = TimeTable.of_rows(a)
        for x in _times(rng, t):
            got = tab.at(x)
            for k in range(3):
                want = np.interp(x, a[:, 0], a[:, 1 + k])
                assert got[k].tobytes() == np.float64(want).tobytes(), (t, x, k)
                assert tab.value(x, k) == want or (np.isnan(want) and np.isnan(tab.value(x, k)))


def test_row_is_numpys_segment():
    """The row found is the segment np.interp uses: searchsorted(side='right') - 1 (the last of
    repeated times), n - 1 from the table's last time on."""
    rng = np.random.default_rng(3)
    for t, v in _tables(rng):
        tab = TimeTable(t, v[:, 0])
        for x in _times(rng, t):
            want = min(int(np.searchsorted(t, x, side="right")) - 1, t.size - 1)
            assert tab.row(x) == want
            assert find_row(t, x, int(rng.integers(-5, t.size + 5))) == want


def test_nan_time_as_np_interp():
    tab = TimeTable([0.0, 1.0, 2.0], [1.0, 2.0, 5.0])
    assert np.isnan(tab.value(np.nan)) and np.isnan(np.interp(np.nan, [0.0, 1.0, 2.0], [1.0, 2.0, 5.0]))


def _cost(n, calls=1000):
    """Seconds for ``calls`` rising look-ups in an n-row table (the best of three)."""
    a = np.column_stack([np.linspace(0.0, 10.0, n), np.sin(np.linspace(0.0, 10.0, n)), np.zeros(n)])
    tab = TimeTable.of_rows(a)
    ts = np.linspace(1.0, 9.0, calls).tolist()
    tab.at(0.5)
    best = np.inf
    for _ in range(3):
        t0 = time.perf_counter()
        for x in ts:
            tab.at(x)
        best = min(best, time.perf_counter() - t0)
    return best


@pytest.mark.parametrize("resume", [False, True])
def test_lookup_cost_does_not_grow_with_the_table(resume):
    """1,000 look-ups in a 1,000,000-row table cost what they cost in a 10,000-row one (np.interp on
    the strided columns: ~4 ms per look-up at 1,000,000 rows), the cursor lost (resume) or not."""
    if resume:
        tab = TimeTable(np.linspace(0.0, 1.0, 1_000_000), np.zeros(1_000_000))
        tab.at(0.9)
        assert tab.row(0.1) == int(np.searchsorted(tab.times, 0.1, side="right")) - 1
    small, large = _cost(10_000), _cost(1_000_000)
    assert large < 3.0 * small + 2e-3, (small, large)
    assert _cost(200_000) < 0.02


def _user_cost(lookup, n, calls=300):
    """Seconds for ``calls`` rising look-ups through ``lookup(n)`` (a callable t -> value), best of 3."""
    f = lookup(n)
    ts = np.linspace(0.1, 0.9, calls).tolist()
    f(0.05)
    best = np.inf
    for _ in range(3):
        t0 = time.perf_counter()
        for x in ts:
            f(x)
        best = min(best, time.perf_counter() - t0)
    return best


def _solver_dt(n):
    from sphdvi.sph import SPHSolver
    from sphdvi.sph.scenes import tank_2d
    st, c = tank_2d(0.2, 0.2, 0.1, 0.1, 0.02)
    table = np.column_stack([np.linspace(0.0, 1.0, n), np.full(n, 1e-4)])
    return SPHSolver(st, c, {"StepAlgorithm": 2}, dt_table=table, visco_table=table)._fixed_dt


def _solver_visco(n):
    sol = _solver_dt(n).__self__

    def f(t):
        sol.time = t
        return sol._visco_lookup.value(t)
    return f


def _motion_file(n):
    import tempfile
    from sphdvi.motion import MotionSet
    with tempfile.TemporaryDirectory() as d:
        path = f"{d}/mv{n}.dat"
        t = np.linspace(0.0, 1.0, n)
        np.savetxt(path, np.column_stack([t, 0.01 * np.sin(t), 0.02 * t, np.cos(t)]), fmt="%.9f")
        mov = {"ref": 1, "begin": {"mov": 1, "start": 0.0},
               "movements": [{"id": 1, "type": "mvrectfile", "duration": 10.0, "file": path,
                              "fields": {"fieldtime": 0, "fieldx": 1, "fieldz": 3}, "ncols": 4}]}
        ms = MotionSet([mov])
        ms.transform(1, 0.01)                   # the file read (kept by the motion)
    return lambda x: ms.transform(1, x)


def _link_table(n):
    from sphdvi.dvi.system import _as_table
    return _as_table(np.column_stack([np.linspace(0.0, 1.0, n), np.linspace(0.0, 1.0, n) ** 2]))


def _body_table(n):
    from sphdvi.mechanism import _vector_series
    t = np.linspace(0.0, 1.0, n)
    return _vector_series({"times": t, "values": [[x, None, 2 * x] for x in t.tolist()]}, "test")


@pytest.mark.parametrize("lookup", [_solver_dt, _solver_visco, _motion_file, _link_table, _body_table])
def test_per_step_lookups_do_not_copy_the_table(lookup):
    """DtFixedFile, ViscoTime, a motion file, a link's table and a floating body's <linearvel>
    table: a look-up in a 200,000-row table costs what it costs in a 2,000-row one (audit e,
    finding 3: np.interp on their strided columns copied them at every step, 0.06-1 ms per look-up
    at 100,000 rows)."""
    small, large = _user_cost(lookup, 2_000), _user_cost(lookup, 200_000)
    assert large < 3.0 * small + 1e-3, (small, large)


def test_motion_file_values_as_np_interp():
    """A motion file's displacement and rate: np.interp's value less the first row, the slope of
    the row segment holding the time (0 before the first row and from the last one on)."""
    from sphdvi.motion import _file_values
    rng = np.random.default_rng(5)
    t = np.cumsum(rng.uniform(0.01, 0.2, 50))
    cols = rng.normal(size=(50, 2))
    tab = TimeTable(t, cols)
    for tau in np.concatenate([rng.uniform(-1, t[-1] - t[0] + 1, 200), t - t[0]]):
        value, rate = _file_values(tab, tau)
        tf = tau + t[0]
        i = int(np.searchsorted(t, tf, side="right")) - 1
        for k in range(2):
            assert value[k] == float(np.interp(tf, t, cols[:, k])) - cols[0, k]
            want = 0.0 if i < 0 or i >= t.size - 1 else (cols[i + 1, k] - cols[i, k]) / (t[i + 1] - t[i])
            assert rate[k] == want
