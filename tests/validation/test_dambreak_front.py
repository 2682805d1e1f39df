"""S3: 2D dam-break front against Martin & Moyce (1952) at two resolutions (a/dp = 25, 50).

Measured (see README): the SPH front leads the experiment by +6…+16 % (dp 0.04) and
+8…+18 % (dp 0.02) over T ∈ [1, 3] — the experiment's gate and wall friction delay
the early surge — while the front speed over T ∈ [1.9, 3] agrees within 3 %.
TOLERANCES.md S3 asks ±5 % on Z(T); that check is kept below as a strict xfail
until the solver meets it.
"""
import json
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.validation.dambreak import (FRONT_RECORDS, front_errors, front_history, front_start_delay,
                                       load_front_record, load_martin_moyce)

REPO = Path(__file__).resolve().parents[2]
CASE = REPO / "cases" / "dambreak2d" / "CaseDambreakVal2D_Def.xml"
REFERENCE = REPO.parent / "shared" / "reference"
if not (REFERENCE / "dambreak2d_front_martin_moyce_1952").is_dir():
    pytest.skip("reference data ../shared/reference not found", allow_module_level=True)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    out = {}
    for dp in (0.04, 0.02):
        d = tmp_path_factory.mktemp(f"dp{dp}")
        r = CliRunner().invoke(main, ["run", str(CASE), "-o", str(d), "--dp", str(dp), "--tmax", "0.72",
                                      "--tout", "0.01", "--threads", "2", "-q"])
        assert r.exit_code == 0, r.output
        t, x = front_history(str(d))
        meta = json.loads((d / "run.json").read_text())
        meta["outdir"] = str(d)
        out[dp] = (t, x, meta)
    return out


def corner_fall(outdir, until=0.25):
    """(times, drop) of the fluid particle that starts at the column's top front corner, over
    0 < t <= ``until``."""
    from sphdvi.io.vtkhdf import read_step, step_times
    path = str(Path(outdir) / "particles.vtkhdf")
    times = step_times(path)
    s = read_step(path, 0)
    fluid = s["Type"] == 3
    k0 = np.argmax(s["points"][fluid, 0] + s["points"][fluid, 2])
    idp, z0 = s["Idp"][fluid][k0], s["points"][fluid][k0, 2]
    steps = [k for k in range(1, times.size) if times[k] <= until + 1e-9]
    drop = []
    for k in steps:
        s = read_step(path, k)
        drop.append(z0 - s["points"][s["Idp"] == idp, 2][0])
    return times[steps], np.array(drop)


def test_the_top_corner_falls_freely_and_the_front_keeps_below_the_ideal_speed(runs):
    """Two checks with their own sources, which pin g and the clock where the comparisons with the
    experiment cannot (the run with g 5 % off is the same dam break on another time scale: its
    front speed moves by 2.5 %, and a fitted start delay absorbs the rest).  At t = 0+ the
    pressure of the released column is harmonic and vanishes on the top and on the front face, so
    near their corner it goes as r² and its gradient vanishes there: the corner falls freely,
    z0 − g t²/2 (the small-time solution of the incompressible dam break; it stays so while the
    corner keeps its right angle).
    Measured over t = 0.03-0.25 s (T ≤ 1.1): 0.984-0.993 of g t²/2 at a/dp 25, 0.991-0.995 at a/dp 50;
    with g × 1.05 / 0.95 in the case 1.034-1.042 / 0.935-0.943 at a/dp 25.  And the front never outruns Ritter's ideal
    shallow-water front 2 √(g·2a) (TOLERANCES S3's upper bound; measured 6.6 m/s against 8.9)."""
    g, a = 9.81, 1.0
    for dp, (t, x, meta) in runs.items():
        tc, drop = corner_fall(meta["outdir"])
        ratio = drop / (0.5 * g * tc ** 2)
        sel = tc >= 0.03 - 1e-9
        print(f"dp={dp}: top corner drop / (g t²/2) {ratio[sel].min():.3f}…{ratio[sel].max():.3f}; "
              f"front speed at most {np.max(np.diff(x) / np.diff(t)):.2f} m/s")
        assert sel.sum() >= 20 and np.all(np.abs(ratio[sel] - 1) <= 0.025), ratio
        assert np.max(np.diff(x) / np.diff(t)) < 2 * np.sqrt(g * 2 * a)


def test_front_speed_and_lead(runs):
    ref = load_martin_moyce(str(REFERENCE))
    for dp, (t, x, meta) in runs.items():
        T, rel, speed = front_errors(t, x, ref)
        print(f"dp={dp}: particles {meta['particles']}, runtime {meta['runtime_s']:.1f} s, "
              f"max |err| {100 * np.abs(rel).max():.1f} %, speed err {100 * speed:+.1f} %")
        assert abs(speed) < 0.05, f"front speed off by {100 * speed:.1f} % at dp={dp}"
        assert np.all(rel > 0), "the SPH front (no gate) should lead the experiment"
    # resolution: the fronts at a/dp = 25 and 50 differ by less than 5 % over T in [1, 3]
    (t1, x1, _), (t2, x2, _) = runs[0.04], runs[0.02]
    tt = np.linspace(1.0, 3.0, 40) / np.sqrt(2 * 9.81)
    f1, f2 = np.interp(tt, t1, x1), np.interp(tt, t2, x2)
    assert np.max(np.abs(f2 - f1) / f2) < 0.05


def test_front_runs_the_experiments_course_after_a_start_delay(runs):
    """The lead is an offset taken before T ≈ 1.2 (at T = 0.41 the fronts agree, Z = 1.11;
    by T = 1.19 the SPH one is 0.26 a ahead), not a faster front: with the experiment's
    clock started ΔT ≈ 0.2-0.25 late (12-14 ms at Martin & Moyce's a = 57 mm) every point
    of T ∈ [1, 3] is within 2.62 % (a/dp 50; 2.77 % at 25; session 34). Asserted: 5 % at each dp
    (the TOLERANCES ±5 %), 3 % at a/dp 50."""
    ref = load_martin_moyce(str(REFERENCE))
    for dp, (t, x, _) in runs.items():
        delay, err = front_start_delay(t, x, ref)
        print(f"dp={dp}: start delay ΔT = {delay:.3f}, max |err| after it {100 * err:.2f} %")
        assert 0.1 <= delay <= 0.4, delay
        assert err <= 0.05, err
    assert front_start_delay(*runs[0.02][:2], ref)[1] < 0.03


def test_front_leads_every_record_of_the_experiment(runs):
    """Not Table 2's transcription alone: the SPH front leads M&M's Fig. 3 (both column sizes,
    a = 1.125 and 2.25 in) and Koshizuka & Oka's repetition (a = 0.146 m) as well, by more than
    the TOLERANCES ±5 % somewhere on T ∈ [1, 3] of each.  Measured at a/dp 50: +5.8…+19.3 %
    (Fig. 3, 1.125 in), +11.9…+17.3 % (Fig. 3, 2.25 in), +8.8…+19.9 % (K&O, whose front is
    slower from T ≈ 2 on); at a/dp 25 +3.8…+17.7 %.  After a start delay ΔT of 0.21-0.28 the
    M&M records are within 0.6-4.4 %, K&O within 6.5-6.7 %."""
    for name in FRONT_RECORDS:
        ref = load_front_record(str(REFERENCE), name)
        for dp, (t, x, _) in runs.items():
            _, rel, _ = front_errors(t, x, ref)
            delay, err = front_start_delay(t, x, ref)
            print(f"{name}, dp={dp}: {100 * rel.min():+.1f}…{100 * rel.max():+.1f} %, "
                  f"after ΔT = {delay:.3f}: {100 * err:.2f} %")
            assert np.all(rel > 0) and rel.max() > 0.05, (name, dp)
            assert 0.15 <= delay <= 0.35 and err < 0.08, (name, dp)


@pytest.mark.xfail(strict=True, raises=AssertionError,
                   reason="TOLERANCES S3 ±5 % on Z(T): measured +8…+18 % at a/dp = 50")
def test_front_within_5_percent_at_a_over_dp_50(runs):
    t, x, _ = runs[0.02]
    _, rel, _ = front_errors(t, x, load_martin_moyce(str(REFERENCE)))
    assert np.abs(rel).max() <= 0.05


MDBC_CASE = REPO / "cases" / "dambreak2d" / "CaseDambreakMdbc2D_Def.xml"


def test_mdbc_case_with_outline_normals(tmp_path, runs):
    """cases/dambreak2d/CaseDambreakMdbc2D_Def.xml, the same dam break with DualSPHysics's mDBC set-up
    (three wall layers, normals from the tank's outline), at a/dp 25: nothing leaks through the walls
    (mDBC on one layer loses 3-4 % of the water by 0.72 s, README), the front keeps its speed and its
    lead over the experiment (measured +5.9…+15.8 %, DBC +6.5…+16.0 %; at a/dp 50 +6.4…+17.5 %,
    DBC +8.2…+18.0 %: the walls do not explain the lead) and stays within 3 % of the DBC front."""
    r = CliRunner().invoke(main, ["run", str(MDBC_CASE), "-o", str(tmp_path), "--dp", "0.04", "--tmax", "0.72",
                                  "--tout", "0.01", "--threads", "2", "-q"])
    assert r.exit_code == 0, r.output
    meta = json.loads((tmp_path / "run.json").read_text())
    assert meta["parameters"]["Boundary"] == 2
    header, *rows = (tmp_path / "run.csv").read_text().splitlines()
    assert rows[-1].split(",")[header.split(",").index("excluded")] == "0", rows[-1]
    t, x = front_history(str(tmp_path))
    ref = load_martin_moyce(str(REFERENCE))
    _, rel, speed = front_errors(t, x, ref)
    print(f"mDBC a/dp 25: {100 * rel.min():+.1f}…{100 * rel.max():+.1f} %, speed {100 * speed:+.1f} %")
    assert abs(speed) < 0.05 and np.all(rel > 0) and rel.max() > 0.05
    t0, x0, _ = runs[0.04]
    tt = np.linspace(1.0, 3.0, 40) / np.sqrt(2 * 9.81)
    assert np.max(np.abs(np.interp(tt, t, x) / np.interp(tt, t0, x0) - 1)) < 0.03
