"""``<special><timeout>`` (DualSPHysics's JTimeOut): uneven output times, at gencase, in a run and
across --resume; without it, outputs TimeOut apart exactly as before."""
import os

import numpy as np
import pytest
from click.testing import CliRunner

from sphdvi.cli import main
from sphdvi.dvi.runner import StepSchedule
from sphdvi.output_schedule import OutputSchedule

from run.test_run import final_state, small_case

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
