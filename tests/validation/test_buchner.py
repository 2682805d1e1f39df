"""S5: dam-break pressure on the downstream wall against Buchner (2002), in the set-up of
Colagrossi & Landrini (2003): cases/dambreak2d/CaseBuchner2D_Def.xml through the CLI, scored by
sphdvi.validation.buchner.case_errors (impact time, the quasi-static level over T = 3-5 and the
time of the second peak, T = t √(g/H), against the digitised record in ../shared/reference).
"""
from pathlib import Path

import numpy as np
import pytest
from _caseruns import cached_runs

from sphdvi.validation import buchner as B

REPO = Path(__file__).resolve().parents[2]
CASE = REPO / "cases" / "dambreak2d" / "CaseBuchner2D_Def.xml"
CASE_MDBC = REPO / "cases" / "dambreak2d" / "CaseBuchnerMdbc2D_Def.xml"
REF = REPO.parent / "shared" / "reference"


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """run(dp, case=CASE) -> case_errors of that run (cached)."""
    if not (REF / B.DATA[0]).is_dir():
        pytest.skip("reference data not found")

    def report(dp, case, e):
        return ("S5 Buchner, %s, H/dp %.0f: impact T %.3f (exp %.3f), level T 3-5 %.3f (exp %.3f, %+.1f %%), second "
                "peak T %.3f (exp %.3f), %.3f (exp %.3f); %d particles, %d steps, %.1f s"
                % (case.stem, B.H / dp, e["sim"]["impact"], e["exp"]["impact"], e["sim"]["plateau"],
                   e["exp"]["plateau"], 100 * e["plateau"], e["sim"]["peak_T"], e["exp"]["peak_T"], e["sim"]["peak"],
                   e["exp"]["peak"], e["particles"], e["steps"], e["runtime_s"]))
    runs = cached_runs(tmp_path_factory, lambda out: B.case_errors(out, str(REF)), report)
    return lambda dp, case=CASE: runs(dp, case)


def test_reference_record_features():
    """The digitised record read as the scorer reads it: impact at T = 2.49 (its first point above
    0.1 after the pre-impact scatter), level 0.546 over T = 3-5, second peak 0.887 at T = 5.84
    (TOLERANCES S5: impact ≈ 2.5, level ≈ 0.55, second peak at T ≈ 5.8-6)."""
    if not (REF / B.DATA[0]).is_dir():
        pytest.skip("reference data not found")
    f = B.features(*B.reference_record(str(REF)))
    # TOLERANCES S5's reading of the record, the independent source
    assert abs(f["impact"] - 2.5) <= 0.05 and abs(f["plateau"] - 0.55) <= 0.01 and 5.8 <= f["peak_T"] <= 6.0
    # and the scorer's own reading, pinned (a regression check of B.features on the file)
    assert f["impact"] == pytest.approx(2.493)
    assert f["plateau"] == pytest.approx(0.546, abs=0.001)
    assert (f["peak_T"], f["peak"]) == (pytest.approx(5.836), pytest.approx(0.887))


def test_features_of_a_synthetic_record():
    """The scorer on a record it can be checked against by hand: a step to 0.6 at T = 2.5 with a
    bump to 0.9 at T = 5.9."""
    T = np.linspace(0, 7, 7001)
    p = np.where(T >= 2.5, 0.6, 0.0) + 0.3 * np.exp(-((T - 5.9) / 0.05) ** 2)
    f = B.features(T, p)
    assert f["impact"] == pytest.approx(2.5, abs=1e-9)
    assert f["plateau"] == pytest.approx(0.6, abs=1e-12)
    assert f["peak_T"] == pytest.approx(5.9, abs=1e-9) and f["peak"] == pytest.approx(0.9, abs=1e-9)


@pytest.mark.slow
def test_s5_second_peak_at_h_over_dp_30(run):
    """H/dp 30 (dp 0.02 m, 2,142 particles): the run-up falls back onto the probe at the
    experiment's time: the second peak within ±0.15 in T of T = 5.84 (measured +0.11, its level
    +10 %)."""
    e = run(0.02)
    assert abs(e["peak_T"]) <= B.PEAK_TOL


@pytest.mark.slow
@pytest.mark.xfail(strict=True, raises=AssertionError,
                   reason="S5 at H/dp 30: the probe at 0.19 H stays dry until T = 2.61 (+0.115 against "
                   "the experiment's rise) and the level over T = 3-5 is 0.25 against 0.55 (-55 %): acoustic ringing "
                   "after the impact, then a level that climbs to 0.4-0.5 only by T = 4.5")
def test_s5_impact_and_level_at_h_over_dp_30(run):
    """TOLERANCES S5's impact (T ≈ 2.5; ±0.1 here) and quasi-static level (≈ 0.55 over T = 3-5;
    20 % here) at H/dp 30."""
    e = run(0.02)
    assert abs(e["impact"]) <= B.IMPACT_TOL
    assert abs(e["plateau"]) <= B.PLATEAU_TOL


@pytest.mark.slow
@pytest.mark.xfail(strict=True, raises=AssertionError,
                   reason="S5 at H/dp 60 with DBC: impact +0.115, level over T = 3-5 -35 % (median "
                   "-32 %), second peak at T = 6.5 (+0.68): with DBC the pressure falls off up the wall faster than "
                   "measured, as at S4's sensor 4")
def test_s5_at_h_over_dp_60(run):
    """TOLERANCES S5 at H/dp 60 (dp 0.01 m, 7,883 particles, ~3 min on 2 threads)."""
    e = run(0.01)
    assert abs(e["impact"]) <= B.IMPACT_TOL
    assert abs(e["plateau"]) <= B.PLATEAU_TOL
    assert abs(e["peak_T"]) <= B.PEAK_TOL


@pytest.mark.slow
def test_s5_run_at_h_over_dp_60_completes_and_hits_the_wall(run):
    """The DBC run at H/dp 60 feeds the strict xfail above, where any AssertionError (a crash in the
    run is one: ``cached_runs`` asserts the exit code and the status) would read as the expected
    failure: here it must complete, and the water reach the probe within 0.2 in T of the
    experiment's impact (measured +0.115; a regression bound, TOLERANCES asks 0.1) with a finite
    level and second peak."""
    e = run(0.01)
    assert e["status"] == "completed"
    assert abs(e["impact"]) <= 0.2
    assert np.isfinite(e["plateau"]) and np.isfinite(e["peak_T"])


@pytest.mark.slow
def test_s5m_level_at_h_over_dp_60(run):
    """S5M, mDBC walls (three layers, normals from the tank's outline), H/dp 60 (9,267 particles,
    ~3 min on 2 threads): the quasi-static level over T = 3-5 within 20 % of the experiment's
    (measured 0.500 against 0.546, −8.5 %, session 40; −4.7 % before 27b5622's wall layers; DBC −35 %)."""
    e = run(0.01, CASE_MDBC)
    assert abs(e["plateau"]) <= B.PLATEAU_TOL


@pytest.mark.slow
@pytest.mark.xfail(strict=True, raises=AssertionError,
                   reason="S5M at H/dp 60: the probe reads the impact at T = 2.596, +0.103 against the "
                   "band's ±0.1 (session 40; the second peak on time, T −0.05, 0.97 against 0.89; before 27b5622's "
                   "wall layers the impact was +0.18 and the second peak +0.70 late)")
def test_s5m_impact_and_second_peak_at_h_over_dp_60(run):
    e = run(0.01, CASE_MDBC)
    assert abs(e["impact"]) <= B.IMPACT_TOL
    assert abs(e["peak_T"]) <= B.PEAK_TOL
