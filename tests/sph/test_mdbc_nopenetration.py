"""mDBC NoPenetration (Boundary=2, SlipMode 2/3): the velocity correction of the
fluid particles that approach a wall surface (sphdvi.sph.nopen).

Measured here (dp = 0.01, 2D):

* one particle over a flat wall: the correction is -f u n with
  f = 2.5 - 2 max(d/dp, 0.25) to 1e-12 (d its height over the first wall layer,
  u its normal velocity relative to the wall), nothing from d = 0.75 dp up, when
  it moves away, or from the second wall layer; the same from the ghost copies
  of a wall across a periodic boundary;
* dam break (column 0.1 x 0.2 m in a 0.4 m tank, to t = 0.45 s, over the impact
  on the right wall at t ~ 0.3 s): without NoPenetration fluid particles cross
  the wall surfaces (SlipMode 2 Verlet / Symplectic: min distance to the surface
  -1.21 / -1.44 dp, 6 / 4 particles behind it at once; SlipMode 3 Verlet -0.89 dp,
  2 particles; SlipMode 3 Symplectic +0.06 dp, none); with it none crosses and
  the min distance is 0.248 / 0.250 / 0.247 / 0.249 dp, against the bound
  dp/4 - max |v| dt of the method (the correction starts dp/4 in front of the
  surface and a particle moves at most |v| dt between two corrections);
* hydrostatic tank (S1 set-up, mDBC SlipMode 2, H/dp = 20, to 5 sqrt(H/g)) with
  NoPenetration: no correction is ever triggered (so the run is the one without
  it), max pointwise pressure error 1.31 % (S1 tolerance 2 %), max |u|
  4.4e-4 sqrt(gH).
"""
import math
import warnings

import numpy as np
import pytest

from sphdvi.sph import SPHSolver
from sphdvi.sph.scenes import constants_2d, shepard_pressure, tank_2d, tank_normals_2d
from sphdvi.sph.state import FIXED, FLUID, MOVING, FluidState

DP = 0.01


def flat_wall(fluid_pos, fluid_vel, wall_vel=(0.0, 0.0, 0.0), layers=3, half_width=12,
              moving=False):
    """2D wall of ``layers`` rows (z = 0, -dp, ...; surface at z = dp/2) and
    the given fluid particles; normals (0, 0, (k + 1/2) dp)."""
    xs = np.arange(-half_width, half_width + 1) * DP
    bd = np.array([[x, 0.0, -k * DP] for k in range(layers) for x in xs])
    fl = np.asarray(fluid_pos, float).reshape(-1, 3)
    pos = np.concatenate([bd, fl])
    nb = len(bd)
    ptype = np.r_[np.full(nb, MOVING if moving else FIXED, np.int8), np.full(len(fl), FLUID, np.int8)]
    vel = np.zeros_like(pos)
    vel[:nb] = wall_vel
    vel[nb:] = np.asarray(fluid_vel, float).reshape(-1, 3)
    normals = np.zeros_like(pos)
    normals[:nb, 2] = 0.5 * DP - bd[:, 2]
    st = FluidState(pos, vel, mass=1000.0 * DP * DP, ptype=ptype)
    return st, normals, nb


def correction(st, normals, params=None, **kw):
    """npshift rows of the fluid particles after one interaction (by idp)."""
    c = constants_2d(DP, g=0.0, cs0=20.0)
    p = {"Boundary": 2, "SlipMode": 2, "NoPenetration": 1, **(params or {})}
    sol = SPHSolver(st, c, p, normals=normals, **kw)
    sol.compute_rates()
    order = np.argsort(sol.state.idp)
    return sol.npshift[order], sol


def expected_f(d):
    """DualSPHysics's factor for a first-layer particle (|N| = dp/2)."""
    return 2.5 - 2.0 * max(d / DP, 0.25)


@pytest.mark.parametrize("d", [0.74, 0.6, 0.5, 0.3, 0.2, 0.0, -0.3])
def test_one_particle_correction_is_the_formula(d):
    """Fluid particle at height d dp over the first wall layer (surface at
    dp/2), approaching at 1 m/s with a tangential speed of 0.3 m/s: the
    correction removes (f = 1) up to reflects (f = 2) the normal velocity and
    leaves the tangential one."""
    u = (0.3, 0.0, -1.0)
    st, normals, nb = flat_wall([(0.2 * DP, 0.0, d * DP)], [u])
    npshift, _ = correction(st, normals)
    row = npshift[nb]
    f = expected_f(d * DP)
    print("d = %.2f dp: correction %s, expected f = %.3f" % (d, row[:4], f))
    assert row[3] == 1.0
    assert row[0] == 0.0 and row[1] == 0.0
    assert abs(row[2] - f * 1.0) < 1e-12
    # normal velocity after the correction: (1 - f) u, between 0 and +1 m/s
    assert 0.0 <= u[2] + row[2] <= 1.0 + 1e-12


@pytest.mark.parametrize("d, u, wall", [
    (0.76, (0.0, 0.0, -1.0), (0.0, 0.0, 0.0)),     # beyond dp/4 in front of the surface
    (0.5, (0.0, 0.0, 0.5), (0.0, 0.0, 0.0)),       # moving away from the wall
    (0.5, (1.0, 0.0, 0.0), (0.0, 0.0, 0.0)),       # moving along it
    (0.5, (0.0, 0.0, -1.0), (0.0, 0.0, -2.0)),     # the wall recedes faster
])
def test_no_correction(d, u, wall):
    st, normals, nb = flat_wall([(0.0, 0.0, d * DP)], [u], wall_vel=wall, moving=True)
    npshift, _ = correction(st, normals)
    assert npshift[nb, 3] == 0.0


def test_moving_wall_uses_the_relative_velocity():
    """Fluid at rest, wall moving up at 1 m/s: the relative normal velocity is
    -1 m/s, the fluid particle gets f * 1 m/s upwards."""
    st, normals, nb = flat_wall([(0.0, 0.0, 0.4 * DP)], [(0.0, 0.0, 0.0)],
                                wall_vel=(0.0, 0.0, 1.0), moving=True)
    npshift, _ = correction(st, normals)
    assert npshift[nb, 3] == 1.0
    assert abs(npshift[nb, 2] - expected_f(0.4 * DP)) < 1e-12


def test_only_the_first_layer_and_3d():
    """3D wall in the y-z plane (surface x = dp/2, two layers: |N| = dp/2 and
    3 dp/2) and a fluid particle at x = 0.6 dp moving at (-1, 0.5, 0.2) m/s:
    only the first layer acts (the second would see it at 0.53 of its normal
    length, inside its own trigger band, and change the mean), the correction
    is (f, 0, 0) with f = 2.5 - 2 * 0.6."""
    g = np.arange(-5, 6) * DP
    Y, Z = np.meshgrid(g, g)
    bd = np.concatenate([np.stack([np.full(Y.size, -k * DP), Y.ravel(), Z.ravel()], 1)
                         for k in range(2)])
    fpos = np.array([[0.6 * DP, 0.3 * DP, -0.2 * DP]])
    pos = np.concatenate([bd, fpos])
    nb = len(bd)
    ptype = np.r_[np.zeros(nb, np.int8), np.full(1, FLUID, np.int8)]
    vel = np.zeros_like(pos)
    vel[nb] = (-1.0, 0.5, 0.2)
    normals = np.zeros_like(pos)
    normals[:nb, 0] = 0.5 * DP - bd[:, 0]
    st = FluidState(pos, vel, mass=1000.0 * DP ** 3, ptype=ptype)
    c = {"dp": DP, "h": math.sqrt(3) * DP, "cs0": 20.0, "rhop0": 1000.0, "gamma": 7.0,
         "b": 400 * 1000 / 7.0, "gravity": [0.0, 0.0, 0.0], "is2d": False, "cflnumber": 0.2}
    sol = SPHSolver(st, c, {"Boundary": 2, "SlipMode": 3, "NoPenetration": 1}, normals=normals)
    sol.compute_rates()
    row = sol.npshift[np.argsort(sol.state.idp)][nb]
    f = expected_f(0.6 * DP)
    print("3D correction", row[:4], "expected", f)
    assert row[3] == 1.0
    assert abs(row[0] - f) < 1e-12 and row[1] == 0.0 and row[2] == 0.0


def test_periodic_ghost_of_the_wall_acts():
    """x-periodic box [0, 21 dp): a wall segment x = 0 ... 10 dp (three layers)
    and a fluid particle at x = 20 dp, 0.45 dp over the first layer: its only
    wall neighbours (within 1.25 dp) are the ghost copies of the segment's
    start across the periodic boundary, which give the correction of a flat
    wall."""
    xs = np.arange(11) * DP
    bd = np.array([[x, 0.0, -k * DP] for k in range(3) for x in xs])
    fl = np.array([[20.0 * DP, 0.0, 0.45 * DP], [15.0 * DP, 0.0, 5.0 * DP]])
    pos = np.concatenate([bd, fl])
    nb = len(bd)
    ptype = np.r_[np.zeros(nb, np.int8), np.full(2, FLUID, np.int8)]
    vel = np.zeros_like(pos)
    vel[nb] = (0.2, 0.0, -1.0)
    normals = np.zeros_like(pos)
    normals[:nb, 2] = 0.5 * DP - bd[:, 2]
    st = FluidState(pos, vel, mass=1000.0 * DP * DP, ptype=ptype)
    npshift, sol = correction(st, normals, periodic="x")
    assert abs(sol.periodicity.length[0] - 21 * DP) < 1e-12
    row = npshift[nb]
    print("correction through the periodic boundary", row[:4])
    assert row[3] == 1.0
    assert abs(row[2] - expected_f(0.45 * DP)) < 1e-12 and row[0] == 0.0
    assert npshift[nb + 1, 3] == 0.0
    # without periodicity the particle has no wall neighbour
    npshift, _ = correction(FluidState(pos, vel, mass=1000.0 * DP * DP, ptype=ptype), normals)
    assert npshift[nb, 3] == 0.0


@pytest.mark.parametrize("step", [1, 2])
def test_one_step_replaces_the_normal_component(step):
    """After a step the corrected component is v^n + dv and the particle moved
    by (v^n + dv) dt along it (Verlet; Symplectic with dv from the corrector);
    the tangential component keeps the integrator's value."""
    u = np.array([0.3, 0.0, -1.0])
    z0 = 0.45 * DP
    st, normals, nb = flat_wall([(0.0, 0.0, z0)], [u])
    c = constants_2d(DP, g=0.0, cs0=20.0)
    p = {"Boundary": 2, "SlipMode": 2, "NoPenetration": 1, "StepAlgorithm": step}
    sol = SPHSolver(st, c, p, normals=normals)
    ref = SPHSolver(flat_wall([(0.0, 0.0, z0)], [u])[0], c, dict(p, NoPenetration=0),
                    normals=normals)
    dt = sol.step()
    assert ref.step() == dt
    i = int(np.flatnonzero(sol.state.idp == nb)[0])
    j = int(np.flatnonzero(ref.state.idp == nb)[0])
    dv = sol.npshift[i, :3]
    v = sol.state.vel[i]
    print("step %d: dv %s, v^{n+1} %s, uncorrected %s" % (step, dv, v, ref.state.vel[j]))
    assert sol.npshift[i, 3] == 1.0 and dv[2] > 1.0
    assert abs(v[2] - (u[2] + dv[2])) < 1e-12
    assert abs(sol.state.pos[i, 2] - (z0 + v[2] * dt)) < 1e-15
    assert v[2] >= 0.0                                   # no longer approaching
    assert abs(v[0] - ref.state.vel[j, 0]) < 1e-12       # tangential: as without the correction
    assert abs(sol.state.pos[i, 0] - ref.state.pos[j, 0]) < 1e-15


W_DAM = 0.4


def dam_break(slip, step, nopen, t_end=0.45):
    """Column 0.1 x 0.2 m at the left of a 0.4 x 0.4 m tank, three wall layers with
    analytic normals, dp = 0.01.  Returns the minimum over the run of the fluid
    particles' distance to the nearest wall surface (negative: behind it), the
    largest count behind a surface at one time, the largest |v| dt of a fluid
    particle, the corrected particle-steps and the excluded particles."""
    st, c = tank_2d(W_DAM, 0.4, 0.1, 0.2, DP, layers=3)
    p = {"Boundary": 2, "SlipMode": slip, "StepAlgorithm": step, "Visco": 0.05,
         "DensityDT": 2, "NoPenetration": nopen}
    sol = SPHSolver(st, c, p, normals=tank_normals_2d(st, W_DAM, DP))
    dmin, ncross, disp, ncorr = np.inf, 0, 0.0, 0
    while sol.time < t_end:
        dt = sol.step()
        s = sol.state
        f = s.ptype == FLUID
        x, z = s.pos[f, 0], s.pos[f, 2]
        d = np.minimum(np.minimum(x - 0.5 * DP, W_DAM - 0.5 * DP - x), z - 0.5 * DP)
        dmin = min(dmin, float(d.min()))
        ncross = max(ncross, int(np.count_nonzero(d < 0)))
        disp = max(disp, float(np.linalg.norm(s.vel[f], axis=1).max()) * dt)
        if nopen:
            ncorr += int(sol.npshift[f, 3].sum())
    return {"dmin": dmin / DP, "ncross": ncross, "disp": disp / DP, "ncorr": ncorr,
            "excluded": sum(sol.n_excluded.values())}


@pytest.mark.parametrize("slip, step", [(2, 1), (2, 2), (3, 1), (3, 2)])
def test_dam_break_no_fluid_crosses_the_walls(slip, step):
    off = dam_break(slip, step, 0)
    on = dam_break(slip, step, 1)
    print("SlipMode %d StepAlgorithm %d  NoPenetration 0: %s  1: %s" % (slip, step, off, on))
    # with the correction: nobody behind a wall surface, and no closer than the
    # method's bound dp/4 - max |v| dt (in dp)
    assert on["ncross"] == 0 and on["excluded"] == 0
    assert on["dmin"] >= 0.25 - on["disp"] - 1e-9
    assert on["ncorr"] > 0
    # without it the fluid gets closer; with SlipMode 2 and Verlet / free-slip it crosses
    assert off["dmin"] < on["dmin"] - 0.15
    if (slip, step) != (3, 2):
        assert off["ncross"] > 0 and off["dmin"] < 0


def test_hydrostatic_tank_is_not_disturbed():
    """S1 set-up (tests/sph/test_hydrostatic.py) with mDBC SlipMode 2 and
    NoPenetration, run to 5 sqrt(H/g) (half the S1 run; pressures averaged
    over the last 30 %): the fluid at rest never triggers the correction and
    the pressure is hydrostatic within the S1 tolerance (2 %)."""
    H, G = 0.2, 9.81
    st, c = tank_2d(0.2, H + 4 * DP, 0.2, H, DP, layers=3, bound_hydrostatic=True)
    p = {"StepAlgorithm": 2, "Kernel": 2, "ViscoTreatment": 1, "Visco": 0.05, "DensityDT": 2,
         "DensityDTvalue": 0.1, "Boundary": 2, "SlipMode": 2, "NoPenetration": 1}
    sol = SPHSolver(st, c, p, normals=tank_normals_2d(st, 0.2, DP))
    fl = st.ptype == FLUID
    top = st.pos[fl, 2].max() + 0.5 * DP
    zs = np.linspace(0.025, 0.175, 7)
    probes = np.stack([np.full_like(zs, 0.1), 0 * zs, zs], 1)
    T = 5 * math.sqrt(H / G)
    acc, nacc, ncorr = np.zeros(len(zs)), 0, 0
    while sol.time < T:
        sol.step()
        ncorr += int(sol.npshift[sol.state.ptype == FLUID, 3].sum())
        if sol.time > 0.7 * T and sol.nstep % 5 == 0:
            acc += shepard_pressure(sol.state, sol.press, probes, c["h"])
            nacc += 1
    pref = c["rhop0"] * G * (top - zs)
    rel = float(np.max(np.abs(acc / nacc - pref) / pref))
    f = sol.state.ptype == FLUID
    umax = float(np.abs(sol.state.vel[f]).max() / math.sqrt(G * H))
    print("hydrostatic with NoPenetration: corrections %d, max relative error %.4f, max |u| %.2e sqrt(gH)"
          % (ncorr, rel, umax))
    assert ncorr == 0
    assert int(f.sum()) == int(fl.sum())
    assert rel < 0.02
    assert umax < 1e-3


@pytest.mark.parametrize("params", [{"Boundary": 1}, {"Boundary": 2, "SlipMode": 1}])
def test_ignored_without_mdbc2_slip_modes(params):
    """DualSPHysics reads NoPenetration only with Boundary=2 and SlipMode 2 or
    3; otherwise it is ignored.  Here it is ignored with a warning."""
    st, normals, _ = flat_wall([(0.0, 0.0, 0.4 * DP)], [(0.0, 0.0, -1.0)])
    c = constants_2d(DP, g=0.0, cs0=20.0)
    with pytest.warns(UserWarning, match="NoPenetration"):
        sol = SPHSolver(st, c, {**params, "NoPenetration": 1}, normals=normals)
    assert not sol.nopen and not hasattr(sol, "npshift")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sol = SPHSolver(st, c, {"Boundary": 2, "SlipMode": 2}, normals=normals)
    assert not sol.nopen and not hasattr(sol, "npshift")      # off by default: no work array


@pytest.mark.parametrize("step", [1, 2])
def test_threaded_kernels_agree_with_serial(step):
    """The threaded detection and correction kernels give the serial results
    bit for bit (a block of 3 x 11 particles crossing the correction band)."""
    import numba
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("numba has one thread")
    threads = numba.get_num_threads()     # an in-process CLI test may have set 1
    numba.set_num_threads(2)
    try:
        _threaded_vs_serial(step)
    finally:
        numba.set_num_threads(threads)


def _threaded_vs_serial(step):
    xs = np.arange(-5, 6) * DP
    fpos = np.array([[x + 0.1 * DP * k, 0.0, (0.55 + 0.9 * k) * DP] for k in range(3) for x in xs])
    fvel = np.tile([0.4, 0.0, -2.0], (len(fpos), 1))
    c = constants_2d(DP, g=9.81, cs0=20.0)
    p = {"Boundary": 2, "SlipMode": 3, "NoPenetration": 1, "StepAlgorithm": step}
    runs = []
    for thr in (10 ** 9, 0):
        st, normals, nb = flat_wall(fpos, fvel)
        sol = SPHSolver(st, c, p, normals=normals, parallel_threshold=thr, light_threshold=thr)
        ncorr = 0
        for _ in range(20):
            sol.step()
            ncorr += int(sol.npshift[sol.state.ptype == FLUID, 3].sum())
        o = np.argsort(sol.state.idp)
        runs.append((sol.state.pos[o], sol.state.vel[o], ncorr, sol._use_parallel()))
    (p0, v0, n0, par0), (p1, v1, n1, par1) = runs
    assert not par0 and par1
    assert n0 > 0 and n0 == n1
    assert np.array_equal(p0, p1) and np.array_equal(v0, v1)
