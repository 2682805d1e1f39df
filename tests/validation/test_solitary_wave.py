"""W6: a solitary wave from a piston (Goring's generation, H = 0.02 m in h = 0.1 m) against the
theory at three gauges (sphdvi.validation.solitary).

Measured (README): h/dp 10 crest −6.1 / −7.0 / −12.2 % of H, 4.6 % fast; h/dp 20 −3.2 / −4.6 /
−5.9 %, 1.1 % fast. Slow: h/dp 20 is 17,091 particles and 39,020 steps (about 6 minutes on 2
threads), h/dp 10 about a minute."""
import pytest

from sphdvi.validation.solitary import GAUGES, solitary_errors

from run.test_run import REPO
from validation._caseruns import cached_runs

CASE = REPO / "cases" / "waveflume2d" / "CaseWaveSolitary2D_Def.xml"


def report(dp, case, e):
    return (f"W6 dp {dp}: crest " + " / ".join(f"{100 * e[f'H_{n}']:+.1f}" for n in GAUGES) +
            f" % of H, speed {100 * e['celerity']:+.2f} % ({100 * e['celerity_still_depth']:+.2f} % for the still "
            f"depth {e['still_depth']:.5f} m), arrival " +
            " / ".join(f"{e[f'arrival_{n}']:+.3f}" for n in GAUGES) + f" s, rms max {100 * e['rms_max']:.1f} % of H")


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    def score(out):
        from sphdvi.validation.runs import run_info
        return dict(solitary_errors(out), status=run_info(out)["status"])
    return cached_runs(tmp_path_factory, score, report)


@pytest.mark.slow
def test_the_solitary_wave_keeps_its_height_and_speed_at_h_over_dp_20(run):
    """Within 10 % of H at each gauge and 3 % of √(g(h + H)) (judgement, as W1's height)."""
    e = run(0.005, CASE)
    assert e["H_max"] <= 0.10
    assert abs(e["celerity"]) <= 0.03
    assert e["rms_max"] <= 0.10
    # the speed against √(g(h₀ + H)) with h₀ the still depth the gauges read (0.7 dp above the top
    # particles): most of the excess over the case's h is the deeper SPH water (+1.1 % -> -0.4 %)
    assert abs(e["celerity_still_depth"]) < 0.5 * abs(e["celerity"])


@pytest.mark.slow
def test_the_solitary_waves_errors_fall_with_dp(run):
    coarse, fine = run(0.01, CASE), run(0.005, CASE)
    assert fine["H_max"] < coarse["H_max"]
    assert abs(fine["celerity"]) < abs(coarse["celerity"])
    assert fine["rms_max"] < coarse["rms_max"]
