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
neighbour terms by ~1.2 %, the lattice sum of the Wendland kernel at
h = sqrt(2) dp by 0.8 %) plus the DBC wall offset.  With mDBC no-slip
(SlipMode 2) the wall offset is gone and the centre-line speed is +2.1 % at
20, 30 and 40 across, the operator's bias predicted by its lattice sum
(1/0.9802).  ViscoLaminarEta 0 (sphdvi's key; the exact Morris operator)
removes the regulariser's 1.2 %: +0.86 % at 30 across, +0.84 % at 40, inside
the 1 % of S9; the start-up transient follows the Morris et al. series within
0.6 % of u_max (1.4 % with DualSPHysics's operator).

With DualSPHysics's ghost velocity (MdbcGhostVelocity 0: the plain kernel
average of the velocity at the ghost node, one-sided and too fast near the
wall) the no-slip wall acts 0.13-0.15 dp inside the water and cancels part of
the operator's bias: centre-line -0.62 % (20 across), +0.17 % (30), as the
steady state of the lattice model (the operator on the particle lattice with
those walls, :func:`mdbc2_lattice_centreline`) predicts: -0.65 %, +0.14 %;
with ViscoLaminarEta 0, -1.05 % at 30 across (predicted -1.08 %), outside the
1 % of S9.  The Verlet integrator is
unstable here (leapfrog applied to diffusion), as expected.
"""
import math

import numpy as np
import pytest

from sphdvi.sph import SPHSolver
from sphdvi.sph.state import FluidState
from sphdvi.validation.poiseuille import series_profile, wendland_lattice_pairs

D = 1e-3
NU = 1e-6
F = 2e-4
UMAX = F * D * D / (8 * NU)


def run_poiseuille(n, t_end=D * D / NU, nx=12, layers=3, artificial=False, coefh=1.0,
                   slip=None, eta=None, sample_times=(), ghostvel=None):
    """slip None: DBC walls with their first layer on z = 0 and z = d.  slip
    1/2/3: mDBC (SlipMode) with the walls' surfaces on z = 0 and z = d, the
    wall particles dp/2, 3dp/2, ... outside and n fluid rows inside.  ``eta``:
    ViscoLaminarEta (None: DualSPHysics's 0.1); ``ghostvel``: MdbcGhostVelocity
    (None: the default, corrected).  ``sample_times`` (units of
    d^2/nu): the largest |u - series|/u_max at each is returned in "transient"."""
    dp = D / n
    xs = np.arange(nx) * dp
    if slip is None:
        fz = np.arange(1, n) * dp
        bz = np.r_[-np.arange(layers) * dp, D + np.arange(layers) * dp]
    else:
        fz = (np.arange(n) + 0.5) * dp
        bz = np.r_[-(np.arange(layers) + 0.5) * dp, D + (np.arange(layers) + 0.5) * dp]
    X, Z = np.meshgrid(xs, fz)
    fl = np.stack([X.ravel(), 0 * X.ravel(), Z.ravel()], 1)
    X, Z = np.meshgrid(xs, bz)
    bd = np.stack([X.ravel(), 0 * X.ravel(), Z.ravel()], 1)
    pos = np.concatenate([bd, fl])
    pt = np.r_[np.zeros(len(bd), np.int8), np.full(len(fl), 3, np.int8)]
    c0 = 10 * UMAX
    h = coefh * math.sqrt(2) * dp
    c = {"dp": dp, "h": h, "cs0": c0, "rhop0": 1000.0, "gamma": 7.0, "b": c0 ** 2 * 1000 / 7,
         "gravity": [F, 0.0, 0.0], "is2d": True, "cflnumber": 0.2}
    st = FluidState(pos, mass=1000 * dp * dp, ptype=pt)
    if artificial:   # alpha for nu = alpha h c0 / 8 (Monaghan 2005, 2D)
        visc = {"ViscoTreatment": 1, "Visco": 8 * NU / (h * c0)}
    else:
        visc = {"ViscoTreatment": 3, "Visco": NU}
    extra, normals = {}, None
    if slip is not None:
        extra = {"Boundary": 2, "SlipMode": slip}
        normals = np.zeros((len(pos), 3))
        nbd = len(bd)
        normals[:nbd, 2] = np.where(bd[:, 2] < 0, -bd[:, 2], D - bd[:, 2])
    if eta is not None:
        extra["ViscoLaminarEta"] = eta
    if ghostvel is not None:
        extra["MdbcGhostVelocity"] = ghostvel
    sol = SPHSolver(st, c, {"StepAlgorithm": 2, "DtFixed": 0.1 * h * h / NU, "DtMin": 0.01 * h * h / NU, **visc, **extra},
                    periodic="x", normals=normals)
    transient = []
    for ts in sample_times:
        sol.run(ts * D * D / NU)
        f = sol.state.ptype == 3
        ua = series_profile(sol.state.pos[f, 2], sol.time)
        transient.append(float(np.abs(sol.state.vel[f, 0] - ua).max() / UMAX))
    sol.run(t_end)
    s = sol.state
    f = s.ptype == 3
    z, u = s.pos[f, 2], s.vel[f, 0]
    centre = np.abs(z - D / 2) < 0.6 * dp
    ua = F / (2 * NU) * z * (D - z)
    res = {"uc": float(u[centre].mean() / UMAX),
           "l2": float(np.sqrt(np.mean((u - ua) ** 2)) / UMAX),
           "wmax": float(np.abs(s.vel[f, 2]).max() / UMAX),
           "spread": float((u.max() - u.min()) / abs(u.mean())),
           "xspan": float(s.pos[:, 0].max() - s.pos[:, 0].min()), "n": int(f.sum()),
           "n0": int((pt == 3).sum()), "transient": transient}
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


def laplacian_lattice_sum(coefh=1.0, eta2=0.01):
    """sum_b V_b z_ab^2 (r_ab . grad W_ab) / (r_ab^2 + eta^2 h^2) on a square
    lattice (Wendland 2D): -1 for an exact Laplacian of a quadratic profile.
    The laminar term's steady centre-line speed is u_max / |sum|."""
    h, x, z, rr, f = wendland_lattice_pairs(coefh)
    return float(np.sum(z * z * rr * rr * f / (rr * rr + eta2 * h * h)))


def mdbc2_lattice_centreline(n, coefh=1.0, eta2=0.01, operator="laminar", dim=2, layers=3):
    """Steady centre-line speed / u_max of the lattice model of the channel
    with mDBC no-slip walls (SlipMode 2) and DualSPHysics's ghost velocity
    (MdbcGhostVelocity 0): n fluid rows at (k + 1/2) dp and
    ``layers`` wall rows on each side, the particles on the (periodic, infinite)
    lattice, density rho0.  The viscous operator sums over lattice rows:
    ``laminar`` Lo & Shao's term (ViscoLaminarEta eta2 = (eta/h)^2), or
    ``monaghan`` DualSPHysics's artificial viscosity with alpha h c0 / 8 = nu
    on approaching pairs only (one of the two sides +-x of each row: half of
    the pair sum).  A wall row's velocity is minus the Shepard average
    sum V W u / sum V W of the fluid rows at its ghost node.  The steady state
    F + sum_b c_ab (u_a - u_b) = 0 is a linear system in the fluid rows."""
    dp = 1.0
    h = coefh * math.sqrt(float(dim)) * dp
    d = n * dp
    fz = (np.arange(n) + 0.5) * dp
    bz = np.r_[-(np.arange(layers) + 0.5) * dp, d + (np.arange(layers) + 0.5) * dp]
    off = np.arange(-int(2 * h / dp) - 1, int(2 * h / dp) + 2) * dp
    if dim == 2:
        x, y, vol, alpha = off, np.zeros_like(off), dp * dp, 7 / (4 * math.pi * h * h)
    else:
        X, Y = np.meshgrid(off, off)
        x, y, vol, alpha = X.ravel(), Y.ravel(), dp ** 3, 21 / (16 * math.pi * h ** 3)

    def row(dz):
        r2 = x * x + y * y + dz * dz
        q = np.sqrt(r2) / h
        t = np.clip(1 - q / 2, 0, None)
        m = q < 2
        return r2[m], alpha * t[m] ** 4 * (2 * q[m] + 1), -5 * alpha / h ** 2 * t[m] ** 3, x[m]

    def coef(dz):
        r2, w, fac, xx = row(dz)
        p = r2 > 0
        if operator == "laminar":        # nu = 1: 4 nu (m/(2 rho)) fac r^2/(r^2 + eta^2)
            return float(np.sum(vol * 2 * fac[p] * r2[p] / (r2[p] + eta2 * h * h)))
        return 0.5 * float(np.sum(vol * 8 * fac[p] * xx[p] ** 2 / (r2[p] + eta2 * h * h)))

    a = np.zeros((n, n))
    for i, za in enumerate(fz):
        for zj in fz:
            a[i, i] += coef(za - zj)
            a[i, fz == zj] -= coef(za - zj)
        for zb in bz:
            zg = -zb if zb < 0 else 2 * d - zb
            ws = np.array([row(zg - zj)[1].sum() for zj in fz])
            cc = coef(za - zb)
            a[i, i] += cc
            a[i] += cc * ws / ws.sum()           # u_b = -(Shepard average at the ghost node)
    u = np.linalg.solve(a, -np.ones(n))
    return float(u[np.abs(fz - d / 2) < 0.6 * dp].mean() / (d * d / 8))


def test_poiseuille_mdbc_no_slip():
    """mDBC SlipMode 2 (no-slip) with the wall surfaces on z = 0 and z = d:
    the wall offset of DBC is gone and the centre-line speed is the operator's
    own fixed-h/dp bias, 1/|lattice sum| = 1.0202 (Lo & Shao eta^2 = 0.01 h^2
    weakens it by 1.2 %, the lattice sum by 0.8 %).  Measured 1.0216 (20
    across) and 1.0210 (30); L2 error 1.84 % -> 1.65 %."""
    pred = 1.0 / abs(laplacian_lattice_sum())
    r20, r30 = run_poiseuille(20, slip=2), run_poiseuille(30, slip=2)
    d20 = run_poiseuille(20)
    for r in (r20, r30):
        assert r["n"] == r["n0"] and r["wmax"] < 1e-3
        assert abs(r["uc"] - pred) < 2e-3
    assert abs(r20["uc"] - 1) < abs(d20["uc"] - 1)        # better than DBC
    assert r30["l2"] < r20["l2"] < d20["l2"]
    print("Poiseuille mDBC no-slip: uc %.4f (20) %.4f (30), lattice prediction %.4f; L2 %.4f -> %.4f, "
          "observed order %.2f" % (r20["uc"], r30["uc"], pred, r20["l2"], r30["l2"],
                                   math.log(r20["l2"] / r30["l2"]) / math.log(1.5)))


def test_poiseuille_mdbc_no_slip_dualsphysics_ghost_velocity():
    """MdbcGhostVelocity 0 (DualSPHysics's Shepard ghost velocity): the lattice
    model with those no-slip walls predicts the centre-line speed 0.9935 (20
    across) and 1.0014 (30); measured 0.9938 and 1.0017; L2 error 1.20 % ->
    0.72 %.  The walls act 0.13-0.15 dp inside the water."""
    for n in (20, 30):
        r = run_poiseuille(n, slip=2, ghostvel=0)
        pred = mdbc2_lattice_centreline(n)
        print("Poiseuille mDBC no-slip, Shepard ghost velocity, n=%d: uc %.4f, lattice model %.4f, L2 %.4f"
              % (n, r["uc"], pred, r["l2"]))
        assert r["n"] == r["n0"] and r["wmax"] < 1e-3
        assert abs(r["uc"] - pred) < 1e-3


def test_channel_mdbc_free_slip_is_plug_flow():
    """mDBC SlipMode 3 (free-slip): the walls exert no shear, so the body force
    accelerates the whole layer uniformly, u = F t (no Poiseuille profile)."""
    t = 0.2 * D * D / NU
    r = run_poiseuille(20, t_end=t, slip=3)
    assert abs(r["uc"] * UMAX / (F * t) - 1) < 2e-3
    assert r["spread"] < 1e-3                  # flat profile
    assert r["wmax"] < 1e-6


def test_channel_mdbc_dbc_velocity_mode():
    """SlipMode 1 keeps the wall particles at the wall velocity; with the wall
    surface half a spacing inside the first layer the channel is effectively
    wider: the centre-line speed is well above u_max (measured 1.137)."""
    r = run_poiseuille(20, slip=1)
    assert 1.08 < r["uc"] < 1.2


def monaghan_lattice_ratio(coefh=1.0, eta2=0.01, approaching_only=True):
    """nu_eff / (alpha h c0 / 8) of DualSPHysics's artificial viscosity
    (Monaghan 1992, Pi_ab = -alpha c h (v_ab.r_ab)/(rho (r^2 + eta^2)))
    on a square lattice in a shear flow u(z) (Wendland 2D).

    The pair acceleration along x is alpha c0 h (du x_ab)/(r^2 + eta^2) x_ab
    F(r) V_b with du = u'z - u''z^2/2; the u' terms cancel, leaving
    nu_eff = -alpha c0 h/2 sum V_b x^2 z^2 F/(r^2 + eta^2).  In the continuum
    the sum is -1/4 and nu_eff = alpha h c0/8 (Monaghan 2005, 2D).  With the
    switch v_ab.r_ab < 0 only approaching pairs act; for each row z exactly
    one of the two sides +-x approaches, so the sum halves."""
    h, x, z, rr, f = wendland_lattice_pairs(coefh)
    ratio = -0.5 * h * float(np.sum(x * x * z * z * f / (rr * rr + eta2 * h * h))) * 8 / h
    return ratio * (0.5 if approaching_only else 1.0)


def test_monaghan_lattice_ratio_continuum_limit():
    """The lattice sum tends to the continuum value (ratio 1 without the
    switch) as h/dp grows: checks the sum used by the S10 prediction."""
    assert abs(monaghan_lattice_ratio(4.0, eta2=0.0, approaching_only=False) - 1) < 2e-3
    assert abs(monaghan_lattice_ratio(1.0) - 0.4262) < 1e-4


def test_s10_artificial_viscosity_equivalence():
    """S10: the flow driven with artificial viscosity only, alpha chosen so
    that alpha h c0 / 8 = nu, mDBC no-slip walls.

    DualSPHysics's Monaghan term acts only on approaching pairs
    (v_ab . r_ab < 0), which halves the viscosity of a shear flow, and on the
    square lattice at h = sqrt(2) dp the pair sum is 0.852 of its continuum
    value: nu_eff = 0.426 alpha h c0/8 (coefh 1.0), 0.459 (coefh 1.2), so the
    centre-line speed is u_max/0.426 = 2.346 u_max (2.179 at coefh 1.2).
    Measured 2.169 (20 across), 2.200 (30), 2.042 at coefh 1.2: -7.6, -6.2,
    -6.3 %, inside the ~10 % judgement of TOLERANCES S10 against this
    prediction.  The rest is the particle disorder the switch allows
    (vertical speeds ~0.5 u_max: receding pairs feel no viscosity).  (With
    sphdvi's earlier no-slip walls, which showed the viscosity the reflected
    normal velocity too rather than the tangential one alone, +4, +5, +3.5 %.)
    Against the literal nu_eff = alpha h c0/8 of TOLERANCES S10 the flow is
    2.4x too fast with DBC walls (strict xfail below)."""
    for n, coefh in ((20, 1.0), (30, 1.0), (20, 1.2)):
        r = run_poiseuille(n, artificial=True, slip=2, coefh=coefh)
        pred = 1 / monaghan_lattice_ratio(coefh)
        print("S10 n=%d coefh %.1f: centre-line %.4f u_max, predicted %.4f (%+.1f %%)"
              % (n, coefh, r["uc"], pred, 100 * (r["uc"] / pred - 1)))
        assert r["n"] == r["n0"]
        assert abs(r["uc"] / pred - 1) < 0.10


@pytest.mark.slow
def test_poiseuille_40_across():
    r = run_poiseuille(40)
    assert abs(r["uc"] - 1) < 0.035


def test_s9_tolerance_1_percent_exact_laminar_operator():
    """TOLERANCES S9: steady centre-line speed within 1 % at 30-40 across, the
    transient series within 2 %.  With DualSPHysics's regulariser
    (ViscoLaminarEta 0.1) the laminar operator is 1.2 % too weak on the
    nearest neighbours and the centre-line speed is +2.1 % at every
    resolution (test above); ViscoLaminarEta 0 gives the exact Morris
    operator (grad W / r is finite at r = 0, nothing to regularise) and leaves
    only the lattice sum's own bias (predicted 1/|sum| = 1.0078 at coefh 1.0,
    1.0062 at 1.2).  mDBC no-slip walls.  Measured centre-line +0.92 / +0.86 /
    +0.84 % (20 / 30 / 40 across, coefh 1.0), +0.82 / +0.70 / +0.66 %
    (coefh 1.2); largest transient error 0.72 / 0.60 / 0.55 % of u_max.
    (With DualSPHysics's ghost velocity, MdbcGhostVelocity 0, the walls' offset
    gives -1.05 % at 30 across: outside.)"""
    times = (0.0225, 0.045, 0.1125, 0.225)      # Morris et al. 1997 Fig. 2, t nu / d^2
    for n, coefh in ((30, 1.0), (30, 1.2)):
        r = run_poiseuille(n, slip=2, eta=0.0, coefh=coefh, sample_times=times)
        pred = 1.0 / abs(laplacian_lattice_sum(coefh, eta2=0.0))
        print("S9 n=%d coefh %.1f ViscoLaminarEta 0: centre-line %+.2f %% (lattice prediction %+.2f %%), "
              "transient max error %s %% of u_max"
              % (n, coefh, 100 * (r["uc"] - 1), 100 * (pred - 1), [round(100 * e, 2) for e in r["transient"]]))
        assert r["n"] == r["n0"] and r["wmax"] < 1e-3
        assert abs(r["uc"] - 1) < 0.01
        assert abs(r["uc"] - pred) < 1.5e-3
        assert max(r["transient"]) < 0.02


def test_s9_transient_series_dualsphysics_operator():
    """The start-up transient against the Morris et al. (1997) series with
    DualSPHysics's own operator (eta = 0.1 h): within 2 % of u_max at
    t nu/d^2 = 0.0225 ... 0.225 (measured 0.18 / 0.23 / 0.59 / 1.38 % at 30
    across); the error grows with t towards the steady +2.1 % bias."""
    r = run_poiseuille(30, slip=2, sample_times=(0.0225, 0.045, 0.1125, 0.225), t_end=0.225 * D * D / NU)
    print("S9 transient, eta 0.1 h: max error %s %% of u_max" % [round(100 * e, 2) for e in r["transient"]])
    assert max(r["transient"]) < 0.02
    assert r["transient"][0] < r["transient"][-1]


@pytest.mark.slow
@pytest.mark.xfail(strict=True, raises=AssertionError, reason="TOLERANCES S10: nu_eff = alpha h c0/8 within ~10 %; DualSPHysics's "
                                        "approaching-pairs switch and the lattice give 0.43x (measured ~0.41x)")
def test_s10_tolerance_10_percent():
    assert abs(run_poiseuille(20, artificial=True)["uc"] - 1) < 0.1


def run_channel_3d(n, slip, t_end, nxy=6, layers=3, ghostvel=1):
    """3D plane channel (periodic in x and y, mDBC walls with their surfaces on
    z = 0 and z = d), laminar viscosity, body force F along x."""
    dp = D / n
    xs = np.arange(nxy) * dp
    fz = (np.arange(n) + 0.5) * dp
    bz = np.r_[-(np.arange(layers) + 0.5) * dp, D + (np.arange(layers) + 0.5) * dp]

    def grid(zs):
        X, Y, Z = np.meshgrid(xs, xs, zs, indexing="ij")
        return np.stack([X.ravel(), Y.ravel(), Z.ravel()], 1)
    bd, fl = grid(bz), grid(fz)
    pos = np.concatenate([bd, fl])
    pt = np.r_[np.zeros(len(bd), np.int8), np.full(len(fl), 3, np.int8)]
    c0 = 10 * UMAX
    h = math.sqrt(3) * dp
    c = {"dp": dp, "h": h, "cs0": c0, "rhop0": 1000.0, "gamma": 7.0, "b": c0 ** 2 * 1000 / 7,
         "gravity": [F, 0.0, 0.0], "is2d": False, "cflnumber": 0.2}
    st = FluidState(pos, mass=1000 * dp ** 3, ptype=pt)
    normals = np.zeros((len(pos), 3))
    normals[:len(bd), 2] = np.where(bd[:, 2] < 0, -bd[:, 2], D - bd[:, 2])
    sol = SPHSolver(st, c, {"StepAlgorithm": 2, "DtFixed": 0.1 * h * h / NU, "DtMin": 0.01 * h * h / NU, "ViscoTreatment": 3,
                            "Visco": NU, "Boundary": 2, "SlipMode": slip, "MdbcGhostVelocity": ghostvel},
                    periodic="xy", normals=normals)
    sol.run(t_end)
    s = sol.state
    f = s.ptype == 3
    return s.pos[f], s.vel[f], int(f.sum()), len(fl), sol.time


def test_channel_3d_mdbc_slip_modes():
    """3D: free-slip gives the uniform u = F t; no-slip gives the parabolic
    profile (centre-line within 3 % of u_max, measured +2.1 %) and no
    cross-flow.  With DualSPHysics's ghost velocity (MdbcGhostVelocity 0) the
    walls' offset costs ~6 % at 10 across: the 3D lattice model predicts
    0.9612 u_max, measured 0.9612."""
    t = 0.2 * D * D / NU
    pos, vel, n, n0, t = run_channel_3d(10, 3, t)
    assert n == n0
    assert np.abs(vel[:, 0] / (F * t) - 1).max() < 2e-3
    for ghostvel in (1, 0):
        pos, vel, n, n0, t = run_channel_3d(10, 2, D * D / NU, ghostvel=ghostvel)
        z = pos[:, 2]
        centre = np.abs(z - D / 2) < 0.6 * D / 10
        uc = vel[centre, 0].mean() / UMAX
        pred = 1.0 if ghostvel else mdbc2_lattice_centreline(10, dim=3)
        print("3D channel no-slip (MdbcGhostVelocity %d) centre-line speed / u_max = %.4f, expected %.4f"
              % (ghostvel, uc, pred))
        assert n == n0
        assert abs(uc - pred) < (0.03 if ghostvel else 2e-3)
        assert np.abs(vel[:, 1:]).max() < 1e-3 * UMAX


def test_lattice_model_walls_offset_converges():
    """The lattice model's no-slip walls act a distance delta inside the water:
    centre-line speed = (operator's own value 1/|lattice sum|) (1 - 4 delta/d).
    delta/dp = 0.131, 0.142, 0.148 at 20, 40, 80 across: the increments halve
    as d/dp doubles (delta = delta_inf - c dp/d), delta_inf = 0.154 dp."""
    op = 1.0 / abs(laplacian_lattice_sum())
    delta = {n: n * (1 - mdbc2_lattice_centreline(n) / op) / 4 for n in (20, 40, 80)}
    ratio = (delta[80] - delta[40]) / (delta[40] - delta[20])
    print("lattice model wall offset / dp:", {n: round(v, 4) for n, v in delta.items()},
          "increment ratio %.3f, limit %.4f" % (ratio, 2 * delta[80] - delta[40]))
    assert abs(ratio - 0.5) < 0.05
    assert 0.1 < 2 * delta[80] - delta[40] < 0.2
