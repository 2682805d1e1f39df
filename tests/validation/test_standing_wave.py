"""S7: period of the first sloshing mode of a 2D tank against linear theory ω² = g k tanh(k d).

The case file cases/standingwave2d/CaseStandingWave2D_Def.xml (L = 1 m, d = 0.5 m, a/d = 0.04,
mDBC, Symplectic, α = 0.01, Fourtakas δ = 0.1, coefh 1.2) runs at d/dp = 20 and 40; the
period is read from the horizontal centre of mass of the water and compared with theory for
the tank the particles fill (L_eff = L − dp). TOLERANCES S7: within 1–2 % at d/dp ≥ 40.

Free-slip walls (mDBC SlipMode 3, mDBC2 with the corrected ghost velocity), as the inviscid theory
assumes. Measured (2026-11-25, the walls' normals from the particles the same as GenCase's from the
tank's outline): −0.85 % (d/dp = 20), −0.63 % (d/dp = 40); amplitude loss 5.33 % and 5.40 % per period
(DualSPHysics's Shepard ghost velocity, MdbcGhostVelocity 0: 5.46 % at d/dp = 40). The loss is over
the ~5 % of TOLERANCES S7 and does not fall with dp: xfail. Before 2026-11-25 the particle-derived
normals of the third layer of the 8-layer walls at d/dp = 40 were 8.5 dp vectors along the wall, their
ghost nodes inside it (dry, so rho0), and the loss 4.7 %; at d/dp = 40 with the new normals but the
third layer kept DBC it is 5.00 %, with the old normals on the deep layers away from the corners
4.40 %: a third layer corrected from the water adds the damping. Earlier figures, with those normals: −0.72 / −0.71 %, 5.3 / 4.7 % (Shepard
ghost velocity −0.75 / −0.72 %, 4.7 / 4.6 %; sphdvi's earlier free-slip, which reflected the ghost
velocity in continuity and viscosity alike: −0.88 / −0.71 %, 4.2 / 4.0 %). With the default
SlipMode 1 (those normals) the walls carry Stokes layers of the artificial viscosity (ν_eff ≈ 0.46 α h c0/8 ≈ 1.1e-3 m²/s at
d/dp = 20): period −1.46 / −0.78 %, loss 10.3 / 8.9 % per period, against 8.7 / 5.7 % from linear
theory with ν_eff (bulk 2νk² plus the walls' Stokes layers, :func:`viscous_decay_per_period`).
At coefh 1.0 (h = √2 dp) the period is ~5 % short at every resolution and does not converge with
dp (−5.4 %, −4.6 %), with or without walls, whatever the initial condition, boundary condition,
density diffusion, c0 or integrator; coefh 1.2, 1.5, 1.75, 2.0 give −1.1, +0.3, 0.0, +0.5 %
(periodic channel, d/dp = 20). Slow (about 2 minutes): ``python -m pytest -m slow tests/validation``.
"""
import math
from pathlib import Path

import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.validation.sloshing import case_periods, viscous_decay_per_period

REPO = Path(__file__).resolve().parents[2]
CASE = REPO / "cases" / "standingwave2d" / "CaseStandingWave2D_Def.xml"


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    out = {}
    for dp in (0.025, 0.0125):
        d = tmp_path_factory.mktemp(f"sw{dp}")
        r = CliRunner().invoke(main, ["run", str(CASE), "-o", str(d), "--dp", str(dp), "--threads", "2", "-q"])
        assert r.exit_code == 0, r.output
        out[dp] = case_periods(str(d))
    return out


def _error(r, key="period_com"):
    return (r[key] - r["period_theory"]) / r["period_theory"]


@pytest.mark.slow
def test_sloshing_period_within_2_percent_and_converging(runs):
    e1, e2 = _error(runs[0.025]), _error(runs[0.0125])
    print(f"S7 period error (centre of mass): d/dp=20 {100 * e1:+.2f} %, d/dp=40 {100 * e2:+.2f} %, "
          f"observed order {math.log(abs(e1) / abs(e2)) / math.log(2):.2f}; "
          f"gauge 'Left': {100 * _error(runs[0.0125], 'period_gauge'):+.2f} %")
    assert abs(e2) <= 0.02                       # TOLERANCES S7: 1-2 % at d/dp >= 40
    assert abs(e2) < abs(e1)                     # error falls with dp


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="measured 5.33 % -> 5.40 % per period at d/dp 20 -> 40 with the walls' "
                   "normals as GenCase's (4.7 % at d/dp 40 with the earlier, broken third-layer normals)")
def test_damping_falls_with_dp(runs):
    """Amplitude loss per period (fitted to the extrema): no growth, and less with finer dp
    (measured 5.33 → 5.40 %; linear theory puts the bulk loss of ν_eff at 2.6 → 1.3 %,
    the rest does not shrink with h and is not explained)."""
    d1, d2 = runs[0.025]["decay"], runs[0.0125]["decay"]
    print(f"S7 amplitude loss per period: d/dp=20 {100 * d1:.1f} %, d/dp=40 {100 * d2:.1f} %")
    assert 0.0 < d2 < d1


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="measured 5.40 % per period at d/dp 40 with the walls' normals as GenCase's")
def test_damping_below_5_percent_per_period(runs):
    """TOLERANCES S7: no anomalous damping above ~5 %/period at alpha = 0.01 (free-slip walls);
    at least the bulk loss linear theory gives for ν_eff (1.3 % at d/dp = 40)."""
    bulk = viscous_decay_per_period(1 - 0.0125, 0.5, 0.46 * 0.01 * 1.2 * math.sqrt(2) * 0.0125 * 45 / 8,
                                    no_slip_walls=False)["bulk"]
    assert bulk < runs[0.0125]["decay"] <= 0.05


@pytest.mark.slow
def test_elevation_gauge_sees_the_same_mode(runs):
    """The run-time SWL gauge 0.05 m from the left wall oscillates with the mode; its crossings
    carry the free second mode the finite-amplitude start excites, so only 5 % is asked."""
    assert abs(_error(runs[0.0125], "period_gauge")) < 0.05
