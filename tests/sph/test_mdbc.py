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


def test_mdbc_extrapolates_a_quadratic_field_from_the_ghost_node_at_twice_the_wall_distance():
    """A linear field is extrapolated exactly from a ghost node at any distance; a quadratic one,
    rho = rho0 + a z², is not, so it shows where the ghost node is.  DualSPHysics (JSphCpu_mdbc.cpp,
    InteractionMdbcCorrectionT2) puts it at r_g = r_b + 2 n (n the normal from the boundary
    particle to the wall, its length the distance) and sets rho_b = rho(r_g) + (r_b − r_g)·∇rho(r_g)
    from the first-order corrected interpolation there: with the exact rho and ∇rho at r_g that is
    a z_g² + (z_b − z_g) 2 a z_g.  The two deeper bottom layers (their ghost nodes 1 and 2 dp
    inside the fluid; the first's sits on the fluid's bottom row, half its kernel empty) match it
    within 5 % (measured 2.9 / 2.6 %, the interpolation's O(h²) error on a quadratic); a ghost node
    at r_b + 2 S n reads 15 / 12 % off for S = 0.95 / 1.05, 47 / 65 % for S = 0.75 / 1.25."""
    dp = 0.01
    st, c = tank_2d(0.3, 0.3, 0.3, 0.2, dp, layers=3)
    normals = tank_normals_2d(st, 0.3, dp)
    rho0, a = c["rhop0"], 2000.0                 # kg/m3 per m²: rho0 + 0.08 kg/m3 at the surface
    fluid = st.ptype == 3
    st.rhop[fluid] = rho0 + a * st.pos[fluid, 2] ** 2
    st.rhop[~fluid] = rho0
    row = np.empty(st.idp.max() + 1, np.int64)
    row[st.idp] = np.arange(st.n)
    sol = SPHSolver(st, c, {"Boundary": 2}, normals=normals)
    sol.compute_rates()
    s = sol.state
    nz = normals[row[s.idp], 2]                  # the normals handed in, in the solver's order
    deep = (s.ptype == 0) & (nz >= 1.5 * dp) & (s.pos[:, 0] > 0.05) & (s.pos[:, 0] < 0.25)
    assert deep.sum() > 30 and np.allclose(s.pos[deep, 2] + nz[deep], 0.5 * dp)   # the wall at z = dp/2
    zb = s.pos[deep, 2]
    zg = zb + 2 * nz[deep]
    expected = a * zg ** 2 + (zb - zg) * 2 * a * zg
    err = np.abs((s.rhop[deep] - rho0) / expected - 1)
    print("mDBC quadratic field: largest error %.2e of the ghost-node extrapolation" % err.max())
    assert err.max() < 0.05


def test_mdbc_slipmode_1_extrapolates_below_rho0_and_sets_dry_walls_to_rho0():
    """DualSPHysics v5.4 (JSphCpu_mdbc.cpp, InteractionMdbcCorrectionT2): the extrapolated
    density is stored as it comes, below rho0 where the hydrostatic line extends above
    the free surface (sphdvi clamped it to rho0 until 2026-11), and a boundary particle
    whose ghost node has no fluid within reach gets rho0, whatever its density was."""
    dp = 0.01
    st, c = tank_2d(0.3, 0.3, 0.3, 0.2, dp, layers=3)
    st.rhop[st.ptype < 2] = 1.01 * c["rhop0"]
    sol = SPHSolver(st, c, {"Boundary": 2}, normals=tank_normals_2d(st, 0.3, dp))
    sol.compute_rates()
    s = sol.state
    rho0 = c["rhop0"]
    top = 0.2 + 0.5 * dp
    rho_h = rho0 * (1 + rho0 * 9.81 * (top - s.pos[:, 2]) / c["b"]) ** (1 / c["gamma"])
    outer = (s.ptype == 0) & (s.pos[:, 0] < s.pos[s.ptype == 0, 0].min() + 0.5 * dp)
    z = s.pos[:, 2]
    above = outer & np.isclose(z, top + 0.5 * dp)          # ghost node dp/2 above the surface
    assert above.sum() == 1
    assert s.rhop[above][0] < rho0
    # the hydrostatic line's value there to 0.16 % of its deficit (clamped: 100 %)
    assert abs(s.rhop[above][0] - rho_h[above][0]) < 0.01 * (rho0 - rho_h[above][0])
    dry = outer & (z > top + 2 * dp)
    assert dry.sum() > 5 and np.all(s.rhop[dry] == rho0)


def test_mdbc_tank_runs_and_stays_still():
    dp = 0.02
    st, c = tank_2d(0.4, 0.4, 0.4, 0.3, dp, layers=3, bound_hydrostatic=True)
    sol = SPHSolver(st, c, {"Boundary": 2, "StepAlgorithm": 2, "DensityDT": 2, "Visco": 0.05},
                    normals=tank_normals_2d(st, 0.4, dp))
    sol.run(0.3)
    fl = sol.state.ptype == 3
    assert sol.state.n == st.n
    assert np.abs(sol.state.vel[fl]).max() < 0.02


def _mdbc_calls_per_step(monkeypatch, params, steps=3):
    """Number of mDBC corrections the solver runs per time step (the serial kernel is
    wrapped with a counter; the scene is below the threading threshold)."""
    from sphdvi.sph import mdbc
    calls = []
    real = mdbc.mdbc_serial

    def counted(*args):
        calls.append(1)
        return real(*args)

    monkeypatch.setattr(mdbc, "mdbc_serial", counted)
    dp = 0.02
    st, c = tank_2d(0.3, 0.3, 0.3, 0.2, dp, layers=3, bound_hydrostatic=True)
    sol = SPHSolver(st, c, {"Boundary": 2, "Visco": 0.05, **params}, normals=tank_normals_2d(st, 0.3, dp),
                    parallel_threshold=10 ** 9)
    for _ in range(steps):
        sol.step()
    return len(calls) / steps, sol


def test_symplectic_corrector_runs_mdbc_as_dualsphysics(monkeypatch):
    """DualSPHysics v5.4 (JSphCpuSingle::MdbcBoundCorrection): the correction runs before
    every interaction except the Symplectic corrector's, unless MdbcCorrector, which v5.4
    sets for its mDBC2 slip modes; v5.0-5.2 read it from the XML key MDBCCorrector."""
    import pytest
    assert _mdbc_calls_per_step(monkeypatch, {"StepAlgorithm": 1})[0] == 1
    assert _mdbc_calls_per_step(monkeypatch, {"StepAlgorithm": 2})[0] == 1
    assert _mdbc_calls_per_step(monkeypatch, {"StepAlgorithm": 2, "MDBCCorrector": 1})[0] == 2
    assert _mdbc_calls_per_step(monkeypatch, {"StepAlgorithm": 2, "SlipMode": 3})[0] == 2
    with pytest.warns(UserWarning, match="MDBCCorrector=0 is ignored"):
        n, sol = _mdbc_calls_per_step(monkeypatch, {"StepAlgorithm": 2, "SlipMode": 2, "MDBCCorrector": 0})
    assert n == 2 and sol.mdbc_corrector


def test_corrector_without_mdbc_keeps_the_predicted_wall_density():
    """Without MDBCCorrector the corrector's interaction sees the wall densities the
    predictor integrated, rho_b = max(rho_mdbc + dt/2 ar_b, rho0): one step gives the same
    state as a step whose corrector evaluation is handed exactly those densities."""
    dp = 0.02
    st, c = tank_2d(0.3, 0.3, 0.3, 0.2, dp, layers=3, bound_hydrostatic=True)
    nor = tank_normals_2d(st, 0.3, dp)
    params = {"Boundary": 2, "StepAlgorithm": 2, "Visco": 0.05, "DensityDT": 2}
    a = SPHSolver(st.copy(), c, params, normals=nor)
    b = SPHSolver(st.copy(), c, {**params, "MDBCCorrector": 1}, normals=nor)
    a.step()
    b.step()
    assert not np.array_equal(a.state.vel, b.state.vel)      # the option acts
    # replay a's step by hand: predictor with the correction, corrector without it
    r = SPHSolver(st.copy(), c, {**params, "MDBCCorrector": 1}, normals=nor)
    dt = r.dt_pre
    r._set_ip(dt)
    s = r.state
    r._reorder_next = True         # as step() does on step 0
    r.compute_rates()
    k = r._integrators(False)
    k["sym_pre"](s.pos, s.vel, s.rhop, r.pos_pre, r.vel_pre, r.rhop_pre, r.ace, r.ar, s.ptype, r.ip, r.out)
    predicted = s.rhop.copy()
    r.boundary = 1                 # the corrector's rates with the walls as they are
    r.compute_rates()
    r.boundary = 2
    bw = s.ptype < 2
    assert np.all(s.rhop[bw] == predicted[bw])
    k["sym_corr"](*r._corr_args())
    sa, sr = a.state.sorted_by_idp(), s.sorted_by_idp()
    for x, y in ((sa.pos, sr.pos), (sa.vel, sr.vel), (sa.rhop, sr.rhop)):
        assert np.array_equal(x, y)


def _tank_with_a_floating_floor(slip):
    """The hydrostatic column of the first test with a stretch of its floor (all three
    layers, 0.1 < x < 0.2) turned into floating particles, normals as the walls'."""
    dp = 0.01
    st, c = tank_2d(0.3, 0.3, 0.3, 0.2, dp, layers=3)
    nor = tank_normals_2d(st, 0.3, dp)
    x, z = st.pos[:, 0], st.pos[:, 2]
    body = (st.ptype == 0) & (z <= 0) & (x > 0.1) & (x < 0.2)
    st.ptype[body] = 2
    st.rhop[st.ptype < 3] = c["rhop0"]
    sol = SPHSolver(st, c, {"Boundary": 2, "SlipMode": slip}, normals=nor)
    return sol, body, c, dp


def test_mdbc_sets_the_density_of_floating_particles_with_slipmode_1():
    """SlipMode 1 corrects floating particles with a normal as it does walls
    (DualSPHysics's UseNormalsFt): their density is the hydrostatic one at the particle,
    to the accuracy of the walls beside them."""
    sol, body, c, dp = _tank_with_a_floating_floor(1)
    sol.compute_rates()
    s = sol.state
    top = 0.2 + 0.5 * dp
    rho_h = c["rhop0"] * (1 + c["rhop0"] * 9.81 * (top - s.pos[:, 2]) / c["b"]) ** (1 / c["gamma"])
    err = np.abs(s.rhop[body] - rho_h[body]) / (rho_h[body] - c["rhop0"])
    assert body.sum() == 27 and err.max() < 1e-3


def test_slipmode_2_and_3_give_floating_particles_the_walls_density():
    """DualSPHysics v5.4 runs mDBC2 over the floating particles too (UseNormalsFt): their
    density is the pressure-cloned one the same particles get as fixed walls, to round-off;
    one whose ghost node is dry (a floating stretch of the side wall above the water)
    gets rho0, as a wall does."""
    import warnings
    for slip in (2, 3):
        with warnings.catch_warnings():
            warnings.simplefilter("error")            # no "floating bodies keep DBC" any more
            sol, body, c, dp = _tank_with_a_floating_floor(slip)
        s = sol.state
        dry = (s.ptype == 0) & (s.pos[:, 0] < 0) & (s.pos[:, 2] > 0.25)
        s.ptype[dry] = 2
        s.rhop[dry] = 1.01 * c["rhop0"]
        sol.compute_rates()
        st, c = tank_2d(0.3, 0.3, 0.3, 0.2, dp, layers=3)
        st.rhop[st.ptype < 3] = c["rhop0"]
        walls = SPHSolver(st, c, {"Boundary": 2, "SlipMode": slip}, normals=tank_normals_2d(st, 0.3, dp))
        walls.compute_rates()
        a, b = s.sorted_by_idp(), walls.state.sorted_by_idp()
        sel = np.isin(a.idp, s.idp[body])
        assert sel.sum() == 27
        assert np.all(a.rhop[sel] > c["rhop0"])
        assert np.allclose(a.rhop[sel], b.rhop[sel], rtol=0, atol=1e-9 * c["rhop0"])
        assert dry.sum() > 5 and np.all(s.rhop[dry] == c["rhop0"])
