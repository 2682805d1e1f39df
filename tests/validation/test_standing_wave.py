"""S7: period of the first sloshing mode of a 2D tank against linear theory ω² = g k tanh(k d).

The case file cases/standingwave2d/CaseStandingWave2D_Def.xml (L = 1 m, d = 0.5 m, a/d = 0.04,
mDBC, Symplectic, α = 0.01, Fourtakas δ = 0.1, coefh 1.2) runs at d/dp = 20 and 40; the
period is read from the horizontal centre of mass of the water and compared with theory for
the tank the particles fill (L_eff = L − dp). TOLERANCES S7: within 1–2 % at d/dp ≥ 40.

Free-slip walls (mDBC SlipMode 3, mDBC2 with the corrected ghost velocity), as the inviscid theory
assumes. The case runs 5 s, about 4.3 periods; the period is read from the up-crossings and the loss
per period fitted to the 8 extrema of the centre of mass about the tank's middle (its equilibrium).
Measured 2026-11-25: period −1.04 % (d/dp = 20), −0.89 % (d/dp = 40); loss 5.59 % and 4.61 % per
period. The same runs to 7 s (12 extrema) give 5.56 / 4.65 %. Over the case's earlier 2.9 s
(2.4 periods, 4 extrema, about the signal's mean) the loss read 5.33 / 5.40 % and the period
−0.85 / −0.63 %: the higher modes the start excites make single periods lose 2–9 %, so 4 extrema
do not fix the rate. Split at d/dp 20 / 40 (4.7 s): with α = 0 the loss is 3.86 / 2.96 %, so the
artificial viscosity adds 1.75 / 1.65 % (linear theory for the bulk with ν_eff ≈ 0.46 α h c0/8:
2.6 / 1.3 %); DensityDT 0 changes nothing (5.64 % at d/dp 20). Before 2026-11-25 the
particle-derived normals of the third layer of the walls ran along them, their ghost nodes dry
inside the wall. With the default SlipMode 1 (normals of then, 2.9 s) the walls carry Stokes
layers of the artificial viscosity (ν_eff ≈ 1.1e-3 m²/s at d/dp = 20): period −1.46 / −0.78 %,
loss 10.3 / 8.9 % per period, against 8.7 / 5.7 % from linear theory with ν_eff (bulk 2νk² plus
the walls' Stokes layers, :func:`viscous_decay_per_period`).
At coefh 1.0 (h = √2 dp) the period is ~5 % short at every resolution and does not converge with
dp (−5.4 %, −4.6 %), with or without walls, whatever the initial condition, boundary condition,
density diffusion, c0 or integrator; coefh 1.2, 1.5, 1.75, 2.0 give −1.1, +0.3, 0.0, +0.5 %
(periodic channel, d/dp = 20). Slow (about 3.5 minutes): ``python -m pytest -m slow tests/validation``.
"""
import math
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.validation.sloshing import case_periods, period_from_signal, viscous_decay_per_period

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


def test_signal_analysis_recovers_period_and_loss_of_a_damped_cosine():
    """period_from_signal on x = 0.5 − a e^(−λt) cos(2πt/T), 5 % loss per period, sampled every
    0.01 s over 4.3 periods as the S7 case: exact about the known centre; about the record's mean
    the loss reads 5.58 %, the bias the case's earlier analysis carried."""
    period, lam = 1.16, -math.log(0.95) / 1.16
    t = np.arange(0.0, 5.0 + 1e-9, 0.01)
    x = 0.5 - 0.01 * np.exp(-lam * t) * np.cos(2 * math.pi * t / period)
    p, loss = period_from_signal(t, x, centre=0.5)
    assert p == pytest.approx(period, rel=1e-6) and loss == pytest.approx(0.05, abs=1e-9)
    p_mean, loss_mean = period_from_signal(t, x)
    assert loss_mean == pytest.approx(0.0558, abs=5e-4) and p_mean == pytest.approx(period, rel=5e-4)


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
def test_damping_falls_with_dp(runs):
    """Amplitude loss per period (fitted to the extrema): no growth, and less with finer dp
    (measured 5.59 → 4.61 %; with α = 0, 3.86 → 2.96 %)."""
    d1, d2 = runs[0.025]["decay"], runs[0.0125]["decay"]
    print(f"S7 amplitude loss per period: d/dp=20 {100 * d1:.2f} %, d/dp=40 {100 * d2:.2f} %")
    assert 0.0 < d2 < d1


@pytest.mark.slow
def test_damping_below_5_percent_per_period(runs):
    """TOLERANCES S7: no anomalous damping above ~5 %/period at alpha = 0.01 (free-slip walls);
    at least the bulk loss linear theory gives for ν_eff (1.3 % at d/dp = 40). Measured 4.61 %."""
    bulk = viscous_decay_per_period(1 - 0.0125, 0.5, 0.46 * 0.01 * 1.2 * math.sqrt(2) * 0.0125 * 45 / 8,
                                    no_slip_walls=False)["bulk"]
    assert bulk < runs[0.0125]["decay"] <= 0.05


@pytest.mark.slow
def test_elevation_gauge_sees_the_same_mode(runs):
    """The run-time SWL gauge 0.05 m from the left wall oscillates with the mode; its crossings
    carry the free second mode the finite-amplitude start excites, so only 5 % is asked."""
    assert abs(_error(runs[0.0125], "period_gauge")) < 0.05
