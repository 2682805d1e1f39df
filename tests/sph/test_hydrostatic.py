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
with h).  Probes measured relative to h (1.5h from the surface) gave 2.0 % /
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


def run_tank(dp, coefh=1.0):
    """Run (cached per dp) and return a dict of measurements."""
    if (dp, coefh) in _RUNS:
        return _RUNS[(dp, coefh)]
    st, c = tank_2d(W, H + 4 * dp, W, H, dp, layers=3, bound_hydrostatic=True, coefh=coefh)
    sol = SPHSolver(st, c, PARAMS)
    h = c["h"]
    fl = st.ptype == 3
    top = st.pos[fl, 2].max() + 0.5 * dp
    zcm0 = st.pos[fl, 2].mean()
    nfluid0 = int(fl.sum())
    T = 10.0 * math.sqrt(H / G)
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
        "umax": float(u.max() / math.sqrt(G * H)),
        "urms": float(np.sqrt(np.mean(u ** 2)) / math.sqrt(G * H)),
        "dzcm": float((sol.state.pos[fl, 2].mean() - zcm0) / dp),
        "nfluid": int(fl.sum()), "nfluid0": nfluid0, "mass": float(sol.state.mass[fl].sum()),
        "steps": sol.nstep,
    }
    print("S1/S2 dp=%g coefh=%g: %s" % (dp, coefh, res))
    _RUNS[(dp, coefh)] = res
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


def test_s1_error_falls_when_h_falls_slower_than_dp():
    """At fixed h/dp the pressure error stalls near 1 % (the kernel-gradient
    lattice sum, -0.992 at h = sqrt(2) dp); SPH converges when h -> 0 and
    dp/h -> 0 together (Quinlan et al. 2006).  Path h ~ dp^(1/2): dp = 0.01,
    h/dp = 1.41 -> dp = 0.005, h/dp = 2.0: max |p - rho0 g (H - z)| / (rho0 g H)
    1.15 % -> 0.49 % (order 1.2).  The next point (dp = 0.0025, h/dp = 2.83,
    slow test) stalls at 0.51 %: another error of ~0.5 % that does not depend
    on h/dp remains (not the column's compression: the weight of the water
    above each probe gives the same figures)."""
    coarse, fine = run_tank(0.01), run_tank(0.005, coefh=math.sqrt(2))
    order = math.log2(coarse["einf"] / fine["einf"])
    print("S1 h ~ dp^1/2: max |p - p_ref| / (rho g H) %.4f -> %.4f, observed order %.2f"
          % (coarse["einf"], fine["einf"], order))
    assert fine["einf"] < 0.6 * coarse["einf"]
    assert abs(fine["wall_force"] - 1) < 0.01 and fine["rel_max"] < 0.02


@pytest.mark.slow
def test_s1_three_resolutions():
    errs = [run_tank(dp) for dp in (0.01, 0.005, 0.0025)]
    rel = [e["rel_max"] for e in errs]
    orders = [math.log2(rel[k] / rel[k + 1]) for k in range(2)]
    print("S1 pointwise relative errors", rel, "observed orders", orders)
    assert rel[2] < rel[0]
