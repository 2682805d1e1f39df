"""S9 / S10: plane Poiseuille flow between two fixed plates, driven by a body force.

Set-up of Morris, Fox & Zhu (1997) *J. Comput. Phys.* 136:214: plates a distance d apart
(walls on z = 0 and z = d), kinematic viscosity ν, body force F along x, fluid at rest at
t = 0. The steady profile is

    u(z) = F z (d − z) / (2ν),            u_max = u(d/2) = F d² / (8ν)                  (1)

and the start-up from rest is Morris et al.'s eq. (21):

    u(z, t) = F z (d − z)/(2ν)
              − Σ_{n≥0} 4 F d² / (ν π³ (2n+1)³) sin((2n+1) π z/d) exp(−(2n+1)² π² ν t/d²)  (2)

S10 drives the same flow with DualSPHysics's artificial viscosity alone (ViscoTreatment 1):
Monaghan (2005) gives ν_eff = α h c0 / (2(dim + 2)) = α h c0 / 8 in 2-D. DualSPHysics's term
acts on approaching pairs only (v_ab·r_ab < 0), which halves it in a shear flow, and on the
square lattice the pair sum is not its continuum value: the "operator prediction" is

    ν_eff = R α h c0 / 8,   R = ½ · (−4 Σ_b x_ab² z_ab² F(r_ab) / (r_ab² + η² h²))            (3)

on the unit square lattice (dp = 1, V_b = 1, F = (dW/dr)/r of the Wendland kernel; the factor
−4 Σ is 1 in the continuum, the ½ is the approaching-pairs switch): R = 0.426 at h = √2 dp,
η² = 0.01 (:func:`monaghan_lattice_ratio`), so the centre-line speed is F d²/(8 ν_eff).

The case file ``cases/poiseuille2d/CasePoiseuille2D_Def.xml`` is this channel (12 periodic
columns, mDBC no-slip walls); :func:`case_errors` scores a run of it. :data:`RESOLUTIONS`
(S9, laminar) and :data:`RESOLUTIONS_S10` (artificial viscosity) hold the ``--dp`` and
``--set`` arguments of the runs at 20, 30 and 40 particles across.
"""
from __future__ import annotations

import math
import os

import numpy as np

D = 1e-3            # plate distance [m]
NU = 1e-6           # kinematic viscosity [m^2/s]
F = 2e-4            # body force [m/s^2]
C0 = 2.5e-4         # speed of sound of the case file: 10 u_max
COEFH = 1.0         # h = coefh sqrt(2) dp (the case file's coefh)
TRANSIENT_WINDOW = 0.25     # t nu/d^2 up to which the outputs count as the transient (Morris Fig. 2: 0.225)


def u_max(f: float = F, nu: float = NU, d: float = D) -> float:
    """Centre-line speed of the steady profile, eq. (1): F d² / (8ν)."""
    return f * d * d / (8 * nu)


def steady_profile(z, f: float = F, nu: float = NU, d: float = D) -> np.ndarray:
    """Steady Poiseuille profile, eq. (1): u(z) = F z (d − z) / (2ν), walls on z = 0 and z = d."""
    z = np.asarray(z, dtype=float)
    return f * z * (d - z) / (2 * nu)


def series_profile(z, t: float, f: float = F, nu: float = NU, d: float = D, terms: int = 200) -> np.ndarray:
    """Start-up Poiseuille flow from rest, Morris, Fox & Zhu (1997) eq. (21) (eq. (2) above):
    u(z,t) = F z (d − z)/(2ν) − Σ_n 4 F d²/(ν π³ (2n+1)³) sin((2n+1) π z/d) exp(−(2n+1)² π² ν t/d²)."""
    z = np.atleast_1d(np.asarray(z, dtype=float))
    k = 2 * np.arange(terms)[:, None] + 1
    modes = 4 * f * d * d / (nu * math.pi ** 3 * k ** 3) * np.sin(k * math.pi * z[None, :] / d) \
        * np.exp(-(k * math.pi) ** 2 * nu * t / (d * d))
    return steady_profile(z, f, nu, d) - modes.sum(0)


def wendland_lattice_pairs(coefh: float = COEFH):
    """Neighbours of a particle on a unit square lattice (dp = 1, V_b = 1) within 2h,
    h = coefh √2: h, x, z, r and F(r) = (dW/dr)/r of the 2-D Wendland kernel (eq. 3 of the
    seed paper, α_D = 7/(4π h²))."""
    h = coefh * math.sqrt(2)
    r = int(2 * h) + 1
    i, j = np.meshgrid(np.arange(-r, r + 1), np.arange(-r, r + 1))
    x, z = i.ravel().astype(float), j.ravel().astype(float)
    rr = np.hypot(x, z)
    keep = (rr > 0) & (rr < 2 * h)
    x, z, rr = x[keep], z[keep], rr[keep]
    q = rr / h
    return h, x, z, rr, 7 / (4 * math.pi * h * h) * (-5 * q) * (1 - q / 2) ** 3 / (h * rr)


def monaghan_lattice_ratio(coefh: float = COEFH, eta2: float = 0.01, approaching_only: bool = True) -> float:
    """R of eq. (3): ν_eff / (α h c0 / 8) of DualSPHysics's artificial viscosity
    (Monaghan 1992, Π_ab = −α c h (v_ab·r_ab) / (ρ (r² + η²))) in a shear flow u(z) on a square
    lattice (dp = 1, Wendland 2-D kernel, h = coefh √2, η² = eta2 h²).

    The x acceleration of a pair is α c0 h (Δu x)/(r² + η²) x F(r) V_b with F = (dW/dr)/r;
    the u' terms of Δu = u' z − u'' z²/2 cancel, leaving ν_eff = −(α c0 h/2) Σ V x² z² F/(r² + η²),
    whose continuum value is α h c0 / 8 (Monaghan 2005, 2-D). With the switch v_ab·r_ab < 0 only
    one of the two sides ±x of each row acts, so the sum halves: R = 0.4262 at coefh 1,
    0.459 at coefh 1.2."""
    h, x, z, rr, fr = wendland_lattice_pairs(coefh)
    ratio = -0.5 * h * float(np.sum(x * x * z * z * fr / (rr * rr + eta2 * h * h))) * 8 / h
    return ratio * (0.5 if approaching_only else 1.0)


def alpha_for(nu: float, dp: float, coefh: float = COEFH, c0: float = C0) -> float:
    """α with α h c0 / 8 = ν (Monaghan 2005, 2-D), h = coefh √2 dp: the S10 choice of the
    API test (tests/sph/test_poiseuille.py)."""
    return 8 * nu / (coefh * math.sqrt(2) * dp * c0)


def _resolution(n: int, artificial: bool = False) -> dict:
    dp = D / n
    sets = []
    if artificial:
        sets = ["ViscoTreatment=1", "Visco=%.10g" % alpha_for(NU, dp)]
    return {"label": f"{n} across", "n": n, "dp": dp, "set": sets}


#: S9 runs of the case file: ``sphdvi run CASE -o OUT --dp DP`` (DtFixed follows dp in the file).
RESOLUTIONS = [_resolution(n) for n in (20, 30, 40)]
#: S10 runs: the same file with ``--set ViscoTreatment=1 --set Visco=alpha``, α h c0/8 = 1e-6 m²/s.
RESOLUTIONS_S10 = [_resolution(n, artificial=True) for n in (20, 30, 40)]


def case_args(res: dict) -> list[str]:
    """The ``sphdvi run`` arguments of one entry of :data:`RESOLUTIONS` / :data:`RESOLUTIONS_S10`."""
    out = ["--dp", repr(res["dp"])]
    for s in res["set"]:
        out += ["--set", s]
    return out


def case_errors(outdir: str) -> dict:
    """Score a finished run of the Poiseuille case file in ``outdir``.

    The channel is read from the gencase file: F = gravity x, dp, h, c0, ν = Visco
    (ViscoTreatment 3) or ν_eff = α h c0/8 (ViscoTreatment 1); the walls' surfaces lie dp/2
    outside the outer fluid rows of the initial state (z0 and d). Returns

    ``centreline``
        mean u of the fluid particles within 0.6 dp of the centre line at the last output,
        over u_max of eq. (1), minus 1 (for an artificial-viscosity run, u_max of ν_eff = α h c0/8);
    ``centreline_series``
        the same speed against the series (2) at the time of the last output, minus 1 (the
        steady value once t ≳ d²/ν; useful for runs cut short); None for an artificial-viscosity run;
    ``transient``
        the largest |u − series (2)| / u_max over the fluid particles at the outputs with
        0 < t ≤ 0.25 d²/ν (Morris et al.'s Fig. 2 goes to 0.225), None if there is none or for
        an artificial-viscosity run; ``transient_all`` the same over every output t > 0;
    ``viscosity``
        "laminar" or "artificial";
    ``centreline_vs_prediction`` (artificial only)
        the centre-line speed over F d²/(8 ν_eff), ν_eff = R α h c0/8 of eq. (3), minus 1;

    and ``l2`` (RMS of u − eq. (1) over u_max at the last output), ``wmax`` (largest |w| / u_max),
    ``dp``, ``n_across``, ``time``, ``fluid_lost`` and from run.json ``particles``, ``steps``,
    ``runtime_s``, ``status``."""
    from ..io.vtkhdf import read_step, step_times
    from .runs import case_data, run_info

    case = case_data(outdir)
    c, p = case["constants"], case["particles"]
    run_meta = run_info(outdir)
    par = dict(case["parameters"], **run_meta.get("parameters", {}))   # the parameters the run used (--set)
    dp, h, c0 = float(c["dp"]), float(c["h"]), float(c["cs0"])
    force = float(np.asarray(c["gravity"], dtype=float)[0])
    zf = p["pos"][p["type"] == 3, 2]
    z0 = float(zf.min()) - dp / 2
    d = float(zf.max() - zf.min()) + dp
    artificial = int(par["ViscoTreatment"]) == 1
    if artificial:
        nu = float(par["Visco"]) * h * c0 / 8
    else:
        nu = float(par["Visco"])
    um = u_max(force, nu, d)

    path = os.path.join(outdir, "particles.vtkhdf")
    times = step_times(path)
    transient, transient_all = [], []
    for k, t in enumerate(times):
        if t <= 0 or artificial:
            continue
        s = read_step(path, k)
        f = s["Type"] == 3
        err = float(np.abs(s["Vel"][f, 0] - series_profile(s["points"][f, 2] - z0, t, force, nu, d)).max() / um)
        transient_all.append(err)
        if t * nu / (d * d) <= TRANSIENT_WINDOW * (1 + 1e-9):
            transient.append(err)
    s = read_step(path, len(times) - 1)
    t = float(times[-1])
    f = s["Type"] == 3
    z, u = s["points"][f, 2] - z0, s["Vel"][f, 0]
    centre = np.abs(z - d / 2) < 0.6 * dp
    uc = float(u[centre].mean())
    out = {
        "viscosity": "artificial" if artificial else "laminar",
        "centreline": uc / um - 1,
        "centreline_series": None if artificial else uc / float(series_profile([d / 2], t, force, nu, d)[0]) - 1,
        "transient": max(transient) if transient else None,
        "transient_all": max(transient_all) if transient_all else None,
        "l2": float(np.sqrt(np.mean((u - steady_profile(z, force, nu, d)) ** 2)) / um),
        "wmax": float(np.abs(s["Vel"][f, 2]).max() / um),
        "dp": dp, "n_across": int(round(d / dp)), "time": t, "u_max": um, "nu": nu,
        "fluid_lost": int(np.count_nonzero(p["type"] == 3) - np.count_nonzero(f)),
        "particles": run_meta.get("particles"), "steps": run_meta.get("steps"),
        "runtime_s": run_meta.get("runtime_s"), "status": run_meta.get("status"),
    }
    if artificial:
        coefh = h / (math.sqrt(2) * dp)
        nu_pred = monaghan_lattice_ratio(coefh) * nu
        out["nu_eff_predicted"] = nu_pred
        out["centreline_vs_prediction"] = uc / u_max(force, nu_pred, d) - 1
    return out
