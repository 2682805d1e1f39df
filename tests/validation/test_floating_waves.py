"""S16: a floating box in waves from a measured flap motion (``cases/flapwaves2d``,
CaseFloatingWavesHadzic2D_Def.xml: the flume of W3 with the box of Hadzic et al. 2005, 0.1 x 0.05 m,
relative density 0.68) against the measured heave, roll and sway of the box.

The fast tests check the case's box (its size and mass at two dp) and the scoring on a synthetic
record; the runs (dp 0.01, 14 min each on 2 threads: with DBC as the case asks, and with mDBC on the
box only) are slow tests."""
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.validation.floating import fluid_inside_box
from sphdvi.validation.floatingwaves import BODY, RECORDS, body_records, body_scores
from sphdvi.validation.flapwaves import load_probe
from sphdvi.validation.runs import case_data

REPO = Path(__file__).resolve().parents[2]
CASE = REPO / "cases" / "flapwaves2d" / "CaseFloatingWavesHadzic2D_Def.xml"
OUTLINE = REPO / "cases" / "flapwaves2d" / "CaseFloatingWavesHadzicOutline2D_Def.xml"
REFERENCE = REPO.parent / "shared" / "reference"
if not (REFERENCE / "floating_box_waves_hadzic_2005").is_dir():
    pytest.skip("reference data ../shared/reference not found", allow_module_level=True)


@pytest.mark.parametrize("dp, count", [(0.01, 50), (0.005, 200)])
def test_the_box_is_the_experiments_at_every_dp(tmp_path, dp, count):
    r = CliRunner().invoke(main, ["gencase", str(CASE), "-o", str(tmp_path), "--dp", str(dp), "-q"])
    assert r.exit_code == 0, r.output
    p = case_data(str(tmp_path))["particles"]
    box = p["type"] == 2
    pos = p["pos"][box]
    # (0.1 − dp) x (0.05 − dp) of particle centres: with the dp/2 beyond them, 0.1 x 0.05 m
    assert box.sum() == count
    assert np.ptp(pos[:, 0]) + dp == pytest.approx(0.1) and np.ptp(pos[:, 2]) + dp == pytest.approx(0.05)
    assert pos[:, 0].min() == pytest.approx(2.06)
    # relative density 0.68 of that box: 3.4 kg per metre, whatever dp
    assert p["mass"][box].sum() == pytest.approx(0.68 * 1000 * 0.1 * 0.05)
    # the water fills around it, not into it
    fluid = p["pos"][p["type"] == 3]
    inside = ((fluid[:, 0] > pos[:, 0].min() - dp / 2) & (fluid[:, 0] < pos[:, 0].max() + dp / 2)
              & (fluid[:, 2] > pos[:, 2].min() - dp / 2))
    assert not inside.any()


def test_the_experiments_box_records():
    t, heave = load_probe(str(REFERENCE), RECORDS["heave"])
    tr, roll = load_probe(str(REFERENCE), RECORDS["roll"])
    ts, sway = load_probe(str(REFERENCE), RECORDS["sway"])
    # 6.3 s to 8.1 s, every 10-20 ms, starting from rest: the group's two highest waves
    assert t[0] == pytest.approx(6.3057, abs=1e-4) and tr[0] == pytest.approx(6.29, abs=1e-4)
    assert abs(heave[0]) < 1e-3 and abs(roll[0]) < 0.5 and abs(sway[0]) < 3e-3
    assert heave.max() == pytest.approx(0.0384, abs=1e-4) and roll.min() == pytest.approx(-23.6, abs=0.05)
    assert sway.max() == pytest.approx(0.1158, abs=1e-4)


def synthetic_run(tmp_path, scale=0.9, delay=0.03, drift=0.02):
    """A bodies.csv whose box moves as the experiment's, ``scale`` times as far, ``delay`` late,
    resting at (2.1, 0.39) until then and drifting ``drift`` before the record starts."""
    t = np.arange(0.0, 8.5, 0.01)
    rec = {}
    for name, column in RECORDS.items():
        te, ve = load_probe(str(REFERENCE), column)
        order = np.argsort(te, kind="stable")    # the roll's times are rounded to 10 ms: some step back
        te, ve = te[order], ve[order]
        rec[name] = scale * np.interp(t - delay, te, ve, left=0.0, right=ve[-1])
    x = 2.1 + rec["sway"] + drift * np.clip((t - 3.0) / 3.0, 0, 1)
    z = 0.39 + rec["heave"]
    header = "time,body,x,y,z,pitch"
    rows = [f"{a:.4f},{BODY},{b:.6f},0,{c:.6f},{-d:.4f}" for a, b, c, d in zip(t, x, z, rec["roll"])]
    (tmp_path / "bodies.csv").write_text(header + "\n" + "\n".join(rows) + "\n")
    return tmp_path


def test_body_scores_of_a_scaled_record(tmp_path):
    e = body_scores(str(synthetic_run(tmp_path, scale=0.9, delay=0.0)), str(REFERENCE), with_waves=False)
    for name in RECORDS:
        # the amplitude 10 % low; the drift before the record taken out of the sway (up to the
        # resampling of the 10 ms synthetic record at the experiment's samples, and the roll's
        # times rounded to 10 ms: some repeat with different angles)
        assert e[f"{name}_corr"] > 0.995, name
        assert e[f"{name}_rms"] == pytest.approx(-0.1, abs=0.005), name
        assert e[f"{name}_range"] == pytest.approx(-0.1, abs=0.01), name
    assert e["amp_max"] == pytest.approx(0.1, abs=0.01)
    t, roll = body_records(str(tmp_path))["roll"]        # roll about −y: −pitch of bodies.csv
    assert roll.min() == pytest.approx(-0.9 * 23.6, abs=0.05)


def test_body_scores_of_a_delayed_record(tmp_path):
    e = body_scores(str(synthetic_run(tmp_path, scale=1.0, delay=0.03)), str(REFERENCE), with_waves=False)
    for name in RECORDS:
        assert e[f"{name}_lag"] == pytest.approx(0.03, abs=0.0051), name
        assert e[f"{name}_corr_lag"] > 0.995 and e[f"{name}_corr"] < e[f"{name}_corr_lag"], name


@pytest.fixture(scope="module")
def run_dp_01(tmp_path_factory):
    out = tmp_path_factory.mktemp("s16") / "dp0.01"
    r = CliRunner().invoke(main, ["run", str(CASE), "-o", str(out), "--dp", "0.01", "--threads", "2", "-q"])
    assert r.exit_code == 0, r.output
    e = body_scores(str(out), str(REFERENCE))
    print({k: round(v, 4) for k, v in e.items()})
    return e


@pytest.mark.slow
def test_heave_and_sway_follow_the_experiment_at_box_over_dp_10(run_dp_01):
    """dp 0.01 (box 10 x 5 particles, 25,141 particles, 13.7 min on 2 threads). Measured (rms as
    a mean over the experiment's samples, before it was taken on a uniform time grid): heave
    correlation 0.940, rms +10.8 %, crest to trough −1.9 %, lag −0.005 s; sway (the drift the
    group's highest waves give the box, 0.11 m) correlation 0.976, range −22.8 %; the wave probes
    0.955 / 0.959 (WP2 stands behind the box). The sway's amplitude: see the xfail below."""
    e = run_dp_01
    assert e["heave_corr"] > 0.9 and abs(e["heave_lag"]) < 0.03
    assert abs(e["heave_rms"]) < 0.15 and abs(e["heave_range"]) < 0.15       # TOLERANCES S16: 10-15 %
    assert e["sway_corr"] > 0.95
    assert e["wave_corr_min"] > 0.9


@pytest.mark.slow
@pytest.mark.xfail(strict=True, raises=AssertionError,
                   reason="sway amplitude within 15 % (judgement: TOLERANCES S16 names heave and roll only; "
                          "the same band for the box's third motion): measured range −22.8 % at box/dp 10 "
                          "(−21.2 % session 35; −13.5 % at box/dp 20)")
def test_sway_amplitude_within_15_percent_at_box_over_dp_10(run_dp_01):
    assert abs(run_dp_01["sway_range"]) <= 0.15


@pytest.mark.slow
def test_roll_follows_the_experiment_at_box_over_dp_10(run_dp_01):
    """The roll (about −y) is in phase with the experiment's once 0.1 s is allowed (correlation
    0.915 at that lag, 0.538 without; the experiment's roll may carry a ~0.1 s time-base offset:
    see sphdvi.validation.floatingwaves). Its amplitude: see the xfail below."""
    e = run_dp_01
    assert e["roll_corr_lag"] > 0.85 and abs(e["roll_lag"]) <= 0.15


@pytest.mark.slow
@pytest.mark.xfail(strict=True, raises=AssertionError,
                   reason="TOLERANCES S16: roll amplitude within 10-15 %; measured −32.4 % rms, −35.0 % crest to "
                          "trough at box/dp 10 on the uniform time grid (session 36; session 35: −27.1 % rms as a "
                          "mean over the experiment's samples, which the SPH box's 0.1 s lead flattered)")
def test_roll_amplitude_within_15_percent_at_box_over_dp_10(run_dp_01):
    assert abs(run_dp_01["roll_rms"]) <= 0.15 and abs(run_dp_01["roll_range"]) <= 0.15


@pytest.fixture(scope="module")
def run_dp_01_mdbc_box(tmp_path_factory):
    """S16 with mDBC on the box only (its normals; the one-layer flume walls and the flap keep DBC)."""
    out = tmp_path_factory.mktemp("s16m") / "dp0.01"
    r = CliRunner().invoke(main, ["run", str(CASE), "-o", str(out), "--dp", "0.01", "--threads", "2", "-q",
                                  "--set", "Boundary=2", "--set", "MdbcMkbound=50"])
    assert r.exit_code == 0, r.output
    e = body_scores(str(out), str(REFERENCE))
    e.update({f"inside_{k}": v for k, v in fluid_inside_box(str(out)).items()})
    print({k: round(v, 4) for k, v in e.items()})
    return e


@pytest.mark.slow
def test_mdbc_on_the_box_brings_heave_within_15_percent_at_box_over_dp_10(run_dp_01_mdbc_box):
    """mDBC on the box at dp 0.01 (session 36, uniform time grid, 1 thread): heave rms +10.5 %,
    crest to trough −0.2 %, correlation 0.948; roll correlation 0.757 (0.937 at −0.07 s); sway
    range −21.2 %; the wave probes 0.948 / 0.967; no water inside the box."""
    e = run_dp_01_mdbc_box
    assert e["roll_corr_lag"] > 0.9 and -0.1 < e["roll_lag"] <= 0
    assert abs(e["heave_rms"]) <= 0.15 and abs(e["heave_range"]) <= 0.15
    assert e["heave_corr"] > 0.9 and abs(e["heave_lag"]) < 0.03
    assert e["sway_corr"] > 0.95 and e["wave_corr_min"] > 0.9


@pytest.mark.slow
@pytest.mark.xfail(strict=True, raises=AssertionError,
                   reason="TOLERANCES S16 roll 10-15 %: with mDBC on the box at box/dp 10, on the uniform time "
                          "grid (session 36): rms -21.3 %, crest to trough -14.2 % (the sample-mean score, "
                          "-12.2 % in session 35, was flattered by the box's 0.07 s lead)")
def test_mdbc_on_the_box_brings_roll_within_15_percent_at_box_over_dp_10(run_dp_01_mdbc_box):
    e = run_dp_01_mdbc_box
    assert abs(e["roll_rms"]) <= 0.15 and abs(e["roll_range"]) <= 0.15     # TOLERANCES S16: 10-15 %


@pytest.mark.slow
def test_no_water_inside_the_mdbc_box(run_dp_01_mdbc_box):
    """No fluid particle inside the rectangle of the box's particle centres at any output. With
    the box's particles seen by the fluid with their share of its mass (0.68 rho0 dp^2, as
    DualSPHysics) 4-5 were lodged in its outer row from 1 s on and the box floated 6 mm low."""
    assert run_dp_01_mdbc_box["inside_max_count"] == 0


@pytest.fixture(scope="module")
def run_outline_dp_02(tmp_path_factory):
    """S16O: mDBC on the box, its normals from its outline as GenCase's (norgeometry), at dp 0.02
    (box 5 x 2 particles, 6,566 particles, ~2 min on 2 threads, 5-9 min on 1)."""
    out = tmp_path_factory.mktemp("s16o") / "dp0.02"
    r = CliRunner().invoke(main, ["run", str(OUTLINE), "-o", str(out), "--dp", "0.02", "--threads", "2", "-q"])
    assert r.exit_code == 0, r.output
    e = body_scores(str(out), str(REFERENCE))
    print({k: round(v, 4) for k, v in e.items()})
    return e


@pytest.mark.slow
def test_outline_normals_heave_within_15_percent_at_box_over_dp_5(run_outline_dp_02):
    """S16O at box/dp 5 (2026-11-27, 1 thread, 518 s): heave correlation 0.888, rms +2.0 %, crest to
    trough −10.1 %; roll correlation 0.538 (0.896 at −0.105 s); sway correlation 0.955; the wave
    probes 0.928 / 0.983. (The box/dp 10 run, 14 min on 2 threads, is left to tools/validate.py S16O.)"""
    e = run_outline_dp_02
    assert abs(e["heave_rms"]) <= 0.15 and abs(e["heave_range"]) <= 0.15    # TOLERANCES S16: 10-15 %
    assert e["heave_corr"] > 0.85 and abs(e["heave_lag"]) < 0.05
    assert e["roll_corr_lag"] > 0.85 and abs(e["roll_lag"]) <= 0.15
    assert e["sway_corr"] > 0.9 and e["wave_corr_min"] > 0.9


@pytest.mark.slow
@pytest.mark.xfail(strict=True, raises=AssertionError,
                   reason="TOLERANCES S16: roll amplitude within 10-15 %; S16O at box/dp 5 measured rms −23.3 % "
                          "(uniform time grid; −10.6 % as the mean over the experiment's samples), crest to trough "
                          "−14.4 % (2026-11-27)")
def test_outline_normals_roll_within_15_percent_at_box_over_dp_5(run_outline_dp_02):
    assert abs(run_outline_dp_02["roll_rms"]) <= 0.15 and abs(run_outline_dp_02["roll_range"]) <= 0.15
