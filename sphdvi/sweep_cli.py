"""``sphdvi sweep``: parameter sweeps and convergence studies (new, run, status, collect, converge), and
``sphdvi run --manifest SWEEPDIR/sweep.csv --index I`` (one entry, as a SLURM array task runs it).

Only click is imported at module level (``sphdvi --help`` stays fast); the logic is in
:mod:`sphdvi.sweep`.
"""
from __future__ import annotations

import os
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
              help="A CSV file whose header names the keys and whose rows are the runs (instead of --vary).")
@click.option("--set", "sets", multiple=True, metavar="KEY=VALUE",
              help="A --set every run gets (repeatable).")
@click.option("--tmax", type=FiniteFloat(min=0), default=None, help="Every run's --tmax [s].")
@click.option("--tout", type=FiniteFloat(min=0, min_open=True), default=None, help="Every run's --tout [s].")
@click.option("--threads", type=click.IntRange(min=1), default=1, show_default=True, help="Threads per run.")
@click.option("--time", "time_limit", default="24:00:00", show_default=True,
              help="SLURM wall-time limit of each array task ([D-]HH:MM:SS).")
@click.option("--throttle", type=click.IntRange(min=1), default=20, show_default=True,
              help="Array tasks at once on the cluster (sbatch --array=0-(N-1)%K).")
@report_errors
def new(case_xml, sweepdir, vary, table, sets, tmax, tout, threads, time_limit, throttle):
    """Expand a parameter space into one run folder per entry, a manifest and an sbatch script.

    Every key and value is checked as 'sphdvi run --set' (or --dp) checks it before anything
    is written (exit 2 naming the key). The same spec into the same folder again does nothing;
    another spec there is exit 2 (saying what differs).
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
    spec = sw.make_spec(case_xml, keys, rows, sets, tmax, tout, threads, time_limit, throttle)
    done = sw.create_sweep(sweepdir, spec)
    n = len(spec["runs"])
    if done == "unchanged":
        click.echo(f"{sweepdir} already holds this sweep ({n} runs): nothing to do")
        return
    if done == "updated":
        click.echo(f"{sweepdir}: the same sweep; {sw.SBATCH} written again for --time {time_limit} "
                   f"--throttle {throttle}")
        return
    dirs = sw.run_dir_name(0, n) + (f"..{sw.run_dir_name(n - 1, n)}" if n > 1 else "")
    click.echo(f"{n} run{'s' if n > 1 else ''} of {os.path.basename(case_xml)} ({', '.join(keys)}) in {sweepdir}: "
               f"{sw.MANIFEST}, {sw.SPEC}, {sw.SBATCH}, {dirs}")
    click.echo(f"run them with 'sbatch {os.path.join(sweepdir, sw.SBATCH)}' or 'sphdvi sweep run {sweepdir}'")


def run_manifest_entry(manifest, index, retry, threads, quiet, given) -> None:
    """``sphdvi run --manifest SWEEPDIR/sweep.csv --index I``: entry I with the sweep's settings
    into its folder, under its run lock (a second task on it: exit 2 naming the holder); run.json
    decides (:func:`sphdvi.sweep.entry_action`): completed -> exit 0 without running, interrupted
    or killed -> --resume, failed/diverged -> their exit code unless --retry (then --overwrite).
    The entry's status in sweep.csv is updated at the end.  ``given``: the run options that
    cannot go with --manifest (exit 2 when one was given)."""
    from . import sweep as sw
    from .cli import _run
    from .errors import InputError
    from .io.runfolder import run_lock
    from .simulation import _Stop
    bad = [name for name, value in given.items() if value]
    if bad:
        raise InputError(f"--manifest: not with {', '.join(bad)}: the sweep's spec gives the run's case and "
                         "options (sweep.json); expected --manifest, --index and optionally --retry, --threads, -q")
    if manifest is None or index is None:
        raise InputError("--manifest and --index go together: expected --manifest SWEEPDIR/sweep.csv --index I")
    sweep = sw.open_sweep(manifest, "--manifest")
    sw.check_index(sweep, index)
    rundir = sweep.run_dir(index)
    label = f"{os.path.basename(rundir)} ({sw.describe(sweep.keys, sweep.runs[index])})"
    with _Stop() as stop:
        try:
            with run_lock(rundir):
                action = sw.entry_action(rundir, retry)
                if action.kind == "done":
                    click.echo(f"{label}: {action.message}: nothing to do", err=True)
                    return
                if action.kind == "refuse":
                    click.echo(f"{label}: {action.message}", err=True)
                    sys.exit(action.exit_code)
                options = sw.entry_run_options(sweep, index, action)
                if not quiet:
                    click.echo(f"{label}: {action.message}", err=True)
                _run(threads=threads if threads is not None else sweep.spec.get("threads"), quiet=quiet,
                     stop=stop, **options)
        finally:
            sw.update_manifest(sweep, {index: sw.run_status(rundir)})


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
    one diverged, 2 when one was refused on bad input, 1 (failed, interrupted). SIGINT/SIGTERM
    stop the runs (each at its next step, resumable) and start no more: run it again to go on.
    """
    from . import sweep as sw
    s = sw.open_sweep(sweepdir)
    jobs = jobs or sw.default_jobs(int(s.spec.get("threads") or 1))
    results = _run_entries(s, jobs, retry)
    _summary(s, results)
    sys.exit(sw.sweep_exit_code(code for _, code in results.values()))


def _run_entries(s, jobs: int, retry: bool) -> dict:
    """The local runner: subprocesses (not a ProcessPoolExecutor) so that a signal reaches each run,
    which then stops cleanly, and a pool worker's death cannot take the others with it.  Returns
    {index: (status, exit code)} of every entry."""
    import signal
    import subprocess
    import time
    from . import sweep as sw
    statuses = sw.refresh(s)
    results, todo = {}, []
    for i in range(len(s.runs)):
        action = sw.entry_action(s.run_dir(i), retry)
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

    def on_signal(signum, frame):
        stopped.append(signum)
        for proc, _, _ in running.values():      # a terminal's SIGINT reached them already: harmless
            if proc.poll() is None:
                proc.send_signal(signum)

    old = {sig: signal.signal(sig, on_signal) for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
           if sig == signal.SIGINT or signal.getsignal(sig) != signal.SIG_IGN}
    try:
        while todo or running:
            while todo and len(running) < jobs and not stopped:
                i = todo.pop(0)
                log = open(os.path.join(s.dir, sw.LOGS, f"{os.path.basename(s.run_dir(i))}.log"), "a")
                cmd = [sys.executable, "-m", "sphdvi", "run", "--manifest", s.manifest, "--index", str(i), "-q"]
                log.write(f"$ sphdvi {' '.join(cmd[3:])}{' --retry' if retry else ''}\n")
                log.flush()
                proc = subprocess.Popen(cmd + (["--retry"] if retry else []), stdout=log, stderr=log, env=env,
                                        stdin=subprocess.DEVNULL)
                running[i] = (proc, time.monotonic(), log)
            if stopped:
                todo.clear()
            for i in [i for i, (p, _, _) in running.items() if p.poll() is not None]:
                proc, t0, log = running.pop(i)
                log.close()
                status = sw.run_status(s.run_dir(i))
                results[i] = (status, proc.returncode)
                click.echo(f"{i:4d}  {sw.describe(s.keys, s.runs[i])}: {status}" +
                           (f" (exit {proc.returncode})" if proc.returncode != sw.STATUS_CODES.get(status) else "")
                           + f"  {time.monotonic() - t0:.1f} s" + _last_error(log.name, proc.returncode))
            time.sleep(0.1)
    finally:
        for sig, handler in old.items():
            signal.signal(sig, handler)
    if stopped:
        click.echo(f"interrupted by {signal.Signals(stopped[0]).name}: the runs stopped are resumable, the others "
                   f"not started; 'sphdvi sweep run {s.dir}' goes on", err=True)
        for i in range(len(s.runs)):
            results.setdefault(i, ("pending", 1))
    return results


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
    (a missing or edited sweep.csv is written anew from sweep.json)."""
    from . import sweep as sw
    s = sw.open_sweep(sweepdir, check_manifest=False)
    statuses = sw.refresh(s)
    click.echo(sw.format_table(sw.status_rows(s, statuses)))


@sweep.command("collect", context_settings=CONTEXT)
@click.argument("sweepdir", type=click.Path(file_okay=False))
@click.option("-o", "--out", "out", type=click.Path(dir_okay=False), required=True,
              help="The tidy CSV to write (atomically).")
@click.option("--file", "names", multiple=True, metavar="NAME",
              help="A CSV every run folder holds (e.g. bodies.csv, a gauge file, a 'measure --csv' output): its "
                   "rows with the run's index and parameters in front (repeatable: a 'file' column says which).")
@report_errors
def collect(sweepdir, out, names):
    """One tidy CSV for pandas: a row per run (parameters, status, particles, steps, physical_time,
    runtime_s, us_per_particle_step), or with --file the rows of each run's NAME (long format)."""
    from . import sweep as sw
    from .errors import InputError
    from .io.atomic import write_text_atomic
    s = sw.open_sweep(sweepdir)
    folder = os.path.dirname(os.path.abspath(out))
    if not os.path.isdir(folder):
        raise InputError(f"-o {out}: the folder {folder} does not exist; expected a file in an existing folder")
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
        header, rows = sw.read_run_csv(reference)
        ref = cv.series(header, rows, ref_column or column, reference, time_name=ref_time_column)
    groups = cv.group_levels(s.keys, s.runs)
    others = [k for k in s.keys if k != "dp"]
    table = [[*others, "index", "dp", "status", "particles", "runtime_s",
              ("error" if ref is not None else "diff_to_finer") + ("_relative" if relative else ""), "order"]]
    skipped = []
    for values, idx in groups:
        dps, signals, metas = [], [], []
        for i in idx:
            meta = sw.run_info(s.run_dir(i)) or {}
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
        folder = os.path.dirname(os.path.abspath(out))
        if not os.path.isdir(folder):
            raise InputError(f"-o {out}: the folder {folder} does not exist; expected a file in an existing folder")
        write_text_atomic(out, sw.table_text(table))


def _fmt(v: float) -> str:
    return "" if v != v else f"{v:.6g}"
