"""M6: Chrono's ADAMS joint references (revolute, prismatic, spherical,
translational spring) — Chrono's own pass criteria (RMS of the difference)."""
import math
from pathlib import Path

import numpy as np
import pytest

from sphdvi.dvi import System

REF = Path(__file__).resolve().parents[2].parent / "shared" / "reference" / \
    "multibody_chrono_adams_reference"
G = 9.80665

pytestmark = pytest.mark.skipif(not REF.is_dir(), reason=f"ADAMS reference data not found at {REF}")


def load(case, what):
    return np.loadtxt(REF / case / f"{case}_ADAMS_{what}.txt", comments="#", skiprows=3)


def run(case, h=5e-4, tend=5.0, solver="bb"):
    s = System(gravity=(0, 0, -G), solver=solver, max_iter=300, tol=1e-12)
    I = (0.04, 0.1, 0.1)
    if case == "Revolute_Case01":
        q0 = (math.cos(-math.pi / 4), math.sin(-math.pi / 4), 0, 0)  # −90° about X
        b = s.add_body(1.0, I, pos=(2, 0, 0), quat=q0)
        s.add_link("hinge", -1, b, point=(0, 0, 0), axis=(0, 1, 0))
    elif case == "Spherical_Case01":
        b = s.add_body(1.0, I, pos=(2, 0, 0))
        s.add_link("spherical", -1, b, point=(0, 0, 0))
    elif case == "Prismatic_Case01":
        b = s.add_body(1.0, I, pos=(2, 0, 0))
        s.add_link("prismatic", -1, b, point=(0, 0, 0), axis=(0, 0, 1))
    else:  # TranSpring_Case01: vertical TSDA, free length 2 m at t = 0
        b = s.add_body(1.0, I, pos=(0, 0, 0))
        s.add_spring(-1, b, point1=(0, 0, 2), point2=(0, 0, 0), stiffness=10.0, damping=0.5,
                     rest_length=2.0)
    every = int(round(0.01 / h))
    n = int(round(tend / h))
    out = {k: [] for k in ("Pos", "Vel", "Quat", "Avel", "Rforce")}
    viol = 0.0
    e = []

    def record():
        out["Pos"].append(s.pos[b].copy())
        out["Vel"].append(s.vel[b].copy())
        out["Quat"].append(s.quat[b].copy())
        out["Avel"].append(s.omega_world[b].copy())
        out["Rforce"].append(s.link_force[0].copy())
        e.append(s.kinetic_energy() + s.potential_energy())

    record()
    for k in range(1, n + 1):
        s.step(h)
        if k % every == 0:
            record()
            viol = max(viol, s.constraint_violation())
    return {k: np.array(v) for k, v in out.items()}, viol, np.array(e)


def rms(a, b):
    return float(np.sqrt(np.mean((a - b) ** 2, axis=0)).max())


# Chrono's thresholds (utest_JOINT_*): Pos 1e-3, Vel 1e-4, Quat 1e-3, Avel 1e-2, Rforce 2e-2.
TOL = {"Pos": 1e-3, "Vel": 1e-4, "Quat": 1e-3, "Avel": 1e-2, "Rforce": 2e-2}


def energy_rms(e):
    """Chrono's ValidateEnergy (utest_JOINT_*): the RMS over the record of the total energy less its
    initial value, in J (TOLERANCES M6: 1e-2)."""
    return float(np.sqrt(np.mean((e - e[0]) ** 2)))


def errors(case, out):
    errs = {}
    for what in ("Pos", "Vel", "Quat", "Avel", "Rforce"):
        ref = load(case, what)[:, 1:]
        ours = out[what][: ref.shape[0]]
        if what == "Quat":  # q and −q are the same rotation
            ours = ours * np.sign(np.sum(ours * ref, axis=1))[:, None]
        errs[what] = rms(ours, ref)
    return errs


def test_adams_revolute():
    out, viol, e = run("Revolute_Case01", h=5e-4)
    errs = errors("Revolute_Case01", out)
    for what, tol in TOL.items():
        assert errs[what] < tol, (what, errs)
    assert viol < 1e-5
    assert energy_rms(e) < 1e-2           # measured 6.5e-3 J (m g L = 19.6 J)


def test_adams_spherical():
    """Same motion as the revolute case.  Chrono's utest_JOINT_spherical
    thresholds are Pos 2e-3, Vel 1e-3, Quat 1e-3, Avel 2e-2, Rforce 2e-2: the
    ADAMS spherical series differs from the ADAMS revolute series of the same
    motion by ~1e-3 RMS in velocity (integrator error of the reference).  Our
    spherical pendulum also meets the revolute thresholds against the revolute
    series."""
    out, viol, e = run("Spherical_Case01", h=5e-4)
    errs = errors("Spherical_Case01", out)
    tol_sph = {"Pos": 2e-3, "Vel": 1e-3, "Quat": 1e-3, "Avel": 2e-2, "Rforce": 2e-2}
    for what, tol in tol_sph.items():
        assert errs[what] < tol, (what, errs)
    errs_rev = errors("Revolute_Case01", out)
    for what in ("Pos", "Vel", "Rforce"):
        assert errs_rev[what] < TOL[what], (what, errs_rev)
    assert viol < 1e-5
    assert energy_rms(e) < 1e-2           # measured 6.5e-3 J


def test_adams_prismatic():
    """Free fall along a translational joint.  Semi-implicit Euler has the
    O(h) offset ½ g h t in position, hence h = 5e-5 for Pos < 1e-3 (the
    velocity error is the 6-digit rounding of the reference)."""
    out, viol, e = run("Prismatic_Case01", h=5e-5)
    errs = errors("Prismatic_Case01", out)
    for what, tol in TOL.items():
        assert errs[what] < tol, (what, errs)
    assert viol < 1e-5
    assert energy_rms(e) < 1e-2           # measured 6.9e-3 J (the O(h) semi-implicit Euler drift)


# utest_JOINT_transpring (TranSpring_Case01 at Δt = 1e-4 s): Pos 1e-3, Vel 3e-4, Rforce 5e-3
TOL_TSDA = {"Pos": 1e-3, "Vel": 3e-4, "Quat": 1e-10, "Avel": 1e-10, "Rforce": 5e-3}


def test_adams_translational_spring():
    """TSDA hanging mass at Chrono's step and thresholds.  The shipped .adm
    lists k = 100, c = 1 with a horizontal geometry, but the ADAMS series is
    reproduced by a vertical spring with k = 10 N/m, c = 0.5 N s/m (the values
    of Chrono's utest) at its free length at t = 0; that is what we model.  The
    soft spring is integrated explicitly (auto scheme), which keeps its
    amplitude; the implicit row loses ~1e-3 of velocity RMS to numerical
    damping (measured 1.3e-3)."""
    out, viol, e = run("TranSpring_Case01", h=1e-4)
    errs = errors("TranSpring_Case01", out)
    for what, tol in TOL_TSDA.items():
        assert errs[what] < tol, (what, errs)
    # the energy books: kinetic + gravity + the spring's k (L − L0)²/2 only falls, and with the
    # damper's work ∫ c v² dt (trapezoids on the 0.01 s record) it stays at its start value
    # (TOLERANCES M6's 1e-2 J on the RMS; measured 2.0e-4 J, 4.4 J dissipated over the 5 s)
    length = np.linalg.norm(out["Pos"] - np.array([0.0, 0.0, 2.0]), axis=1)
    mech = e + 0.5 * 10.0 * (length - 2.0) ** 2
    assert np.all(np.diff(mech) <= 1e-9)
    vz = out["Vel"][:, 2]
    work = np.concatenate([[0.0], np.cumsum(0.5 * 0.5 * (vz[1:] ** 2 + vz[:-1] ** 2) * 0.01)])
    assert energy_rms(mech + work) < 1e-2 and mech[0] - mech[-1] > 4.0


@pytest.mark.slow
def test_adams_translational_spring_fine():
    """M9: utest_JOINT_tsda's thresholds at Δt = 1e-5 s, Pos 1e-4, Vel 5e-5."""
    out, viol, e = run("TranSpring_Case01", h=1e-5)
    errs = errors("TranSpring_Case01", out)
    tol = dict(TOL_TSDA, Pos=1e-4, Vel=5e-5)
    for what in tol:
        assert errs[what] < tol[what], (what, errs)
