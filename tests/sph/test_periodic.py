"""Periodic ghosts: rates equal those of the middle copy of a tiled domain."""
import numpy as np
import pytest

from sphdvi.sph import SPHSolver
from sphdvi.sph.state import FluidState

from _helpers import constants, jittered_block, random_state


@pytest.mark.parametrize("is2d,axes", [(True, "x"), (True, "xz"), (False, "xy")])
def test_periodic_rates_match_tiled_domain(is2d, axes):
    rng = np.random.default_rng(5)
    dp = 0.01
    nside = 12 if is2d else 7
    pos = jittered_block(nside, dp, is2d, rng, jitter=0.1)
    pos -= pos.min(0)
    pos += 0.2 * dp                      # keep inside [0, L) on every axis
    s = random_state(pos, dp, is2d, rng)
    L = nside * dp
    c = constants(dp, is2d, g=0.0)
    p = {"DensityDT": 1, "Visco": 0.05}
    # periodic box from the particle extent + dp: make it exactly nside*dp
    per = SPHSolver(s.copy(), c, p, periodic=axes)
    per.periodicity.lo[:] = 0.0
    for k in per.periodicity.axes:
        per.periodicity.length[k] = L
        per.periodicity.shift[k, k] = L
    per.compute_rates()
    # tiled reference: 3 copies along each periodic axis, middle one compared
    ks = [{"x": 0, "y": 1, "z": 2}[a] for a in axes]
    offs = [np.zeros(3)]
    for k in ks:
        offs = [o + e for o in offs for e in (-L * np.eye(3)[k], 0 * np.eye(3)[k], L * np.eye(3)[k])]
    big = FluidState(np.concatenate([s.pos + o for o in offs]), np.tile(s.vel, (len(offs), 1)),
                     np.tile(s.rhop, len(offs)), np.tile(s.mass, len(offs)),
                     idp=np.concatenate([s.idp + 100000 * m for m in range(len(offs))]))
    ref = SPHSolver(big, c, p)
    ref.compute_rates()
    mid = [m for m, o in enumerate(offs) if not o.any()][0]
    sel = (ref.state.idp >= 100000 * mid) & (ref.state.idp < 100000 * (mid + 1))
    o_ref = np.argsort(ref.state.idp[sel])
    o_per = np.argsort(per.state.idp)
    scale = np.abs(ref.ace).max()
    assert np.abs(ref.ace[sel][o_ref] - per.ace[o_per]).max() < 1e-10 * scale
    assert np.abs(ref.ar[sel][o_ref] - per.ar[o_per]).max() < 1e-10 * np.abs(ref.ar).max()


def test_wrap_keeps_particles_in_box():
    rng = np.random.default_rng(2)
    dp = 0.01
    pos = jittered_block(10, dp, True, rng, jitter=0.0)
    s = random_state(pos, dp, True, rng, vscale=0.0)
    s.vel[:, 0] = 0.3
    c = constants(dp, True, g=0.0)
    sol = SPHSolver(s, c, {"StepAlgorithm": 2}, periodic="x")
    sol.run(0.05)
    x = sol.state.pos[:, 0]
    lo, L = sol.periodicity.lo[0], sol.periodicity.length[0]
    assert x.min() >= lo and x.max() < lo + L
    assert sol.state.n == 100


@pytest.mark.parametrize("params", [{"StepAlgorithm": 2, "Shifting": 4, "ShiftAdvCoef": -0.01},
                                    {"ViscoTreatment": 2, "Shifting": 1}])
def test_periodic_work_arrays_are_kept_and_carry_nothing_over(params):
    """The extended set's work arrays live between steps (grown when needed, not made anew per
    call); a step's results do not depend on what a previous call left in them: the same steps
    with the arrays filled with NaN before each step give the same state to the last bit."""
    def run(poison):
        rng = np.random.default_rng(7)
        dp = 0.01
        pos = jittered_block(14, dp, True, rng, jitter=0.1)
        s = random_state(pos, dp, True, rng, vscale=0.2)
        sol = SPHSolver(s, constants(dp, True, g=0.0), {"DensityDT": 1, "Visco": 0.05, **params}, periodic="xz")
        kept = None
        for _ in range(6):
            if poison:
                for key, a in sol._bufs.items():
                    if key.startswith("periodic_") and a.dtype.kind == "f":
                        a.fill(np.nan)
            sol.step()
            ids = {k: id(a) for k, a in sol._bufs.items() if k.startswith("periodic_")}
            assert {"periodic_nb", "periodic_pos_x", "periodic_idx", "periodic_oi"} <= set(ids)
            if kept is not None:        # the same arrays step after step (the ghosts' number varies
                assert sum(ids[k] == kept.get(k) for k in ids) >= len(ids) // 2      # within the room)
            kept = ids
        st = sol.state
        return np.concatenate([st.pos.ravel(), st.vel.ravel(), st.rhop, sol.ace.ravel()])
    a, b = run(False), run(True)
    assert np.isfinite(a).all() and np.array_equal(a, b)


def _numpy_ghosts(per, pos, width):
    """The numpy formulation of JSphCpuSingle::PeriodicMakeList that Periodicity.ghosts had
    until session 36 (the reference of the compiled loop)."""
    src = np.arange(pos.shape[0])
    disp = np.zeros((pos.shape[0], 3))
    for k in per.axes:
        p = pos[src, k] + disp[:, k]
        lo, hi = per.lo[k], per.lo[k] + per.length[k]
        low = np.flatnonzero(p < lo + width)
        high = np.flatnonzero(p >= hi - width)
        src = np.concatenate([src, src[low], src[high]])
        disp = np.concatenate([disp, disp[low] + per.shift[k], disp[high] - per.shift[k]])
    n = pos.shape[0]
    return src[n:], disp[n:]


@pytest.mark.parametrize("axes,incs", [(["x"], {"XPeriodicIncZ": 0.013}),
                                       (["x", "z"], {"XPeriodicIncZ": 0.0, "ZPeriodicIncX": 0.0}),
                                       (["x", "y", "z"], {"XPeriodicIncY": 0.004, "YPeriodicIncZ": -0.007})])
def test_compiled_ghosts_and_wrap_equal_the_numpy_formulation(axes, incs):
    """The compiled ghost list (corner ghosts of ghosts included, the room grown from too
    small) and wrap give bitwise what the numpy formulation gives."""
    from sphdvi.sph.periodic import Periodicity
    rng = np.random.default_rng(3)
    pos = rng.uniform(0.0, 0.3, (2000, 3))
    per = Periodicity(axes, pos, 0.01, incs)
    width = 0.05
    ref_src, ref_disp = _numpy_ghosts(per, pos, width)
    bufs = {"src": np.empty(3, np.int64), "disp": np.empty((3, 3))}      # far too small: grown
    for _ in range(2):                                # and again with the grown room kept
        src, disp = per.ghosts(pos, width, bufs)
        assert ref_src.size > 500 and np.array_equal(src, ref_src) and np.array_equal(disp, ref_disp)
    assert bufs["src"].shape[0] >= ref_src.size
    src, disp = per.ghosts(pos, width)            # without kept arrays: copies
    assert np.array_equal(src, ref_src) and np.array_equal(disp, ref_disp)
    moved = pos + rng.uniform(-0.05, 0.05, pos.shape)
    ref = moved.copy()
    for k in per.axes:                            # JSphCpu::UpdatePos, axis by axis
        lo, hi = per.lo[k], per.lo[k] + per.length[k]
        below, above = ref[:, k] < lo, ref[:, k] >= hi
        ref[below] += per.shift[k]
        ref[above] -= per.shift[k]
    per.wrap(moved)
    assert np.array_equal(moved, ref) and not np.array_equal(ref, pos + 0)
