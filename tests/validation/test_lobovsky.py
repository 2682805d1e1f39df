"""S4: the Lobovsky et al. (2014) dam break, H = 0.3 m (slow: about 2 minutes at dp 5 mm, 12 at 2.5 mm).

The case file cases/lobovsky2d/CaseLobovsky2D_Def.xml carries run-time SWL gauges at
H1–H4 (x = 0.3, 0.865, 1.114, 1.3625 m); the level h(T), T = t √(g/H), is compared with
both experimental repetitions over each gauge's window before the reflected bore arrives.
Error measure: mean |h_sph − h_exp| / mean h_exp over the window.  The level is measured
from the model's bed, dp/2 above the centres of the floor particles: GenCase puts the
floor particles on the drawn floor z = 0 and the first fluid layer at z = dp, so the
column of 60 layers spans z = dp/2 … 0.3 + dp/2 (the tank of the experiment shifted by
dp/2, as the walls of cases/standingwave2d).

It also carries density gauges P1–P4 at the right-wall pressure sensors (z = 3, 15, 30,
80 mm; probed 1.5h off the wall, sensor 1 also 1.5h above the floor, since DBC keeps the
fluid about 1.5h from walls).  p = B((ρ/ρ0)^γ − 1) is scored as TOLERANCES S4 asks:
the first impact (p/ρgH first above 0.1) within ±0.05 in T of the experiment's, and the
quasi-static level after it (mean p/ρgH over T = 3–5) within 20 %.  Reference: the
paper's representative repetition (Fig. 18, 'peak event 5').
"""
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.validation import lobovsky

REPO = Path(__file__).resolve().parents[2]
CASE = REPO / "cases" / "lobovsky2d" / "CaseLobovsky2D_Def.xml"
REF = REPO.parent / "shared" / "reference" / "dambreak2d_lobovsky_2014"
DATA = REF / "waterLevel"


@pytest.mark.parametrize("name", ["H2", "H3", "H4"])
def test_level_windows_end_before_the_reflected_bore(name):
    """Each downstream gauge's window ends on the surge's level, before the bore reflected from the
    right wall lifts it: over the window's last 0.25 T both repetitions move by less than 0.02 H
    (H4's window ended at T = 5.5 before: its level rose 0.21 → 0.24 and 0.23 → 0.29 over 5.25-5.5).
    H4's window ends just before that rise: 0.03 H or more within 0.3 T after its end."""
    if not DATA.is_dir():
        pytest.skip("reference data not found")
    (t0, t1), files = lobovsky.WINDOWS[name]
    for f in files:
        e = np.loadtxt(DATA / f, comments="#")
        tail = e[(e[:, 0] >= t1 - 0.25) & (e[:, 0] <= t1), 1]
        assert np.ptp(tail) < 0.02, f"{name} {f}: {np.ptp(tail):.3f} H"
        if name == "H4":
            after = e[(e[:, 0] >= t1) & (e[:, 0] <= t1 + 0.3), 1]
            assert after.max() - after[0] > 0.03, f


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    if not DATA.is_dir():
        pytest.skip("reference data not found")
    out = tmp_path_factory.mktemp("lobovsky")
    r = CliRunner().invoke(main, ["run", str(CASE), "-o", str(out), "--threads", "2", "-q"])
    assert r.exit_code == 0, r.output
    return out


@pytest.fixture(scope="module")
def run_dir_fine(tmp_path_factory):
    """The same case at dp = 2.5 mm (H/dp = 120; about 12 minutes on 2 threads)."""
    if not DATA.is_dir():
        pytest.skip("reference data not found")
    out = tmp_path_factory.mktemp("lobovsky_fine")
    r = CliRunner().invoke(main, ["run", str(CASE), "-o", str(out), "--dp", "0.0025", "--threads", "2", "-q"])
    assert r.exit_code == 0, r.output
    return out


@pytest.fixture(scope="module")
def errors(run_dir):
    errs = lobovsky.level_errors(str(run_dir), str(REF.parent))
    print("S4 water-level errors: " + ", ".join(f"{k} {100 * v:.1f} %" for k, v in errs.items()))
    return errs


@pytest.fixture(scope="module")
def pressures(run_dir):
    scores = lobovsky.pressure_scores(str(run_dir), str(REF.parent))
    for k, (ti, te, ps, pe) in scores.items():
        print(f"S4 {k}: first impact T {ti:.3f} (exp {te:.3f}), level T 3-5 {ps:.3f} (exp {pe:.3f}, "
              f"{100 * (ps / pe - 1):+.1f} %)")
    return scores


@pytest.mark.slow
def test_lobovsky_level_in_the_reservoir(errors):
    """H1 (inside the initial column): measured 1.0 % (DBC), 1.3 % (mDBC, 3 layers)."""
    assert errors["H1"] <= 0.10


@pytest.mark.slow
@pytest.mark.parametrize("name", [
    "H2", pytest.param("H3", marks=pytest.mark.xfail(
        strict=True, raises=AssertionError, reason="TOLERANCES S4 10 %: measured 12.5 % at dp 5 mm (DBC; mDBC, 3 layers: 12.6 %): the "
                            "SPH layer rides on the DBC wall gap, which shrinks with h: 8.1 % at dp 2.5 mm "
                            "(test_lobovsky_levels_at_h_over_dp_120)")),
    "H4"])
def test_lobovsky_levels_downstream(errors, name):
    """Measured (DBC): H2 8.0 %, H4 8.2 % (H4's window to T = 5.5); rerun 2026-11-27 with H4's window
    to 5.25, before the reflected bore: H2 6.9 %, H3 12.5 %, H4 8.7 % (8.3 % to 5.5)."""
    assert errors[name] <= 0.10, f"{name}: {100 * errors[name]:.1f} %"


@pytest.mark.slow
def test_lobovsky_first_impact_time(pressures):
    """Measured T_sph - T_exp: P1 -0.010, P2 -0.015, P3 -0.019 (DBC, dp 5 mm)."""
    for name in ("P1", "P2", "P3"):
        ti, te, _, _ = pressures[name]
        assert abs(ti - te) <= 0.05, f"{name}: {ti:.3f} vs {te:.3f}"


@pytest.mark.slow
def test_lobovsky_pressure_after_impact(pressures):
    """Measured: P1 -7.3 %, P2 +1.5 %, P3 -10.3 % (mean p/ρgH over T = 3-5)."""
    for name in ("P1", "P2", "P3"):
        _, _, ps, pe = pressures[name]
        assert abs(ps / pe - 1.0) <= 0.20, f"{name}: {ps:.3f} vs {pe:.3f}"


@pytest.mark.slow
@pytest.mark.xfail(strict=True, raises=AssertionError, reason="sensor 4 (z = 80 mm): measured level 0.204 vs 0.533 (-62 %) and "
                                        "impact 0.07 early; in 2-D SPH the pressure falls off up the wall faster "
                                        "than in the experiment (15/30/80 mm: 0.70/0.57/0.20 vs 0.69/0.64/0.53)")
def test_lobovsky_pressure_at_sensor_4(pressures):
    ti, te, ps, pe = pressures["P4"]
    assert abs(ti - te) <= 0.05 and abs(ps / pe - 1.0) <= 0.20, f"{ti:.3f}/{te:.3f}, {ps:.3f}/{pe:.3f}"


@pytest.mark.slow
def test_lobovsky_levels_at_h_over_dp_120(errors, run_dir_fine):
    """At dp = 2.5 mm every gauge is within the 10 % of TOLERANCES S4, and the downstream
    errors fall from dp = 5 mm: the excess water level of DBC is the wall gap (~1.5h),
    which halves with h.  Measured 2026-11-27 (session 37, 1 thread, 2,791 s, H4 to T = 5.25):
    H1 1.6 %, H2 5.6 %, H3 7.9 %, H4 5.6 % (dp 5 mm: 0.9, 6.9, 12.5, 8.7 %); session 34, H4 to
    T = 5.5: 1.5, 5.5, 8.1, 5.8 %."""
    fine = lobovsky.level_errors(str(run_dir_fine), str(REF.parent))
    print("S4 water-level errors at dp 2.5 mm: " + ", ".join(f"{k} {100 * v:.1f} %" for k, v in fine.items()))
    for name, err in fine.items():
        assert err <= 0.10, f"{name}: {100 * err:.1f} %"
    for name in ("H2", "H3", "H4"):
        assert fine[name] < errors[name], f"{name}: {100 * fine[name]:.1f} % vs {100 * errors[name]:.1f} %"


@pytest.mark.slow
@pytest.mark.parametrize("name", ["P1", "P2", pytest.param("P3", marks=pytest.mark.xfail(
    strict=True, raises=AssertionError,
    reason="2026-11-27 (session 37) rerun, 1 thread: P3's first crossing of 0.1 is a lone splash reading "
           "p/rho g H 1.87 at T 2.447 (0 before and after), 0.062 T before the experiment's 2.509; the bulk "
           "arrives at T 2.48-2.51; the session-34 run had it 0.042 T early"))])
def test_lobovsky_pressure_at_h_over_dp_120(run_dir_fine, name):
    """At dp 2.5 mm the gauges, 1.5h off the wall as at dp 5 mm (the case writes their position
    with GenCase's H), give the same levels after impact: measured 2026-11-27 (session 37, 1 thread)
    P1 0.720 (-0.5 %), P2 0.700 (+2.2 %), P3 0.602 (-5.8 %), P4 0.207 (-61.2 %); first impact
    0.045 / 0.027 / 0.062 T early (P3 fails ±0.05: a lone splash reaches its gauge first).  Session
    34: P1 0.715 (-1.2 %), P2 0.699 (+2.0 %), P3 0.596 (-6.7 %), P4 0.211 (-60.5 %) against
    0.671 / 0.695 / 0.573 / 0.204 at dp 5 mm; first impact 0.045 / 0.015 / 0.042 T early. With the gauges fixed 10.6 mm off the wall
    (3h at this dp, outside the DBC wall layer, which reads low) they read 0.835 / 0.824 / 0.749
    (+15.4 / +20.3 / +17.3 %): 20 mm off the wall the water is at 0.87 / 0.71 (dp 5 mm) and
    0.80 / 0.76 (dp 2.5 mm) at z = 15 / 30 mm."""
    ti, te, ps, pe = lobovsky.pressure_scores(str(run_dir_fine), str(REF.parent))[name]
    print(f"S4 {name} at dp 2.5 mm: first impact T {ti:.3f} (exp {te:.3f}), level {ps:.3f} (exp {pe:.3f}, "
          f"{100 * (ps / pe - 1):+.1f} %)")
    assert abs(ti - te) <= 0.05
    assert abs(ps / pe - 1.0) <= 0.20, f"{name}: {ps:.3f} vs {pe:.3f}"
