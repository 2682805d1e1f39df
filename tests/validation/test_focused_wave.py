"""W7: a focused wave group from a piston (NewWave of JONSWAP Hs = 0.03 m, Tp = 1.4 s in d = 0.3 m,
focused at x = 2 m) against the linear sum of the group's waves at three gauges
(sphdvi.validation.focused); W8: the same group generated to second order, against the group with its
bound waves.

Measured (README): W7 A/dp 1.4 (dp 0.02) crest −9.0 % of A, 0.045 s early, correlation ≥ 0.965, rms
≤ 12.5 % of A; A/dp 2.8 (dp 0.01) crest −2.8 %, 0.040 s early, correlation ≥ 0.974, rms ≤ 10.3 %.
W8 A/dp 1.4 crest −20.8 % of the second-order crest, 0.031 s early, correlation ≥ 0.981, rms ≤ 10.5 %;
A/dp 2.8 crest −11.3 %, 0.026 s early, correlation ≥ 0.993, rms ≤ 6.6 % (two runs on 2 threads).
Slow: dp 0.02 is 4,926 particles and 39,250 steps (about 2 minutes on 1 thread), dp 0.01 18,851
particles and 79,899 steps (16 minutes on 1 thread beside another run, 14 on 2 threads; the four runs of
this file, about 25 minutes on 2 threads)."""
import pytest

from sphdvi.validation.focused import GAUGES, focused_errors

from run.test_run import REPO
from validation._caseruns import cached_runs

CASE = REPO / "cases" / "waveflume2d" / "CaseWaveFocused2D_Def.xml"
CASE2 = REPO / "cases" / "waveflume2d" / "CaseWaveFocused2ndOrder2D_Def.xml"        # W8: second order


def report(dp, case, e):
    return (f"{'W8' if case == CASE2 else 'W7'} dp {dp}: crest {100 * e['crest']:+.1f} % of A, at {e['focus_time']:+.3f} s from t_f, trough "
            f"{100 * e['trough']:+.1f} %; correlation " + " / ".join(f"{e[f'corr_{n}']:.3f}" for n in GAUGES) +
            ", rms " + " / ".join(f"{100 * e[f'rms_{n}']:.1f}" for n in GAUGES) + " % of A")


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    def score(out):
        from sphdvi.validation.runs import run_info
        return dict(focused_errors(out), status=run_info(out)["status"])
    return cached_runs(tmp_path_factory, score, report)


@pytest.mark.slow
def test_the_group_focuses_at_a_over_dp_2_8(run):
    """The crest at the focus within 10 % of A and its time within 0.1 s (0.07 Tp) of t_f; at the three
    gauges the elevation against the linear group: correlation >= 0.9, rms within 15 % of A
    (judgement, as W1 and W4: the linear group is the target, its second-order crest is a few per
    cent higher and its troughs shallower)."""
    e = run(0.01, CASE)
    assert abs(e["crest"]) <= 0.10
    assert abs(e["focus_time"]) <= 0.1
    assert e["corr_min"] >= 0.9
    assert e["rms_max"] <= 0.15


@pytest.mark.slow
@pytest.mark.parametrize("case", [CASE, CASE2], ids=["W7", "W8"])
def test_the_focused_groups_errors_fall_with_dp(run, case):
    coarse, fine = run(0.02, case), run(0.01, case)
    assert abs(fine["crest"]) < abs(coarse["crest"])
    assert fine["rms_max"] < coarse["rms_max"]
    assert fine["corr_min"] > coarse["corr_min"]


@pytest.mark.slow
def test_the_second_order_group_fits_its_theory_at_a_over_dp_2_8(run):
    """W8 (W7's group generated to second order) against the group with its bound waves: focus time
    within 0.1 s, correlation >= 0.9, rms within 15 % of A (W7's judgement); and it fits its theory
    closer than W7's first-order generation fits the linear group, at every gauge and in the trough
    (measured: correlation >= 0.993 against 0.974, rms <= 6.6 % against 10.3 %, trough -2.4 % against
    -11.0 %)."""
    e, first = run(0.01, CASE2), run(0.01, CASE)
    assert abs(e["focus_time"]) <= 0.1
    assert e["corr_min"] >= 0.9
    assert e["rms_max"] <= 0.15
    for n in GAUGES:
        assert e[f"rms_{n}"] < first[f"rms_{n}"] and e[f"corr_{n}"] > first[f"corr_{n}"]
    assert abs(e["trough"]) < abs(first["trough"])


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="W8's crest at the focus is 11.3 % below the second-order theory's at "
                   "A/dp 2.8 (20.8 % at 1.4): the SPH rounds the group's sharper second-order crest (W7's "
                   "first-order crest is 2.8 % below the linear one); 10 % is W7's judgement")
def test_the_second_order_crest_within_10_percent(run):
    assert abs(run(0.01, CASE2)["crest"]) <= 0.10


@pytest.mark.parametrize("case", [CASE, CASE2], ids=["W7", "W8"])
def test_the_scorer_reads_the_theorys_group_as_exact(tmp_path, case):
    """Gauge files holding the theory's own elevation (on a still level of 0.3 m; W8's with the bound
    waves) score as no error: crest, focus time, rms 0 and correlation 1 (the scorer, without a run)."""
    import numpy as np
    from click.testing import CliRunner

    from sphdvi.cli import main
    from sphdvi.validation.focused import focused_paddle

    r = CliRunner().invoke(main, ["gencase", str(case), "-o", str(tmp_path), "--dp", "0.04"])
    assert r.exit_code == 0, r.output
    paddle = focused_paddle(str(tmp_path))
    t = np.arange(0.0, 8.0, 0.005)
    for name, x in GAUGES.items():
        z = 0.3 + np.where(t > 0.3, paddle.elevation_at(x, t), 0.0)
        rows = "\n".join(f"{ti:.17g};{x};0;{zi:.17g}" for ti, zi in zip(t, z))
        (tmp_path / f"GaugesSWL_{name}.csv").write_text("time [s];swlx [m];swly [m];swlz [m]\n" + rows + "\n")
    e = focused_errors(str(tmp_path))
    assert abs(e["crest"]) < 1e-3 and abs(e["focus_time"]) < 5e-3
    assert e["rms_max"] < 1e-9 and e["corr_min"] > 1 - 1e-12
