"""`sphdvi run` into a folder that already holds a run: a new run is refused unless
--overwrite (which deletes the earlier results first), gauge files start anew, --resume
goes on with the run's own --tmax/--tout/--set, leftover temporaries go, a signal during
start-up ends the run as 'interrupted', and a resume without the particle file warns.
Tiny runs (dp 0.1, a few steps)."""
import json
import os
import shutil
import signal
import subprocess
import sys
import time
import warnings
from pathlib import Path

import h5py
import pytest
from click.testing import CliRunner

from sphdvi.cli import main

REPO = Path(__file__).resolve().parents[2]
DAMBREAK = REPO / "cases" / "dambreak2d" / "CaseDambreakVal2D_Def.xml"
CASE_H5 = "CaseDambreakVal2D.h5"
RUN = ["--dp", "0.1", "--tmax", "0.004", "--tout", "0.002", "--threads", "1", "-q"]


def invoke(args):
    return CliRunner().invoke(main, [str(a) for a in args])


def csv_rows(path):
    return Path(path).read_text().splitlines()[1:]


def nsteps(path):
    with h5py.File(path, "r") as f:
        return int(f["VTKHDF/Steps"].attrs["NSteps"])


@pytest.fixture(scope="module")
def done(tmp_path_factory):
    """A finished tiny run: outputs at 0, 0.002, 0.004 (tests copy it)."""
    base = tmp_path_factory.mktemp("done")
    out = base / "out"
    r = invoke(["run", DAMBREAK, "-o", out] + RUN)
    assert r.exit_code == 0, r.output
    return out


def copy_run(src, dest):
    shutil.copytree(src, dest)
    return dest


def test_new_run_into_earlier_results_is_refused_and_changes_nothing(done, tmp_path):
    out = copy_run(done, tmp_path / "o")
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    for source in (DAMBREAK, out):
        r = invoke(["run", source, "-o", out] + RUN)
        assert r.exit_code == 2, r.output
        assert "Traceback" not in r.output
        for text in ("holds the results of an earlier run", "status 'completed'", "--resume", "--overwrite",
                     "particles.vtkhdf", "restart.h5"):
            assert text in r.output, (text, r.output)
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    r = invoke(["run", out, "--resume", "--overwrite"])
    assert r.exit_code == 2 and "give one" in r.output


def test_refusal_of_a_killed_run_names_its_last_output(done, tmp_path):
    """run.json of a killed run still says 'running' at t = 0 (it is written at the start and the
    end): the refusal says it was killed (no run holds the folder's lock), with run.csv's last output time."""
    out = copy_run(done, tmp_path / "o")
    meta = json.loads((out / "run.json").read_text())
    meta.update(status="running", physical_time=0.0)
    (out / "run.json").write_text(json.dumps(meta))
    r = invoke(["run", out] + RUN)
    assert r.exit_code == 2, r.output
    assert "status 'running' though no run holds the folder: it was killed (SIGKILL, a crash); its last output " \
        "at t=0.00" in r.output
    assert "at t=0 s" not in r.output


def test_gencase_into_a_run_folder_is_refused_unless_overwrite(done, tmp_path):
    """A new case drawn into a folder holding a run's results would leave them beside a case
    they do not belong to: refused, nothing changed; with --overwrite the results go."""
    out = copy_run(done, tmp_path / "o")
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    r = invoke(["gencase", DAMBREAK, "-o", out, "--dp", "0.05", "-q"])
    assert r.exit_code == 2 and "Traceback" not in r.output, r.output
    for text in ("holds the results of a run", "restart.h5", "--overwrite"):
        assert text in r.output, (text, r.output)
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    r = invoke(["gencase", DAMBREAK, "-o", out, "--dp", "0.05", "--overwrite", "-q"])
    assert r.exit_code == 0, r.output
    assert sorted(p.name for p in out.iterdir()) == [CASE_H5, "CaseDambreakVal2D_All.vtp"]


def test_a_second_case_into_a_case_folder_is_refused_unless_overwrite(tmp_path):
    """Another case's gencase output in OUT would leave two cases there, which `run OUT`, --resume
    and `measure` cannot tell apart: gencase and `run CASE.xml` refuse (exit 2, the files named,
    nothing changed); --overwrite deletes them (the user's other files stay)."""
    g = tmp_path / "g"
    assert invoke(["gencase", DAMBREAK, "-o", g, "--dp", "0.1", "-q"]).exit_code == 0
    (g / "notes.txt").write_text("the user's")
    other = tmp_path / "CaseOther_Def.xml"
    other.write_text(DAMBREAK.read_text())
    before = {p.name: p.read_bytes() for p in g.iterdir()}
    for args in (["gencase", other, "-o", g, "--dp", "0.1", "-q"], ["run", other, "-o", g] + RUN):
        r = invoke(args)
        assert r.exit_code == 2 and "Traceback" not in r.output, r.output
        for text in ("gencase output of another case", CASE_H5, "CaseDambreakVal2D_All.vtp", "--overwrite"):
            assert text in r.output, (text, r.output)
        assert {p.name: p.read_bytes() for p in g.iterdir()} == before
    r = invoke(["run", other, "-o", g, "--overwrite"] + RUN)
    assert r.exit_code == 0, r.output
    names = {p.name for p in g.iterdir()}
    assert "CaseOther.h5" in names and "notes.txt" in names and not names & {CASE_H5, "CaseDambreakVal2D_All.vtp"}
    assert invoke(["run", g, "--resume", "--tmax", "0.006"]).exit_code == 0
    # the same case again needs no --overwrite for its own case file (a gencase output folder)
    assert invoke(["gencase", other, "-o", tmp_path / "h", "--dp", "0.1", "-q"]).exit_code == 0
    assert invoke(["gencase", other, "-o", tmp_path / "h", "--dp", "0.1", "-q"]).exit_code == 0


def test_gencase_folder_runs_and_overwrite_starts_clean(done, tmp_path):
    # a gencase output folder (case files only) runs without --overwrite
    g = tmp_path / "g"
    assert invoke(["gencase", DAMBREAK, "-o", g, "--dp", "0.1", "-q"]).exit_code == 0
    assert invoke(["run", g, "--tmax", "0.002", "--tout", "0.002", "--threads", "1", "-q"]).exit_code == 0
    assert nsteps(g / "particles.vtkhdf") == 2
    # --overwrite: nothing of the earlier run stays (stale body and gauge files included)
    out = copy_run(done, tmp_path / "o")
    for name in ("bodies.csv", "links.csv", "GaugesVel_old.csv", "excluded.csv"):
        (out / name).write_text("earlier run\n")
    (out / "notes.txt").write_text("the user's")
    r = invoke(["run", DAMBREAK, "-o", out, "--overwrite", "--dp", "0.1", "--tmax", "0.002", "--tout", "0.002",
                "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output
    names = {p.name for p in out.iterdir()}
    assert not names & {"bodies.csv", "links.csv", "GaugesVel_old.csv", "excluded.csv"}
    assert "notes.txt" in names
    assert nsteps(out / "particles.vtkhdf") == 2 and len(csv_rows(out / "run.csv")) == 2
    meta = json.loads((out / "run.json").read_text())
    assert meta["status"] == "completed" and meta["overrides"]["tmax"] == 0.002
    with h5py.File(out / "restart.h5", "r") as f:       # the new run's checkpoint (the old one was part 2)
        assert int(f["scalars"].attrs["part"]) == 1
    times = [float(r.split(";")[0]) for r in csv_rows(out / "GaugesSWL_Swl_x02.csv")]
    assert times[0] == 0.0 and times == sorted(times) and len(times) == len(set(times))


def test_overwrite_deletes_the_earlier_exports_and_nothing_else(done, tmp_path):
    """--overwrite: the .vtp series and .pvd that `sphdvi export` made of the earlier run go
    (a folder left empty goes too); the user's files beside them, and numbered files in a
    folder without an export's collection, stay."""
    out = copy_run(done, tmp_path / "o")
    assert invoke(["export", out]).exit_code == 0
    assert invoke(["export", out, "--isosurface"]).exit_code == 0
    assert sorted(p.name for p in (out / "vtp").iterdir()) == ["Part_0000.vtp", "Part_0001.vtp", "Part_0002.vtp",
                                                              "particles.pvd"]
    (out / "vtp" / "view.pvsm").write_text("the user's ParaView state")
    (out / "mine").mkdir()
    (out / "mine" / "Part_0007.vtp").write_text("not an export")
    r = invoke(["run", out, "--overwrite", "--tmax", "0.002", "--tout", "0.002", "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output
    assert sorted(p.name for p in (out / "vtp").iterdir()) == ["view.pvsm"]
    assert not (out / "iso").exists()
    assert (out / "mine" / "Part_0007.vtp").read_text() == "not an export"


def tree(folder):
    """Every file under ``folder`` (hidden ones too): relative path -> bytes."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in Path(folder).rglob("*") if p.is_file()}


def test_overwrite_that_fails_on_bad_input_loses_nothing(done, tmp_path):
    """--overwrite sets the earlier files aside and deletes them only once the new run's start-up
    has passed its checks: a command that stops on bad input (exit 2) after gencase, or in the
    run's start-up (a DtFixedFile that is not there), leaves OUT byte for byte as it was, the
    exports and another case's gencase output included, and no new case beside them."""
    out = copy_run(done, tmp_path / "o")
    assert invoke(["export", out]).exit_code == 0
    before = tree(out)
    bad_dp = tmp_path / "CaseBad_Def.xml"
    bad_dp.write_text(DAMBREAK.read_text().replace('<definition dp="', '<definition dp="-'))
    other = tmp_path / "CaseOther_Def.xml"
    other.write_text(DAMBREAK.read_text())
    missing = ["--set", f"DtFixedFile={tmp_path / 'missing.csv'}"]
    for args in (["run", out, "--overwrite"] + missing + RUN,
                 ["run", DAMBREAK, "-o", out, "--overwrite"] + missing + RUN,
                 ["run", other, "-o", out, "--overwrite"] + missing + RUN,
                 ["run", bad_dp, "-o", out, "--overwrite"] + RUN[2:],
                 ["gencase", bad_dp, "-o", out, "--overwrite", "-q"]):
        r = invoke(args)
        assert r.exit_code == 2 and "Traceback" not in r.output, (args, r.output)
        assert tree(out) == before, args
    # what a killed --overwrite left aside is pointed out by the next run
    left = out / ".sphdvi-overwritten"
    left.mkdir()
    (left / "run.csv").write_text("an earlier run's")
    with pytest.warns(UserWarning, match="holds the files of a run that an interrupted --overwrite set aside"):
        invoke(["run", out, "--resume", "--tmax", "0.004", "--threads", "1", "-q"])
    # a good run with --overwrite then replaces them, and leaves nothing aside
    r = invoke(["run", out, "--overwrite", "--tmax", "0.002", "--tout", "0.002", "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output
    assert not (out / ".sphdvi-overwritten").exists() and not (out / "vtp").exists()
    assert nsteps(out / "particles.vtkhdf") == 2


def test_export_again_drops_the_parts_of_a_longer_earlier_export(done, tmp_path):
    out = copy_run(done, tmp_path / "o")
    assert invoke(["export", out]).exit_code == 0
    assert invoke(["run", out, "--overwrite", "--tmax", "0.002", "--tout", "0.002", "--threads", "1",
                   "-q"]).exit_code == 0
    (out / "vtp").mkdir(exist_ok=True)
    (out / "vtp" / "Part_0002.vtp").write_text("left by an export of a longer run")
    (out / "vtp" / "Part_0002.txt").write_text("the user's")
    assert invoke(["export", out]).exit_code == 0
    assert sorted(p.name for p in (out / "vtp").iterdir()) == ["Part_0000.vtp", "Part_0001.vtp", "Part_0002.txt",
                                                              "particles.pvd"]


def test_gauge_files_start_anew_in_a_new_run(done, tmp_path):
    """RunGauges of a new run (resume=False) rewrites its files: one series, not two."""
    from sphdvi.io.casefile import read_case_h5
    from sphdvi.measure.gauges import RunGauges
    from sphdvi.run_options import apply_overrides
    from sphdvi.simulation import special_parameters
    out = copy_run(done, tmp_path / "o")
    path = out / "GaugesSWL_Swl_x02.csv"
    assert len(csv_rows(path)) >= 2
    data = read_case_h5(str(out / CASE_H5))
    RunGauges(data, apply_overrides(special_parameters(data), (), 0.004, 0.002), str(out), resume=False).close()
    rows = csv_rows(path)
    assert len(rows) == 1 and float(rows[0].split(";")[0]) == 0.0


def test_resume_reuses_the_run_options(done, tmp_path):
    out = copy_run(done, tmp_path / "o")
    # a change of --tout or of a parameter is refused, nothing touched
    before = (out / "run.csv").read_bytes()
    for opts, what in ((["--tout", "0.001"], "TimeOut 0.002 -> 0.001"), (["--set", "Visco=0.05"], "Visco")):
        r = invoke(["run", out, "--resume", "--tmax", "0.008"] + opts)
        assert r.exit_code == 2 and what in r.output and "only --tmax may change" in r.output, r.output
    assert (out / "run.csv").read_bytes() == before
    # --tmax extends the run; its outputs stay 0.002 apart (the case's TimeOut is 0.01); the
    # same --tout given again is accepted
    r = invoke(["run", out, "--resume", "--tmax", "0.008", "--tout", "0.002", "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output
    times = [float(row.split(",")[1]) for row in csv_rows(out / "run.csv")]
    assert len(times) == 5 and all(0.0015 < b - a < 0.003 for a, b in zip(times, times[1:]))
    meta = json.loads((out / "run.json").read_text())
    assert meta["overrides"] == {"tmax": 0.008, "tout": 0.002, "set": []}
    assert meta["parameters"]["TimeOut"] == 0.002 and meta["status"] == "completed"
    # a plain --resume keeps the stored --tmax: nothing more to do
    r = invoke(["run", out, "--resume", "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output
    assert len(csv_rows(out / "run.csv")) == 5


def test_extending_a_run_that_ended_between_outputs_keeps_the_schedule(tmp_path):
    """A run to a TimeMax between two outputs ends with an output there; extended with --resume
    --tmax, its next output is the schedule's next one (0.003 was skipped before: after an output
    at 0.0025 the next came at 0.004), and its times are those of an uninterrupted run besides."""
    whole, ext = tmp_path / "whole", tmp_path / "ext"
    opts = ["--dp", "0.1", "--tout", "0.001", "--threads", "1", "-q"]
    assert invoke(["run", DAMBREAK, "-o", whole, "--tmax", "0.005"] + opts).exit_code == 0
    assert invoke(["run", DAMBREAK, "-o", ext, "--tmax", "0.0025"] + opts).exit_code == 0
    r = invoke(["run", ext, "--resume", "--tmax", "0.005", "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output

    def times(out):
        return [float(row.split(",")[1]) for row in csv_rows(out / "run.csv")]
    assert len(times(whole)) == 6
    assert times(ext) == sorted(times(whole) + [times(ext)[3]])     # the same steps; one output more
    assert 0.0025 <= times(ext)[3] < times(whole)[3] and times(whole)[3] >= 0.003


def test_first_output_after_a_clock_time():
    from sphdvi.output_schedule import OutputSchedule
    every = OutputSchedule.every(0.05)
    assert every.first_after(0.125) == pytest.approx(0.15)
    assert every.first_after(0.1000000000001, 1e-12) == pytest.approx(0.15)
    assert every.first_after(0.15 - 1e-14, 1e-12) == pytest.approx(0.2)       # at 0.15 to round-off
    rows = OutputSchedule([(0.0, 0.1), (0.25, 0.01)])
    assert rows.first_after(0.12) == pytest.approx(0.2)
    assert rows.first_after(0.2) == pytest.approx(0.25)
    assert rows.first_after(0.253) == pytest.approx(0.26)


def test_resume_cuts_run_log_back_to_the_restart_output(done, tmp_path):
    """A run killed after an output's log line but before its checkpoint (a body-only run
    checkpoints at most once a second) resumes from the earlier output: the log lines written
    after it go, so that each Part line is there once (they were written twice before)."""
    out = copy_run(done, tmp_path / "o")              # restart.h5 at part 2
    log = out / "run.log"
    kept = log.read_text().split("completed:")[0]     # the lines up to the restart output's
    log.write_text(kept + "Part 0003  t=0.006000 s  steps=99  (written before the kill)\nWARNING: lost\n")
    r = invoke(["run", out, "--resume", "--tmax", "0.008", "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output
    text = log.read_text()
    assert text.startswith(kept) and "before the kill" not in text and "lost" not in text
    parts = [line.split()[1] for line in text.splitlines() if line.startswith("Part ")]
    assert parts == ["0000", "0001", "0002", "0003", "0004"]


def test_log_to_part():
    from sphdvi.io.runfiles import log_to_part
    lines = ["Part 0000  t=0", "Part 0001  t=1", "WARNING: excluded", "a step's note", "Part 0002  t=2"]
    assert log_to_part(lines, 1) == lines[:3]
    assert log_to_part(lines, 2) == lines
    assert log_to_part(["resumed"], 3) == ["resumed"]


def test_resume_with_a_tmax_below_the_time_reached_is_refused(done, tmp_path):
    """--resume --tmax below the run's time (t = 0.0042 after TimeMax 0.004) is refused, nothing
    touched (the run was marked completed at TimeMax 0.002 before, and kept it); the run's own
    TimeMax again is accepted (nothing to do), as in a body-only run."""
    out = copy_run(done, tmp_path / "o")
    before = tree(out)
    r = invoke(["run", out, "--resume", "--tmax", "0.002", "--threads", "1", "-q"])
    assert r.exit_code == 2 and "Traceback" not in r.output, r.output
    assert "--tmax 0.002: the run in" in r.output and "has reached t=0.00424" in r.output
    assert "expected a --tmax beyond it" in r.output
    assert tree(out) == before
    assert invoke(["run", out, "--resume", "--tmax", "0.004", "--threads", "1", "-q"]).exit_code == 0
    pend = tmp_path / "pend"
    assert invoke(["run", REPO / "cases" / "pendulum" / "CasePendulum_Def.xml", "-o", pend, "--tmax", "0.05",
                   "-q"]).exit_code == 0
    r = invoke(["run", pend, "--resume", "--tmax", "0.01", "-q"])
    assert r.exit_code == 2 and "has reached t=0.05" in r.output, r.output


def test_resume_with_a_case_xml_checks_it_is_the_runs(done, tmp_path):
    """`run CASE.xml --resume -o OUT` goes on with the case drawn in OUT: its own file is accepted;
    another case's file, or the same file edited since, is refused naming what to do (either
    resumed the old case silently before), nothing touched."""
    out = copy_run(done, tmp_path / "o")
    before = tree(out)
    other = tmp_path / "CaseOther_Def.xml"
    other.write_text(DAMBREAK.read_text())
    edited = tmp_path / "CaseDambreakVal2D_Def.xml"
    edited.write_text(DAMBREAK.read_text().replace("<parameters>", '<parameters><parameter key="Visco" value="0.5"/>'))
    for xml, text in ((other, "holds a run of the case 'CaseDambreakVal2D'"), (edited, "has changed since gencase")):
        r = invoke(["run", xml, "-o", out, "--resume", "--tmax", "0.006", "--threads", "1", "-q"])
        assert r.exit_code == 2 and text in r.output and f"'sphdvi run {out} --resume'" in r.output, r.output
        assert tree(out) == before
    r = invoke(["run", DAMBREAK, "-o", out, "--resume", "--tmax", "0.006", "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output


def test_a_run_of_a_gencase_folder_into_another_folder_resumes_and_measures_there(tmp_path):
    """`sphdvi run G -o OUT` leaves OUT without a case file: `run OUT --resume` (what its message
    says) and `measure ... OUT` find it by run.json's case_file (both said "no gencase output")."""
    g, out = tmp_path / "g", tmp_path / "out"
    assert invoke(["gencase", DAMBREAK, "-o", g, "--dp", "0.1", "-q"]).exit_code == 0
    assert invoke(["run", g, "-o", out, "--tmax", "0.002", "--tout", "0.002", "--threads", "1", "-q"]).exit_code == 0
    r = invoke(["run", out, "--resume", "--tmax", "0.004", "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output
    assert nsteps(out / "particles.vtkhdf") == 3
    r = invoke(["measure", "elevation", out, "--at", "0.2"])
    assert r.exit_code == 0 and len(r.stdout.splitlines()) == 4, r.output


def test_resume_of_what_never_ran(tmp_path):
    """--resume of a gencase folder that never ran says so, without a warning about run.json
    first; of a folder that is not there, says that (it said 'not a folder or case file')."""
    g = tmp_path / "g"
    assert invoke(["gencase", DAMBREAK, "-o", g, "--dp", "0.1", "-q"]).exit_code == 0
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        r = invoke(["run", g, "--resume"])
    assert r.exit_code == 2 and f"{g} holds no run to continue (no restart.h5); start it with" in r.output
    assert not [w for w in caught if "run.json" in str(w.message)]
    r = invoke(["run", DAMBREAK, "--resume", "-o", tmp_path / "missing"])
    assert r.exit_code == 2 and "missing does not exist: there is no run to continue" in r.output, r.output


def test_leftover_temporaries_go_at_start(done, tmp_path):
    out = copy_run(done, tmp_path / "o")
    (out / ".restart.h5.k3j_x9a1.tmp").write_bytes(b"half a checkpoint")
    (out / ".run.json.abcd1234.tmp").write_text("{")
    r = invoke(["run", out, "--resume", "--tmax", "0.006", "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output
    assert not [p.name for p in out.iterdir() if p.name.endswith(".tmp")]


def test_resume_without_particle_file_warns(done, tmp_path):
    out = copy_run(done, tmp_path / "o")
    os.unlink(out / "particles.vtkhdf")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        r = invoke(["run", out, "--resume", "--tmax", "0.006", "--threads", "1", "-q"])
    assert r.exit_code == 0, r.output
    msgs = [str(w.message) for w in caught if "particles.vtkhdf was missing" in str(w.message)]
    assert msgs and "parts 0..2 are not in it" in msgs[0], [str(w.message) for w in caught]
    assert "WARNING: --resume:" in (out / "run.log").read_text()


def test_sigterm_during_startup_ends_interrupted(tmp_path):
    """The signal comes as soon as gencase has written the case file (start-up: loading,
    compiling): exit 1, run.json 'interrupted', no traceback."""
    out = tmp_path / "o"
    env = dict(os.environ, SPHDVI_DEBUG="1")
    proc = subprocess.Popen([sys.executable, "-m", "sphdvi", "run", str(DAMBREAK), "-o", str(out), "--dp", "0.1",
                             "--tmax", "5", "--tout", "0.002", "--threads", "1", "-q"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env, cwd=REPO)
    deadline = time.monotonic() + 60
    while not (out / CASE_H5).exists() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.005)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 1, err
    assert "Traceback" not in err and "interrupted: stopped by signal" in err
    meta = json.loads((out / "run.json").read_text())
    assert meta["status"] == "interrupted" and "stopped by signal" in meta["message"]


def test_run_and_resume_without_set_do_not_import_the_case_reader(tmp_path):
    """`sphdvi run <gencase folder>` and `sphdvi run <run folder> --resume` without --set do not
    import the XML case reader (lxml, the schema): they read only the case file; with --set of a
    data-file key the reader's key list is needed, and imported then."""
    g, out = tmp_path / "g", tmp_path / "out"
    assert invoke(["gencase", DAMBREAK, "-o", g, "--dp", "0.1", "-q"]).exit_code == 0
    code = ("import sys\nfrom sphdvi.cli import main\n"
            "try:\n    main(sys.argv[1:], standalone_mode=False)\n"
            "finally:\n    print('READER', 'sphdvi.case.reader' in sys.modules)\n")
    for args in ([g, "-o", out, "--tmax", "0.002", "--tout", "0.002"], [out, "--resume", "--tmax", "0.004"]):
        res = subprocess.run([sys.executable, "-c", code, "run"] + [str(a) for a in args] + ["--threads", "1", "-q"],
                             cwd=REPO, capture_output=True, text=True, timeout=300)
        assert res.returncode == 0, res.stderr
        assert "READER False" in res.stdout, (args, res.stdout, res.stderr)
    assert nsteps(out / "particles.vtkhdf") == 3
    from sphdvi.run_options import absolute_file_sets
    assert absolute_file_sets(()) == ()
    assert absolute_file_sets(["DtFixedFile=dt.csv", "Visco=0.1"]) == (f"DtFixedFile={os.path.abspath('dt.csv')}",
                                                                       "Visco=0.1")
