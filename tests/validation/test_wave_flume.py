"""The wave maker against first-order wavemaker theory (``cases/waveflume2d``): a piston (W1) or a
flap hinged at the bottom (W2) makes regular waves H = 0.03 m, T = 1.2 s in d = 0.3 m; the incident
height from three gauges, and the paddle's stroke on its particles against Biesel's H/S.

Measured (README, W1): incident height −13.0 % of H at dp 0.02 (H/dp 1.5), −10.3 % at dp 0.01
(H/dp 3), reflection from the damping zone 7 %.  DualSPHysics advises H/dp ≥ 10 for generated
waves; at these coarse resolutions the height falls short by about 10 %, less as dp falls.
W2 (flap): −9.8 % at dp 0.02, reflection 6.4 %.

Slow (each 8.4 s of waves, about a minute at dp 0.02 on a slow 2-core host, two at dp 0.01): the
paddles' strokes and ramps are tested fast in tests/motion and tests/run/test_moving.py."""
from pathlib import Path

import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.motion import flap_height_to_stroke, piston_height_to_stroke, wave_number
from sphdvi.validation.waveflume import DEPTH, H, PERIOD, paddle_stroke, wave_errors

REPO = Path(__file__).resolve().parents[2]
CASE = REPO / "cases" / "waveflume2d" / "CaseWaveFlume2D_Def.xml"
FLAP_CASE = REPO / "cases" / "waveflume2d" / "CaseWaveFlap2D_Def.xml"
K = wave_number(PERIOD, DEPTH)


def run_case(tmp_path, dp, case=CASE):
    out = tmp_path / f"dp{dp}"
    r = CliRunner().invoke(main, ["run", str(case), "-o", str(out), "--dp", str(dp), "--threads", "2", "-q"])
    assert r.exit_code == 0, r.output
    return out


def run(tmp_path, dp, case=CASE):
    return wave_errors(run_case(tmp_path, dp, case))


@pytest.mark.slow
def test_piston_makes_the_wave_height_of_the_theory_at_h_over_dp_1_5(tmp_path):
    out = run_case(tmp_path, 0.02)
    # the paddle moves with Biesel's stroke (S = H / 1.0405) to the sampling's round-off
    assert paddle_stroke(out, "piston") == pytest.approx(H / piston_height_to_stroke(K, DEPTH), rel=2e-3)
    e = wave_errors(out)
    print({k: round(v, 4) for k, v in e.items()})
    # the flap's H/S used for a piston would give +84 %, no ramp or a wrong period a poor fit;
    # the coarse SPH wave is ~13 % short (measured −13.0 %)
    assert -0.16 < e["H_incident"] < -0.08
    assert e["reflection"] < 0.10


@pytest.mark.slow
def test_flap_makes_the_wave_height_of_the_theory_at_h_over_dp_1_5(tmp_path):
    out = run_case(tmp_path, 0.02, FLAP_CASE)
    # the flap turns about its bottom hinge with Biesel's stroke at the still-water level (H / 0.5644)
    assert paddle_stroke(out, "flap") == pytest.approx(H / flap_height_to_stroke(K, DEPTH), rel=2e-3)
    e = wave_errors(out)
    print({k: round(v, 4) for k, v in e.items()})
    # the piston's H/S used for the flap would give −46 %; measured −9.8 %, a shortfall like the piston's
    assert -0.13 < e["H_incident"] < -0.065
    assert e["reflection"] < 0.10


@pytest.mark.slow
def test_the_height_deficit_falls_with_dp(tmp_path):
    coarse, fine = run(tmp_path, 0.02), run(tmp_path, 0.01)
    print(coarse["H_incident"], fine["H_incident"])
    assert abs(fine["H_incident"]) < abs(coarse["H_incident"]) - 0.015
