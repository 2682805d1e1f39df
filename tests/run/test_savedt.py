"""``<special><savedt>`` (DualSPHysics's JSaveDt): DtInfo.csv and DtAllInfo.csv, their columns
against the time-step formula (eq. 10), their window, and a resume that writes them bitwise as an
uninterrupted run does."""
import math

import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.io.dtinfo import dtinfo_header

from run.test_run import assert_gencase_error, small_case

COMMON = ["--threads", "1", "-q"]


def invoke(args):
    return CliRunner().invoke(main, [str(a) for a in args])


def savedt_case(tmp_path, body, params=""):
    path = small_case(tmp_path, extra_params=params)
    path.write_text(path.read_text().replace("<special>", f"<special><savedt>{body}</savedt>", 1))
    return path


def read_rows(path):
    lines = path.read_text().splitlines()
    return lines[0], [[float(v) if v.strip() else math.nan for v in line.split(";")] for line in lines[1:]]


def run_steps(out):
    return int((out / "run.csv").read_text().splitlines()[-1].split(",")[2])


def test_each_step_row_obeys_the_time_step_formula(tmp_path):
    """An interval shorter than a step gives a row per step: Dtf = min(Dt1, Dt2) (Verlet, dt
    above DtMin), Dt1 = CFL sqrt(h/AceMax), Dt2 = CFL h/(max(c0, 10 VelMax) + h ViscDtMax);
    DtAllInfo holds the same steps, their dt adding up to the run's time."""
    case = savedt_case(tmp_path, '<interval value="1e-7"/><fullinfo value="1"/><alldt value="1"/>')
    out = tmp_path / "o"
    r = invoke(["run", case, "-o", out, "--tmax", "0.02", "--tout", "0.005"] + COMMON)
    assert r.exit_code == 0, r.output
    head, rows = read_rows(out / "DtInfo.csv")
    assert head == dtinfo_header(True)
    assert head.startswith("Time [s];Values;Dtf_mean [s];Dtf_min [s];Dtf_max [s];Dt1_mean [s]")   # DualSPHysics's
    assert "AceMax_mean [m/s^2]" in head and ";ViscDtMax_mean;" in head and head.endswith("VelMax_max [m/s]")
    rows = np.array(rows)
    steps = run_steps(out)
    assert rows.shape == (steps, 20) and np.all(rows[:, 1] == 1)
    t, dtf, dt1, dt2 = rows[:, 0], rows[:, 2], rows[:, 5], rows[:, 8]
    ace, visc, vel = rows[:, 11], rows[:, 14], rows[:, 17]
    assert np.all(np.diff(t) > 0) and t[0] == 0.0
    np.testing.assert_allclose(t[1:], np.cumsum(dtf)[:-1], rtol=1e-9)
    np.testing.assert_allclose(dtf, np.minimum(dt1, dt2), rtol=1e-11)
    import json
    meta = json.loads((out / "run.json").read_text())
    from sphdvi.io.casefile import read_case_h5
    c = read_case_h5(str(next(out.glob("*.h5")) if not (out / "restart.h5").exists() else
                         next(p for p in out.glob("*.h5") if p.name != "restart.h5")))["constants"]
    cfl, h, c0 = 0.2, float(c["h"]), float(c["cs0"])
    np.testing.assert_allclose(dt1, cfl * np.sqrt(h / ace), rtol=1e-11)
    np.testing.assert_allclose(dt2, cfl * h / (np.maximum(c0, 10 * vel) + h * visc), rtol=1e-11)
    _, every = read_rows(out / "DtAllInfo.csv")
    every = np.array(every)
    assert (out / "DtAllInfo.csv").read_text().startswith("Time [s];Dtf [s]\n")
    np.testing.assert_array_equal(every, rows[:, [0, 2]])
    assert every[:, 1].sum() == pytest.approx(meta["physical_time"], rel=1e-12)


@pytest.mark.parametrize("algorithm", [1, 2])
def test_intervals_window_and_bitwise_resume(tmp_path, algorithm):
    """Rows every 0.003 s from 0.004 to 0.016 (an interval in progress at each output, 0.005
    apart); the window holds every step that starts in it; a run stopped at 0.01 and resumed
    writes both files byte for byte as the uninterrupted one."""
    body = '<start value="0.004"/><finish value="0.016"/><interval value="0.003"/><alldt value="true"/>'
    case = savedt_case(tmp_path, body, f'<parameter key="StepAlgorithm" value="{algorithm}"/>')
    a, b = tmp_path / "a", tmp_path / "b"
    assert invoke(["run", case, "-o", a, "--tmax", "0.02", "--tout", "0.005"] + COMMON).exit_code == 0
    head, rows = read_rows(a / "DtInfo.csv")
    assert head == dtinfo_header(False)
    rows = np.array(rows)
    _, every = read_rows(a / "DtAllInfo.csv")
    every = np.array(every)
    assert every[0, 0] >= 0.004 and every[-1, 0] <= 0.016 and every[0, 0] - every[0, 1] < 0.004
    assert rows[:, 1].sum() == len(every)               # every step of the window, once
    # a row per interval, cut at every output as DualSPHysics's JDsSaveDt::SaveData does: a new row
    # where a step starts in another interval than the one before or after an output
    outputs = np.array([float(x.split(",")[1]) for x in (a / "run.csv").read_text().splitlines()[1:]])
    starts = every[:, 0]
    k = np.floor((starts - 0.004) / 0.003)
    new_row = np.ones(len(starts), bool)
    new_row[1:] = (k[1:] != k[:-1]) | [np.any((outputs > t0 + 1e-9) & (outputs <= t1 + 1e-9))
                                       for t0, t1 in zip(starts[:-1], starts[1:])]
    np.testing.assert_array_equal(rows[:, 0], starts[new_row])
    assert len(rows) > len(np.unique(k))                  # some intervals were cut by an output
    assert np.all(rows[:, 3] <= rows[:, 2]) and np.all(rows[:, 2] <= rows[:, 4])
    if algorithm == 2:          # a Symplectic step's dt is the min of the terms found before it
        np.testing.assert_allclose(rows[:, 3], np.minimum(rows[:, 6], rows[:, 9]), rtol=1e-11)
    assert invoke(["run", case, "-o", b, "--tmax", "0.01", "--tout", "0.005"] + COMMON).exit_code == 0
    r = invoke(["run", b, "--resume", "--tmax", "0.02"] + COMMON)
    assert r.exit_code == 0, r.output
    for name in ("DtInfo.csv", "DtAllInfo.csv"):
        assert (b / name).read_bytes() == (a / name).read_bytes(), name


@pytest.mark.parametrize("body, message", [
    ('<interval value="0"/>', "interval=0"),
    ('<finish value="0.1"/><start value="0.2"/>', "is before start"),
    ('<every value="1"/>', "unknown element <every>"),
    ('<fullinfo value="maybe"/>', "is not a boolean"),
])
def test_bad_savedt_is_a_case_error(tmp_path, body, message):
    assert_gencase_error(savedt_case(tmp_path, body), tmp_path / "g", message)


def test_a_body_only_run_says_it_has_no_dt_to_record(tmp_path):
    from pathlib import Path
    src = Path(__file__).resolve().parents[2] / "cases" / "pendulum"
    xml = next(src.glob("*_Def.xml"))
    for extra in src.iterdir():
        if extra.is_file():
            (tmp_path / extra.name).write_bytes(extra.read_bytes())
    case = tmp_path / xml.name
    case.write_text(xml.read_text().replace("<special>", "<special><savedt/>", 1))
    out = tmp_path / "o"
    with pytest.warns(UserWarning, match="body-only run"):
        r = invoke(["run", case, "-o", out, "--tmax", "0.05", "-q"])
    assert r.exit_code == 0, r.output
    assert "<special><savedt>: a body-only run" in (out / "run.log").read_text()
    assert not (out / "DtInfo.csv").exists()


def test_a_diverged_run_keeps_the_dt_of_every_step_it_took(tmp_path):
    """DtFixed far above the CFL limit blows up (exit 3); DtInfo.csv and DtAllInfo.csv hold every step,
    the last one's included, and show the force condition Dt1 collapsing under the imposed dt."""
    import json
    case = savedt_case(tmp_path, '<interval value="0.002"/><alldt value="1"/>')
    out = tmp_path / "o"
    with pytest.warns(UserWarning, match="excluded"):
        r = invoke(["run", case, "-o", out, "--tmax", "0.5", "--tout", "0.01", "--set", "DtFixed=0.004"] + COMMON)
    assert r.exit_code == 3, r.output
    meta = json.loads((out / "run.json").read_text())
    assert meta["status"] == "diverged"
    _, every = read_rows(out / "DtAllInfo.csv")
    _, rows = read_rows(out / "DtInfo.csv")
    rows = np.array(rows)
    assert len(every) == meta["steps"] == rows[:, 1].sum()
    assert np.all(np.array(every)[:, 1] == 0.004)
    # Dt1 = CFL sqrt(h/|a|max): below the imposed 0.004 s from the first step, under a tenth of it by the last
    assert rows[-1, 6] < 0.1 * 0.004 and rows[0, 6] < 0.004 and rows[-1, 6] < 0.2 * rows[0, 6]
