"""The command line and run files against the written spec (audit 9): readers of particles.vtkhdf
during a run and OUT's run lock, one exit code for an interrupted command, run.json's resolved
parameters and constants, the commands messages suggest, --set CFLnumber, --tmax/--set TimeMax
conflicts, the threads warning under SLURM, progress lines with dt and warnings beside the bar.
Tiny runs (dp 0.1) and one run in a subprocess, stopped after a few outputs."""
import io
import json
import os
import signal
import subprocess
import sys
import textwrap
import time
import types
import warnings
from pathlib import Path

import pytest
from click.testing import CliRunner

from sphdvi.cli import main

REPO = Path(__file__).resolve().parents[2]
DAMBREAK = REPO / "cases" / "dambreak2d" / "CaseDambreakVal2D_Def.xml"
CASE_H5 = "CaseDambreakVal2D.h5"
TINY = ["--threads", "1", "-q"]


def invoke(args):
    return CliRunner().invoke(main, [str(a) for a in args])


def assert_input_error(r, *texts):
    assert r.exit_code == 2, r.output
    assert "Traceback" not in r.output
    for text in texts:
        assert text in r.output, (text, r.output)


@pytest.fixture(scope="module")
def gcase(tmp_path_factory):
    """A gencase output of the dam break at dp 0.1 (a few hundred particles)."""
    out = tmp_path_factory.mktemp("g") / "g"
    r = invoke(["gencase", DAMBREAK, "-o", out, "--dp", "0.1", "-q"])
    assert r.exit_code == 0, r.output
    assert not (out / ".sphdvi.lock").exists()          # the lock goes with the command
    return out


def _rows(out):
    path = Path(out) / "run.csv"
    return path.read_text().splitlines()[1:] if path.exists() else []


def _wait_for(cond, proc, timeout=120.0):
    t0 = time.monotonic()
    while not cond():
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() - t0 < timeout, "timed out"
        time.sleep(0.1)


H5_READER = textwrap.dedent("""
    import sys
    from sphdvi.io.vtkhdf import read_step, step_times
    path = sys.argv[1]
    n = len(step_times(path))
    print(n, len(read_step(path, n - 1)["Idp"]))
""")
VTK_READER = textwrap.dedent("""
    import sys
    from vtkmodules.vtkIOHDF import vtkHDFReader
    r = vtkHDFReader()
    r.SetFileName(sys.argv[1])
    r.UpdateInformation()
    r.Update()
    print(r.GetNumberOfSteps(), r.GetOutput().GetNumberOfPoints())
""")


def _read_between_outputs(proc, out, tmp_path):
    """Read particles.vtkhdf with the writer stopped (SIGSTOP), in other processes: sphdvi's reader (h5py),
    VTK's vtkHDFReader (ParaView's), `sphdvi measure` and `sphdvi export`.  Stopped in the middle of an
    output (a few ms of each), a reader may find the file inconsistent: then the run goes on to its next
    output and the readers try again.  Returns the step counts read."""
    path = str(out / "particles.vtkhdf")
    for _ in range(8):
        rows = len(_rows(out))
        os.kill(proc.pid, signal.SIGSTOP)
        try:
            h5 = subprocess.run([sys.executable, "-c", H5_READER, path], capture_output=True, text=True, timeout=120)
            if h5.returncode != 0:
                assert "in the middle of an output" in h5.stderr, h5.stderr      # said so, no other failure
                continue
            vtk = subprocess.run([sys.executable, "-c", VTK_READER, path], capture_output=True, text=True,
                                 timeout=120)
            if vtk.returncode != 0:
                continue
            m = invoke(["measure", "points", out, "--points", "1,0,0.1", "--last", "1"])
            e = invoke(["export", out, "--dir", tmp_path / "vtp"])
            if m.exit_code or e.exit_code:
                assert "in the middle of an output" in m.output + e.output, m.output + e.output
                continue
            return [int(x) for x in h5.stdout.split() + vtk.stdout.split()]
        finally:
            os.kill(proc.pid, signal.SIGCONT)
            _wait_for(lambda: len(_rows(out)) > rows, proc)
    raise AssertionError("no reader read the particle file in 8 attempts")


def test_the_particle_file_reads_during_the_run_and_the_run_lock_keeps_a_second_run_out(gcase, tmp_path):
    """particles.vtkhdf opens while the run writes it (h5py, vtkHDFReader, sphdvi measure and export;
    the HDF5 file lock kept every reader out for the whole run before); a second run into the same OUT
    (fresh, --overwrite, --resume) or a gencase --overwrite is refused naming the running one's pid; the
    lock file a SIGKILLed run leaves blocks nothing: --resume goes on."""
    pytest.importorskip("vtkmodules.vtkIOHDF")
    out = tmp_path / "o"
    proc = subprocess.Popen([sys.executable, "-m", "sphdvi", "run", str(gcase), "-o", str(out), "--tmax", "100",
                             "--tout", "0.2"] + TINY, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        _wait_for(lambda: len(_rows(out)) >= 3, proc)
        assert (out / ".sphdvi.lock").read_text().split()[0] == str(proc.pid)
        nsteps, npts, vtk_steps, vtk_pts = _read_between_outputs(proc, out, tmp_path)
        assert nsteps >= 3 and vtk_steps == nsteps and npts == vtk_pts == 301
        assert len(list((tmp_path / "vtp").glob("Part_*.vtp"))) == nsteps
        # a second run into OUT, whatever its options
        for extra in ([], ["--overwrite"], ["--resume"]):
            r = invoke(["run", gcase, "-o", out, "--tmax", "0.01"] + TINY + extra)
            assert_input_error(r, f"is in use by a sphdvi command that is running (pid {proc.pid} on ")
        assert_input_error(invoke(["gencase", DAMBREAK, "-o", out, "--dp", "0.1", "-q", "--overwrite"]),
                           f"(pid {proc.pid} on ")
        assert proc.poll() is None and (out / "particles.vtkhdf").exists()
    finally:
        proc.kill()
        proc.wait()
    assert (out / ".sphdvi.lock").exists()          # left by the killed run
    reached = float(_rows(out)[-1].split(",")[1])
    r = invoke(["run", out, "--resume", "--tmax", f"{reached + 0.01:.6g}"] + TINY)
    assert r.exit_code == 0, r.output
    assert json.loads((out / "run.json").read_text())["status"] == "completed"
    assert not (out / ".sphdvi.lock").exists()


def test_a_reader_that_catches_an_output_being_written_says_so(gcase, tmp_path):
    """A particle file that cannot be read while a run holds its folder: exit 2 with a message saying the
    run was writing an output (and to read again), no traceback, not 'corrupt'."""
    out = tmp_path / "o"
    assert invoke(["run", gcase, "-o", out, "--tmax", "0.004", "--tout", "0.002"] + TINY).exit_code == 0
    path = out / "particles.vtkhdf"
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])      # as a reader may see it mid-output
    holder = subprocess.Popen([sys.executable, "-c", "import sys, time\nfrom sphdvi.io.runfolder import run_lock\n"
                               "with run_lock(sys.argv[1]):\n    print('held', flush=True)\n    time.sleep(60)",
                               str(out)], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        for args in (["measure", "elevation", out, "--at", "0.5"], ["export", out]):
            r = invoke(args)
            assert_input_error(r, "while the run writing it (pid", "was in the middle of an output", "read it again")
            assert "corrupt" not in r.output
    finally:
        holder.kill()
        holder.wait()
    r = invoke(["export", out])                   # no run: a damaged file
    assert_input_error(r, "truncated or corrupt?")


def test_the_run_lock_is_reentrant_and_a_stale_lock_file_blocks_nothing(tmp_path):
    from sphdvi.io.runfolder import RUN_LOCK_FILE, run_lock, run_lock_holder
    out = tmp_path / "new"
    (tmp_path / "stale").mkdir()
    (tmp_path / "stale" / RUN_LOCK_FILE).write_text("999999 elsewhere run\n")
    assert run_lock_holder(str(tmp_path / "stale")) is None
    with run_lock(str(tmp_path / "stale")):
        assert str(os.getpid()) in run_lock_holder(str(tmp_path / "stale"))
    with run_lock(str(out)):
        assert (out / RUN_LOCK_FILE).read_text().split()[0] == str(os.getpid())
        with run_lock(str(out)):                 # the CLI's lock, then simulation.run's
            pass
        assert (out / RUN_LOCK_FILE).exists()
    assert not out.exists()                       # made for the lock, left empty: removed


def _default_hup_and_int():
    signal.signal(signal.SIGHUP, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def test_interrupted_commands_exit_1_with_a_message(tmp_path):
    """SIGINT, SIGTERM and SIGHUP end gencase, measure and export (report_errors) with exit 1 and
    'interrupted by SIG...', as an interrupted run (README: 1 runtime failure or interruption); gencase
    exited 130 on SIGINT and died by SIGTERM (-15) before."""
    code = textwrap.dedent("""
        import time, click
        from sphdvi.cli_errors import report_errors
        @click.command()
        @report_errors
        def slow():
            print("ready", flush=True)
            time.sleep(60)
        slow()
    """)
    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        # the child starts with SIGHUP and SIGINT at their defaults, whatever this process inherited
        # (under nohup SIGHUP is ignored, and report_errors rightly leaves an ignored SIGHUP ignored;
        # a background job of a shell without job control starts with SIGINT ignored, and Python then
        # installs no KeyboardInterrupt handler: the suite run that way timed out here)
        proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                text=True, preexec_fn=_default_hup_and_int)
        assert proc.stdout.readline().strip() == "ready"
        proc.send_signal(sig)
        _, err = proc.communicate(timeout=30)
        assert proc.returncode == 1, (sig, proc.returncode, err)
        assert f"interrupted by {sig.name}" in err and "Traceback" not in err


def test_run_json_holds_the_resolved_parameters_and_constants(gcase, tmp_path):
    """DtIni/DtMin 0 ('auto') are written as the values used (h/c0, CoefDtMin h/c0, DualSPHysics's Run.out),
    named in parameters_auto; the constants (dp, h, B, c0, ...) are there; MdbcFastSingle (an earlier
    spelling of MDBCFastSingle) is not; a run of no step has no us_per_particle_step (null)."""
    out = tmp_path / "o"
    r = invoke(["run", gcase, "-o", out, "--tmax", "0"] + TINY)
    assert r.exit_code == 0, r.output
    meta = json.loads((out / "run.json").read_text())
    c, p = meta["constants"], meta["parameters"]
    assert c["dp"] == pytest.approx(0.1) and c["cflnumber"] == pytest.approx(0.2)
    for key in ("h", "b", "cs0", "gamma", "rhop0", "massfluid", "massbound", "is2d"):
        assert key in c, key
    assert p["DtIni"] == pytest.approx(c["h"] / c["cs0"])
    assert p["DtMin"] == pytest.approx(p["CoefDtMin"] * c["h"] / c["cs0"])
    assert meta["parameters_auto"] == {"DtIni": "h/c0", "DtMin": "CoefDtMin*h/c0"}
    assert "MdbcFastSingle" not in p and "MDBCFastSingle" in p
    assert meta["steps"] == 0 and meta["us_per_particle_step"] is None
    # a DtMin given stays as given
    out2 = tmp_path / "o2"
    assert invoke(["run", gcase, "-o", out2, "--tmax", "0", "--set", "DtMin=1e-6"] + TINY).exit_code == 0
    meta = json.loads((out2 / "run.json").read_text())
    assert meta["parameters"]["DtMin"] == 1e-6 and meta["parameters_auto"] == {"DtIni": "h/c0"}


def test_suggested_commands_are_built_from_source_and_options(gcase, tmp_path):
    """--resume into a folder with no run: the suggestion is 'sphdvi run SOURCE -o OUT' with the options
    given ('sphdvi run OUT' before, which fails where OUT holds no case); a start-up interrupted by a
    signal suggests the command with its --tmax/--set and --overwrite (they were dropped)."""
    r = invoke(["run", gcase, "-o", tmp_path / "none", "--resume"] + TINY)
    assert_input_error(r, f"start one without --resume: 'sphdvi run {gcase} -o {tmp_path / 'none'}'")
    empty = tmp_path / "empty"
    empty.mkdir()
    r = invoke(["run", gcase, "-o", empty, "--resume", "--tmax", "0.5"] + TINY)
    assert_input_error(r, f"start it with 'sphdvi run {gcase} -o {empty} --tmax 0.5'")
    from sphdvi.simulation import run
    out = tmp_path / "int"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = run(str(gcase / CASE_H5), str(out), tmax=0.5, sets=("Visco=0.05",), quiet=True, threads=1,
                  stop=types.SimpleNamespace(signal=15))
    assert res.status == "interrupted"
    assert f"run again with 'sphdvi run {gcase} -o {out} --tmax 0.5 --set Visco=0.05 --overwrite'" in res.message


def test_set_cflnumber_is_a_run_parameter(gcase, tmp_path):
    """--set CFLnumber (only the time step reads it) is taken: a smaller one takes more steps; the other
    constants, which gencase draws the particles with, are refused saying so."""
    steps = {}
    for cfl in ("0.2", "0.1"):
        out = tmp_path / f"c{cfl}"
        r = invoke(["run", gcase, "-o", out, "--tmax", "0.01", "--set", f"CFLnumber={cfl}"] + TINY)
        assert r.exit_code == 0, r.output
        meta = json.loads((out / "run.json").read_text())
        assert meta["constants"]["cflnumber"] == float(cfl) and meta["parameters"]["CFLnumber"] == float(cfl)
        steps[cfl] = meta["steps"]
    assert steps["0.1"] > 1.6 * steps["0.2"]
    for bad in ("CFLnumber=0", "cflnumber=abc", "CFLnumber=inf"):
        assert_input_error(invoke(["run", gcase, "-o", tmp_path / "bad", "--tmax", "0.01", "--set", bad] + TINY),
                           "--set ", "expected a")
    r = invoke(["run", gcase, "-o", tmp_path / "bad", "--tmax", "0.01", "--set", "gamma=7"] + TINY)
    assert_input_error(r, "gencase draws the particles with it", "--set takes the <parameters> keys and CFLnumber")
    # a resume keeps it: another value is refused
    out = tmp_path / "c0.1"
    r = invoke(["run", out, "--resume", "--set", "CFLnumber=0.3"] + TINY)
    assert_input_error(r, "CFLnumber 0.1 -> 0.3")


def test_tmax_and_set_timemax_of_two_values_are_refused(gcase, tmp_path):
    for args, text in ((["--tmax", "0.02", "--set", "TimeMax=0.05"], "--tmax 0.02 and --set TimeMax=0.05"),
                       (["--tout", "0.01", "--set", "TimeOut=0.025"], "--tout 0.01 and --set TimeOut=0.025")):
        r = invoke(["run", gcase, "-o", tmp_path / "o"] + args + TINY)
        assert_input_error(r, text, "give ", "two values")
    from sphdvi.run_options import conflicting_options
    conflicting_options(["TimeMax=0.02"], 0.02, None)       # the same value: fine


def test_slurm_cpus_above_what_numba_starts_are_lowered_with_a_warning(monkeypatch):
    from numba import config
    from sphdvi.simulation import _usable_threads
    limit = int(config.NUMBA_NUM_THREADS)
    monkeypatch.setenv("SLURM_CPUS_PER_TASK", str(limit + 2))
    with pytest.warns(UserWarning, match=f"SLURM_CPUS_PER_TASK={limit + 2}: numba runs at most {limit} threads"):
        assert _usable_threads(None) == limit
    monkeypatch.setenv("SLURM_CPUS_PER_TASK", "1")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert _usable_threads(None) == 1


class _Tty(io.StringIO):
    def isatty(self):
        return True


def test_progress_lines_carry_dt_and_a_warning_starts_on_a_line_of_its_own():
    from sphdvi.io.runfiles import PROGRESS_INTERVAL_S, Progress
    assert PROGRESS_INTERVAL_S == 30.0
    pipe = io.StringIO()
    Progress(1.0, False, stream=pipe, interval=0.0).update(0.5, 100, 1501, dt=1.25e-4)
    assert "steps=100 particles=1501 dt=0.000125 s wall=" in pipe.getvalue()
    tty = _Tty()
    shown = []
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        warnings.showwarning = lambda message, *a, **k: shown.append((str(message), tty.getvalue()))
        bar = Progress(1.0, False, stream=tty)
        bar.update(0.5, 100, 1501, force=True, dt=1e-4)
        warnings.warn("more than 10% of the particles were excluded")
        bar.update(0.6, 120, 1501, force=True, dt=1e-4)
        bar.close()
        assert warnings.showwarning is not bar._show_warning      # put back
    assert shown and shown[0][0].startswith("more than 10%")
    assert shown[0][1].endswith("\r\033[K")        # the bar's line cleared before the warning
    assert "dt=0.0001 s" in tty.getvalue() and tty.getvalue().endswith("\n")


def test_help_texts_give_units_and_the_sep_of_each_command():
    for args, texts in ((["gencase", "--help"], ["Particle spacing [m]"]),
                        (["run", "--help"], ["Particle spacing [m]", "CFLnumber", "status: running", "every 30 s"]),
                        (["export", "--help"], ["Isosurface grid spacing [m]"]),
                        (["measure", "elevation", "--help"], ["vertical [m]", "PosX/PosY/PosZ rows"]),
                        (["measure", "points", "--help"], ["Points [m]"]),
                        (["measure", "forces", "--help"], ["a Part column"]),
                        (["measure", "bodies", "--help"], ["a Part column"])):
        r = invoke(args)
        assert r.exit_code == 0, r.output
        flat = " ".join(r.output.split())
        for text in texts:
            assert text in flat, (args, text)
    for cmd in ("forces", "bodies"):
        assert "PosX" not in invoke(["measure", cmd, "--help"]).output


def test_an_unknown_parameter_key_points_to_the_list_that_exists(tmp_path):
    text = DAMBREAK.read_text()
    assert '<parameter key="Visco"' in text
    bad = tmp_path / "Bad_Def.xml"
    bad.write_text(text.replace('<parameter key="Visco"', '<parameter key="Foozle" value="1" />\n'
                                '            <parameter key="Visco"', 1))
    r = invoke(["gencase", bad, "-o", tmp_path / "o", "--dp", "0.1", "-q"])
    assert_input_error(r, "unknown parameter key 'Foozle'", "sphdvi/case/parameters.py")
    assert "sphdvi parameters list" not in r.output
