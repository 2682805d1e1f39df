"""Time stepping as DualSPHysics v5.4: the Verlet/Euler cycle, the Symplectic dt, the force term
of eq. 10, DtFixed below DtMin (hunt6/c findings 1, 2, 5, 6)."""
import math

import numpy as np
import pytest

from sphdvi.sph import SPHSolver
from sphdvi.sph import timestep as ts
from sphdvi.sph.scenes import tank_2d


def small_tank(dp=0.02):
    return tank_2d(0.4, 0.4, 0.2, 0.3, dp)


def euler_steps(verlet_steps, nsteps):
    """1-based numbers of the steps the solver takes as Euler steps."""
    st, c = small_tank()
    sol = SPHSolver(st, c, {"VerletSteps": verlet_steps})
    found = []
    args = sol._verlet_args

    def spy(euler):
        if euler:
            found.append(sol.nstep + 1)
        return args(euler)
    sol._verlet_args = spy
    for _ in range(nsteps):
        sol.step()
    return found


@pytest.mark.parametrize("verlet_steps,expected", [(3, [3, 6, 9]), (2, [2, 4, 6, 8, 10]),
                                                   (1, list(range(1, 11)))])
def test_verlet_takes_an_euler_step_every_verlet_steps(verlet_steps, expected):
    """JSphCpu::ComputeVerlet: VerletStep++ then Euler when it reaches VerletSteps (steps
    VerletSteps, 2 VerletSteps, ...; VerletSteps=1: every step).  sphdvi took it one step later."""
    assert euler_steps(verlet_steps, 10) == expected


def test_symplectic_next_dt_is_the_smaller_of_predictor_and_corrector():
    """ComputeStep_Sym: SymplecticDtPre = min(DtVariable after the predictor's interaction,
    DtVariable after the corrector's); sphdvi kept the corrector's alone."""
    st, c = small_tank()
    sol = SPHSolver(st, c, {"StepAlgorithm": 2, "DensityDT": 2, "Visco": 0.02})
    terms = []
    rates = sol.compute_rates

    def spy():
        rates()
        terms.append(sol.dtmax.max(axis=0).copy())
    sol.compute_rates = spy

    def eq10(t):
        dt1, dt2 = ts.dt_conditions(*t, sol.h, sol.cs0)
        return max(sol.cfl * min(dt1, dt2), sol.dtmin)
    smaller_pred = 0
    for _ in range(150):
        terms.clear()
        sol.step()
        dt_p, dt_c = eq10(terms[0]), eq10(terms[1])
        assert sol.dt_pre == min(dt_p, dt_c)
        smaller_pred += dt_p < dt_c
    assert smaller_pred > 0          # the predictor's dt is the smaller one in some steps


def test_force_term_without_gravity_over_fluid_and_floating():
    """JSphCpuSingle::ComputeAceMax: max |ace| over fluid and floating particles, ace as the
    interaction leaves it (gravity comes in the update).  Still water: |a - g| ~ g where sphdvi's
    max |a| (gravity included) was ~0 in the bulk."""
    st, c = small_tank()
    fl = np.flatnonzero(st.ptype == 3)
    st.ptype[fl[:5]] = 2                 # a few floating particles among the fluid
    sol = SPHSolver(st, c, {})
    sol.compute_rates()
    s = sol.state
    g = np.asarray(c["gravity"], float)
    a_fluid = ((sol.ace[s.ptype == 3] - g) ** 2).sum(1)
    a_float = (sol.ace[s.ptype == 2] ** 2).sum(1)
    assert sol.dtmax[:, 0].max() == max(a_fluid.max(), a_float.max())
    assert math.sqrt(sol.dtmax[:, 0].max()) > 0.5 * 9.81
    # the periodic path's dt_terms, and the <accinputs> one, alike
    ace = np.array([[0.0, 0.0, -9.81], [3.0, 0.0, 4.0], [1e3, 0.0, 0.0]])
    ptype = np.array([3, 2, 0], np.int8)
    assert ts.dt_terms(ace, np.zeros((3, 3)), np.zeros(3), ptype, 2, 0.0, 0.0, -9.81)[0] == 25.0
    from sphdvi.sph.accinput import fluid_ace_max2
    assert fluid_ace_max2(ace, ptype, 0.0, 0.0, -9.81) == 25.0


@pytest.mark.parametrize("params,what", [({"DtFixed": 1e-7}, "DtFixed"), ({}, "DtFixedFile")])
def test_an_imposed_dt_below_dtmin_is_warned_about(params, what):
    """DualSPHysics's DtVariable raises DtFixed / DtFixedFile values below DtMin to DtMin; sphdvi
    keeps them and says so at start-up."""
    st, c = small_tank()
    table = None if params else np.array([[0.0, 1e-7], [1.0, 1e-3]])
    with pytest.warns(UserWarning, match=f"{what}.*below DtMin"):
        sol = SPHSolver(st, c, params, dt_table=table)
    assert sol.step() == 1e-7


def test_a_symplectic_step_raised_to_dtmin_counts_once():
    """Both of a Symplectic step's dt evaluations are raised to DtMin: n_dtmin counts the step once."""
    st, c = small_tank()
    sol = SPHSolver(st, c, {"StepAlgorithm": 2, "DtMin": 1e-5, "DtIni": 1e-5})
    sol.cfl = 1e-9
    sol.run(1.0, max_steps=3)
    assert sol.n_dtmin == 3 and sol.dt_pre == 1e-5
