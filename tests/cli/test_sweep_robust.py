"""``sphdvi sweep`` under the conditions of a cluster and of hand-made files (audit hunt11/a): the
manifest written from run.json read under its lock, sweep.sbatch as sbatch's parser reads it, the
case's data files in its checksum, run folders that hold another run or an unreadable run.json,
the CSV layouts sphdvi and DualSPHysics write, a running run's progress, a refused start-up, the
local runner's children (their own session, stopped when the runner dies, an entry held by
another process), keys and values given twice.  Most run folders are written by hand (run.json,
run.csv, gauge files); one tiny 2D dam break runs where a real process is needed."""
import contextlib
import csv
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from click.testing import CliRunner

from sphdvi import sweep as sw_mod
from sphdvi.cli import main

REPO = Path(__file__).resolve().parents[2]
DAMBREAK = REPO / "cases" / "dambreak2d" / "CaseDambreakVal2D_Def.xml"
FLAP = REPO / "cases" / "flapwaves2d"
TINY = ["--tmax", "0.02", "--tout", "0.01"]


def invoke(args):
    return CliRunner().invoke(main, [str(a) for a in args])


def assert_input_error(r, *texts):
    assert r.exit_code == 2, r.output
    assert "Traceback" not in r.output and "internal error" not in r.output, r.output
    for text in texts:
        assert text in r.output, (text, r.output)


def manifest(sweepdir):
    with open(Path(sweepdir) / "sweep.csv", newline="") as fh:
        return list(csv.DictReader(fh))


def new_sweep(path, *args):
    r = invoke(["sweep", "new", DAMBREAK, "-o", path, *args])
    assert r.exit_code == 0, r.output
    return path


def fake_run(sweepdir, index, status, **extra):
    """A run.json for entry ``index`` as ``sphdvi run --manifest`` would write it (case, overrides,
    dp, TimeMax), with ``status`` and ``extra``."""
    spec = json.loads((Path(sweepdir) / "sweep.json").read_text())
    values = dict(zip(spec["keys"], spec["runs"][index]))
    sets = spec["set"] + [f"{k}={v}" for k, v in values.items() if k != "dp"]
    meta = {"case": "CaseDambreakVal2D", "overrides": {"tmax": spec["tmax"], "tout": spec["tout"], "set": sets},
            "constants": {"dp": float(values.get("dp", 0.0085))}, "parameters": {"TimeMax": spec["tmax"] or 1.5},
            "status": status, "steps": 10, "physical_time": 0.02, "runtime_s": 1.5, "particles": 100}
    meta.update(extra)
    rundir = Path(sweepdir) / f"run_{index:04d}"
    (rundir / "run.json").write_text(json.dumps(meta))
    return rundir


# ---------------------------------------------------------------------------------------------
# the manifest: statuses read under the lock (1), a file system without flock (12), a missing or
# unwritable sweep.csv (15)
# ---------------------------------------------------------------------------------------------
def test_statuses_are_read_under_the_manifest_lock(tmp_path, monkeypatch):
    """A writer (here `sweep status`) that waited for the lock while a task ended writes the task's
    'completed', not the 'running' it would have read before taking the lock."""
    sw = new_sweep(tmp_path / "sw", "--vary", "Visco=0.01", *TINY)
    fake_run(sw, 0, "running")
    real = sw_mod._manifest_lock

    @contextlib.contextmanager
    def task_ends_meanwhile(sweep):
        with real(sweep):
            fake_run(sw, 0, "completed")
            yield

    monkeypatch.setattr(sw_mod, "_manifest_lock", task_ends_meanwhile)
    r = invoke(["sweep", "status", sw])
    assert r.exit_code == 0, r.output
    assert manifest(sw)[0]["status"] == "completed"


def test_a_file_system_without_flock_is_warned_once(tmp_path, monkeypatch):
    import fcntl
    sw = new_sweep(tmp_path / "sw", "--vary", "Visco=0.01,0.02", *TINY)
    sweep = sw_mod.open_sweep(str(sw))
    fake_run(sw, 1, "completed")

    def no_flock(fd, op):
        raise OSError(37, "No locks available")

    monkeypatch.setattr(fcntl, "flock", no_flock)
    with pytest.warns(UserWarning, match="cannot lock it.*without the lock") as caught:
        sw_mod.update_manifest(sweep, [0])
        sw_mod.update_manifest(sweep, [1])
    assert len(caught) == 1
    assert [m["status"] for m in manifest(sw)] == ["pending", "completed"]


def test_a_missing_manifest_is_written_again_and_status_reads_an_unwritable_sweep(tmp_path, monkeypatch):
    sw = new_sweep(tmp_path / "sw", "--vary", "Visco=0.01,0.02", *TINY)
    fake_run(sw, 0, "completed")
    (sw / "sweep.csv").unlink()
    with pytest.warns(UserWarning, match="sweep.csv: cannot be read"):
        r = invoke(["run", "--manifest", sw / "sweep.csv", "--index", 0])
    assert r.exit_code == 0 and "nothing to do" in r.output, r.output
    assert [m["status"] for m in manifest(sw)] == ["completed", "pending"]
    (sw / "sweep.csv").unlink()
    with pytest.warns(UserWarning, match="sweep.csv: cannot be read"):
        r = invoke(["sweep", "collect", sw, "-o", tmp_path / "t.csv"])
    assert r.exit_code == 0, r.output

    def read_only(sweep):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(sw_mod, "_manifest_lock", read_only)
    r = invoke(["sweep", "status", sw])
    assert r.exit_code == 0, r.output
    assert "not updated (Permission denied)" in r.output and "completed" in r.output


# ---------------------------------------------------------------------------------------------
# sweep.sbatch (2, 13, 16)
# ---------------------------------------------------------------------------------------------
def slurm_argument(text: str) -> str:
    """The first argument of an #SBATCH line as sbatch reads it (slurm src/sbatch/opt.c
    _get_argument: blanks end it outside quotes, '\\' escapes, an unescaped '#' outside quotes
    starts a comment)."""
    out, quote, escape = [], "", False
    for ch in text.lstrip():
        if escape:
            escape = False
        elif ch == "\\":
            escape = True
            continue
        elif quote:
            if ch == quote:
                quote = ""
                continue
        elif ch in "\"'":
            quote = ch
            continue
        elif ch == "#" or ch.isspace():
            break
        out.append(ch)
    return "".join(out)


def test_sbatch_lines_of_a_folder_with_blanks_hash_percent_and_quotes(tmp_path):
    folder = tmp_path / 'my "big" sweep #1 50%'
    r = invoke(["sweep", "new", DAMBREAK, "-o", folder, "--vary", "Visco=0.01,0.02", "--command", "echo"] + TINY)
    assert r.exit_code == 0, r.output
    assert f"'sbatch {folder}/sweep.sbatch'" not in r.output and "sweep run '" in r.output   # quoted for a shell
    text = (folder / "sweep.sbatch").read_text()
    out = next(ln for ln in text.splitlines() if ln.startswith("#SBATCH --output="))
    parsed = slurm_argument(out[len("#SBATCH "):])
    assert parsed == "--output=" + str(folder / "logs").replace("%", "%%") + "/%A_%a.out"
    # the task's command line under bash: this sweep's manifest, the index, SLURM's CPUs as --threads
    env = dict(os.environ, SLURM_ARRAY_TASK_ID="1", SLURM_CPUS_PER_TASK="4")
    done = subprocess.run(["bash", str(folder / "sweep.sbatch")], env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split("\n")[0] == f"run --manifest {folder}/sweep.csv --index 1 --threads 4"
    assert_input_error(invoke(["sweep", "new", DAMBREAK, "-o", tmp_path / "a\\b", "--vary", "Visco=0.01"]),
                       "backslash")
    assert not (tmp_path / "a\\b").exists()


def test_sbatch_runs_this_python_and_warns_past_slurms_array_size(tmp_path):
    sw = new_sweep(tmp_path / "sw", "--vary", "Visco=0.01,0.02", "--threads", "3", *TINY)
    last = (sw / "sweep.sbatch").read_text().splitlines()[-1]
    assert last.startswith(f"{sys.executable} -m sphdvi run --manifest ")
    assert last.endswith("--threads ${SLURM_CPUS_PER_TASK:-3}")
    r = invoke(["sweep", "new", DAMBREAK, "-o", tmp_path / "big", "--vary", "Visco=" + ",".join(
        f"0.0{i:03d}" for i in range(1, 35)), "--vary", "CFLnumber=" + ",".join(f"0.{i:02d}" for i in range(10, 40))])
    assert r.exit_code == 0, r.output
    assert "warning: 1020 runs" in r.output and "MaxArraySize (1001" in r.output


def test_the_same_sweep_in_a_moved_folder_writes_sweep_sbatch_again(tmp_path):
    args = ["--vary", "Visco=0.01", *TINY]
    sw = new_sweep(tmp_path / "sw", *args)
    shutil.move(sw, tmp_path / "moved")
    r = invoke(["sweep", "new", DAMBREAK, "-o", tmp_path / "moved", *args])
    assert r.exit_code == 0 and "sweep.sbatch written again" in r.output, r.output
    text = (tmp_path / "moved" / "sweep.sbatch").read_text()
    assert str(tmp_path / "moved" / "sweep.csv") in text and str(sw) + "/" not in text
    r = invoke(["sweep", "new", DAMBREAK, "-o", tmp_path / "moved", *args])
    assert r.exit_code == 0 and "nothing to do" in r.output and "(1 run)" in r.output


# ---------------------------------------------------------------------------------------------
# the case's data files (3); keys and values given twice (5); --table as people write it (15)
# ---------------------------------------------------------------------------------------------
def test_a_changed_data_file_of_the_case_is_refused(tmp_path):
    case = tmp_path / "case"
    shutil.copytree(FLAP, case)
    xml = case / "CaseFlapWavesHadzic2D_Def.xml"
    args = ["sweep", "new", xml, "-o", tmp_path / "sw", "--vary", "Visco=0.01", "--tmax", "0.01"]
    assert invoke(args).exit_code == 0
    spec = json.loads((tmp_path / "sw" / "sweep.json").read_text())
    assert list(spec["case_files"]) == ["CaseFlapWavesHadzic2D_Flap.dat"]
    with open(case / "CaseFlapWavesHadzic2D_Flap.dat", "a") as fh:
        fh.write("100 0\n")
    assert_input_error(invoke(args), "another sweep", "CaseFlapWavesHadzic2D_Flap.dat")
    r = invoke(["run", "--manifest", tmp_path / "sw" / "sweep.csv", "--index", 0])
    assert_input_error(r, "CaseFlapWavesHadzic2D_Flap.dat, a file the case", "has changed")
    assert not (tmp_path / "sw" / "run_0000" / "run.json").exists()
    # the refusal is what `sweep status` shows for the entry (7)
    r = invoke(["sweep", "status", tmp_path / "sw"])
    assert r.exit_code == 0 and "0      0.01   refused" in r.output, r.output
    assert "run_0000 refused at its start-up: " in r.output and "has changed" in r.output
    assert manifest(tmp_path / "sw")[0]["status"] == "refused"


@pytest.mark.parametrize("args, text", [
    (["--vary", "CFLnumber=0.1,0.2", "--vary", "cflnumber=0.3"], "--vary CFLnumber: given twice"),
    (["--vary", "cflnumber=0.1", "--set", "CFLnumber=0.2"], "both varied and fixed"),
    (["--vary", "Visco=0.01,0.010"], "0.01 and 0.010 are the same value"),
    (["--vary", "dp=4e-2,0.04"], "4e-2 and 0.04 are the same value"),
])
def test_a_key_or_value_given_twice_is_refused(tmp_path, args, text):
    assert_input_error(invoke(["sweep", "new", DAMBREAK, "-o", tmp_path / "sw"] + args), text)
    assert not (tmp_path / "sw").exists()


def test_keys_in_another_letter_case_and_values_valid_only_together(tmp_path):
    sw = new_sweep(tmp_path / "sw", "--vary", "cflnumber=0.1,0.2")
    assert list(manifest(sw)[0]) == ["index", "CFLnumber", "dir", "status"]
    # RhopOutMin 1350 is above the case's RhopOutMax 1300, but each entry raises RhopOutMax with it
    sw = new_sweep(tmp_path / "rho", "--vary", "RhopOutMin=700,1350", "--vary", "RhopOutMax=1400,1500")
    assert len(manifest(sw)) == 4
    assert_input_error(invoke(["sweep", "new", DAMBREAK, "-o", tmp_path / "x", "--vary", "RhopOutMin=1350"]),
                       "RhopOutMin=1350")


def test_table_with_blanks_after_commas_repeated_rows_and_semicolons(tmp_path):
    table = tmp_path / "t.csv"
    table.write_text('dp, Visco\n"0.05", "0.02"\n0.04, 0.01\n')
    sw = tmp_path / "sw"
    r = invoke(["sweep", "new", DAMBREAK, "-o", sw, "--table", table])
    assert r.exit_code == 0, r.output
    assert [(m["dp"], m["Visco"]) for m in manifest(sw)] == [("0.05", "0.02"), ("0.04", "0.01")]
    table.write_text("dp,Visco\n0.05,0.02\n0.050,2e-2\n")
    assert_input_error(invoke(["sweep", "new", DAMBREAK, "-o", tmp_path / "x", "--table", table]),
                       "t.csv:3: the same run as line 2")
    table.write_text("dp;Visco\n0.05;0.02\n")
    assert_input_error(invoke(["sweep", "new", DAMBREAK, "-o", tmp_path / "x", "--table", table]),
                       "one column 'dp;Visco'", "separated by ','")


# ---------------------------------------------------------------------------------------------
# run folders that hold another run (9) or an unreadable run.json (10)
# ---------------------------------------------------------------------------------------------
def test_a_folder_holding_another_run_is_not_adopted(tmp_path):
    sw = new_sweep(tmp_path / "sw", "--vary", "Visco=0.5", "--vary", "dp=0.04,0.05", *TINY)
    assert_input_error(invoke(["sweep", "converge", sw, "--file", "run.csv", "--column", "x"]), "no run folder")
    rundir = fake_run(sw, 0, "completed", overrides={"tmax": 0.02, "tout": 0.01, "set": ["Visco=0.01"]})
    (rundir / "particles.vtkhdf").write_text("results")
    fake_run(sw, 1, "completed")
    before = (rundir / "run.json").read_bytes()
    r = invoke(["run", "--manifest", sw / "sweep.csv", "--index", 0])
    assert_input_error(r, "holds another run than entry 0 (Visco=0.5 dp=0.04)", "--set Visco=0.01, not Visco=0.5",
                       "move that folder's files away")
    assert (rundir / "run.json").read_bytes() == before and (rundir / "particles.vtkhdf").read_text() == "results"
    assert_input_error(invoke(["sweep", "collect", sw, "-o", tmp_path / "t.csv"]), "holds another run")
    assert_input_error(invoke(["sweep", "converge", sw, "--file", "run.csv", "--column", "steps"]),
                       "holds another run")
    r = invoke(["sweep", "status", sw])
    assert_input_error(r, "another run in the folder", "holds another run")
    assert [m["status"] for m in manifest(sw)] == ["pending", "completed"]
    r = invoke(["sweep", "run", sw])
    assert r.exit_code == 2 and "refused: " in r.output and "1 refused" in r.output, r.output
    # a dp that differs, and a folder made again without its sweep.json
    fake_run(sw, 1, "completed", constants={"dp": 0.03})
    assert_input_error(invoke(["run", "--manifest", sw / "sweep.csv", "--index", 1]), "dp 0.03, not 0.05")
    for name in ("sweep.json", "sweep.csv", "sweep.sbatch"):
        (sw / name).unlink()
    assert_input_error(invoke(["sweep", "new", DAMBREAK, "-o", sw, "--vary", "Visco=0.5", "--vary", "dp=0.04,0.05"]
                              + TINY), "holds other files (run_0000, run_0001)")


def test_an_unreadable_run_json_is_exit_2_and_deletes_nothing(tmp_path):
    sw = new_sweep(tmp_path / "sw", "--vary", "Visco=0.01", *TINY)
    rundir = fake_run(sw, 0, "completed")
    text = (rundir / "run.json").read_text()
    (rundir / "run.json").write_text(text[: len(text) // 2])
    (rundir / "particles.vtkhdf").write_text("results")
    r = invoke(["run", "--manifest", sw / "sweep.csv", "--index", 0])
    assert_input_error(r, f"{rundir / 'run.json'}: cannot be read")
    assert (rundir / "particles.vtkhdf").read_text() == "results"
    assert_input_error(invoke(["sweep", "status", sw]), "run.json unreadable")
    assert_input_error(invoke(["sweep", "collect", sw, "-o", tmp_path / "t.csv"]), "cannot be read")


# ---------------------------------------------------------------------------------------------
# sweep collect: the CSV layouts (4), a torn last row (11), a running run's progress (7), -o (15)
# ---------------------------------------------------------------------------------------------
def test_collect_reads_the_csv_layouts_sphdvi_and_dualsphysics_write(tmp_path):
    import numpy as np
    from sphdvi.measure.tables import Table, table_text
    sw = new_sweep(tmp_path / "sw", "--vary", "Visco=0.01,0.02,0.03", *TINY)
    table = Table(np.array([0.0, 0.01]), ["press_0", "press_1"], ["Pa", "Pa"], np.array([[1.0, 2.0], [3.0, 4.0]]),
                  positions=np.array([[0.5, 0.0, 0.1], [0.6, 0.0, 0.1]]))
    for i in range(3):
        fake_run(sw, i, "completed")
    (sw / "run_0000" / "mt.csv").write_text(table_text(table, ";"))        # measure --sep ';' (MeasureTool's)
    (sw / "run_0001" / "mt.csv").write_text("# a comment, with commas\n" + table_text(table, ","))
    (sw / "run_0002" / "mt.csv").write_text("Part;Time [s];press_0 [Pa];vel [m/s] (x,y,z);\n0;0;5;6;\n")
    out = tmp_path / "t.csv"
    r = invoke(["sweep", "collect", sw, "-o", out, "--file", "mt.csv"])
    assert r.exit_code == 0, r.output
    with open(out, newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["index", "Visco", "Part", "Time [s]", "press_0 [Pa]", "press_1 [Pa]", "time [s]",
                       "vel [m/s] (x,y,z)"]
    assert rows[1:] == [["0", "0.01", "0", "0", "1", "2", "", ""], ["0", "0.01", "1", "0.01", "3", "4", "", ""],
                        ["1", "0.02", "", "", "1", "2", "0", ""], ["1", "0.02", "", "", "3", "4", "0.01", ""],
                        ["2", "0.03", "0", "0", "5", "", "", "6"]]
    assert_input_error(invoke(["sweep", "collect", sw, "-o", out, "--file", "nosuch.csv"]),
                       "--file nosuch.csv: no run folder", "nothing to collect")


def test_collect_leaves_out_a_torn_row_and_shows_a_running_runs_progress(tmp_path):
    sw = new_sweep(tmp_path / "sw", "--vary", "Visco=0.01,0.02", "--tmax", "0.3")
    fake_run(sw, 0, "completed")
    rundir = fake_run(sw, 1, "running", steps=0, physical_time=0.0, runtime_s=None)
    (rundir / "run.csv").write_text("part,time,steps,particles,excluded,dtmin,dtmax,walltime\n"
                                    "0,0,0,100,0,0,0,0.01\n1,0.03,40,100,0,1e-4,1e-4,0.5\n2,0.0600123,80,100,0,")
    (rundir / "GaugesSWL_Swl.csv").write_text("time [s];swlz [m]\n0;2.0\n0.03;2.02\n0.06;2.0")
    out = tmp_path / "t.csv"
    r = invoke(["sweep", "collect", sw, "-o", out, "--file", "GaugesSWL_Swl.csv"])
    assert r.exit_code == 0 and "run_0000/GaugesSWL_Swl.csv" in r.output, r.output
    with open(out, newline="") as fh:
        assert [row[-1] for row in csv.reader(fh)] == ["swlz [m]", "2.0", "2.02"]
    r = invoke(["sweep", "collect", sw, "-o", out])
    assert r.exit_code == 0, r.output
    with open(out, newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert (rows[1]["status"], rows[1]["steps"], rows[1]["physical_time"], rows[1]["runtime_s"]) == \
        ("running", "40", "0.03", "")
    r = invoke(["sweep", "status", sw])
    assert r.exit_code == 0, r.output
    assert "running (killed: no process holds it)  0.03/0.3" in r.output
    for bad in (sw / "sweep.csv", sw / "run_0000" / "x.csv"):
        assert_input_error(invoke(["sweep", "collect", sw, "-o", bad]), "a file of the sweep itself")


# ---------------------------------------------------------------------------------------------
# run --manifest's messages (8); the local runner's children (6, 14)
# ---------------------------------------------------------------------------------------------
def test_retry_without_manifest_says_what_it_goes_with(tmp_path):
    assert_input_error(invoke(["run", DAMBREAK, "--retry"]), "--retry goes with --manifest")
    assert_input_error(invoke(["run", "--index", 0]), "--index goes with --manifest")


def test_an_entry_another_process_holds_is_running_elsewhere(tmp_path):
    sw = new_sweep(tmp_path / "sw", "--vary", "dp=0.05", *TINY)
    lock = sw / "run_0000" / ".sphdvi.lock"
    holder = subprocess.Popen([sys.executable, "-c", (
        "import fcntl, os, sys, time\n"
        f"fd = os.open({str(lock)!r}, os.O_RDWR | os.O_CREAT)\n"
        "fcntl.flock(fd, fcntl.LOCK_EX); os.write(fd, b'4242 node17 run\\n')\n"
        "print('held', flush=True); time.sleep(60)\n")], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        r = invoke(["sweep", "run", sw])
    finally:
        holder.kill()
        holder.wait()
    assert r.exit_code == 1, r.output
    assert "running elsewhere (pid 4242 on node17)" in r.output and "1 runs: 1 running elsewhere" in r.output


def _gone(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] in ("Z", "X")
    except OSError:
        return True


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="PR_SET_PDEATHSIG is Linux's")
def test_the_runs_stop_when_the_runner_is_killed(tmp_path):
    """The runner's children are in a session of their own (a terminal's Ctrl-C reaches them once,
    from the runner) and get SIGTERM when it dies, SIGKILL included: no orphan goes on holding the
    entry; it stops resumable."""
    sw = new_sweep(tmp_path / "sw", "--vary", "dp=0.05", "--tmax", "0.5", "--tout", "0.01")
    runner = subprocess.Popen([sys.executable, "-m", "sphdvi", "sweep", "run", str(sw)], stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL, start_new_session=True)
    lock = sw / "run_0000" / ".sphdvi.lock"
    deadline = time.time() + 60
    child = None
    while time.time() < deadline and child is None and runner.poll() is None:
        with contextlib.suppress(OSError, ValueError, IndexError):
            child = int(lock.read_text().split()[0])
        time.sleep(0.05)
    assert child is not None, "the run did not start"
    try:
        assert os.getpgid(child) != os.getpgid(runner.pid)
        runner.send_signal(signal.SIGKILL)
        runner.wait()
        deadline = time.time() + 60
        while time.time() < deadline and not _gone(child):
            time.sleep(0.05)
        assert _gone(child), "the run outlived its runner"
    finally:
        if runner.poll() is None:
            runner.kill()
            runner.wait()
        if not _gone(child):
            os.kill(child, signal.SIGKILL)
    assert json.loads((sw / "run_0000" / "run.json").read_text())["status"] == "interrupted"
    log = (sw / "logs" / "run_0000.log").read_text()
    assert f"go on with 'sphdvi run --manifest {sw}/sweep.csv --index 0'" in log and "--resume'" not in log
