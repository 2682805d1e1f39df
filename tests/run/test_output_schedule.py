"""``<special><timeout>`` (DualSPHysics's JTimeOut): uneven output times, at gencase, in a run and
across --resume; without it, outputs TimeOut apart exactly as before."""
import os

import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.dvi.runner import StepSchedule
from sphdvi.output_schedule import OutputSchedule

from run.test_run import REPO, final_state, small_case

TIMEOUT = ('<timeout><tout time="0" timeout="0.004"/><tout time="0.006" timeout="0.001"/>'
           '<tout time="0.0085" timeout="0.003"/></timeout>')
# 0, then 0.004 apart; from 0.006 (an output) 0.001 apart; 0.0085 (an output: the next row's
# time cuts the 0.001 interval short); then 0.003 apart counted from 0.0085
EXPECTED = [0.0, 0.004, 0.006, 0.007, 0.008, 0.0085, 0.0115, 0.0145]


def schedule_times(schedule, n):
    return [schedule.nth(k) for k in range(n)]


def test_uniform_schedule_is_the_loops_own_arithmetic():
    """(k + 1) TimeOut, bit for bit, as the loop computed it before schedules existed."""
    for tout in (0.01, 0.003, 0.1, 1 / 3, 2.5e-4):
        s = OutputSchedule.every(tout)
        t = 0.0
        for k in range(5000):
            assert s.nth(k) == k * tout
            t = s.after(t)
            assert t == (k + 1) * tout


def test_rows_as_dualsphysics():
    s = OutputSchedule([(0, 0.004), (0.006, 0.001), (0.0085, 0.003)])
    assert schedule_times(s, len(EXPECTED)) == pytest.approx(EXPECTED, abs=1e-15)
    late = OutputSchedule([(0.5, 0.1)])          # before the first row: that row's time
    assert schedule_times(late, 4) == pytest.approx([0.0, 0.5, 0.6, 0.7])
    with pytest.raises(ValueError):
        OutputSchedule([(0, 0.1), (0, 0.2)])


def test_body_only_step_schedule_puts_each_output_at_its_nearest_step():
    s = OutputSchedule([(0, 0.004), (0.006, 0.001), (0.0085, 0.003)])
    sched = StepSchedule(0.0145, 0.004, 5e-4, None, s)
    steps = [k for k in range(1, sched.nsteps + 1) if sched.is_output(k)]
    assert np.allclose(np.array(steps) * 5e-4, EXPECTED[1:])
    plain = StepSchedule(0.01, 0.004, 1e-3)
    assert [k for k in range(1, 11) if plain.is_row(k)] == [4, 8, 10]
    # a TimeMax between two steps takes the step after it, as an SPH run (round() stopped short)
    assert StepSchedule(1.0125, 0.1, 1e-3).nsteps == 1013
    assert StepSchedule(0.3, 0.1, 0.1).nsteps == 3             # 0.3 / 0.1 = 2.9999999999999996


def invoke(args):
    return CliRunner().invoke(main, [str(a) for a in args])


def run_times(out):
    rows = (out / "run.csv").read_text().splitlines()[1:]
    return np.array([float(r.split(",")[1]) for r in rows])


def timeout_case(tmp_path):
    path = small_case(tmp_path)
    path.write_text(path.read_text().replace("<special>", "<special>" + TIMEOUT, 1))
    return path


def test_run_writes_at_the_rows_times_and_resumes_on_them(tmp_path):
    case = timeout_case(tmp_path)
    assert "<timeout>" in case.read_text()
    a, b = tmp_path / "a", tmp_path / "b"
    common = ["--threads", "1", "-q"]
    r = invoke(["run", case, "-o", a, "--tmax", "0.0145"] + common)
    assert r.exit_code == 0, r.output
    t = run_times(a)
    # each output at the first step that reaches its time (the steps are ~1e-4 s)
    assert len(t) == len(EXPECTED)
    assert np.all(t >= np.array(EXPECTED) - 1e-12) and np.all(t - np.array(EXPECTED) < 2e-4)
    # stopped at the 0.0085 output and resumed: the same outputs and bitwise the same state
    assert invoke(["run", case, "-o", b, "--tmax", "0.0085"] + common).exit_code == 0
    r = invoke(["run", b, "--resume", "--tmax", "0.0145"] + common)
    assert r.exit_code == 0, r.output
    assert np.array_equal(run_times(b), t)
    sa, ka = final_state(a)
    sb, kb = final_state(b)
    assert ka["nstep"] == kb["nstep"]
    for k in sa:
        assert np.array_equal(sa[k], sb[k]), k
    # --tout asks for even outputs instead
    r = invoke(["run", case, "-o", tmp_path / "c", "--tmax", "0.012", "--tout", "0.004"] + common)
    assert r.exit_code == 0, r.output
    assert np.allclose(run_times(tmp_path / "c"), [0, 0.004, 0.008, 0.012], atol=2e-4)


@pytest.mark.parametrize("rows, message", [
    ('<tout time="0" timeout="0.01"/><tout time="0" timeout="0.02"/>', "does not follow the row before"),
    ('<tout time="0" timeout="0"/>', "is not positive"),
    ('<tout time="-1" timeout="0.1"/>', "is negative"),
    ('<tout time="0" />', "timeout"),
    ('<touts time="0" timeout="0.1"/>', "not a DualSPHysics output-time row"),
    ('', "has no <tout> row"),
])
def test_bad_timeout_rows_are_case_errors(tmp_path, rows, message):
    path = small_case(tmp_path)
    path.write_text(path.read_text().replace("<special>", f"<special><timeout>{rows}</timeout>", 1))
    r = invoke(["gencase", path, "-o", tmp_path / "g"])
    assert r.exit_code == 2, r.output
    assert "CaseDB_Def.xml:" in r.output and message in r.output
    assert "Traceback" not in r.output
    assert os.path.basename(str(path)) in r.output


def test_a_single_timeout_row_sets_the_interval_of_a_body_only_run(tmp_path):
    """<timeout> with one row from t = 0 is an even schedule of its own interval, not TimeOut's."""
    from pathlib import Path
    src = Path(__file__).resolve().parents[2] / "cases" / "pendulum"
    xml = next(src.glob("*_Def.xml"))
    text = xml.read_text()
    assert "<special>" in text
    case = tmp_path / xml.name
    case.write_text(text.replace("<special>", '<special><timeout><tout time="0" timeout="0.02"/></timeout>', 1))
    for extra in src.iterdir():
        if extra.name != xml.name and extra.is_file():
            (tmp_path / extra.name).write_bytes(extra.read_bytes())
    out = tmp_path / "o"
    r = invoke(["run", case, "-o", out, "--tmax", "0.1", "-q"])
    assert r.exit_code == 0, r.output
    assert np.allclose(run_times(out), np.arange(0, 0.1001, 0.02), atol=1e-9)


def test_a_step_longer_than_the_interval_skips_the_times_it_jumped(tmp_path):
    """DualSPHysics's GetNextTime(TimeStep): after an output the next one is the first scheduled
    time after the clock.  Outputs 1e-4 s apart with steps of ~1.3e-4 s until 0.01, then 0.005
    apart: one output per step until 0.01, then 0.015, 0.02 (sphdvi stepped from the previous
    scheduled time, fell behind the clock, and then wrote every step long after 0.01)."""
    path = small_case(tmp_path)
    rows = '<timeout><tout time="0" timeout="0.0001"/><tout time="0.01" timeout="0.005"/></timeout>'
    path.write_text(path.read_text().replace("<special>", "<special>" + rows, 1))
    out = tmp_path / "o"
    r = invoke(["run", path, "-o", out, "--tmax", "0.02", "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output
    t = run_times(out)
    late = t[t > 0.0101]
    assert late.size == 2 and np.all(np.abs(late - [0.015, 0.02]) < 2e-4), late
    steps = [int(line.split(",")[2]) for line in (out / "run.csv").read_text().splitlines()[1:]]
    early = np.diff(steps)[: int(np.count_nonzero(t <= 0.0101)) - 1]
    assert np.all(early == 1)                                  # every step an output before 0.01


def test_body_only_outputs_at_the_first_step_reaching_their_time():
    """As an SPH run (and DualSPHysics): an output at the first step whose end reaches it, the next
    time after that step's; not the nearest step (round-half-even put 0.0025 at step 2, before it)."""
    def outputs(tout, tmax=0.012, dt=1e-3, table=None):
        s = StepSchedule(tmax, tout, dt, None, table)
        return [k for k in range(1, s.nsteps + 1) if s.is_output(k)]
    assert outputs(0.0025) == [3, 5, 8, 10, 12]                # 12: the last step
    assert outputs(0.0015) == [2, 3, 5, 6, 8, 9, 11, 12]
    assert outputs(None, table=OutputSchedule([(0, 0.0025), (0.0075, 0.0035)]))[:2] == [3, 5]
    extra = StepSchedule(0.012, 0.01, 1e-3, 0.0025)
    assert [k for k in range(1, 13) if extra.is_row(k) and not extra.is_output(k)] == [3, 5, 8]


def test_timeoutextra_rows_whatever_timeout_says(tmp_path):
    """DualSPHysics writes the extra floating rows whenever TimeOutExtra >= 0 (negative, its default
    -1: none), with a <timeout> table too; sphdvi dropped them when TimeOutExtra >= TimeOut (and
    refused -1, and a WrnPartsOut other than 0 and 1, which DualSPHysics reads as != 0)."""
    case = tmp_path / "CaseFloatingBox2D_Def.xml"
    src = (REPO / "cases" / "floatingbox2d" / "CaseFloatingBox2D_Def.xml").read_text()
    case.write_text(src.replace("<special>", '<special><timeout><tout time="0" timeout="0.05"/></timeout>', 1)
                    if "<special>" in src else src.replace("<parameters>", '<special><timeout><tout time="0" '
                                                           'timeout="0.05"/></timeout></special><parameters>', 1))
    common = ["--dp", "0.04", "--tmax", "0.1", "--threads", "1", "-q", "--set", "FtPause=0", "--set", "TimeOut=0.01"]
    out = tmp_path / "o"
    r = invoke(["run", case, "-o", out, "--set", "TimeOutExtra=0.02"] + common)
    assert r.exit_code == 0, r.output
    times = np.unique([float(x.split(",")[0]) for x in (out / "bodies.csv").read_text().splitlines()[1:]])
    assert times.size == 7 and np.all(np.abs(times - [0, 0.02, 0.04, 0.05, 0.06, 0.08, 0.1]) < 5e-4), times
    r = invoke(["run", case, "-o", tmp_path / "n", "--set", "TimeOutExtra=-1", "--set", "WrnPartsOut=2"] + common)
    assert r.exit_code == 0, r.output
    assert np.unique([float(x.split(",")[0]) for x in
                      (tmp_path / "n" / "bodies.csv").read_text().splitlines()[1:]]).size == 3
