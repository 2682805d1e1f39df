"""Waves from a relaxation zone (W10, ``cases/waveflume2d/CaseWaveRelaxZone2D_Def.xml``): W1's flume and
waves (H = 0.03 m, T = 1.2 s, d = 0.3 m) made by an ``<rzwaves_regular>`` zone on the closed end instead of
a piston, scored as W1 (the incident height from three gauges over the last two periods).

Measured (README, W10): incident height −5.3 % of H at dp 0.02 (H/dp 1.5), −4.9 % at dp 0.01; the wave
runs 1.0 / 1.7 % faster than linear theory; reflection from the damping zone 2.9 / 3.8 % (W1's piston:
−5.1 / −4.2 %, 2.1 / 1.9 % fast). Slow: 8.4 s of waves, about 30 s at dp 0.02 on 2 threads; the zone
itself is tested fast in tests/sph/test_relaxzones.py and tests/run/test_relaxzones_run.py."""
from pathlib import Path

import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.validation.waveflume import wave_errors

REPO = Path(__file__).resolve().parents[2]
CASE = REPO / "cases" / "waveflume2d" / "CaseWaveRelaxZone2D_Def.xml"


@pytest.mark.slow
def test_a_relaxation_zone_makes_the_wave_height_of_the_theory_at_h_over_dp_1_5(tmp_path):
    out = tmp_path / "dp0.02"
    r = CliRunner().invoke(main, ["run", str(CASE), "-o", str(out), "--dp", "0.02", "--threads", "2", "-q"])
    assert r.exit_code == 0, r.output
    e = wave_errors(str(out))
    print({k: round(v, 4) for k, v in e.items()})
    # a zone relaxing towards twice the wave, or a wrong phase speed or depth in its theory, gives a poor
    # height or speed; measured −5.3 %, 1.0 % fast, reflection 2.9 %
    assert abs(e["H_incident"]) <= 0.10
    assert abs(e["celerity"]) <= 0.03
    assert e["reflection"] < 0.05


WALL_CASE = REPO / "cases" / "waveflume2d" / "CaseWaveRelaxZoneWall2D_Def.xml"


@pytest.mark.slow
def test_a_slow_relaxation_zone_takes_out_the_wave_coming_back(tmp_path):
    """W11: the zone (1.5 m of it in the water, coefdt 20) in W5's flume closed by a wall, scored as W5:
    R = (A − A0)/B of the wave B coming back (a still wall or a paddle that does not absorb: R = 1).
    Measured at dp 0.02: R 0.080, the wave leaving it −5.6 % of H before the wall's wave returns and
    −3.8 % after; the same zone with coefdt 1000 reflected 0.56 (about 2 minutes on 1 thread)."""
    from sphdvi.validation.waveflume import absorption_errors
    out = tmp_path / "dp0.02"
    r = CliRunner().invoke(main, ["run", str(WALL_CASE), "-o", str(out), "--dp", "0.02", "--threads", "2", "-q"])
    assert r.exit_code == 0, r.output
    e = absorption_errors(str(out))
    print({k: round(v, 4) for k, v in e.items()})
    assert e["reflection"] <= 0.1
    assert abs(e["H_before"]) <= 0.10 and abs(e["H_incident"]) <= 0.10
    assert e["H_returning"] > 0.5            # the wall did send the waves back
