"""The wave maker against first-order wavemaker theory (``cases/waveflume2d``): a piston (W1) or a
flap hinged at the bottom (W2) makes regular waves H = 0.03 m, T = 1.2 s in d = 0.3 m; the incident
height from three gauges, and the paddle's stroke on its particles against Biesel's H/S.

Measured (README, W1, the cases' coefh 1.2): incident height −5.1 % of H at dp 0.02 (H/dp 1.5),
−4.2 % at dp 0.01 (H/dp 3); the wave runs 2.1 / 1.9 % faster than linear theory; reflection from the
damping zone 3 %. W2 (flap): +3.1 % at dp 0.02, 2.6 % fast. With coefh 1.0 (h = √2 dp, the cases'
setting before 2026-11-26) W1 came out −12.9 / −10.3 % low and 9.0 / 6.8 % fast.

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
    # measured −5.1 %, 2.1 % fast, reflection 3.0 % (2.2 % with the wave's own k)
    assert abs(e["H_incident"]) <= 0.10
    assert abs(e["celerity"]) <= 0.03
    assert e["reflection"] < 0.05


@pytest.mark.slow
def test_flap_makes_the_wave_height_of_the_theory_at_h_over_dp_1_5(tmp_path):
    out = run_case(tmp_path, 0.02, FLAP_CASE)
    # the flap turns about its bottom hinge with Biesel's stroke at the still-water level (H / 0.5644)
    assert paddle_stroke(out, "flap") == pytest.approx(H / flap_height_to_stroke(K, DEPTH), rel=2e-3)
    e = wave_errors(out)
    print({k: round(v, 4) for k, v in e.items()})
    # the piston's H/S used for the flap would give −46 %; measured +3.1 %, 2.6 % fast
    assert abs(e["H_incident"]) <= 0.10
    assert abs(e["celerity"]) <= 0.03
    assert e["reflection"] < 0.05


@pytest.mark.slow
def test_the_height_deficit_falls_with_dp(tmp_path):
    coarse, fine = run(tmp_path, 0.02), run(tmp_path, 0.01)
    print(coarse["H_incident"], fine["H_incident"])
    assert abs(fine["H_incident"]) < abs(coarse["H_incident"])            # −5.1 → −4.2 %
    assert abs(fine["celerity"]) < abs(coarse["celerity"])                # 2.1 → 1.9 %


IRREGULAR_CASE = REPO / "cases" / "waveflume2d" / "CaseWaveIrregular2D_Def.xml"


@pytest.fixture(scope="module")
def irregular(tmp_path_factory):
    """irregular_errors of the W4 run at dp 0.02 (about 6 minutes on 2 threads), run once for the
    two tests below."""
    from sphdvi.validation.waveflume import irregular_errors
    out = run_case(tmp_path_factory.mktemp("w4"), 0.02, IRREGULAR_CASE)
    e = irregular_errors(out)
    print({k: round(v, 3) for k, v in e.items()})
    return e


@pytest.mark.slow
def test_irregular_waves_follow_the_linear_sum_of_the_sea_state(irregular):
    """W4: a piston makes a JONSWAP sea (Hs 0.04 m, Tp 1.4 s, 50 waves) in d = 0.3 m; at the three
    gauges (0.6 / 1.2 / 1.8 m) the SPH surface is the linear sum of the sea state's waves. Measured
    at dp 0.02 (session 34, Verlet's Euler step every VerletSteps steps as DualSPHysics's):
    correlation 0.979 / 0.966 / 0.950, rms −11.2 / −14.5 / −17.0 % (the coarse surface's height
    deficit, growing along the flume as W1's: the rms target is the strict xfail below; the same
    code with the earlier Euler count gave −8.4 / −13.5 / −14.3 %, the figure moves by a few per
    cent with any perturbation of a 98,000-step Verlet run). Before: 0.976 / 0.965 / 0.951, rms
    −7.1 / −12.2 / −13.6 %, best shifts −0.030 / −0.035 / −0.045 s (the SPH wave runs ~2 % fast, as
    W1's) with correlations 0.990 / 0.985 / 0.982 there. What holds is asserted here: W3's
    judgement correlation ≥ 0.9, the correlation at the best shift ≥ 0.975, the shifts early by at
    most 0.1 s and growing along the flume, and the rms deficit below 20 % (a regression bound on
    the measured 17 %, stated as such: linear in the stroke, a paddle 10 % short would read about −25 %). With coefh 1.0
    the same run gave 0.971 / 0.900 / 0.822 and −14.3 / −16.2 / −17.4 % (−0.04 / −0.075 / −0.11 s),
    and at dp 0.01 still 0.863 and −19.5 % at WG3."""
    e = irregular
    gauges = ("WG1", "WG2", "WG3")
    assert e["corr_min"] >= 0.9
    assert min(e[f"{g}_corr_lag"] for g in gauges) >= 0.975
    assert all(-0.1 <= e[f"{g}_lag"] <= 0.0 for g in gauges) and e["WG3_lag"] <= e["WG1_lag"]
    assert all(e[f"{g}_rms"] < 0.0 for g in gauges) and e["rms_max"] <= 0.20


@pytest.mark.slow
@pytest.mark.xfail(strict=True, raises=AssertionError,
                   reason="W4 rms within 15 % (judgement, as W3): measured -11.2 / -14.5 / -17.0 % at dp 0.02 "
                   "since Verlet's Euler step comes every VerletSteps steps as DualSPHysics's (-7.1 / -12.2 / "
                   "-13.6 % with sphdvi's earlier count of VerletSteps + 1)")
def test_irregular_waves_rms_within_15_percent_at_dp_0_02(irregular):
    assert irregular["rms_max"] <= 0.15


IRREGULAR_CASE2 = REPO / "cases" / "waveflume2d" / "CaseWaveIrregular2ndOrder2D_Def.xml"      # W9


@pytest.mark.slow
def test_the_second_order_sea_follows_its_theory_with_more_of_its_energy(tmp_path_factory, irregular):
    """W9: W4's sea generated to second order (waveorder 2), against the sea to second order (its
    linear waves and their bound waves). Measured at dp 0.02 (2026-11-29, 142 s on 2 threads):
    correlation 0.973 / 0.960 / 0.953, at the best shifts (−0.035 / −0.040 / −0.050 s) 0.993 / 0.987 /
    0.987, rms −7.5 / −10.9 / −13.4 %: the SPH surface keeps more of the sea's energy than W4's
    (−10.0 / −12.9 / −16.1 % that day), within W3's 15 % at every gauge; its correlation is W4's
    (0.977 / 0.968 / 0.951): at this resolution the SPH's own phase lag, not the bound waves, sets it."""
    from sphdvi.validation.waveflume import irregular_errors
    e = irregular_errors(run_case(tmp_path_factory.mktemp("w9"), 0.02, IRREGULAR_CASE2))
    print({k: round(v, 3) for k, v in e.items()})
    gauges = ("WG1", "WG2", "WG3")
    assert e["corr_min"] >= 0.9
    assert min(e[f"{g}_corr_lag"] for g in gauges) >= 0.975
    assert all(-0.1 <= e[f"{g}_lag"] <= 0.0 for g in gauges)
    assert e["rms_max"] <= 0.15
    assert all(abs(e[f"{g}_rms"]) < abs(irregular[f"{g}_rms"]) for g in gauges)


def test_fitted_wavenumber_recovers_the_waves_own_k():
    """Three gauges' complex amplitudes of an incident and a 5 % reflected wave of k = 0.92 k0: the fit
    finds k to its 1e-4 k0 step and, with it, the reflection; a lone incident wave of that k split
    with the theory's k0 reads as a reflected one (W1 at dp 0.02: 7.5 % against 2.5 % with its own k)."""
    import numpy as np
    from sphdvi.validation.waveflume import GAUGES, fitted_wavenumber, incident_reflected
    x = np.array(list(GAUGES.values()))
    k = 0.92 * K
    amp = 0.014 * np.exp(-1j * k * x) + 0.0007 * np.exp(1j * (k * x + 0.4))
    assert fitted_wavenumber(x, amp, K) == pytest.approx(k, abs=1e-4 * K)
    inc, ref = incident_reflected(x, amp, fitted_wavenumber(x, amp, K))
    assert abs(ref) / abs(inc) == pytest.approx(0.05, abs=2e-3)
    lone = 0.014 * np.exp(-1j * k * x)
    inc, ref = incident_reflected(x, lone, fitted_wavenumber(x, lone, K))
    assert abs(ref) / abs(inc) < 1e-3
    inc0, ref0 = incident_reflected(x, lone, K)
    assert abs(ref0) / abs(inc0) > 0.03


def test_a_wave_in_deeper_still_water_is_fast_for_the_case_depth_and_right_for_its_own(tmp_path):
    """Gauge files of a linear wave H in 0.307 m of still water (the kernel-sum surface 0.7 dp above the
    top particles at dp 0.01): wave_errors reads the still depth from the first 0.1 s, finds the wave's
    k, the phase speed k(d)/k(0.307) − 1 = +0.78 % against the case's d = 0.3 m and 0 against the still
    depth."""
    import numpy as np
    from sphdvi.validation.waveflume import GAUGES, STILL_BEFORE
    d = 0.307
    k = wave_number(PERIOD, d)
    omega = 2 * np.pi / PERIOD
    t = np.arange(0.0, 8.4 + 1e-9, 0.01)
    for name, x in GAUGES.items():
        eta = np.where(t > STILL_BEFORE, 0.5 * H * np.cos(omega * t - k * x), 0.0)
        rows = "".join(f"{ti:.15g};0;0;{d + e:.12g};0;0;0;0;0;0\n" for ti, e in zip(t, eta))
        (tmp_path / f"GaugesSWL_{name}.csv").write_text("time [s];a;b;swlz [m];c;d;e;f;g;h\n" + rows)
    e = wave_errors(str(tmp_path))
    assert e["still_depth"] == pytest.approx(d, abs=1e-12)
    assert e["celerity"] == pytest.approx(K / k - 1, abs=2e-4) and 0.0075 < e["celerity"] < 0.0081
    assert abs(e["celerity_still_depth"]) < 2e-4
    assert abs(e["H_incident"]) < 1e-3 and e["reflection"] < 1e-2


AWAS_CASE = REPO / "cases" / "waveflume2d" / "CaseWaveAwas2D_Def.xml"


@pytest.mark.slow
def test_absorbing_piston_takes_out_the_wave_the_wall_sends_back(tmp_path):
    """W5: the W1 flume closed by a wall. With AWAS the paddle reflects the returning wave as linear
    theory says its absorber should (|R| 0.202 with the gauge 5 dp = 0.1 m out at dp 0.02; measured
    0.143, the windows within 0.003; 0.098 / 0.296 with the gauge at 0.068 / 0.2 m, theory 0.153 /
    0.380), and the wave leaving it stays the one asked for (+2.5 %); the same piston without
    <awas_zsurf> sends it all back (measured |R| 0.93)."""
    from sphdvi.validation.waveflume import absorption_errors
    out = run_case(tmp_path, 0.02, AWAS_CASE)
    e = absorption_errors(out)
    print({k: round(v, 4) for k, v in e.items()})
    assert abs(e["reflection"] - e["reflection_theory"]) <= 0.1 and e["reflection_spread"] < 0.1
    assert abs(e["H_incident"]) <= 0.10 and e["H_returning"] > 0.5
    from lxml import etree
    tree = etree.parse(str(AWAS_CASE))
    awas = tree.find(".//awas_zsurf")
    awas.getparent().remove(awas)
    still = tmp_path / "CaseWaveStill_Def.xml"
    tree.write(str(still))
    r = CliRunner().invoke(main, ["run", str(still), "-o", str(tmp_path / "still"), "--dp", "0.02", "--threads", "2",
                                  "-q"])
    assert r.exit_code == 0, r.output
    e = absorption_errors(tmp_path / "still", gauge_x=0.1)
    print({k: round(v, 4) for k, v in e.items()})
    assert e["reflection"] > 0.8
