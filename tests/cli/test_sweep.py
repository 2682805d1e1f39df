"""``sphdvi sweep`` (new, run, status, collect) and ``sphdvi run --manifest --index``: the expansion
of the parameter space, checks before anything is written, the sbatch script, one entry run once
(then skipped), resumed after an interruption, refused after a divergence unless --retry, the
manifest updated under its lock, the local runner, the tidy CSV.  Tiny 2D dam breaks (dp 0.04 /
0.05, a few hundred steps, 1 thread)."""
import csv
import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
from click.testing import CliRunner

from sphdvi.cli import main

REPO = Path(__file__).resolve().parents[2]
DAMBREAK = REPO / "cases" / "dambreak2d" / "CaseDambreakVal2D_Def.xml"
TINY = ["--tmax", "0.02", "--tout", "0.01"]


def invoke(args):
    return CliRunner().invoke(main, [str(a) for a in args])


def assert_input_error(r, *texts):
    assert r.exit_code == 2, r.output
    assert "Traceback" not in r.output
    for text in texts:
        assert text in r.output, (text, r.output)


def manifest(sweepdir):
    with open(Path(sweepdir) / "sweep.csv", newline="") as fh:
        return list(csv.DictReader(fh))


def run_json(rundir):
    return json.loads((Path(rundir) / "run.json").read_text())


@pytest.fixture(scope="module")
def ran(tmp_path_factory):
    """A 2 x 2 sweep (Visco, dp) run by the local runner, 2 at a time; the runner's output."""
    sw = tmp_path_factory.mktemp("sweep") / "sw"
    r = invoke(["sweep", "new", DAMBREAK, "-o", sw, "--vary", "Visco=0.01,0.05", "--vary", "dp=0.04,0.05"] + TINY)
    assert r.exit_code == 0, r.output
    r = invoke(["sweep", "run", sw, "--jobs", "2"])
    return sw, r


def test_vary_expands_the_cartesian_product_in_order(tmp_path):
    sw = tmp_path / "sw"
    r = invoke(["sweep", "new", DAMBREAK, "-o", sw, "--vary", "Visco=0.01,0.02,0.05", "--vary", "dp=0.04,0.05",
                "--set", "CFLnumber=0.15"] + TINY)
    assert r.exit_code == 0, r.output
    rows = manifest(sw)
    assert list(rows[0]) == ["index", "Visco", "dp", "dir", "status"]
    assert [(r["Visco"], r["dp"]) for r in rows] == [("0.01", "0.04"), ("0.01", "0.05"), ("0.02", "0.04"),
                                                     ("0.02", "0.05"), ("0.05", "0.04"), ("0.05", "0.05")]
    assert [r["index"] for r in rows] == [str(i) for i in range(6)]
    assert [r["dir"] for r in rows] == [f"run_{i:04d}" for i in range(6)]
    assert {r["status"] for r in rows} == {"pending"}
    assert all((sw / f"run_{i:04d}").is_dir() and not os.listdir(sw / f"run_{i:04d}") for i in range(6))
    assert (sw / "logs").is_dir()
    spec = json.loads((sw / "sweep.json").read_text())
    assert spec["case"] == str(DAMBREAK) and os.path.isabs(spec["case"])
    assert spec["keys"] == ["Visco", "dp"] and spec["runs"][1] == ["0.01", "0.05"]
    assert spec["set"] == ["CFLnumber=0.15"] and spec["tmax"] == 0.02 and spec["tout"] == 0.01
    assert spec["threads"] == 1 and spec["version"]


def test_table_gives_one_run_per_row(tmp_path):
    table = tmp_path / "t.csv"
    table.write_text("dp,Visco\n0.05,0.03\n\n0.04,0.01\n")
    r = invoke(["sweep", "new", DAMBREAK, "-o", tmp_path / "sw", "--table", table] + TINY)
    assert r.exit_code == 0, r.output
    assert [(r["dp"], r["Visco"]) for r in manifest(tmp_path / "sw")] == [("0.05", "0.03"), ("0.04", "0.01")]
    r = invoke(["sweep", "new", DAMBREAK, "-o", tmp_path / "x", "--table", table, "--vary", "Visco=1"])
    assert_input_error(r, "--vary", "--table")
    assert_input_error(invoke(["sweep", "new", DAMBREAK, "-o", tmp_path / "x"]), "--vary")
    table.write_text("dp,Visco\n0.05,0.03\n0.04\n")
    assert_input_error(invoke(["sweep", "new", DAMBREAK, "-o", tmp_path / "x", "--table", table]), "t.csv:3")
    assert not (tmp_path / "x").exists()


@pytest.mark.parametrize("args, text", [
    (["--vary", "Visko=0.01,0.02"], "did you mean 'Visco'"),
    (["--vary", "Visco=0.01,abc"], "--vary Visco=abc"),
    (["--vary", "dp=0.04,-1"], "--vary dp=-1"),
    (["--vary", "dp=0.04,nan"], "--vary dp=nan"),
    (["--vary", "Visco=0.01", "--set", "Visco=0.02"], "both varied and fixed"),
    (["--vary", "Visco=0.01", "--set", "CFLnumbr=0.2"], "CFLnumbr"),
    (["--vary", "Visco=0.01,", "--tmax", "1"], "--vary"),
    (["--vary", "TimeMax=0.5", "--tmax", "1"], "TimeMax"),
    (["--vary", "RhopOutMin=1400"], "RhopOutMin"),
    (["--vary", "status=1"], "a column of the manifest"),
    (["--vary", "Visco=0.01", "--time", "tomorrow"], "--time"),
    (["--vary", "Visco=0.01", "--set", "ViscoTime=nofile.txt"], "nofile.txt"),
    (["--vary", "ViscoTime=nofile.txt"], "--vary ViscoTime=nofile.txt"),
])
def test_a_bad_key_or_value_is_exit_2_before_anything_is_written(tmp_path, args, text):
    """Each key and value is checked as 'sphdvi run --set' / '--dp' would check it, naming the key."""
    r = invoke(["sweep", "new", DAMBREAK, "-o", tmp_path / "sw"] + args)
    assert_input_error(r, text)
    assert not (tmp_path / "sw").exists()


def test_a_warning_of_the_checks_is_printed_once(tmp_path):
    r = invoke(["sweep", "new", DAMBREAK, "-o", tmp_path / "sw", "--vary", "PosDouble=1", "--vary", "Visco=0.01,0.02"])
    assert r.exit_code == 0, r.output
    assert r.output.count("warning: --set PosDouble: parameter 'PosDouble' is deprecated") == 1


def test_a_varied_data_file_is_made_absolute(tmp_path, monkeypatch):
    """ViscoTime=FILE is relative to the current folder, as with 'sphdvi run --set': sweep.json keeps
    it absolute, so that the runs (from any folder, on a cluster node) find it."""
    monkeypatch.chdir(tmp_path)
    for name in ("a.txt", "b.txt"):
        (tmp_path / name).write_text("time visco\n0 0.05\n1 0.05\n")
    r = invoke(["sweep", "new", DAMBREAK, "-o", "sw", "--vary", "ViscoTime=a.txt,b.txt"])
    assert r.exit_code == 0, r.output
    assert json.loads((tmp_path / "sw" / "sweep.json").read_text())["runs"] == [[str(tmp_path / "a.txt")],
                                                                                 [str(tmp_path / "b.txt")]]


def test_same_spec_again_does_nothing_and_another_is_exit_2(tmp_path):
    sw = tmp_path / "sw"
    args = ["sweep", "new", DAMBREAK, "-o", sw, "--vary", "Visco=0.01,0.02"] + TINY
    assert invoke(args).exit_code == 0
    before = {p.name: (p.stat().st_mtime_ns, p.read_bytes()) for p in sw.iterdir() if p.is_file()}
    r = invoke(args)
    assert r.exit_code == 0 and "nothing to do" in r.output
    assert {p.name: (p.stat().st_mtime_ns, p.read_bytes()) for p in sw.iterdir() if p.is_file()} == before
    assert_input_error(invoke(["sweep", "new", DAMBREAK, "-o", sw, "--vary", "Visco=0.01,0.03"] + TINY),
                       "another sweep", "run 1: Visco=0.02 -> Visco=0.03")
    assert_input_error(invoke(args[:-1] + ["0.02"]), "tout: 0.01 -> 0.02")
    assert_input_error(invoke(args + ["--set", "CFLnumber=0.1"]), "set: [] -> ['CFLnumber=0.1']")
    r = invoke(args + ["--time", "48:00:00"])       # the job's wall time only: sweep.sbatch is written again
    assert r.exit_code == 0 and "sweep.sbatch" in r.output
    assert "#SBATCH --time=48:00:00" in (sw / "sweep.sbatch").read_text()
    assert (sw / "sweep.csv").read_bytes() == before["sweep.csv"][1]
    other = tmp_path / "other"
    other.mkdir()
    (other / "notes.txt").write_text("mine")
    assert_input_error(invoke(["sweep", "new", DAMBREAK, "-o", other, "--vary", "Visco=0.01"]), "notes.txt")


def test_sbatch_script(tmp_path):
    sw = tmp_path / "sw"
    r = invoke(["sweep", "new", DAMBREAK, "-o", sw, "--vary", "Visco=0.01,0.02,0.03", "--vary", "dp=0.04,0.05",
                "--threads", "2", "--time", "1-02:00:00", "--throttle", "4"] + TINY)
    assert r.exit_code == 0, r.output
    lines = (sw / "sweep.sbatch").read_text().splitlines()
    assert lines[0] == "#!/bin/bash"
    for line in ("#SBATCH --array=0-5%4", "#SBATCH --cpus-per-task=2", "#SBATCH --time=1-02:00:00",
                 "#SBATCH --job-name=sphdvi-sw", f'#SBATCH --output="{sw}/logs/%A_%a.out"',
                 f"{sys.executable} -m sphdvi run --manifest {sw}/sweep.csv --index $SLURM_ARRAY_TASK_ID "
                 "--threads ${SLURM_CPUS_PER_TASK:-2}"):
        assert line in lines, (line, lines)
    # the throttle is N when N is smaller; the default wall time is 24 h
    assert invoke(["sweep", "new", DAMBREAK, "-o", tmp_path / "b", "--vary", "Visco=0.01,0.02"]).exit_code == 0
    text = (tmp_path / "b" / "sweep.sbatch").read_text()
    assert "#SBATCH --array=0-1%2" in text and "#SBATCH --time=24:00:00" in text
    assert "#SBATCH --cpus-per-task=1" in text


def test_run_manifest_index_runs_an_entry_once(tmp_path):
    sw = tmp_path / "sw"
    assert invoke(["sweep", "new", DAMBREAK, "-o", sw, "--vary", "Visco=0.03,0.04", "--vary", "dp=0.05"]
                  + TINY).exit_code == 0
    r = invoke(["run", "--manifest", sw / "sweep.csv", "--index", 1, "-q"])
    assert r.exit_code == 0, r.output
    meta = run_json(sw / "run_0001")
    assert meta["status"] == "completed" and meta["parameters"]["Visco"] == 0.04
    assert meta["constants"]["dp"] == 0.05 and meta["parameters"]["TimeMax"] == 0.02
    assert meta["threads"] == 1
    assert [r["status"] for r in manifest(sw)] == ["pending", "completed"]
    before = (sw / "run_0001" / "run.json").read_bytes()
    r = invoke(["run", "--manifest", sw / "sweep.csv", "--index", 1])
    assert r.exit_code == 0 and "nothing to do" in r.output
    assert (sw / "run_0001" / "run.json").read_bytes() == before       # no new steps, same time
    assert not os.listdir(sw / "run_0000")
    # what --manifest refuses
    assert_input_error(invoke(["run", "--manifest", sw / "sweep.csv", "--index", 2]), "expected 0 to 1")
    assert_input_error(invoke(["run", "--manifest", sw / "sweep.csv", "--index", 0, "--set", "Visco=1"]),
                       "not with --set")
    assert_input_error(invoke(["run", DAMBREAK, "--manifest", sw / "sweep.csv", "--index", 0]), "not with SOURCE")
    assert_input_error(invoke(["run", "--manifest", sw / "sweep.csv"]), "--index")
    (tmp_path / "x.csv").write_text("index,dir,status\n")
    assert_input_error(invoke(["run", "--manifest", tmp_path / "x.csv", "--index", 0]), "not a sweep")
    edited = (sw / "sweep.csv").read_text().replace("0.03", "0.07")
    (sw / "sweep.csv").write_text(edited)
    assert_input_error(invoke(["run", "--manifest", sw / "sweep.csv", "--index", 0]), "was edited")
    assert_input_error(invoke(["sweep", "run", sw]), "sphdvi sweep status")
    # `sweep status` writes the manifest anew from sweep.json and the runs' run.json
    for damage in (lambda: None, (sw / "sweep.csv").unlink):
        damage()
        assert invoke(["sweep", "status", sw]).exit_code == 0
        assert [(r["Visco"], r["status"]) for r in manifest(sw)] == [("0.03", "pending"), ("0.04", "completed")]


def test_an_entry_another_task_runs_is_exit_2_naming_it(tmp_path):
    sw = tmp_path / "sw"
    assert invoke(["sweep", "new", DAMBREAK, "-o", sw, "--vary", "dp=0.05"] + TINY).exit_code == 0
    lock = sw / "run_0000" / ".sphdvi.lock"
    holder = subprocess.Popen([sys.executable, "-c", (
        "import fcntl, os, sys, time\n"
        f"fd = os.open({str(lock)!r}, os.O_RDWR | os.O_CREAT)\n"
        "fcntl.flock(fd, fcntl.LOCK_EX); os.write(fd, b'4242 node17 run\\n')\n"
        "print('held', flush=True); time.sleep(60)\n")], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        assert_input_error(invoke(["run", "--manifest", sw / "sweep.csv", "--index", 0]), "pid 4242 on node17")
    finally:
        holder.kill()
        holder.wait()
    assert not (sw / "run_0000" / "run.json").exists()


def test_a_diverged_entry_exits_3_unless_retry(tmp_path):
    sw = tmp_path / "sw"
    assert invoke(["sweep", "new", DAMBREAK, "-o", sw, "--vary", "dp=0.05"] + TINY).exit_code == 0
    rundir = sw / "run_0000"
    (rundir / "run.json").write_text(json.dumps({"status": "diverged", "message": "NaN at t=0.01",
                                                 "physical_time": 0.01, "steps": 3}))
    r = invoke(["run", "--manifest", sw / "sweep.csv", "--index", 0])
    assert r.exit_code == 3 and "diverged" in r.output and "--retry" in r.output
    assert manifest(sw)[0]["status"] == "diverged"
    r = invoke(["sweep", "run", sw])
    assert r.exit_code == 3 and "1 diverged" in r.output
    r = invoke(["run", "--manifest", sw / "sweep.csv", "--index", 0, "--retry", "-q"])
    assert r.exit_code == 0, r.output
    assert run_json(rundir)["status"] == "completed" and manifest(sw)[0]["status"] == "completed"


def test_manifest_updates_under_the_lock_lose_nothing(tmp_path):
    """Array tasks that end at once each rewrite sweep.csv: under SWEEPDIR/.sweep.lock none is lost."""
    from sphdvi import sweep as sw_mod
    sw = tmp_path / "sw"
    assert invoke(["sweep", "new", DAMBREAK, "-o", sw, "--vary", "Visco=" + ",".join(
        f"0.0{i}" for i in range(1, 10))]).exit_code == 0
    sweep = sw_mod.open_sweep(str(sw))
    names = ["completed", "diverged", "failed", "interrupted"]

    def task(i):
        for k in range(20):     # a run.json of status names[(i + k) % 4], then the entry's update
            (sw / f"run_{i:04d}" / "run.json").write_text(json.dumps({"status": names[(i + k) % 4]}))
            sw_mod.update_manifest(sweep, [i])

    threads = [threading.Thread(target=task, args=(i,)) for i in range(9)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert [r["status"] for r in manifest(sw)] == [names[(i + 19) % 4] for i in range(9)]
    assert (sw / ".sweep.lock").exists()
    assert not [n for n in os.listdir(sw) if n.endswith(".tmp")]


def test_local_runner_runs_every_entry_then_nothing(ran):
    sw, r = ran
    assert r.exit_code == 0, r.output
    for i, (visco, dp) in enumerate([("0.01", "0.04"), ("0.01", "0.05"), ("0.05", "0.04"), ("0.05", "0.05")]):
        assert f"{i:4d}  Visco={visco} dp={dp}: completed" in r.output
    assert "4 runs: 4 completed" in r.output
    assert [m["status"] for m in manifest(sw)] == ["completed"] * 4
    before = [(sw / f"run_{i:04d}" / "run.json").read_bytes() for i in range(4)]
    r2 = invoke(["sweep", "run", sw, "--jobs", "2"])
    assert r2.exit_code == 0 and "nothing to run" in r2.output
    assert [(sw / f"run_{i:04d}" / "run.json").read_bytes() for i in range(4)] == before


def test_each_run_got_its_parameters(ran):
    sw, _ = ran
    metas = [run_json(sw / f"run_{i:04d}") for i in range(4)]
    assert [m["parameters"]["Visco"] for m in metas] == [0.01, 0.01, 0.05, 0.05]
    assert [m["constants"]["dp"] for m in metas] == [0.04, 0.05, 0.04, 0.05]
    assert metas[0]["particles"] == metas[2]["particles"] > metas[1]["particles"] == metas[3]["particles"]
    assert all(m["parameters"]["TimeMax"] == 0.02 and m["threads"] == 1 for m in metas)
    # each run folder is self-contained: the case drawn, run.json, the outputs
    assert all((sw / f"run_{i:04d}" / "CaseDambreakVal2D.h5").is_file() for i in range(4))


def test_status_table(ran):
    sw, _ = ran
    r = invoke(["sweep", "status", sw])
    assert r.exit_code == 0, r.output
    lines = r.output.splitlines()
    assert lines[0].split() == ["index", "Visco", "dp", "status", "t/TimeMax", "[s]", "runtime_s"]
    assert lines[1].split()[:4] == ["0", "0.01", "0.04", "completed"] and "/0.02" in lines[1]


def test_collect_one_row_per_run_and_files_long(ran, tmp_path):
    sw, _ = ran
    out = tmp_path / "tidy.csv"
    r = invoke(["sweep", "collect", sw, "-o", out])
    assert r.exit_code == 0, r.output
    with open(out, newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert list(rows[0]) == ["index", "Visco", "dp", "dir", "status", "particles", "steps", "physical_time",
                             "runtime_s", "us_per_particle_step"]
    for i, row in enumerate(rows):
        meta = run_json(sw / f"run_{i:04d}")
        assert row["status"] == meta["status"] == "completed"
        assert int(row["particles"]) == meta["particles"] and int(row["steps"]) == meta["steps"]
        for key in ("physical_time", "runtime_s", "us_per_particle_step"):
            assert float(row[key]) == meta[key]
    # --file: every run's gauge file, long format, the parameters in front
    (sw / "run_0003" / "GaugesSWL_Swl_x02.csv").rename(sw / "run_0003" / "moved.csv")
    try:
        r = invoke(["sweep", "collect", sw, "-o", out, "--file", "GaugesSWL_Swl_x02.csv"])
    finally:
        (sw / "run_0003" / "moved.csv").rename(sw / "run_0003" / "GaugesSWL_Swl_x02.csv")
    assert r.exit_code == 0, r.output
    assert "run_0003/GaugesSWL_Swl_x02.csv" in r.output
    with open(out, newline="") as fh:
        rows = list(csv.reader(fh))
    head = (sw / "run_0000" / "GaugesSWL_Swl_x02.csv").read_text().splitlines()
    assert rows[0] == ["index", "Visco", "dp"] + head[0].split(";")
    per_run = [(sw / f"run_{i:04d}" / "GaugesSWL_Swl_x02.csv").read_text().splitlines()[1:] for i in range(3)]
    assert len(rows) == 1 + sum(len(p) for p in per_run)
    assert rows[1] == ["0", "0.01", "0.04"] + per_run[0][0].split(";")
    assert rows[-1] == ["2", "0.05", "0.04"] + per_run[2][-1].split(";")
    # two files: a 'file' column says which
    r = invoke(["sweep", "collect", sw, "-o", out, "--file", "run.csv", "--file", "GaugesSWL_Swl_x02.csv"])
    assert r.exit_code == 0, r.output
    with open(out, newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert list(rows[0])[:4] == ["index", "Visco", "dp", "file"]
    assert {r["file"] for r in rows} == {"run.csv", "GaugesSWL_Swl_x02.csv"}
    assert_input_error(invoke(["sweep", "collect", tmp_path, "-o", out]), "not a sweep")


def test_sigint_stops_the_runner_and_the_entries_resume(tmp_path):
    """SIGINT to `sweep run` stops its runs at their next step (interrupted, resumable) and starts no
    more; `run --manifest --index` and `sweep run` then resume them to the end."""
    sw = tmp_path / "sw"
    assert invoke(["sweep", "new", DAMBREAK, "-o", sw, "--vary", "Visco=0.01,0.02,0.03", "--vary", "dp=0.04",
                   "--tmax", "0.4", "--tout", "0.002"]).exit_code == 0
    proc = subprocess.Popen([sys.executable, "-m", "sphdvi", "sweep", "run", str(sw), "--jobs", "2"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    csvs = [sw / f"run_{i:04d}" / "run.csv" for i in range(2)]
    deadline = time.time() + 120
    while time.time() < deadline and proc.poll() is None and not all(
            c.exists() and c.read_text().count("\n") >= 3 for c in csvs):
        time.sleep(0.05)
    assert proc.poll() is None, "the runs ended before they could be stopped"
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 1, (out, err)
    assert "interrupted by SIGINT" in err and "Traceback" not in err + out
    statuses = [m["status"] for m in manifest(sw)]
    assert statuses == ["interrupted", "interrupted", "pending"], (statuses, out, err)
    steps = run_json(sw / "run_0000")["steps"]
    r = invoke(["run", "--manifest", sw / "sweep.csv", "--index", 0, "-q"])
    assert r.exit_code == 0, r.output
    meta = run_json(sw / "run_0000")
    assert meta["status"] == "completed" and meta["steps"] > steps and meta["physical_time"] >= 0.4
    assert "resumed from part" in (sw / "run_0000" / "run.log").read_text()
    r = invoke(["sweep", "run", sw])
    assert r.exit_code == 0, r.output
    assert [m["status"] for m in manifest(sw)] == ["completed"] * 3
    assert "resumed from part" in (sw / "run_0001" / "run.log").read_text()
