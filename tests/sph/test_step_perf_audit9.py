"""Step performance fixes (audit 9): the periodic path's compiled gather-and-pack (no ghost rows
computed, no copy-back, no second dt pass) gives the old formulation's results to the bit; the
branch-free bounding box; the counting of neighbour pairs without a list; memory_bytes counting
arrays held in tuples and spare room; the cached state-array check and dt reduction."""
import numba
import numpy as np
import pytest

from sphdvi.sph import SPHSolver
from sphdvi.sph import cells as _cells
from sphdvi.sph import interaction as _ia
from sphdvi.sph import solver as _solver
from sphdvi.sph import timestep as _ts
from sphdvi.sph.state import FluidState

from _helpers import constants, jittered_block, random_state


def _old_compute_rates_periodic(self):
    """SPHSolver._compute_rates_periodic as it was before audit 9 (numpy gathers of the extended
    set, every row of it computed, the real rows copied back, a separate dt pass): the reference."""
    self._check_state_arrays()
    s = self.state
    per = self.periodicity
    per.wrap(s.pos)
    n = s.n
    src, disp = per.ghosts(s.pos, 2.0 * self.h, self._ghost_bufs)
    ne = n + src.shape[0]
    w = self._periodic_work
    unsorted = w("pos_x", ne, (3,), zero=False)
    unsorted[:n] = s.pos
    np.take(s.pos, src, axis=0, out=unsorted[n:], mode="clip")
    unsorted[n:] += disp
    order = self.cells.build(unsorted, parallel=self._use_parallel(light=True))
    source = w("source", ne, (), np.int64, zero=False)
    source[:n] = self._periodic_rows(n)
    source[n:] = src
    idx = np.take(source, order, out=w("idx", ne, (), np.int64, zero=False), mode="clip")
    pos_e = np.take(unsorted, order, axis=0, out=w("pos", ne, (3,), zero=False), mode="clip")
    vel_e = np.take(s.vel, idx, axis=0, out=w("vel", ne, (3,), zero=False), mode="clip")
    rhop_e = np.take(s.rhop, idx, out=w("rhop", ne, zero=False), mode="clip")
    mass_e = np.take(s.mass, idx, out=w("mass", ne, zero=False), mode="clip")
    ptype_e = np.take(s.ptype, idx, out=w("ptype", ne, (), s.ptype.dtype, zero=False), mode="clip")
    cell_e = np.take(self.cells.cell, order, out=w("cell", ne, (), self.cells.cell.dtype, zero=False),
                     mode="clip")
    nb = w("nb", ne, self.nb.shape[1:])
    ace = w("ace", ne, (3,))
    ar = w("ar", ne)
    viscdt = w("viscdt", ne)
    shiftpos = w("shiftpos", ne, (3,)) if self.shift else self.shiftpos
    shiftdet = w("shiftdet", ne) if self.shift else self.shiftdet
    tau = (np.take(self.tau, idx, axis=0, out=w("tau", ne, self.tau.shape[1:], zero=False), mode="clip")
           if self.visco_kind == 2 else self.tau)
    gradvel = w("gradvel", ne, (6,)) if self.visco_kind == 2 else self.gradvel
    rows_e = self._periodic_rows(ne)
    par = self._use_parallel()
    k = self._kernels(par)
    k["pack"](self.is2d, pos_e, vel_e, rhop_e, mass_e, self.cst, nb)
    ncx, ncy, ncz = self.cells.shape
    geo = (ncx, ncz) if self.is2d else (ncx, ncy, ncz)
    real = order < n
    dst = order[real]
    rr = np.flatnonzero(real)
    back = _solver._copy_rows_2d, _solver._copy_rows_1d
    if self.shift == 4 and self._need_shift_adv:
        fstype = w("fstype", ne, (), np.int8)
        fsnormal = w("fsnormal", ne, (3,))
        nctype = w("nctype", ne if self.adv else 1, (), np.int8)
        row_of = np.empty(n, np.int64)
        row_of[dst] = rr
        work = tuple(w(f"shift_adv{k}", ne, a.shape[1:], a.dtype) for k, a in enumerate(self._fs_work))
        self._advanced_shift(par, nb, ptype_e, cell_e, rows_e, shiftpos, fstype, fsnormal, work,
                             src_row=row_of[idx], nctype=nctype)
        for a, out in ((fstype, self.fstype), (fsnormal, self.fsnormal), (shiftpos, self.shiftpos)) + (
                ((nctype, self.nctype),) if self.adv else ()):
            back[a.ndim == 1](a, rr, out, dst)
    shiftpos_r = shiftpos
    nctype_r = self.nctype
    if self.adv:
        shiftpos_r = np.take(self.shiftpos, idx, axis=0, out=w("shiftpos_r", ne, (3,), zero=False), mode="clip")
        nctype_r = np.take(self.nctype, idx, out=w("nctype_r", ne, (), self.nctype.dtype, zero=False), mode="clip")
    k["rates"](self.kernel, self.visco_kind, self.ddt, self.rates_shift, self.adv, self._mdbc2_flag,
               self.ftmode, nb, ptype_e, cell_e, rows_e, self.cells.cell_start, *geo, self.cst, tau,
               ace, ar, viscdt, shiftpos_r, shiftdet, gradvel, self._tvel(ne),
               w("dtmax", (ne + _ia.CHUNK - 1) // _ia.CHUNK, (3,)), nctype_r)
    _solver._copy_rows_2d(ace, rr, self.ace, dst)
    _solver._copy_rows_1d(ar, rr, self.ar, dst)
    _solver._copy_rows_1d(viscdt, rr, self.viscdt, dst)
    if self.rates_shift:
        _solver._copy_rows_2d(shiftpos, rr, self.shiftpos, dst)
        _solver._copy_rows_1d(shiftdet, rr, self.shiftdet, dst)
    if self.visco_kind == 2:
        _solver._copy_rows_2d(gradvel, rr, self.gradvel, dst)
        k["sps"](self.gradvel, s.rhop, s.ptype, self.sps_smag, self.sps_blin, self.tau)
    self.dtmax = np.array([_ts.dt_terms(self.ace, s.vel, self.viscdt, s.ptype, self.dt_vel_type,
                                        *self.gravity)])


class _OldPeriodic(SPHSolver):
    _compute_rates_periodic = _old_compute_rates_periodic


def _channel(is2d, rng):
    """Jittered fluid over two rows of fixed wall particles (periodic along x; y too in 3D)."""
    dp = 0.01
    nside = 12 if is2d else 7
    fluid = jittered_block(nside, dp, is2d, rng, jitter=0.1)
    fluid[:, 2] += 2.0 * dp
    walls = jittered_block(nside, dp, is2d, rng, jitter=0.0)
    walls = walls[walls[:, 2] < 1.5 * dp]
    pos = np.concatenate([walls, fluid])
    ptype = np.r_[np.zeros(len(walls), np.int8), np.full(len(fluid), 3, np.int8)]
    s = random_state(pos, dp, is2d, rng, ptype=ptype, vscale=0.1)
    s.vel[ptype == 0] = 0.0
    return s, constants(dp, is2d, g=9.81)


CASES = [
    (True, "x", {"DensityDT": 2, "Visco": 0.05}),
    (True, "x", {"StepAlgorithm": 2, "ViscoTreatment": 3, "Visco": 1e-3, "Shifting": 1, "DensityDT": 1}),
    (True, "xz", {"ViscoTreatment": 2, "Visco": 1e-3, "Shifting": 2, "ShiftTFS": 1.5}),
    (True, "x", {"StepAlgorithm": 2, "Shifting": 4, "ShiftAdvCoef": -0.05, "ShiftAdvALE": 1,
                 "ShiftAdvNCPress": 1, "DensityDT": 1, "DtAllParticles": 1}),
    (False, "xy", {"DensityDT": 1, "Visco": 0.05, "Kernel": 1}),
    (False, "xy", {"StepAlgorithm": 2, "Shifting": 4, "ShiftAdvCoef": -0.05, "ShiftAdvALE": 1,
                   "ShiftAdvNCPress": 1}),
]


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("is2d,axes,params", CASES)
def test_periodic_step_bitwise_as_the_numpy_formulation(is2d, axes, params, threads):
    """The periodic path (compiled gather-and-pack, real rows only, rates straight into the
    particles' rows, dt terms from the interaction's per-chunk maxima without the copies, as
    DualSPHysics's ComputeAceMax ignores periodic particles) steps to the same bits as the
    numpy formulation it replaced, on 1 and 2 threads with every kernel threaded."""
    if threads > numba.config.NUMBA_NUM_THREADS:
        pytest.skip("needs 2 threads")
    s, c = _channel(is2d, np.random.default_rng(11))
    if is2d and "z" in axes:
        s = FluidState(s.pos[s.ptype == 3], s.vel[s.ptype == 3], s.rhop[s.ptype == 3], s.mass[s.ptype == 3])
    prev = numba.get_num_threads()
    numba.set_num_threads(threads)
    try:
        out = []
        for cls in (_OldPeriodic, SPHSolver):
            sol = cls(s.copy(), c, params, periodic=axes, parallel_threshold=0, light_threshold=0)
            dts = [sol.step() for _ in range(8)]
            st = sol.state
            out.append(np.concatenate([st.pos.ravel(), st.vel.ravel(), st.rhop, sol.ace.ravel(), sol.ar,
                                       sol.viscdt, np.asarray(dts)]))
    finally:
        numba.set_num_threads(prev)
    assert np.isfinite(out[0]).all()
    assert np.array_equal(out[0].view(np.uint64), out[1].view(np.uint64))


def test_periodic_copies_are_not_computed():
    """The packing marks the periodic copies (oi = -1 - their particle) and the real rows (oi =
    the particle's row, each once); the time-step terms are the interaction's per-chunk maxima
    over the real rows, equal to a pass over the particles (DualSPHysics's ComputeAceMax
    ignores periodic particles)."""
    s, c = _channel(True, np.random.default_rng(3))
    sol = SPHSolver(s, c, {"DensityDT": 2}, periodic="x")
    sol.step()
    sol.compute_rates()
    st = sol.state
    src = sol.periodicity.ghosts(st.pos, 2.0 * sol.h)[0]
    ne = st.n + src.shape[0]
    assert src.shape[0] > 0
    oi = sol._bufs["periodic_oi"][:ne]
    assert np.array_equal(np.sort(oi[oi >= 0]), np.arange(st.n))
    assert np.array_equal(np.sort(-1 - oi[oi < 0]), np.sort(src))
    assert sol.dtmax.shape == ((ne + _ia.CHUNK - 1) // _ia.CHUNK, 3)
    want = _ts.dt_terms(sol.ace, st.vel, sol.viscdt, st.ptype, sol.dt_vel_type, *sol.gravity)
    assert tuple(sol.dtmax.max(axis=0)) == want


def test_periodic_step_gathers_in_compiled_code(monkeypatch):
    """The periodic step (no mDBC) gathers the extended set in compiled code: no numpy take."""
    s, c = _channel(True, np.random.default_rng(4))
    sol = SPHSolver(s, c, {"DensityDT": 2, "ViscoTreatment": 2, "Visco": 1e-3}, periodic="x")
    sol.step()

    def no_take(*a, **k):
        raise AssertionError("numpy take in the periodic step")
    monkeypatch.setattr(_solver.np, "take", no_take)
    sol.step()


def _old_bounding_box(pos):
    """The compare-and-store loop bounding_box had before (the reference of its results)."""
    lo = [float(v) for v in pos[0]]
    hi = list(lo)
    for i in range(1, pos.shape[0]):
        for k in range(3):
            v = float(pos[i, k])
            if v < lo[k]:
                lo[k] = v
            if v > hi[k]:
                hi[k] = v
    return np.array(lo), np.array(hi)


def test_bounding_box_same_bits_as_compare_and_store_incl_nan():
    """min()/max() accumulators give the old loop's bits: a NaN in the first row stays, a later
    NaN is skipped, -0.0 and 0.0 are not exchanged, infinities kept."""
    rng = np.random.default_rng(0)
    specials = np.array([np.nan, 0.0, -0.0, np.inf, -np.inf, 1.5, -2.5])
    for _ in range(400):
        pos = rng.choice(specials, size=(int(rng.integers(1, 7)), 3))
        for got, ref in zip(_cells.bounding_box(pos), _old_bounding_box(pos)):
            assert np.array_equal(got.view(np.uint64), ref.view(np.uint64)), pos
    pos = rng.normal(size=(1000, 3))
    pos[0, 1] = np.nan          # NaN row 0: poisons y
    pos[500] = np.nan           # a later NaN row: skipped
    lo, hi = _cells.bounding_box(pos)
    rlo, rhi = _old_bounding_box(pos)
    assert np.array_equal(lo, rlo, equal_nan=True) and np.array_equal(hi, rhi, equal_nan=True)
    assert np.isnan(lo[1]) and np.isnan(hi[1]) and np.isfinite(lo[[0, 2]]).all()


@pytest.mark.parametrize("is2d", [True, False])
def test_count_pairs_without_a_list(is2d):
    """count_pairs_from_cells counts what _pairs_from_cells lists (pairs with a particle of type
    >= min_type), without storing the pairs."""
    rng = np.random.default_rng(1)
    dp = 0.01
    pos = jittered_block(14 if is2d else 7, dp, is2d, rng)
    pt = rng.choice(np.array([0, 3], np.int8), pos.shape[0])
    h = 1.2 * dp
    cl = _cells.CellList(h, is2d)
    order = cl.build(pos)
    p = np.ascontiguousarray(pos[order])
    ps = np.ascontiguousarray(pt[order])
    cs = np.ascontiguousarray(cl.cell[order])
    pairs = np.array(_cells._pairs_from_cells(p, cs, cl.cell_start, *cl.shape, is2d, 2 * h)).reshape(-1, 2)
    for min_type in (0, 2):
        want = int(np.count_nonzero((ps[pairs[:, 0]] >= min_type) | (ps[pairs[:, 1]] >= min_type)))
        assert _cells.count_pairs_from_cells(p, cs, cl.cell_start, *cl.shape, is2d, 2 * h, ps, min_type) == want
    assert 0 < want < len(pairs)


def _all_bases(sol):
    """Every array reachable from the solver's, the state's and the cell list's attributes (in
    tuples and lists too) and its work buffers, by base."""
    seen = {}
    items = []
    for obj in (sol.state, sol, sol.cells):
        names = obj.__slots__ if hasattr(obj, "__slots__") else vars(obj)
        for name in names:
            a = getattr(obj, name, None)
            items += list(a) if isinstance(a, (tuple, list)) else [a]
    items += list(sol._bufs.values()) + list(sol._ghost_bufs.values())
    for a in items:
        if isinstance(a, np.ndarray):
            while isinstance(a.base, np.ndarray):
                a = a.base
            seen[id(a)] = a.nbytes
    return sum(seen.values())


def test_memory_bytes_counts_tuples_and_spare_room():
    """Shifting 4's work arrays (held in a tuple) and the cell list's spare rows are counted."""
    rng = np.random.default_rng(2)
    dp = 0.01
    s = random_state(jittered_block(20, dp, True, rng), dp, True, rng)
    sol = SPHSolver(s, constants(dp, True), {"StepAlgorithm": 2, "Shifting": 4})
    sol.run(1e9, max_steps=3)
    m = sol.memory_bytes()
    assert m == _all_bases(sol)
    fs = sum(a.nbytes for a in sol._fs_work)
    room = sum(a.nbytes for a in sol.cells._room)
    # the arrays directly on the objects (the old count), less the cell/order views
    direct = {}
    for obj in (sol.state, sol, sol.cells):
        names = obj.__slots__ if hasattr(obj, "__slots__") else vars(obj)
        for name in names:
            a = getattr(obj, name, None)
            if isinstance(a, np.ndarray):
                direct[id(a)] = a.nbytes
    for a in list(sol._bufs.values()) + list(sol._ghost_bufs.values()):
        direct[id(a)] = a.nbytes
    old = sum(direct.values())
    assert m >= old - sol.cells.cell.nbytes - sol.cells.order.nbytes + fs + room
    assert fs > 40 * s.n


def test_state_array_replaced_between_steps_is_still_coerced():
    """The state-array check skips arrays it has seen, not an array put in their place."""
    rng = np.random.default_rng(3)
    dp = 0.01
    s = random_state(jittered_block(10, dp, True, rng), dp, True, rng)
    sol = SPHSolver(s, constants(dp, True), {})
    ref = SPHSolver(s.copy(), constants(dp, True), {})
    for _ in range(3):
        sol.step()
        ref.step()
    v = sol.state.vel.astype(np.float32).astype(np.float64)
    sol.state.vel = np.asfortranarray(v)
    ref.state.vel = v.copy()
    sol.state.rhop = sol.state.rhop.astype(np.float32)
    ref.state.rhop = ref.state.rhop.astype(np.float32).astype(np.float64)
    sol.step()
    ref.step()
    assert sol.state.vel.flags.c_contiguous and sol.state.rhop.dtype == np.float64
    assert np.array_equal(sol.state.pos, ref.state.pos) and np.array_equal(sol.state.rhop, ref.state.rhop)
    with pytest.raises(ValueError, match="rows"):
        sol.state.mass = sol.state.mass[:-1].copy()
        sol.step()


def test_dtmax_columns_as_numpy_max():
    """The compiled reduction of the per-chunk dt terms equals numpy's max(axis=0), NaN included."""
    rng = np.random.default_rng(4)
    for rows in (1, 2, 165):
        d = rng.random((rows, 3))
        assert np.array_equal(np.array(_solver._dtmax_columns(d)), d.max(axis=0))
        d[rows // 2, 1] = np.nan
        assert np.array_equal(np.array(_solver._dtmax_columns(d)), d.max(axis=0), equal_nan=True)
