"""--resume with run-time gauges: a resumed (or SIGKILLed and resumed) run writes exactly the gauge
rows of an uninterrupted one, bitwise on 1 thread (DualSPHysics's JGaugeItem keeps its next compute
and next output times as state; JSph::SaveData writes the gauges' rows at every output)."""
import json
import os
import re
import signal
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
from click.testing import CliRunner

from sphdvi.cli import main

REPO = Path(__file__).resolve().parents[2]
DAMBREAK = REPO / "cases" / "dambreak2d" / "CaseDambreakVal2D_Def.xml"

# computedt 0.007 does not divide the output interval (TimeOut 0.01): the row kept is the first
# computed one at or after each multiple of 0.01, and the output schedule lags the compute one
LAGGING = """<gauges>
    <default><output value="true" /></default>
    <velocity name="V7"><point x="0.5" y="0" z="0.5" /><computedt value="0.007" /></velocity>
    <velocity name="Vstart"><point x="0.5" y="0" z="0.5" /><computedt value="0.007" />
      <outputtime start="0.025" end="1" /></velocity>
    <maxz name="M7"><point0 x="0.5" y="0" z="0" /><height value="3" /><computedt value="0.007" /></maxz>
    <swl name="S"><point0 x="0.5" y="0" z="-0.05" /><point2 x="0.5" y="0" z="2.5" /></swl>
  </gauges>"""

# every step, with <timeout> rows (every 0.002 s) and a TimeOut (0.05 s) that no row reaches
EVERY_STEP = """<timeout><tout time="0" timeout="0.002" /></timeout>
  <gauges>
    <default><output value="true" /></default>
    <velocity name="Vall"><point x="0.5" y="0" z="0.5" /><computedt value="0" /><outputdt value="0" /></velocity>
  </gauges>"""

# run in a subprocess: SIGKILL right after the checkpoint of part PART (as a kill between two outputs)
KILLED_AFTER_PART = """
import os, signal, sys
from sphdvi import simulation
save = simulation.SPHRun.save_checkpoint
def save_then_die(self, path, extra):
    save(self, path, extra)
    if extra["part"] == {part}:
        os.kill(os.getpid(), signal.SIGKILL)
simulation.SPHRun.save_checkpoint = save_then_die
from sphdvi.cli import main
main(sys.argv[1:])
"""


def invoke(args):
    return CliRunner().invoke(main, [str(a) for a in args])


def gauge_case(tmp_path, gauges, timeout="0.01"):
    text = DAMBREAK.read_text().replace('dp="0.01"', 'dp="0.04"')
    text = re.sub(r"<gauges>.*?</gauges>", gauges, text, flags=re.S)
    text = re.sub(r'(key="TimeOut" value=")[^"]*"', rf'\g<1>{timeout}"', text)
    path = tmp_path / "CaseGR_Def.xml"
    path.write_text(text)
    return path


def gauge_files(out):
    return {p.name: p.read_text() for p in sorted(out.glob("Gauges*.csv"))}


def assert_same_run(a, b):
    """The gauge files equal line by line, and the final particle states bitwise."""
    ga, gb = gauge_files(a), gauge_files(b)
    assert ga.keys() == gb.keys() and ga
    for name in ga:
        assert ga[name].splitlines() == gb[name].splitlines(), name
    with h5py.File(a / "restart.h5", "r") as fa, h5py.File(b / "restart.h5", "r") as fb:
        assert fa["scalars"].attrs["nstep"] == fb["scalars"].attrs["nstep"]
        for k in ("pos", "vel", "rhop", "idp"):
            assert np.array_equal(fa["state"][k][...], fb["state"][k][...]), k


def test_resume_keeps_the_rows_of_a_lagging_output_schedule(tmp_path):
    """computedt not dividing outputdt, and an <outputtime start> after the restart time: the resumed
    run keeps the rows the uninterrupted one keeps (0.02107 s of V7 and M7, 0.02813 s of Vstart were
    dropped when the output schedule restarted at the first multiple after the restart time)."""
    case = gauge_case(tmp_path, LAGGING)
    common = ["--tout", "0.01", "--threads", "1", "-q"]
    a, b = tmp_path / "a", tmp_path / "b"
    assert invoke(["run", case, "-o", a, "--tmax", "0.04"] + common).exit_code == 0
    assert invoke(["run", case, "-o", b, "--tmax", "0.02"] + common).exit_code == 0
    with h5py.File(b / "restart.h5", "r") as f:
        state = json.loads(f["scalars"].attrs.get("gauges", "{}"))
    r = invoke(["run", b, "--resume", "--tmax", "0.04"] + common)
    assert r.exit_code == 0, r.output
    assert_same_run(a, b)
    assert state["GaugesVel_Vstart.csv"][1] == 0            # no row kept yet at 0.02 s: its output schedule at 0
    v7 = [float(l.split(";")[0]) for l in (a / "GaugesVel_V7.csv").read_text().splitlines()[1:]]
    assert len(v7) == 4 and any(0.02 < t < 0.021 + 0.0007 for t in v7)   # the row after 0.02 s
    vs = [float(l.split(";")[0]) for l in (a / "GaugesVel_Vstart.csv").read_text().splitlines()[1:]]
    assert len(vs) == 2 and 0.025 < vs[0] < 0.03, vs


def test_resume_of_a_checkpoint_without_gauge_state(tmp_path):
    """An older checkpoint (no gauge schedules): the rows go on from the first multiples after the
    restart time, as before; with computedt dividing outputdt that is the uninterrupted run's rows."""
    case = gauge_case(tmp_path, LAGGING)
    common = ["--tout", "0.01", "--threads", "1", "-q"]
    a, b = tmp_path / "a", tmp_path / "b"
    assert invoke(["run", case, "-o", a, "--tmax", "0.04"] + common).exit_code == 0
    assert invoke(["run", case, "-o", b, "--tmax", "0.02"] + common).exit_code == 0
    with h5py.File(b / "restart.h5", "a") as f:
        del f["scalars"].attrs["gauges"]
    r = invoke(["run", b, "--resume", "--tmax", "0.04"] + common)
    assert r.exit_code == 0, r.output
    assert (a / "GaugesSWL_S.csv").read_text() == (b / "GaugesSWL_S.csv").read_text()
    times = [float(l.split(";")[0]) for l in (b / "GaugesVel_V7.csv").read_text().splitlines()[1:]]
    assert np.all(np.diff(times) > 0)


def test_sigkill_after_a_timeout_row_loses_no_gauge_row(tmp_path):
    """<timeout> rows every 0.002 s, TimeOut 0.05 s: a run killed (SIGKILL) after its checkpoint at
    part 5 and resumed writes every gauge row of an uninterrupted run (the rows since t=0 were held
    in memory until a multiple of TimeOut, and lost)."""
    case = gauge_case(tmp_path, EVERY_STEP, timeout="0.05")
    args = ["--tmax", "0.02", "--threads", "1", "-q"]
    a, b = tmp_path / "a", tmp_path / "b"
    assert invoke(["run", case, "-o", a] + args).exit_code == 0
    env = dict(os.environ, NUMBA_NUM_THREADS="1")
    proc = subprocess.run([sys.executable, "-c", KILLED_AFTER_PART.format(part=5), "run", str(case), "-o", str(b)]
                          + args, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, timeout=300)
    assert proc.returncode == -signal.SIGKILL, proc.stderr.decode()[-2000:]
    assert json.loads((b / "run.json").read_text())["status"] == "running"
    rows = (b / "GaugesVel_Vall.csv").read_text().splitlines()[1:]
    assert len(rows) > 10 and float(rows[-1].split(";")[0]) >= 0.01 - 1e-9      # flushed with part 5
    r = invoke(["run", b, "--resume", "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output
    assert_same_run(a, b)
    steps = json.loads((a / "run.json").read_text())["steps"]
    assert len((a / "GaugesVel_Vall.csv").read_text().splitlines()) == 1 + steps + 1     # header, t=0, each step
