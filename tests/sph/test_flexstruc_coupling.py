"""A flexible structure in the SPH solver (sphdvi.sph.flexstruc through SPHSolver): the fluid's
forces on it and its own are equal and opposite (a fluid block hitting a free elastic block keeps
the total momentum), the threaded passes give the serial run's bits, and a failure is recorded."""
import numpy as np
import pytest

from sphdvi.sph import SPHSolver
from sphdvi.sph.flexstruc import FlexStruc
from sphdvi.sph.scenes import lattice_2d
from sphdvi.sph.state import FluidState

from _helpers import constants

DP = 0.01
RHO_S = 1500.0


def scene(speed=1.0):
    """A fluid block 10 x 10 (rows 0..9 dp) moving at ``speed`` in +x at a free elastic block 6 x 10
    one dp beyond it (mkbound 1, moving boundary particles), no gravity."""
    fluid = lattice_2d(0.0, 9 * DP, 0.0, 9 * DP, DP)
    solid = lattice_2d(11 * DP, 16 * DP, 0.0, 9 * DP, DP)
    pos = np.vstack([fluid, solid])
    n_f = fluid.shape[0]
    ptype = np.r_[np.full(n_f, 3), np.full(solid.shape[0], 1)].astype(np.int8)
    vel = np.zeros_like(pos)
    vel[:n_f, 0] = speed
    mass = np.full(pos.shape[0], 1000.0 * DP * DP)
    mk = np.r_[np.full(n_f, 1), np.full(solid.shape[0], 12)]          # fluidcount 10: mkbound 1 = mk 12
    st = FluidState(pos, vel, np.full(pos.shape[0], 1000.0), mass, ptype, mk=mk)
    c = constants(DP, True, g=0.0, cs0=20.0)
    body = {"mkbound": 1, "mkclamp": [0], "density": RHO_S, "youngmod": 2e5, "poissratio": 0.3,
            "constitmodel": 1, "hgfactor": 0.05}
    labels = np.where(ptype == 3, -1, mk - 11)
    flex = FlexStruc([body], st.pos, st.idp, labels, ptype, is2d=True, h=c["h"], dp=DP, kernel=2)
    return st, c, flex


def momentum(sol, flex):
    s = sol.state
    m = np.where(s.ptype == 3, s.mass, 0.0)
    m[np.isin(s.idp, flex.idp)] = RHO_S * flex.vol
    return (m[:, None] * s.vel).sum(axis=0)


def test_the_fluid_and_the_structure_exchange_equal_and_opposite_forces():
    """Symplectic (both halves of the pair updated with the mid-step forces): the total momentum of
    the fluid and the free elastic block stays to round-off while the block takes a third of it."""
    st, c, flex = scene()
    sol = SPHSolver(st, c, {"StepAlgorithm": 2, "ViscoTreatment": 1, "Visco": 0.05}, flex=flex)
    p0 = momentum(sol, flex)
    for _ in range(300):
        sol.step()
    p1 = momentum(sol, flex)
    s = sol.state
    solid_p = RHO_S * flex.vol * s.vel[np.isin(s.idp, flex.idp), 0].sum()
    assert solid_p > 0.2 * p0[0]                       # the block has been pushed
    assert abs(p1[0] - p0[0]) < 1e-10 * p0[0] and abs(p1[2]) < 1e-10 * p0[0]
    assert flex.fail[0] == -1


@pytest.mark.parametrize("algorithm", [1, 2])
def test_threaded_passes_give_the_serial_bits(algorithm, monkeypatch):
    monkeypatch.setattr("sphdvi.sph.flexstruc.PARALLEL_MIN", 0)      # the structure's threaded passes too
    import numba
    runs = []
    old = numba.get_num_threads()
    numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
    try:
        for thr in ({"parallel_threshold": 10 ** 9}, {"parallel_threshold": 0, "light_threshold": 0}):
            st, c, flex = scene()
            sol = SPHSolver(st, c, {"StepAlgorithm": algorithm}, flex=flex, **thr)
            for _ in range(40):
                sol.step()
            runs.append(sol.state.sorted_by_idp())
    finally:
        numba.set_num_threads(old)
    assert np.array_equal(runs[0].pos, runs[1].pos) and np.array_equal(runs[0].vel, runs[1].vel)


def test_a_structure_leaving_the_domain_is_recorded():
    st, c, flex = scene(speed=0.0)
    st.vel[np.isin(st.idp, flex.idp), 0] = 50.0          # thrown out of the box
    sol = SPHSolver(st, c, {"StepAlgorithm": 1}, flex=flex, domain=((-0.05, -1, -0.05), (0.2, 1, 0.15)))
    for _ in range(200):
        sol.step()
        if flex.fail[0] >= 0:
            break
    assert flex.fail[0] >= 0 and flex.fail[1] == 2


def test_the_structures_sound_speed_limits_dt():
    """dt = CFL h / max c_i (c_i = c_s sqrt(det F)) where it is below the fluid's conditions."""
    st, c, flex = scene(speed=0.0)
    flex.csound[:] = 500.0
    sol = SPHSolver(st, c, {"StepAlgorithm": 1}, flex=flex)
    dt = sol.step()
    assert dt == pytest.approx(0.2 * c["h"] / 500.0, rel=1e-9)
