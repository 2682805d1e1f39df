"""mDBC (Boundary=2): ghost-node extrapolation of the boundary density."""
import numpy as np

from sphdvi.sph import SPHSolver
from sphdvi.sph.scenes import tank_2d, tank_normals_2d


def test_mdbc_extrapolates_hydrostatic_density_to_the_walls():
    """Hydrostatic lattice column, three wall layers with analytic normals: the
    boundary densities set by mDBC equal the hydrostatic (Tait) density at the
    boundary particles (first-order consistent: a linear field is exact), for
    the bottom layers away from the corners."""
    dp = 0.01
    st, c = tank_2d(0.3, 0.3, 0.3, 0.2, dp, layers=3)
    st.rhop[st.ptype < 2] = c["rhop0"]                    # start from rho0
    sol = SPHSolver(st, c, {"Boundary": 2}, normals=tank_normals_2d(st, 0.3, dp))
    sol.compute_rates()
    s = sol.state
    top = 0.2 + 0.5 * dp
    rho_h = c["rhop0"] * (1 + c["rhop0"] * 9.81 * (top - s.pos[:, 2]) / c["b"]) ** (1 / c["gamma"])
    bottom = (s.ptype == 0) & (s.pos[:, 2] <= 0) & (s.pos[:, 0] > 0.05) & (s.pos[:, 0] < 0.25)
    assert bottom.sum() > 30
    err = np.abs(s.rhop[bottom] - rho_h[bottom]) / (rho_h[bottom] - c["rhop0"])
    print("mDBC bottom density error relative to the hydrostatic excess: %.2e" % err.max())
    assert err.max() < 1e-3
    # DBC leaves them at rho0 at this point
    dbc = SPHSolver(tank_2d(0.3, 0.3, 0.3, 0.2, dp, layers=3)[0], c, {})
    dbc.state.rhop[dbc.state.ptype < 2] = c["rhop0"]
    dbc.compute_rates()
    assert np.all(dbc.state.rhop[dbc.state.ptype < 2] == c["rhop0"])


def test_mdbc_tank_runs_and_stays_still():
    dp = 0.02
    st, c = tank_2d(0.4, 0.4, 0.4, 0.3, dp, layers=3, bound_hydrostatic=True)
    sol = SPHSolver(st, c, {"Boundary": 2, "StepAlgorithm": 2, "DensityDT": 2, "Visco": 0.05},
                    normals=tank_normals_2d(st, 0.4, dp))
    sol.run(0.3)
    fl = sol.state.ptype == 3
    assert sol.state.n == st.n
    assert np.abs(sol.state.vel[fl]).max() < 0.02
