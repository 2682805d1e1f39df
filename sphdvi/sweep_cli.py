"""``sphdvi sweep``: parameter sweeps and convergence studies (new, run, status, collect, converge), and
``sphdvi run --manifest SWEEPDIR/sweep.csv --index I`` (one entry, as a SLURM array task runs it).

Only click is imported at module level (``sphdvi --help`` stays fast); the logic is in
:mod:`sphdvi.sweep`.
"""
from __future__ import annotations

import os
import shlex
import sys

import click

from .cli_errors import FiniteFloat, report_errors

CONTEXT = {"help_option_names": ["-h", "--help"], "max_content_width": 100}


@click.group(context_settings=CONTEXT)
def sweep():
    """Parameter sweeps: N independent runs of one case, a manifest and a SLURM job array.

    \b
      sphdvi sweep new CASE.xml -o SWEEP --vary Visco=0.01,0.02 --vary dp=0.02,0.01 --tmax 1
      sbatch SWEEP/sweep.sbatch          # on a cluster: one array task per run
      sphdvi sweep run SWEEP             # or here, J runs at a time
      sphdvi sweep status SWEEP
      sphdvi sweep collect SWEEP -o tidy.csv [--file GaugesSWL_Swl_x02.csv]
      sphdvi sweep converge SWEEP --file GaugesSWL_WP1.csv --column swlz [--reference ref.csv]
    """


@sweep.command("new", context_settings=CONTEXT)
@click.argument("case_xml", type=click.Path(dir_okay=False))
@click.option("-o", "--out", "sweepdir", type=click.Path(file_okay=False), required=True,
              help="The sweep folder (sweep.csv, sweep.json, sweep.sbatch, logs/, one run_XXXX per run).")
@click.option("--vary", "vary", multiple=True, metavar="KEY=V1,V2,...",
              help="Values of a key (repeatable; the runs are the Cartesian product, the first key varying "
                   "slowest): dp (sphdvi run --dp) or any key 'sphdvi run --set' takes.")
@click.option("--table", "table", type=click.Path(dir_okay=False), default=None,
              help="A CSV file (',' separated) whose header names the keys and whose rows are the runs (instead "
                   "of --vary).")
@click.option("--set", "sets", multiple=True, metavar="KEY=VALUE",
              help="A --set every run gets (repeatable).")
@click.option("--tmax", type=FiniteFloat(min=0), default=None, help="Every run's --tmax [s].")
@click.option("--tout", type=FiniteFloat(min=0, min_open=True), default=None, help="Every run's --tout [s].")
@click.option("--threads", type=click.IntRange(min=1), default=1, show_default=True, help="Threads per run.")
@click.option("--time", "time_limit", default="24:00:00", show_default=True,
              help="SLURM wall-time limit of each array task ([D-]HH:MM:SS).")
@click.option("--throttle", type=click.IntRange(min=1), default=20, show_default=True,
              help="Array tasks at once on the cluster (sbatch --array=0-(N-1)%K).")
@click.option("--command", "command", default=None, metavar="TEXT",
              help="How sweep.sbatch starts sphdvi, as shell words (e.g. 'srun sphdvi' or 'apptainer exec "
                   "sphdvi.sif sphdvi'); default: this Python, '<python> -m sphdvi'.")
@report_errors
def new(case_xml, sweepdir, vary, table, sets, tmax, tout, threads, time_limit, throttle, command):
    """Expand a parameter space into one run folder per entry, a manifest and an sbatch script.

    Every key and value is checked as 'sphdvi run --set' (or --dp) checks it before anything
    is written (exit 2 naming the key; also a key given twice, CFLnumber in any letter case being
    one key, or a value given twice as the same number, 0.01,0.010). The same spec into the same folder again does
    nothing (sweep.sbatch is written again when the folder moved); another spec there is exit 2
    (saying what differs). Make the sweep where it runs: sweep.json and sweep.sbatch hold
    absolute paths (the case, the sweep folder, this Python).
    """
    from . import sweep as sw
    from .errors import InputError
    if bool(vary) == bool(table):
        raise InputError("give the parameter space with --vary KEY=V1,V2,... (repeatable) or with --table FILE.csv "
                         "(one of them)")
    keys, rows = sw.read_table(table) if table else sw.parse_vary(vary)
    rows = rows if table else sw.product_rows(rows)
    time_limit = sw.check_slurm_time(time_limit)
    lines = sw.check_entries(case_xml, keys, rows, sets, tmax, tout, source="--table" if table else "--vary")
    for line in lines:
        click.echo(f"warning: {line}", err=True)
    if command is not None and not command.strip():
        raise InputError("--command '': expected the shell words that start sphdvi (e.g. 'srun sphdvi')")
    spec = sw.make_spec(case_xml, keys, rows, sets, tmax, tout, threads, time_limit, throttle,
                        command.strip() if command else None)
    done = sw.create_sweep(sweepdir, spec)
    n = len(spec["runs"])
    runs = f"{n} run{'s' if n != 1 else ''}"
    if n > sw.SLURM_MAX_ARRAY:
        click.echo(f"warning: {runs}: sweep.sbatch's --array=0-{n - 1} goes past SLURM's default MaxArraySize "
                   f"({sw.SLURM_MAX_ARRAY}: indices up to {sw.SLURM_MAX_ARRAY - 1}), which sbatch refuses unless "
                   "the cluster raised it (scontrol show config | grep MaxArraySize); split the sweep, or submit "
                   f"it in parts: sbatch --array=0-{sw.SLURM_MAX_ARRAY - 2}%K ... (the --array given to sbatch "
                   "replaces the script's)", err=True)
    if done == "unchanged":
        click.echo(f"{sweepdir} already holds this sweep ({runs}): nothing to do")
        return
    if done == "moved":
        click.echo(f"{sweepdir} already holds this sweep ({runs}); {sw.SBATCH} written again: it named another "
                   "folder (the sweep was moved) or another Python")
        return
    if done == "updated":
        click.echo(f"{sweepdir}: the same sweep; {sw.SBATCH} written again for --time {time_limit} "
                   f"--throttle {throttle}" + (f" --command {command}" if command else ""))
        return
    dirs = sw.run_dir_name(0, n) + (f"..{sw.run_dir_name(n - 1, n)}" if n > 1 else "")
    click.echo(f"{runs} of {os.path.basename(case_xml)} ({', '.join(keys)}) in {sweepdir}: "
               f"{sw.MANIFEST}, {sw.SPEC}, {sw.SBATCH}, {dirs}")
    click.echo(f"run them with 'sbatch {shlex.quote(os.path.join(sweepdir, sw.SBATCH))}' or "
               f"'sphdvi sweep run {shlex.quote(sweepdir)}'")


def run_manifest_entry(manifest, index, retry, threads, quiet, given) -> None:
    """``sphdvi run --manifest SWEEPDIR/sweep.csv --index I``: entry I with the sweep's settings
    into its folder, under its run lock (a second task on it: exit 2 naming the holder); run.json
    decides (:func:`sphdvi.sweep.entry_action`; a folder holding another run or an unreadable
    run.json: exit 2, nothing deleted): completed -> exit 0 without running, interrupted or killed
    -> --resume, failed/diverged -> their exit code unless --retry (then --overwrite).  A start-up
    refused on bad input is recorded for ``sweep status`` (``refused``).  The entry's status in
    sweep.csv is updated at the end, read from run.json under the sweep's lock.  ``given``: the
    run options that cannot go with --manifest (exit 2 when one was given)."""
    from . import sweep as sw
    from .cli import _run
    from .errors import EXIT_INPUT, InputError, SphdviError
    from .io.runfolder import run_lock
    from .simulation import _Stop
    if manifest is None:
        flags = [name for name, value in (("--retry", retry), ("--index", index is not None)) if value]
        raise InputError(f"{' and '.join(flags)} go{'es' if len(flags) == 1 else ''} with --manifest "
                         "SWEEPDIR/sweep.csv (an entry of a sweep); a plain run starts again with --overwrite")
    bad = [name for name, value in given.items() if value]
    if bad:
        raise InputError(f"--manifest: not with {', '.join(bad)}: the sweep's spec gives the run's case and "
                         "options (sweep.json); expected --manifest, --index and optionally --retry, --threads, -q")
    if index is None:
        raise InputError("--manifest and --index go together: expected --manifest SWEEPDIR/sweep.csv --index I")
    sweep = sw.open_sweep(manifest, "--manifest")
    sw.check_index(sweep, index)
    rundir = sweep.run_dir(index)
    label = f"{os.path.basename(rundir)} ({sw.describe(sweep.keys, sweep.runs[index])})"
    again = (f"go on with 'sphdvi run --manifest {shlex.quote(sweep.manifest)} --index {index}' or "
             f"'sphdvi sweep run {shlex.quote(sweep.dir)}'")

    def hint(message: str) -> str:
        """A run's advice to resume or re-run by hand, as this sweep's command."""
        import re
        return re.sub(r"[;:,]?\s*(resume with|run again with|go on with) '.*$", f"; {again}", message, flags=re.S)

    with _Stop() as stop:
        try:
            with run_lock(rundir):
                action = sw.entry_action(sweep, index, retry)
                if action.kind == "done":
                    click.echo(f"{label}: {action.message}: nothing to do", err=True)
                    return
                if action.kind == "refuse":
                    click.echo(f"{label}: {action.message}", err=True)
                    sys.exit(action.exit_code)
                if not quiet:
                    click.echo(f"{label}: {action.message}", err=True)
                sw.clear_refused(rundir)
                try:
                    options = sw.entry_run_options(sweep, index, action)
                    _run(threads=threads if threads is not None else sweep.spec.get("threads"), quiet=quiet,
                         stop=stop, hint=hint, **options)
                except SphdviError as exc:
                    if exc.exit_code == EXIT_INPUT and not os.path.exists(os.path.join(rundir, "run.json")):
                        sw.mark_refused(rundir, str(exc))
                    raise
        finally:
            sw.update_manifest(sweep, [index])


@sweep.command("run", context_settings=CONTEXT)
@click.argument("sweepdir", type=click.Path(file_okay=False))
@click.option("-j", "--jobs", type=click.IntRange(min=1), default=None,
              help="Runs at once (default: the CPUs of this process's affinity // threads per run).")
@click.option("--retry", is_flag=True, help="Run the failed and diverged entries again from the start.")
@report_errors
def run(sweepdir, jobs, retry):
    """Run every entry not completed here, J at a time (each a 'sphdvi run --manifest --index' process).

    \b
    Prints a line per finished run and a summary. Exit code: 0 when all completed, else 3 when
    one diverged, 2 when one was refused on bad input (its start-up, or a folder holding another
    run or an unreadable run.json), 1 (failed, interrupted, or run elsewhere: another live process
    holds the entry). SIGINT/SIGTERM stop the runs (each at its next step, resumable) and start no
    more; a second SIGINT kills them (they resume from their last output). Run it again to go on.
    The runs stop too when this command is killed (SIGKILL included).
    """
    from . import sweep as sw
    s = sw.open_sweep(sweepdir)
    jobs = jobs or sw.default_jobs(int(s.spec.get("threads") or 1))
    results = _run_entries(s, jobs, retry)
    _summary(s, results)
    sys.exit(sw.sweep_exit_code(code for _, code in results.values()))


ELSEWHERE = "running elsewhere"


def _child_setup(parent: int):
    """What each run's process does before it starts (Linux; None elsewhere): ask for SIGTERM when
    the runner dies, whatever kills it (prctl PR_SET_PDEATHSIG), so that the run stops cleanly,
    resumable, instead of going on as an orphan holding the entry; a runner already gone: SIGTERM
    now.  libc is looked up here, in the runner, not in the forked child."""
    import ctypes
    import signal
    try:
        prctl = ctypes.CDLL(None, use_errno=True).prctl
    except (OSError, AttributeError):
        return None
    term = int(signal.SIGTERM)

    def setup():
        prctl(1, term, 0, 0, 0)                 # PR_SET_PDEATHSIG = 1
        if os.getppid() != parent:
            os.kill(os.getpid(), term)
    return setup


def _run_entries(s, jobs: int, retry: bool) -> dict:
    """The local runner: subprocesses (not a ProcessPoolExecutor) so that a signal reaches each run,
    which then stops cleanly, and a pool worker's death cannot take the others with it.  Each run
    is in a session of its own (a terminal's Ctrl-C reaches the runner only, which passes it on
    once; a second SIGINT kills the runs) and gets SIGTERM when the runner dies (Linux).  An entry
    another live process holds is left to it ("running elsewhere").  Returns {index: (status,
    exit code)} of every entry."""
    import signal
    import subprocess
    import time
    from . import sweep as sw
    from .errors import EXIT_FAILURE, EXIT_INPUT, InputError
    from .io.runfolder import run_lock_holder
    statuses, problems = sw.refresh(s)
    results, todo = {}, []
    for i in range(len(s.runs)):
        if i in problems:
            results[i] = ("refused", EXIT_INPUT)
            click.echo(f"{i:4d}  {sw.describe(s.keys, s.runs[i])}: refused: {problems[i]}")
            continue
        try:
            action = sw.entry_action(s, i, retry)
        except InputError as exc:
            results[i] = ("refused", EXIT_INPUT)
            click.echo(f"{i:4d}  {sw.describe(s.keys, s.runs[i])}: refused: {exc}")
            continue
        if action.kind == "done":
            results[i] = ("completed", 0)
        elif action.kind == "refuse":
            results[i] = (statuses[i], action.exit_code)
            click.echo(f"{i:4d}  {sw.describe(s.keys, s.runs[i])}: {action.message}")
        else:
            todo.append(i)
    if not todo:
        if all(code == 0 for _, code in results.values()):
            click.echo(f"all {len(s.runs)} runs completed already: nothing to run")
        return results
    click.echo(f"{len(todo)} of {len(s.runs)} runs to go, {jobs} at a time ({len(s.runs) - len(todo)} done or "
               f"refused)", err=True)
    env = dict(os.environ)
    env.setdefault("NUMBA_NUM_THREADS", str(int(s.spec.get("threads") or 1)))
    os.makedirs(os.path.join(s.dir, sw.LOGS), exist_ok=True)
    stopped = []
    running = {}         # index -> (Popen, start time, log file)
    setup = _child_setup(os.getpid()) if sys.platform.startswith("linux") else None

    def on_signal(signum, frame):
        stopped.append(signum)
        if len(stopped) == 1:
            for proc, _, _ in running.values():      # once: the runs are in sessions of their own
                if proc.poll() is None:
                    proc.send_signal(signum)
        elif signum == signal.SIGINT and stopped.count(signal.SIGINT) == 2:
            click.echo("second SIGINT: killing the runs (SIGKILL); they resume from their last output", err=True)
            for proc, _, _ in running.values():
                if proc.poll() is None:
                    proc.kill()

    old = {sig: signal.signal(sig, on_signal) for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
           if sig == signal.SIGINT or signal.getsignal(sig) != signal.SIG_IGN}
    try:
        while todo or running:
            while todo and len(running) < jobs and not stopped:
                i = todo.pop(0)
                holder = run_lock_holder(s.run_dir(i))
                if holder is not None:
                    results[i] = (ELSEWHERE, EXIT_FAILURE)
                    click.echo(f"{i:4d}  {sw.describe(s.keys, s.runs[i])}: {ELSEWHERE} ({holder}): left to it")
                    continue
                log = open(os.path.join(s.dir, sw.LOGS, f"{os.path.basename(s.run_dir(i))}.log"), "a")
                cmd = [sys.executable, "-m", "sphdvi", "run", "--manifest", s.manifest, "--index", str(i), "-q"]
                log.write(f"$ sphdvi {' '.join(cmd[3:])}{' --retry' if retry else ''}\n")
                log.flush()
                proc = subprocess.Popen(cmd + (["--retry"] if retry else []), stdout=log, stderr=log, env=env,
                                        stdin=subprocess.DEVNULL, start_new_session=True, preexec_fn=setup)
                running[i] = (proc, time.monotonic(), log)
            if stopped:
                todo.clear()
            for i in [i for i, (p, _, _) in running.items() if p.poll() is not None]:
                proc, t0, log = running.pop(i)
                log.close()
                results[i] = _finished(s, i, proc.returncode, time.monotonic() - t0, log.name)
            time.sleep(0.1)
    finally:
        for sig, handler in old.items():
            signal.signal(sig, handler)
    if stopped:
        click.echo(f"interrupted by {signal.Signals(stopped[0]).name}: the runs stopped are resumable, the others "
                   f"not started; 'sphdvi sweep run {shlex.quote(s.dir)}' goes on", err=True)
        for i in range(len(s.runs)):
            results.setdefault(i, ("pending", 1))
    return results


def _finished(s, i: int, code: int, seconds: float, log_path: str) -> tuple:
    """The line of a run that ended and its (status, exit code); an entry that another process
    took meanwhile (its run refused with exit 2 as the lock was held) is "running elsewhere"."""
    from . import sweep as sw
    from .errors import EXIT_FAILURE, EXIT_INPUT, InputError
    from .io.runfolder import run_lock_holder
    what = f"{i:4d}  {sw.describe(s.keys, s.runs[i])}"
    holder = run_lock_holder(s.run_dir(i)) if code == EXIT_INPUT else None
    if holder is not None:
        click.echo(f"{what}: {ELSEWHERE} ({holder}): left to it")
        return ELSEWHERE, EXIT_FAILURE
    try:
        status = sw.entry_status(s, i)
    except InputError:
        status = "refused"
    click.echo(f"{what}: {status}" + (f" (exit {code})" if code != sw.STATUS_CODES.get(status) else "")
               + f"  {seconds:.1f} s" + _last_error(log_path, code))
    return status, code


def _last_error(log_path: str, code: int) -> str:
    """The last line of a failed run's log (its error), for the runner's line."""
    if code == 0:
        return ""
    try:
        with open(log_path, encoding="utf-8", errors="replace") as fh:
            lines = [ln.strip() for ln in fh.read().splitlines() if ln.strip()]
    except OSError:
        return ""
    return f"\n      {lines[-1]}  (log: {log_path})" if lines else f"  (log: {log_path})"


def _summary(s, results) -> None:
    from collections import Counter
    counts = Counter(status for status, _ in results.values())
    click.echo(f"{len(s.runs)} runs: " + ", ".join(f"{n} {status}" for status, n in sorted(counts.items())))


@sweep.command("status", context_settings=CONTEXT)
@click.argument("sweepdir", type=click.Path(file_okay=False))
@report_errors
def status(sweepdir):
    """Refresh every entry's status from its run.json into sweep.csv and print a table
    (a missing or edited sweep.csv is written anew from sweep.json; a sweep folder this user
    cannot write: the table only, with a warning). A running entry's t is its last output's;
    an entry whose start-up refused it shows 'refused' and why. Exit 2 when a run folder holds
    another run or an unreadable run.json (said on stderr, nothing changed)."""
    from . import sweep as sw
    from .errors import EXIT_INPUT
    s = sw.open_sweep(sweepdir, check_manifest=False)
    try:
        statuses, problems = sw.refresh(s)
    except OSError as exc:
        click.echo(f"warning: {s.manifest} not updated ({exc.strerror or exc}): the table is read from the "
                   "runs' run.json", err=True)
        statuses, problems = sw.read_statuses(s)
    click.echo(sw.format_table(sw.status_rows(s, statuses, problems)))
    for line in sw.refused_notes(s, statuses):
        click.echo(line)
    for i in sorted(problems):
        click.echo(f"error: {problems[i]}", err=True)
    if problems:
        sys.exit(EXIT_INPUT)


def _check_out(s, out: str) -> None:
    """``-o`` of collect/converge: a file in an existing folder, not one of the sweep's own files
    (sweep.csv, sweep.json, sweep.sbatch) or inside a run folder."""
    from . import sweep as sw
    from .errors import InputError
    path = os.path.realpath(out)
    folder = os.path.dirname(path)
    if not os.path.isdir(folder):
        raise InputError(f"-o {out}: the folder {folder} does not exist; expected a file in an existing folder")
    own = {os.path.realpath(os.path.join(s.dir, n)) for n in (sw.MANIFEST, sw.SPEC, sw.SBATCH, sw.LOCK)}
    runs = {os.path.realpath(s.run_dir(i)) for i in range(len(s.runs))}
    if path in own or any(path == r or path.startswith(r + os.sep) for r in runs):
        raise InputError(f"-o {out}: a file of the sweep itself ({os.path.relpath(path, os.path.realpath(s.dir))}); "
                         "expected a file outside its manifest and run folders (e.g. -o tidy.csv)")


@sweep.command("collect", context_settings=CONTEXT)
@click.argument("sweepdir", type=click.Path(file_okay=False))
@click.option("-o", "--out", "out", type=click.Path(dir_okay=False), required=True,
              help="The tidy CSV to write (atomically; not the sweep's own sweep.csv).")
@click.option("--file", "names", multiple=True, metavar="NAME",
              help="A CSV every run folder holds (e.g. bodies.csv, a gauge file, a 'measure --csv' output, either "
                   "--sep): its rows with the run's index and parameters in front (repeatable: a 'file' column says "
                   "which). A torn last row of a running run is left out; a NAME no run holds is exit 2.")
@report_errors
def collect(sweepdir, out, names):
    """One tidy CSV for pandas: a row per run (parameters, status, particles, steps, physical_time,
    runtime_s, us_per_particle_step; a running run's steps and time from its run.csv), or with
    --file the rows of each run's NAME (long format). A run folder holding another run, or an
    unreadable run.json: exit 2."""
    from . import sweep as sw
    from .io.atomic import write_text_atomic
    s = sw.open_sweep(sweepdir)
    _check_out(s, out)
    if names:
        table, missing = sw.file_table(s, list(names))
        if missing:
            click.echo(f"skipped ({len(missing)}, no such file): {', '.join(missing)}", err=True)
    else:
        table = sw.summary_table(s)
    write_text_atomic(out, sw.table_text(table))
    click.echo(f"{len(table) - 1} rows -> {out}")


@sweep.command("converge", context_settings=CONTEXT)
@click.argument("sweepdir", type=click.Path(file_okay=False))
@click.option("--file", "name", required=True, metavar="NAME",
              help="The CSV in each run folder that holds the signal (a gauge file, bodies.csv, a 'measure --csv' "
                   "output).")
@click.option("--column", required=True, metavar="COL", help="Its column to study (the unit may be left out: swlz).")
@click.option("--time-column", default=None, metavar="COL", help="Its time column (default: the one named time).")
@click.option("--where", "where", multiple=True, metavar="COL=VALUE",
              help="Only the rows with this value (repeatable), e.g. --where body=floating50 in bodies.csv.")
@click.option("--reference", type=click.Path(dir_okay=False, exists=True), default=None,
              help="A CSV of the reference signal (analytic or measured; ',' ';' or tab separated): each run's "
                   "error against it. Without it, each run's difference to the next finer run.")
@click.option("--ref-column", default=None, metavar="COL", help="The reference's column (default: --column).")
@click.option("--ref-time-column", default=None, metavar="COL",
              help="The reference's time column (default: the one named time).")
@click.option("--norm", type=click.Choice(["rms", "max", "end"]), default="rms", show_default=True,
              help="rms or max over the shared times, or the difference at the last shared time.")
@click.option("--tmin", type=FiniteFloat(), default=None, help="Score from this time [s].")
@click.option("--tmax", type=FiniteFloat(), default=None, help="Score up to this time [s].")
@click.option("--relative", is_flag=True, help="Divide by the same norm of the reference (or of the finer run).")
@click.option("-o", "--out", "out", type=click.Path(dir_okay=False), default=None,
              help="Also write the table as CSV (atomically).")
@report_errors
def converge(sweepdir, name, column, time_column, where, reference, ref_column, ref_time_column, norm, tmin, tmax,
             relative, out):
    """Error against resolution and run time of a sweep over dp: for each group of runs that differ
    only in dp, each completed run's error (against --reference) or difference to the next finer
    run, its wall time (run.json runtime_s) and the observed order (sphdvi/convergence.py)."""
    from . import convergence as cv
    from . import sweep as sw
    from .errors import InputError
    from .io.atomic import write_text_atomic
    s = sw.open_sweep(sweepdir)
    pairs = []
    for item in where:
        k, eq, v = item.partition("=")
        if not eq or not k.strip():
            raise InputError(f"--where {item}: expected COL=VALUE")
        pairs.append((k.strip(), v.strip()))
    ref = None
    if reference is not None:
        header, rows = sw.read_run_csv(reference, complete_only=False)
        ref = cv.series(header, rows, ref_column or column, reference, time_name=ref_time_column)
    groups = cv.group_levels(s.keys, s.runs)
    others = [k for k in s.keys if k != "dp"]
    table = [[*others, "index", "dp", "status", "particles", "runtime_s",
              ("error" if ref is not None else "diff_to_finer") + ("_relative" if relative else ""), "order"]]
    if out is not None:
        _check_out(s, out)
    for i in range(len(s.runs)):
        sw.entry_meta(s, i)             # a folder holding another run, an unreadable run.json: exit 2
    if not any(os.path.isfile(os.path.join(s.run_dir(i), name)) for i in range(len(s.runs))):
        raise InputError(f"--file {name}: no run folder of {s.dir} holds it (nothing to study); expected a file the "
                         "runs write, e.g. a gauge file (Gauges*.csv), bodies.csv, run.csv")
    skipped = []
    for values, idx in groups:
        dps, signals, metas = [], [], []
        for i in idx:
            meta = sw.entry_meta(s, i) or {}
            path = os.path.join(s.run_dir(i), name)
            sig = None
            if meta.get("status") != "completed":
                skipped.append(f"{os.path.basename(s.run_dir(i))} ({meta.get('status') or 'pending'})")
            elif not os.path.isfile(path):
                skipped.append(f"{os.path.basename(s.run_dir(i))} (no {name})")
            else:
                header, rows = sw.read_run_csv(path)
                sig = cv.series(header, rows, column, path, time_name=time_column, where=pairs)
            dps.append(float(s.runs[i][s.keys.index("dp")]))
            signals.append(sig)
            metas.append(meta)
        err, orders = cv.level_errors(dps, signals, norm, ref, tmin, tmax, relative)
        for k, i in enumerate(idx):
            meta = metas[k]
            table.append([*(values[o] for o in others), str(i), s.runs[i][s.keys.index("dp")],
                          str(meta.get("status") or "pending"), sw.csv_value(meta.get("particles")),
                          sw.csv_value(meta.get("runtime_s")), _fmt(err[k]), _fmt(orders[k])])
    if skipped:
        click.echo(f"left out ({len(skipped)}): {', '.join(skipped)}", err=True)
    click.echo(sw.format_table(table))
    if out is not None:
        write_text_atomic(out, sw.table_text(table))


def _fmt(v: float) -> str:
    return "" if v != v else f"{v:.6g}"
