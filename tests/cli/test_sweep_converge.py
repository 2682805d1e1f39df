"""``sphdvi sweep converge``: error against resolution and run time of a sweep over dp
(sphdvi/convergence.py).  The observed order is checked on signals whose error is a known power of
dp (f_k(t) = sin t + C dp_k^p cos t), on equal and unequal refinement ratios; the command on a sweep
folder whose runs' files are written by the test (no simulation: the runs' outputs are the input)."""
import csv
import json
import math
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi import convergence as cv
from sphdvi.cli import main
from sphdvi.errors import InputError

REPO = Path(__file__).resolve().parents[2]
DAMBREAK = REPO / "cases" / "dambreak2d" / "CaseDambreakVal2D_Def.xml"


def invoke(args):
    return CliRunner().invoke(main, [str(a) for a in args])


def signal(dp, p, t, c=3.0):
    """A run's signal whose error against sin t is c dp^p cos t."""
    return np.sin(t) + c * dp ** p * np.cos(t)


@pytest.mark.parametrize("dps", [(0.04, 0.02, 0.01), (0.04, 0.02, 0.0125), (0.03, 0.02, 0.0125)])
@pytest.mark.parametrize("p", [1.0, 1.5, 2.0])
def test_order_from_differences_recovers_the_power_of_dp(dps, p):
    """Celik et al. (2008) eqs. 3-4: for f_k = f + C dp_k^p the three differences give p exactly,
    also for unequal refinement ratios (where ln(d0/d1)/ln r alone would not)."""
    f = [x ** p for x in dps]
    got = cv.order_from_differences(f[0] - f[1], f[1] - f[2], dps[0] / dps[1], dps[1] / dps[2])
    assert got == pytest.approx(p, abs=1e-9)
    if dps[0] / dps[1] != dps[1] / dps[2]:
        naive = math.log((f[0] - f[1]) / (f[1] - f[2])) / math.log(dps[1] / dps[2])
        assert abs(naive - p) > 0.05            # the correction q(p) matters here


def test_order_from_differences_not_converging_is_nan():
    assert math.isnan(cv.order_from_differences(1.0, 2.0, 2.0, 2.0))     # the differences grow
    assert math.isnan(cv.order_from_differences(0.0, 1.0, 2.0, 2.0))
    assert math.isnan(cv.order_from_differences(1.0, float("nan"), 2.0, 2.0))


def test_level_errors_against_a_reference_and_without():
    """Against sin t the rms error is c dp^p rms(cos t), order p between levels; without a
    reference the differences to the next finer level give p from three levels.  The runs write
    at different times (interpolated onto the reference's or the finer run's)."""
    dps = [0.04, 0.02, 0.01, 0.005]
    t_ref = np.linspace(0.0, 2.0, 401)
    ref = (t_ref, np.sin(t_ref))
    signals = []
    for k, dp in enumerate(dps):
        t = np.linspace(0.0, 2.0, 2001 + 7 * k)
        signals.append((t, signal(dp, 2.0, t)))
    err, orders = cv.level_errors(dps, signals, "rms", ref)
    rms_cos = np.sqrt(np.mean(np.cos(t_ref) ** 2))
    for e, dp in zip(err, dps):
        assert e == pytest.approx(3.0 * dp ** 2 * rms_cos, rel=2e-3)
    assert orders[:3] == pytest.approx([2.0] * 3, abs=5e-3) and math.isnan(orders[3])
    rel, _ = cv.level_errors(dps, signals, "rms", ref, relative=True)
    assert rel[0] == pytest.approx(err[0] / np.sqrt(np.mean(np.sin(t_ref) ** 2)), rel=1e-12)
    diff, orders = cv.level_errors(dps, signals, "rms")
    assert math.isnan(diff[3]) and orders[:2] == pytest.approx([2.0, 2.0], abs=5e-3)
    assert math.isnan(orders[2]) and math.isnan(orders[3])
    # max and end norms, and a window
    e_end, _ = cv.level_errors(dps, signals, "end", ref, tmax=1.0)
    assert e_end[0] == pytest.approx(3.0 * 0.04 ** 2 * math.cos(1.0), rel=2e-3)
    e_max, _ = cv.level_errors(dps, signals, "max", ref, tmin=1.0)
    assert e_max[1] == pytest.approx(3.0 * 0.02 ** 2 * abs(math.cos(1.0)), rel=2e-3)
    # a level without data is skipped: the orders bridge it
    signals[1] = None
    err2, orders2 = cv.level_errors(dps, signals, "rms", ref)
    assert math.isnan(err2[1]) and orders2[0] == pytest.approx(2.0, abs=5e-3)


def test_series_reads_units_separators_filters_and_repeated_times():
    header = ["time", "body", "x", "heave [m]"]
    rows = [["0", "a", "1", "0.5"], ["0", "b", "9", "9"], ["0.1", "a", "2", "0.6"], ["0.1", "b", "9", "9"],
            ["0.1", "a", "3", "0.7"], ["0.05", "a", "4", "0.8"]]
    t, f = cv.series(header, rows, "heave", "bodies.csv", where=[("body", "a")])
    assert list(t) == [0.0, 0.05, 0.1] and list(f) == [0.5, 0.8, 0.7]     # sorted; the last row of t = 0.1
    with pytest.raises(InputError, match="no column 'z'; its columns: time, body, x, heave"):
        cv.series(header, rows, "z", "bodies.csv")
    with pytest.raises(InputError, match="no rows match body=c"):
        cv.series(header, rows, "x", "bodies.csv", where=[("body", "c")])
    with pytest.raises(InputError, match=r"bodies.csv:2: expected numbers"):
        cv.series(header, rows, "body", "bodies.csv")
    with pytest.raises(InputError, match="give --time-column"):
        cv.series(["t", "x"], [["0", "1"]], "x", "f.csv")
    t, f = cv.series(["t", "x"], [["0", "1"]], "x", "f.csv", time_name="t")
    assert list(f) == [1.0]


def _fake_sweep(tmp_path, dps=("0.04", "0.02", "0.01"), viscos=("0.01", "0.02"), p=2.0, pending=()):
    """A sweep folder made by 'sweep new' whose runs' outputs the test writes: run.json (completed,
    particles, runtime_s) and a ';' gauge file with a signal of error 3 dp^p cos t (Visco 0.02: 2x)."""
    sw = tmp_path / "sw"
    r = invoke(["sweep", "new", DAMBREAK, "-o", sw, "--vary", "Visco=" + ",".join(viscos),
                "--vary", "dp=" + ",".join(dps), "--tmax", "0.1"])
    assert r.exit_code == 0, r.output
    with open(sw / "sweep.csv", newline="") as fh:
        entries = list(csv.DictReader(fh))
    for e in entries:
        i, dp, visco = int(e["index"]), float(e["dp"]), float(e["Visco"])
        run = sw / e["dir"]
        status = "interrupted" if i in pending else "completed"
        run.joinpath("run.json").write_text(json.dumps({"status": status, "particles": int(1 / dp ** 2),
                                                        "runtime_s": 10.0 / dp, "physical_time": 2.0}))
        t = np.linspace(0.0, 2.0, 1001)        # the reference's times (every 0.01 s) among them
        f = signal(dp, p, t, c=3.0 * visco / 0.01)
        lines = ["time [s];swlx [m];swlz [m]"] + [f"{float(a)!r};0.6;{float(b)!r}" for a, b in zip(t, f)]
        run.joinpath("GaugesSWL_WP1.csv").write_text("\n".join(lines) + "\n")
    return sw, entries


def test_converge_command_against_a_reference(tmp_path):
    sw, entries = _fake_sweep(tmp_path)
    t = np.linspace(0.0, 2.0, 201)
    ref = tmp_path / "ref.csv"
    ref.write_text("time,eta\n" + "".join(f"{float(a)!r},{math.sin(a)!r}\n" for a in t))
    out = tmp_path / "conv.csv"
    r = invoke(["sweep", "converge", sw, "--file", "GaugesSWL_WP1.csv", "--column", "swlz", "--reference", ref,
                "--ref-column", "eta", "-o", out])
    assert r.exit_code == 0, r.output
    with open(out, newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert list(rows[0]) == ["Visco", "index", "dp", "status", "particles", "runtime_s", "error", "order"]
    rms_cos = np.sqrt(np.mean(np.cos(t) ** 2))
    by_visco = {}
    for row in rows:
        by_visco.setdefault(row["Visco"], []).append(row)
    assert [r["dp"] for r in by_visco["0.01"]] == ["0.04", "0.02", "0.01"]       # coarse to fine
    for visco, group in by_visco.items():
        for row in group:
            want = 3.0 * float(visco) / 0.01 * float(row["dp"]) ** 2 * rms_cos
            assert float(row["error"]) == pytest.approx(want, rel=1e-5)      # 6 digits printed
            assert float(row["runtime_s"]) == pytest.approx(10.0 / float(row["dp"]))
        assert [float(r["order"]) for r in group[:2]] == pytest.approx([2.0, 2.0], abs=1e-3)
        assert group[2]["order"] == ""
    assert "error" in r.output and "order" in r.output


def test_converge_command_without_reference_and_a_run_left_out(tmp_path):
    sw, entries = _fake_sweep(tmp_path, dps=("0.04", "0.02", "0.0125", "0.01"), viscos=("0.01",), pending=(3,))
    r = invoke(["sweep", "converge", sw, "--file", "GaugesSWL_WP1.csv", "--column", "swlz [m]", "--relative"])
    assert r.exit_code == 0, r.output
    assert "left out (1): run_0003 (interrupted)" in r.output
    lines = [ln.split() for ln in r.output.splitlines() if ln.startswith("0.01 ")]
    assert [ln[2] for ln in lines] == ["0.04", "0.02", "0.0125", "0.01"]
    # the differences of levels 0-1-2 give 2 (unequal ratios 2 and 1.6); level 3 not completed
    assert float(lines[0][-1]) == pytest.approx(2.0, abs=1e-3)
    assert len(lines[1]) == 7 and lines[3][3] == "interrupted" and len(lines[3]) == 6     # no order / no value


def test_converge_needs_dp_varied_and_known_columns(tmp_path):
    sw = tmp_path / "sw"
    assert invoke(["sweep", "new", DAMBREAK, "-o", sw, "--vary", "Visco=0.01,0.02", "--tmax", "0.1"]).exit_code == 0
    r = invoke(["sweep", "converge", sw, "--file", "GaugesSWL_WP1.csv", "--column", "swlz"])
    assert r.exit_code == 2 and "does not vary dp" in r.output and "Traceback" not in r.output
    sw2, _ = _fake_sweep(tmp_path / "b")
    r = invoke(["sweep", "converge", sw2, "--file", "GaugesSWL_WP1.csv", "--column", "swly"])
    assert r.exit_code == 2 and "no column 'swly'" in r.output
    r = invoke(["sweep", "converge", sw2, "--file", "GaugesSWL_WP1.csv", "--column", "swlz", "--where", "nokey"])
    assert r.exit_code == 2 and "--where nokey: expected COL=VALUE" in r.output
