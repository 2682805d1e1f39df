"""S9 / S10 from the case file cases/poiseuille2d/CasePoiseuille2D_Def.xml, run through the CLI.

The case is the set-up of tests/sph/test_poiseuille.py (Morris, Fox & Zhu 1997: d = 1e-3 m,
ν = 1e-6, F = 2e-4 m/s², c0 = 10 u_max, DtFixed = 0.1 h²/ν, Symplectic, 12 periodic columns,
mDBC no-slip walls with their surfaces on z = 0 and z = d, ViscoLaminarEta 0) drawn by gencase;
:func:`sphdvi.validation.poiseuille.case_errors` scores the runs.

The mDBC normals of the walls, computed from the particles with the periodic images of the
wall (sphdvi/case/normals.py), are the plates' own, (0, 0, distance to the surface): the
case-file run is the API model (centre-line equal to 1e-6) and meets S9: +0.92 / +0.86 /
+0.84 % at 20 / 30 / 40 across, transient 0.78 / 0.65 / 0.60 % of u_max. (Before the normals saw
the periodic images, the wall particles within 2 dp of the periodic ends got corner normals and
the flow was 1.97 / 1.58 / 1.40 % too fast.) Each run takes 1-4 s on one thread; the 40-across
runs are marked slow.
"""
import importlib.util
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.io.casefile import read_case_h5
from sphdvi.validation import poiseuille as P

REPO = Path(__file__).resolve().parents[2]
CASE = REPO / "cases" / "poiseuille2d" / "CasePoiseuille2D_Def.xml"
RES = {r["n"]: r for r in P.RESOLUTIONS}
RES_S10 = {r["n"]: r for r in P.RESOLUTIONS_S10}


def _api():
    """tests/sph/test_poiseuille.py (its run_poiseuille is the API-level model)."""
    spec = importlib.util.spec_from_file_location("_api_test_poiseuille", REPO / "tests" / "sph" / "test_poiseuille.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """run(n, artificial=False) -> case_errors of that run (cached)."""
    cache = {}

    def _run(n, artificial=False):
        key = (n, artificial)
        if key not in cache:
            res = (RES_S10 if artificial else RES)[n]
            out = tmp_path_factory.mktemp("poiseuille_%d_%s" % key)
            r = CliRunner().invoke(main, ["run", str(CASE), "-o", str(out), "--threads", "1", "-q",
                                          "--overwrite"] + P.case_args(res))
            assert r.exit_code == 0, r.output
            e = P.case_errors(str(out))
            print("Poiseuille case %d across, %s: centre-line %+.3f %%, transient %s, %s vs "
                  "prediction, %d particles, %d steps, %.2f s"
                  % (n, e["viscosity"], 100 * e["centreline"],
                     None if e["transient"] is None else "%.3f %%" % (100 * e["transient"]),
                     "%+.2f %%" % (100 * e["centreline_vs_prediction"]) if artificial else "-",
                     e["particles"], e["steps"], e["runtime_s"]))
            assert e["status"] == "completed" and e["fluid_lost"] == 0
            cache[key] = e
        return cache[key]
    return _run


def test_case_geometry_and_dt_follow_dp(tmp_path):
    """At every --dp of RESOLUTIONS: n fluid rows at (k + 1/2) dp, 12 columns (x period 12 dp),
    3 wall layers on each side at dp/2, 3dp/2, 5dp/2 outside z = 0 and z = d, and the
    expressions DtFixed = 0.1 h²/ν, TimeMax = d²/ν, TimeOut = d²/(20ν) resolved for that dp."""
    for res in P.RESOLUTIONS:
        out = tmp_path / str(res["n"])
        r = CliRunner().invoke(main, ["gencase", str(CASE), "-o", str(out), "--dp", repr(res["dp"]), "-q"])
        assert r.exit_code == 0, r.output
        c = read_case_h5(str(out / "CasePoiseuille2D.h5"))
        dp, h = c["constants"]["dp"], c["constants"]["h"]
        pos, t = c["particles"]["pos"], c["particles"]["type"]
        assert dp == pytest.approx(res["dp"], rel=1e-12) and h == pytest.approx(np.sqrt(2) * dp, rel=1e-12)
        assert c["constants"]["cs0"] == pytest.approx(10 * P.u_max())
        assert c["constants"]["gravity"][0] == pytest.approx(P.F)
        np.testing.assert_allclose(np.unique(np.round(pos[:, 0] / dp, 6)), np.arange(12))
        np.testing.assert_allclose(np.unique(np.round(pos[t == 3, 2] / dp, 6)), np.arange(res["n"]) + 0.5)
        wall = np.unique(np.round(pos[t == 0, 2] / dp, 6))
        np.testing.assert_allclose(wall, np.r_[-2.5, -1.5, -0.5, res["n"] + np.array([0.5, 1.5, 2.5])])
        p = c["parameters"]
        assert p["DtFixed"] == pytest.approx(0.1 * h * h / P.NU, rel=1e-12)
        assert p["TimeMax"] == pytest.approx(P.D ** 2 / P.NU) and p["TimeOut"] == pytest.approx(0.05)
        assert (p["ViscoTreatment"], p["Visco"], p["ViscoLaminarEta"], p["Boundary"], p["SlipMode"]) == \
            (3, pytest.approx(P.NU), 0.0, 2, 2)


def test_case_is_the_api_model(run):
    """The case-file run is tests/sph/test_poiseuille.py's model at the same resolution (20
    across): the centre-line speed and the L2 error agree to 1e-6 u_max (the outputs hold
    float32 velocities; measured 2e-8 and 5e-8), laminar (S9) and with --set ViscoTreatment=1
    --set Visco=alpha (S10). The API runs to t_end = (1 - 1e-9) d²/ν: its ``run(d²/ν)`` takes a
    2001st step (the time after 2000 steps of DtFixed is 0.99999999999995 s), which moves the
    disordered S10 flow by 1.3e-4 u_max."""
    api = _api()
    t_end = (1 - 1e-9) * P.D ** 2 / P.NU
    a9 = api.run_poiseuille(20, slip=2, eta=0.0, t_end=t_end)
    e9 = run(20)
    a10 = api.run_poiseuille(20, artificial=True, slip=2, t_end=t_end)
    e10 = run(20, artificial=True)
    print("case - API, 20 across: S9 centre-line %.2e, L2 %.2e; S10 centre-line %.2e"
          % (e9["centreline"] + 1 - a9["uc"], e9["l2"] - a9["l2"], e10["centreline"] + 1 - a10["uc"]))
    assert e9["steps"] == e10["steps"] == 2000
    assert abs(e9["centreline"] + 1 - a9["uc"]) < 1e-6
    assert abs(e9["l2"] - a9["l2"]) < 1e-6
    assert abs(e10["centreline"] + 1 - a10["uc"]) < 1e-6


def test_s9_tolerance(run):
    """TOLERANCES S9 at 30 across: centre-line within 1 % (measured +0.86 %; the lattice sum
    of the exact Morris operator predicts +0.78 %) and the Morris et al. series within 2 % of
    u_max at the outputs 0 < t ν/d² ≤ 0.25 (measured 0.65 %); no vertical flow."""
    e = run(30)
    assert abs(e["centreline"]) < 0.01
    assert e["transient"] < 0.02
    assert e["wmax"] < 1e-3


def test_s10_against_operator_prediction(run):
    """S10: the case with --set ViscoTreatment=1 --set Visco=alpha (alpha h c0/8 = nu) against
    the operator prediction nu_eff = 0.426 alpha h c0/8 (approaching pairs only, lattice sum),
    within the ~10 % of TOLERANCES S10: measured -7.6 % at 20 across (the API test's value)."""
    e = run(20, artificial=True)
    assert e["viscosity"] == "artificial"
    assert abs(e["centreline_vs_prediction"]) < 0.10


@pytest.mark.slow
def test_s9_40_across(run):
    """40 across: +0.84 %, transient 0.60 % (inside S9), below the 30-across error."""
    e40 = run(40)
    assert abs(e40["centreline"]) < 0.01 and e40["transient"] < 0.02
    assert abs(e40["centreline"]) < abs(run(30)["centreline"])


@pytest.mark.slow
def test_s10_30_and_40_across(run):
    """S10 at 30 and 40 across against the operator prediction (measured -6.2 %, -4.4 %)."""
    for n in (30, 40):
        assert abs(run(n, artificial=True)["centreline_vs_prediction"]) < 0.10
