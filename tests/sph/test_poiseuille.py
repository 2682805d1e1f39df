"""S9 Poiseuille flow with laminar viscosity (ViscoTreatment 3), periodic in x.

Morris, Fox & Zhu (1997) set-up: plates d = 1e-3 m apart, nu = 1e-6 m^2/s,
body force F = 2e-4 m/s^2 along x, steady u(z) = F z (d - z) / (2 nu),
u_max = F d^2 / (8 nu) = 2.5e-5 m/s.  2D, 12 particle columns in a
periodic x box, three layers of DBC wall particles at z <= 0 and z >= d
(the first wall layers on z = 0 and z = d), c0 = 10 u_max, Symplectic,
DtFixed = 0.1 h^2/nu (DualSPHysics's dt rule has no viscous-diffusion limit),
run to t = d^2/nu (the slowest transient mode has decayed by e^-pi^2).

Measured: centre-line speed / u_max = 1.035 (n = 20 across), 1.030 (30),
1.027 (40): above the 1 % of TOLERANCES S9; the error falls slowly with dp
(observed order ~0.5).  The remaining ~2.5 % is a fixed-h/dp bias of the
Lo & Shao operator (its eta^2 = 0.01 h^2 regulariser weakens the nearest
neighbour terms by ~2 %) plus the DBC wall offset.  The Verlet integrator
is unstable here (leapfrog applied to diffusion), as expected.
"""
import math

import numpy as np
import pytest

from sphdvi.sph import SPHSolver
from sphdvi.sph.state import FluidState

D = 1e-3
NU = 1e-6
F = 2e-4
UMAX = F * D * D / (8 * NU)


def run_poiseuille(n, t_end=D * D / NU, nx=12, layers=3, artificial=False):
    dp = D / n
    xs = np.arange(nx) * dp
    fz = np.arange(1, n) * dp
    bz = np.r_[-np.arange(layers) * dp, D + np.arange(layers) * dp]
    X, Z = np.meshgrid(xs, fz)
    fl = np.stack([X.ravel(), 0 * X.ravel(), Z.ravel()], 1)
    X, Z = np.meshgrid(xs, bz)
    bd = np.stack([X.ravel(), 0 * X.ravel(), Z.ravel()], 1)
    pos = np.concatenate([bd, fl])
    pt = np.r_[np.zeros(len(bd), np.int8), np.full(len(fl), 3, np.int8)]
    c0 = 10 * UMAX
    h = math.sqrt(2) * dp
    c = {"dp": dp, "h": h, "cs0": c0, "rhop0": 1000.0, "gamma": 7.0, "b": c0 ** 2 * 1000 / 7,
         "gravity": [F, 0.0, 0.0], "is2d": True, "cflnumber": 0.2}
    st = FluidState(pos, mass=1000 * dp * dp, ptype=pt)
    if artificial:   # alpha for nu = alpha h c0 / 8 (Monaghan 2005, 2D)
        visc = {"ViscoTreatment": 1, "Visco": 8 * NU / (h * c0)}
    else:
        visc = {"ViscoTreatment": 3, "Visco": NU}
    sol = SPHSolver(st, c, {"StepAlgorithm": 2, "DtFixed": 0.1 * h * h / NU, **visc},
                    periodic="x")
    sol.run(t_end)
    s = sol.state
    f = s.ptype == 3
    z, u = s.pos[f, 2], s.vel[f, 0]
    centre = np.abs(z - D / 2) < 0.6 * dp
    ua = F / (2 * NU) * z * (D - z)
    res = {"uc": float(u[centre].mean() / UMAX),
           "l2": float(np.sqrt(np.mean((u - ua) ** 2)) / UMAX),
           "wmax": float(np.abs(s.vel[f, 2]).max() / UMAX),
           "xspan": float(s.pos[:, 0].max() - s.pos[:, 0].min()), "n": int(f.sum()),
           "n0": int((pt == 3).sum())}
    print("Poiseuille n=%d: %s" % (n, res))
    return res


def test_poiseuille_laminar_periodic():
    r20, r30 = run_poiseuille(20), run_poiseuille(30)
    for r in (r20, r30):
        assert r["n"] == r["n0"]
        assert r["xspan"] < 12 * D / 20 + 1e-12      # particles stay in the periodic box
        assert r["wmax"] < 1e-3                       # flow stays parallel
    assert abs(r30["uc"] - 1) < 0.04
    assert r30["l2"] < 0.03
    e20, e30 = abs(r20["uc"] - 1), abs(r30["uc"] - 1)
    print("Poiseuille centre-line error %.4f -> %.4f, observed order %.2f"
          % (e20, e30, math.log(e20 / e30) / math.log(30 / 20)))
    assert e30 < e20


def test_s10_artificial_viscosity_equivalence():
    """S10: the same flow driven with artificial viscosity only, alpha chosen so
    that alpha h c0 / 8 = nu.  DualSPHysics's Monaghan term acts only on
    approaching pairs (v_ab . r_ab < 0), so in a steady shear flow roughly half
    the pairs contribute: the measured centre-line speed is 2.53 u_max (n = 20),
    i.e. nu_eff ~ 0.4 alpha h c0 / 8, far outside the ~10 % judgement of
    TOLERANCES S10.  The particles also leave their rows (vertical speeds up to
    ~0.5 u_max).  Asserted as a regression band around the measured value."""
    r = run_poiseuille(20, artificial=True)
    assert 2.2 < r["uc"] < 2.9
    assert r["n"] == r["n0"]


@pytest.mark.slow
def test_poiseuille_40_across():
    r = run_poiseuille(40)
    assert abs(r["uc"] - 1) < 0.035


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="TOLERANCES S9: centre-line speed within 1 % at 30-40 across; "
                                        "measured +3.0 % (30) and +2.7 % (40)")
def test_s9_tolerance_1_percent():
    assert abs(run_poiseuille(30)["uc"] - 1) < 0.01


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="TOLERANCES S10: nu_eff = alpha h c0/8 within ~10 %; measured ~0.4x")
def test_s10_tolerance_10_percent():
    assert abs(run_poiseuille(20, artificial=True)["uc"] - 1) < 0.1
