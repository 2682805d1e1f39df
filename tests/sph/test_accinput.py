"""Imposed accelerations of fluid blocks (``<accinputs>``, DualSPHysics's JDsAccInput):
the table and its integrated velocities, the added acceleration term by term against a
numpy evaluation, and a free block whose momentum follows the imposed acceleration exactly
(the pair forces cancel)."""
import numpy as np
import pytest

from sphdvi.sph import SPHSolver
from sphdvi.sph.accinput import AccInput, add_acc_input, fluid_ace_max2, integrated_velocities
from sphdvi.sph.state import FluidState

from _helpers import constants, jittered_block

G = np.array([0.0, 0.0, -9.81])


def spec(table, mkfluid=(0,), gravity=True, start=0.0, end=None, centre=(0.1, 0.0, 0.2)):
    return {"mkfluid": list(mkfluid), "start": start, "end": end, "centre": list(centre),
            "globalgravity": gravity, "table": table}


def test_velocities_are_integrated_with_each_rows_own_acceleration():
    table = np.array([[0.0, 1, 0, 0, 0, 2, 0], [0.5, 3, 0, 0, 0, 2, 0], [2.0, -1, 0, 0, 0, 0, 0]], float)
    v = integrated_velocities(table)
    # v_0 = 0; v_1 = 3 * 0.5; v_2 = v_1 - 1 * 1.5 (rectangles with a_k, as DualSPHysics)
    assert v[:, 1].tolist() == [0.0, 1.5, 0.0]
    assert v[:, 5].tolist() == [0.0, 1.0, 1.0]
    inp = AccInput(spec(table.tolist(), start=0.25, end=1.0))
    assert inp.values(0.2) is None and inp.values(1.1) is None
    lin, ang, vlin, w = inp.values(0.25)
    assert lin[0] == pytest.approx(2.0) and ang[1] == pytest.approx(2.0)
    assert vlin[0] == pytest.approx(0.75) and w[1] == pytest.approx(0.5)


def test_a_repeated_time_is_a_step_as_jlinearvalue():
    """Rows 0:0, 1:0, 1:2, 3:2 ("switch on at t = 1"): JLinearValue::FindTime/GetValue3d3d
    gives the row before the step at t = 1 itself and the one after it just past; the velocity
    gains nothing over the zero-length row (a_k · 0)."""
    from sphdvi.sph.accinput import linear_value
    table = np.array([[0, 0, 0, 0, 0, 0, 0], [1, 0, 0, 0, 0, 0, 0], [1, 2, 0, 0, 0, 4, 0],
                      [3, 2, 0, 0, 0, 4, 0]], float)
    inp = AccInput(spec(table.tolist(), start=-5.0))      # active before the table: its first row
    got = {t: inp.values(t) for t in (-1.0, 0.5, 1.0, 1.0 + 1e-12, 2.0, 5.0)}
    assert [float(got[t][0][0]) for t in got] == [0.0, 0.0, 0.0, 2.0, 2.0, 2.0]
    assert [float(got[t][1][1]) for t in got] == [0.0, 0.0, 0.0, 4.0, 4.0, 4.0]
    assert got[2.0][2][0] == pytest.approx(2.0) and got[1.0][2][0] == 0.0 and got[5.0][3][1] == pytest.approx(8.0)
    # a table without repeated times: np.interp's values
    t, v = np.array([0.0, 0.5, 2.0]), np.array([[1.0], [3.0], [-1.0]])
    for x in (-1, 0, 0.25, 0.5, 1.2, 2, 3):
        assert linear_value(t, v, x)[0] == pytest.approx(np.interp(x, t, v[:, 0]), abs=1e-15)


def reference(pos, vel, lin, ang, vlin, w, centre, angular):
    """The added acceleration in DualSPHysics's form (numpy, per particle)."""
    d = pos - centre
    a = np.tile(lin, (pos.shape[0], 1))
    if angular:
        a += np.cross(ang, d) + np.cross(w, np.cross(w, d))
        cor = np.empty_like(a)
        cor[:, 0] = 2 * w[1] * vel[:, 2] - 2 * w[2] * (vel[:, 1] - vlin[1])
        cor[:, 1] = 2 * w[2] * vel[:, 0] - 2 * w[0] * (vel[:, 2] - vlin[2])
        cor[:, 2] = 2 * w[0] * vel[:, 1] - 2 * w[1] * (vel[:, 0] - vlin[0])
        a += cor
    return a


@pytest.mark.parametrize("is2d", [False, True])
@pytest.mark.parametrize("gravity", [True, False])
@pytest.mark.parametrize("parallel", [False, True])
def test_added_acceleration_term_by_term(is2d, gravity, parallel):
    rng = np.random.default_rng(3)
    n = 500
    pos, vel = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    mk = rng.integers(1, 4, n).astype(np.int32)          # mkfluid 0..2
    ptype = np.where(rng.random(n) < 0.9, 3, 0).astype(np.int8)
    table = [[0.0, 0.5, -0.2, 1.0, 0.3, -1.2, 0.7], [2.0, 1.5, 0.4, -1.0, -0.3, 2.2, 0.1]]
    inp = AccInput(spec(table, mkfluid=(0, 2), gravity=gravity))
    ace = rng.normal(size=(n, 3))
    before = ace.copy()
    assert add_acc_input(ace, pos, vel, mk, ptype, inp, 0.7, G, is2d, parallel)
    lin, ang, vlin, w = inp.values(0.7)
    want = reference(pos, vel, lin - (0.0 if gravity else G), ang, vlin, w, inp.centre, True)
    if is2d:
        want[:, 1] = 0.0
    sel = (ptype == 3) & np.isin(mk, [1, 3])
    np.testing.assert_allclose(ace[sel] - before[sel], want[sel], rtol=1e-12, atol=1e-12)
    assert np.array_equal(ace[~sel], before[~sel])          # other blocks, boundaries: untouched
    assert fluid_ace_max2(ace, ptype) == pytest.approx(np.max(np.sum(ace[ptype == 3] ** 2, axis=1)))


def test_angular_terms_only_while_the_angular_acceleration_is_not_zero():
    """As DualSPHysics 5.4: a rotation at constant ω (α = 0) adds no centripetal or
    Coriolis term; only the linear acceleration."""
    table = [[0.0, 0, 0, 0, 0, 4.0, 0], [1.0, 0, 0, 0, 0, 4.0, 0], [1.0 + 1e-9, 0, 0, 0, 0, 0, 0],
             [3.0, 1.0, 0, 0, 0, 0, 0]]
    inp = AccInput(spec(table))
    pos, vel = np.array([[1.0, 0.0, 0.0]]), np.array([[0.0, 0.0, 1.0]])
    mk, ptype = np.array([1], np.int32), np.array([3], np.int8)
    ace = np.zeros((1, 3))
    add_acc_input(ace, pos, vel, mk, ptype, inp, 2.0, G, False)
    assert inp.values(2.0)[3][1] == pytest.approx(4.0)      # ω = 4 rad/s held
    np.testing.assert_allclose(ace[0], [0.5, 0.0, 0.0])     # the linear term alone


def free_blocks(is2d):
    """Two separate jittered blocks, mkfluid 0 (mk 1) and 1 (mk 2), no walls, no gravity
    field other than the case's."""
    dp = 0.02
    rng = np.random.default_rng(0)
    a = jittered_block(8, dp, is2d, rng)
    b = jittered_block(8, dp, is2d, rng) + np.array([1.0, 0.0, 0.0])
    pos = np.vstack([a, b])
    n = pos.shape[0]
    vol = dp ** 2 if is2d else dp ** 3
    mk = np.r_[np.full(a.shape[0], 1), np.full(b.shape[0], 2)].astype(np.int32)
    st = FluidState(pos, np.zeros((n, 3)), np.full(n, 1000.0), np.full(n, 1000.0 * vol), None, None, mk)
    return st, constants(dp, is2d, g=9.81)


def verlet_velocity(nsteps, dt, verlet_steps=40):
    """v/a after ``nsteps`` of DualSPHysics's Verlet from rest under a constant a (v^-1 = v^0;
    an Euler step at steps verlet_steps, 2 verlet_steps, ...): the leapfrog's start leaves
    the odd steps dt ahead, and an Euler step on an even one carries that on (a (t + dt))."""
    v, vm1, k = 0.0, 0.0, 0
    for _ in range(nsteps):
        k += 1
        if k >= verlet_steps:
            k = 0
            v, vm1 = v + dt, v
        else:
            v, vm1 = vm1 + 2.0 * dt, v
    return v


@pytest.mark.parametrize("alg", [1, 2])
def test_a_free_block_moves_with_the_imposed_acceleration(alg):
    """globalgravity 0 and a_lin = (2, 0, 0.5): the pair forces of a free block cancel, so
    its mean velocity after t is a_lin t to round-off (Verlet: a_lin times the scheme's own
    v/a), while the other block falls with g."""
    st, c = free_blocks(True)
    inp = AccInput(spec([[0.0, 2.0, 0, 0.5, 0, 0, 0], [1.0, 2.0, 0, 0.5, 0, 0, 0]], gravity=False))
    sol = SPHSolver(st, c, {"StepAlgorithm": alg, "DtFixed": 1e-4, "DtMin": 1e-5}, acc_inputs=[inp])
    sol.run(0.02)
    s = sol.state
    m1, m2 = s.mk == 1, s.mk == 2
    te = verlet_velocity(sol.nstep, 1e-4) if alg == 1 else sol.time
    np.testing.assert_allclose(s.vel[m1].mean(axis=0), [2.0 * te, 0.0, 0.5 * te], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(s.vel[m2].mean(axis=0), [0.0, 0.0, -9.81 * te], rtol=1e-9, atol=1e-12)


def test_the_time_step_sees_the_imposed_acceleration():
    """The force term of dt (CFL √(h/|a|max)) follows the added acceleration."""
    st, c = free_blocks(True)
    big = AccInput(spec([[0.0, 2e4, 0, 0, 0, 0, 0], [1.0, 2e4, 0, 0, 0, 0, 0]]))
    plain = SPHSolver(st.copy(), c, {"StepAlgorithm": 1})
    pushed = SPHSolver(st.copy(), c, {"StepAlgorithm": 1}, acc_inputs=[big])
    dt_plain, dt_pushed = plain.step(), pushed.step()
    a2 = pushed.dtmax.max(axis=0)[0]
    assert a2 == pytest.approx(fluid_ace_max2(pushed.ace, pushed.state.ptype, *pushed.gravity))
    assert a2 > 4e8 * 0.99
    # the force term 0.2 √(h/|a|) now limits dt (the sound term did before; DtMin is below it)
    assert dt_pushed == pytest.approx(0.2 * np.sqrt(c["h"] / np.sqrt(a2)), rel=1e-9) and dt_pushed < dt_plain
