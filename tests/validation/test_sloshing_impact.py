"""S8: SPHERIC Test 10 (low filling) from ``cases/sloshing2d``: a tank rolled with the measured angle
record (``<mvrotfile>``), the left-wall pressure read by a point that moves with the tank
(``measure points --trackmkbound``), outputs every 1 ms around the impacts (``<special><timeout>``).

Measured (README, S8; session 36) at dp 0.008 (11.6 particles over the depth): the four impacts at
−0.05 / −4.0 / −2.4 / −6.1 % of the roll period from the experiment's; peaks −43 / +106 / +200 /
+59 %.  With the roll turned the other way (right-handed about axisp1 → axisp2, sphdvi's sense
before it followed DualSPHysics's MatrixRot) the water hit the left wall half a period late."""
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.validation.sloshing_impact import ROLL_PERIOD, WINDOWS, impact_errors, sensor_pressure

REPO = Path(__file__).resolve().parents[2]
CASE = REPO / "cases" / "sloshing2d" / "CaseSloshingTest10_2D_Def.xml"
REFERENCE = REPO.parent / "shared" / "reference"


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """run(dp) -> (outdir, impact_errors) of the case at that dp, each run once."""
    cache = {}

    def get(dp):
        if dp not in cache:
            out = tmp_path_factory.mktemp(f"dp{dp}")
            r = CliRunner().invoke(main, ["run", str(CASE), "-o", str(out), "--dp", str(dp), "--threads", "2", "-q"])
            assert r.exit_code == 0, r.output
            e = impact_errors(out, REFERENCE)
            print(f"dp {dp}:", {k: round(v, 4) for k, v in e.items()})
            cache[dp] = (out, e)
        return cache[dp]
    return get


@pytest.mark.slow
def test_impacts_on_the_left_wall_come_when_the_experiment_records_them(run):
    """dp 0.008 (2.3 min of CPU on 2 threads): the coarse run, a check of the roll and the probe."""
    out, e = run(0.008)
    # every impact within 7 % of the roll period (measured ≤ 6.1 %; the first within 0.3 %; on
    # 2026-11-27 −0.05 / −4.0 / −2.4 / −6.1 %): the opposite roll sense puts them half a period (50 %)
    # off; TOLERANCES S8's 3 % is asserted at dp 0.004 below
    assert e["dt_max"] < 0.07 and abs(e["dt1"]) < 0.02
    # the pressure rises to impact levels in each window (peaks 2.1-11.4 kPa against 2.7-7.1 kPa),
    # and not beyond 5 times the experiment's (measured at most 3.0 times: −43 / +106 / +200 / +59 %)
    assert all(0.5 * e[f"p_exp{k}"] < e[f"p_sph{k}"] < 5.0 * e[f"p_exp{k}"] for k in range(1, 5))
    # between the windows the sensor sees no impact: the largest pressure outside them stays lower
    t, p = sensor_pressure(out)
    outside = np.ones(t.size, bool)
    for lo, hi in WINDOWS:
        outside &= ~((t >= lo - 0.1 * ROLL_PERIOD) & (t <= hi))
    assert p[outside].max() < min(e[f"p_sph{k}"] for k in range(1, 5))


@pytest.mark.slow
def test_impact_times_within_3_percent_at_dp_0_004(run):
    """TOLERANCES S8, impact times within 3 % of the roll period, at dp 0.004 (depth/dp 23, 5,856
    particles, about 11 min on 1 thread): measured +1.1 / −0.6 / −1.9 / −2.0 % (max 2.0 %, session 36), down
    from 6.1 % at dp 0.008; the peaks within 5 times the experiment's (measured +77 / +58 / +165 / +114 %:
    the WCSPH pressure spikes at the probe, see the strict xfail below)."""
    _, fine = run(0.004)
    _, coarse = run(0.008)
    assert fine["dt_max"] <= 0.03
    assert fine["dt_max"] < coarse["dt_max"]
    assert all(0.5 * fine[f"p_exp{k}"] < fine[f"p_sph{k}"] < 5.0 * fine[f"p_exp{k}"] for k in range(1, 5))


@pytest.mark.slow
@pytest.mark.xfail(strict=True, raises=AssertionError,
                   reason="TOLERANCES S8 peak pressure within 20-30 %: measured +77 / +58 / +165 / +114 % at "
                   "dp 0.004 (-43 / +106 / +200 / +59 % at dp 0.008; session 36, 2026-11-27): the raw SPH peaks are "
                   "spikes above the experiment's, which samples every ~2.4 ms; averaged over 10 ms "
                   "-10...+46 % (before session 36), not scored")
def test_impact_peaks_within_30_percent_at_dp_0_004(run):
    _, e = run(0.004)
    assert e["peak_max"] <= 0.30
