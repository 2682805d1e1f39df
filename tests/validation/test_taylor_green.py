"""S11: the Taylor–Green vortex from cases/taylorgreen2d/CaseTaylorGreen2D_Def.xml, through the CLI.

A square of fluid L = 1 m periodic in x and z, U = 1 m/s, ν = 0.01 m²/s (Re = 100), c0 = 10 U,
Symplectic, Wendland, laminar viscosity, Molteni density diffusion 0.1, Shifting 4 with
ShiftAdvCoef −0.2, ShiftAdvALE and ShiftAdvNCPress; the initial field of Taylor & Green written
into the gencase file by sphdvi.validation.taylorgreen.impose_initial_field. The kinetic energy
must decay as exp(−16π²νt/L²) (TOLERANCES S11: the rate within 5 % at 100² particles, with
shifting; plain WCSPH without shifting: does not crash).
"""
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.io.casefile import read_case_h5
from sphdvi.validation import taylorgreen as T

REPO = Path(__file__).resolve().parents[2]
CASE = REPO / "cases" / "taylorgreen2d" / "CaseTaylorGreen2D_Def.xml"


def _gencase(out, n):
    r = CliRunner().invoke(main, ["gencase", str(CASE), "-o", str(out), "--dp", repr(T.SIDE / n), "-q"])
    assert r.exit_code == 0, r.output
    T.impose_initial_field(str(out))


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """run(n, *sets, tmax=None) -> case_errors of that run (cached)."""
    cache = {}

    def _run(n, *sets, tmax=None):
        key = (n, sets, tmax)
        if key not in cache:
            out = tmp_path_factory.mktemp("taylorgreen_%d" % n)
            _gencase(out, n)
            args = ["run", str(out), "--threads", "1", "-q"] + [a for s in sets for a in ("--set", s)]
            if tmax is not None:
                args += ["--tmax", str(tmax)]
            r = CliRunner().invoke(main, args)
            assert r.exit_code == 0, r.output
            e = T.case_errors(str(out))
            print("Taylor-Green %dx%d %s: decay rate %+.2f %%, energy within %.2f %%, velocity error %.2f %% at "
                  "t = %.2f, monotone %s; %d steps, %.1f s"
                  % (n, n, " ".join(sets) or "(case file)", 100 * e["rate_error"], 100 * e["energy_error"],
                     100 * e["velocity_error"], e["time"], e["monotone"], e["steps"], e["runtime_s"]))
            assert e["status"] == "completed" and e["fluid_lost"] == 0
            cache[key] = e
        return cache[key]
    return _run


def test_initial_field_is_taylor_green(tmp_path):
    """N × N particles at (k + 1/2) dp, periodic in x and z, no gravity; after
    impose_initial_field the velocity is eq. (1) and the Tait pressure of the density is
    eq. (2), both to round-off."""
    n = 25
    _gencase(tmp_path, n)
    c = read_case_h5(str(tmp_path / "CaseTaylorGreen2D.h5"))
    dp = c["constants"]["dp"]
    p = c["particles"]
    assert np.all(p["type"] == 3) and len(p["type"]) == n * n
    np.testing.assert_allclose(np.unique(np.round(p["pos"][:, 0] / dp, 9)), np.arange(n) + 0.5)
    np.testing.assert_allclose(np.unique(np.round(p["pos"][:, 2] / dp, 9)), np.arange(n) + 0.5)
    par = c["parameters"]
    assert (par["XZPeriodic"], par["Shifting"], par["ViscoTreatment"], par["Visco"]) == (1, 4, 3, T.NU)
    assert np.all(np.asarray(c["constants"]["gravity"]) == 0)
    np.testing.assert_allclose(p["vel"], T.velocity(p["pos"]), atol=1e-14)
    b, gamma, rhop0 = c["constants"]["b"], c["constants"]["gamma"], c["constants"]["rhop0"]
    press = b * ((p["rhop"] / rhop0) ** gamma - 1)
    np.testing.assert_allclose(press, T.pressure(p["pos"], rhop0), atol=1e-9 * rhop0)


def test_s11_at_25_a_side(run):
    """25² particles to t = 2 s (the energy falls to 4 %): the decay rate of the kinetic energy
    over 0.1-2 s within 5 % of 16π²ν/L² (measured −0.36 %), the energy never rising, and the
    velocity field at t = 2 s within 2 % of eq. (1) (measured 0.98 %). The energy itself
    strays up to 5.6 % from the analytic curve at this resolution (t ≈ 0.6 s; 1.5 % at 50², 1.2 %
    at 100²): the flow's strain compresses the particle lattice in the first 0.15 s faster than
    the shifting restores it."""
    e = run(25)
    assert abs(e["rate_error"]) < 0.05
    assert e["monotone"]
    assert e["velocity_error"] < 0.02


def test_without_shifting_the_run_completes_but_the_vortex_loses_its_energy(run):
    """Plain WCSPH (Shifting 0) on the same case: it completes with every particle (TOLERANCES:
    "does not crash"), but the particles, carried by the flow's strain, lose their lattice
    order, the continuity equation compresses the fluid (the mean density rises ~3 % by
    t = 0.15 s) and the vortex loses most of its energy by t = 0.4 s: the decay rate over
    0.1-1 s is more than twice the analytic one (measured +171 %, the energy 93 % below the
    analytic curve at t = 1 s; at 50² to 2 s +37 %, 85 % below, monotone). That is why the case
    shifts its particles."""
    e = run(25, "Shifting=0", tmax=1.0)
    assert e["rate_error"] > 1.0
    assert e["energy_error"] > 0.5


@pytest.mark.slow
def test_s11_tolerance_at_100_a_side(run):
    """TOLERANCES S11 at 100² particles: the decay rate within 5 % (measured −0.02 %), the
    energy within 5 % of the analytic curve at every output (1.16 %) and monotone; the velocity
    field at t = 2 s within 2 % of eq. (1) (0.58 %). 3.5 min of stepping on 1 thread."""
    e = run(100)
    assert abs(e["rate_error"]) < 0.05
    assert e["energy_error"] < 0.05
    assert e["monotone"]
    assert e["velocity_error"] < 0.02
