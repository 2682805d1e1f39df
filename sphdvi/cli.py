"""The ``sphdvi`` command line: a thin click layer over the library.

Nothing heavy is imported at start-up (``sphdvi --help`` must not import numba);
each command imports what it needs. User errors print ``file:line: element:
message`` and exit 2 without a traceback; a diverged run exits 3.
"""
from __future__ import annotations

import os
import sys

import click

from ._version import __version__
from .cli_errors import FiniteFloat, report_errors

os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

CONTEXT = {"help_option_names": ["-h", "--help"], "max_content_width": 100}


def print_warnings(warnings) -> None:
    for w in warnings:
        click.echo(w, err=True)


def _user_warning_line(message, category, filename, lineno, line=None, _default=None):
    """``warning: message`` for the library's UserWarnings (a user's case, not a code
    location); Python's usual form for the rest."""
    if issubclass(category, UserWarning):
        return f"warning: {message}\n"
    return _default(message, category, filename, lineno, line)


@click.group(context_settings=CONTEXT)
@click.version_option(__version__, "--version", prog_name="sphdvi")
def main():
    """sphdvi: DualSPHysics-style SPH coupled to a Chrono-style DVI multibody solver.

    \b
    Typical use:
      sphdvi gencase cases/dambreak2d/CaseDambreakVal2D_Def.xml -o out/dambreak2d
      sphdvi run out/dambreak2d --tmax 0.5
      sphdvi measure points out/dambreak2d --points "0.5,0,0.1" --vars vel,press

    \b
    Exit codes of every command: 0 success, 1 runtime failure or interruption
    (SIGINT, SIGTERM, SIGHUP), 2 bad input, 3 a run that diverged.
    """
    import functools
    import warnings
    if not isinstance(warnings.formatwarning, functools.partial):
        warnings.formatwarning = functools.partial(_user_warning_line, _default=warnings.formatwarning)


@main.command(context_settings=CONTEXT)
@click.argument("case_xml", type=click.Path(dir_okay=False))
@click.option("-o", "--out", "outdir", type=click.Path(file_okay=False), default=None,
              help="Output folder (default: ./<casename>_out).")
@click.option("--max-nodes", type=click.IntRange(min=1), default=200_000_000, show_default=True,
              help="Refuse drawing domains with more lattice nodes than this.")
@click.option("--dp", type=FiniteFloat(min=0, min_open=True), default=None,
              help="Particle spacing [m], overriding <definition dp> (default: the case's).")
@click.option("--overwrite", is_flag=True,
              help="Write into an OUT that holds a run's results: they are deleted (a run of another case).")
@click.option("-q", "--quiet", is_flag=True, help="Print only warnings and errors.")
@report_errors
def gencase(case_xml, outdir, max_nodes, dp, overwrite, quiet):
    """Turn a DualSPHysics case file into particles, like GenCase.

    Writes OUT/<casename>.h5 (particles, constants, parameters, bodies, links,
    motions, materials, gauges and the source XML) and OUT/<casename>_All.vtp
    (for ParaView), and prints a GenCase-like summary.
    """
    from .case.gencase import build_case, summary, write_outputs
    from .case.reader import case_name_from_path
    from .errors import CaseError
    if not os.path.isfile(case_xml):
        raise CaseError("case file not found", file=case_xml, expected="an existing XML case file")
    from .io.runfolder import (check_new_run_folder, check_other_case, clear_earlier_results, delete_files,
                               run_lock)
    if outdir is None:
        outdir = f"{case_name_from_path(case_xml)}_out"
    with run_lock(outdir, "gencase"):       # no run writes into OUT meanwhile
        check_new_run_folder(outdir, overwrite, command="gencase")
        others = check_other_case(outdir, case_name_from_path(case_xml), overwrite)
        result = build_case(case_xml, outdir, max_nodes=max_nodes, dp=dp)
        # what --overwrite replaces goes only once the case is built (bad input deletes nothing)
        delete_files(outdir, others)
        clear_earlier_results(outdir)
        files = write_outputs(result, outdir)
    print_warnings(result.warnings)
    if not quiet:
        click.echo(summary(result))
        click.echo("Files: " + ", ".join(files))


@main.command(context_settings=CONTEXT)
@click.argument("source", type=click.Path(), required=False)
@click.option("-o", "--out", "outdir", type=click.Path(file_okay=False), default=None,
              help="Output folder (default: SOURCE when it is a gencase output, else ./<casename>_out).")
@click.option("--tmax", type=FiniteFloat(min=0), default=None,
              help="Simulated time [s] (default: the case's TimeMax; not with a --set TimeMax of another value).")
@click.option("--tout", type=FiniteFloat(min=0, min_open=True), default=None,
              help="Output interval [s] (default: the case's TimeOut or <special><timeout>; not with a --set "
                   "TimeOut of another value).")
@click.option("--threads", type=click.IntRange(min=1), default=None,
              help="Threads (default: SLURM_CPUS_PER_TASK or the CPU affinity).")
@click.option("--set", "sets", multiple=True, metavar="KEY=VALUE",
              help="Override an execution parameter, e.g. --set Visco=0.05 (repeatable): any <parameters> key "
                   "(case-sensitive, as in the XML) and CFLnumber; not the other <constantsdef> constants, "
                   "the DomainFixed* keys or nested keys (<special>, gauges), which shape what gencase draws "
                   "(edit the XML). A file of ViscoTime or DtFixedFile is relative to the current directory "
                   "(in the XML: to the case's folder).")
@click.option("--resume", is_flag=True,
              help="Continue an interrupted run from its last output, with the --tmax/--tout/--set it was "
                   "started with (--tmax may be raised to extend it).")
@click.option("--overwrite", is_flag=True,
              help="Start a new run into an OUT that holds an earlier run's results: they are deleted first, "
                   "with what 'sphdvi export' made of them in OUT's sub-folders.")
@click.option("--dp", type=FiniteFloat(min=0, min_open=True), default=None,
              help="Particle spacing [m]. With a case XML: override <definition dp> (gencase runs with it). "
                   "With a gencase folder or --resume, where gencase does not run, only the case's own dp is "
                   "accepted.")
@click.option("-q", "--quiet", is_flag=True,
              help="No progress bar or lines, no summary; warnings and errors still print.")
@click.option("--manifest", type=click.Path(dir_okay=False), default=None,
              help="Run one entry of a sweep ('sphdvi sweep new'): SWEEPDIR/sweep.csv, with --index; instead of "
                   "SOURCE, -o, --set, --dp, --tmax, --tout. A completed entry is not run again, an interrupted "
                   "one resumes.")
@click.option("--index", type=click.IntRange(min=0), default=None, help="The entry of --manifest (0, 1, ...).")
@click.option("--retry", is_flag=True, help="With --manifest: run a failed or diverged entry again from the start.")
@report_errors
def run(source, outdir, tmax, tout, threads, sets, resume, overwrite, dp, quiet, manifest, index, retry):
    """Run a case: SOURCE is a case XML (gencase runs first) or a gencase output folder.

    \b
    Outputs in OUT: particles.vtkhdf (one temporal VTKHDF file), run.json,
    run.log, run.csv, restart.h5; cases with bodies write bodies.csv and links.csv,
    runs that exclude fluid particles excluded.csv (one row per particle),
    cases with <special><savedt> DtInfo.csv (and DtAllInfo.csv); <special>
    <outputparts> chooses the particles particles.vtkhdf holds.
    A new run into an OUT holding an earlier run's results needs --overwrite;
    a run holds OUT/.sphdvi.lock while it runs (a second run into OUT is
    refused). particles.vtkhdf can be read (ParaView, measure, export) while
    the run writes it. run.json status: running (started, not ended; also
    what a SIGKILLed run leaves), completed, diverged, interrupted, failed.
    Progress: a bar on a terminal, else a line every 30 s (t, steps, dt,
    particles, wall, eta).
    Exit codes: 0 completed, 1 failed or interrupted (SIGINT, SIGTERM, SIGHUP:
    resumable), 2 bad input, 3 diverged.
    """
    from .errors import InputError
    from .simulation import _Stop
    if manifest is not None or index is not None or retry:     # a sweep's entry (sphdvi/sweep_cli.py)
        from .sweep_cli import run_manifest_entry
        return run_manifest_entry(manifest, index, retry, threads, quiet, {
            "SOURCE": source, "-o": outdir, "--set": sets, "--dp": dp is not None, "--tmax": tmax is not None,
            "--tout": tout is not None, "--resume": resume, "--overwrite": overwrite})
    if source is None:
        raise click.UsageError("Missing argument 'SOURCE' (a case XML or a gencase output folder; or --manifest "
                               "with --index).")
    if resume and overwrite:
        raise InputError("--resume and --overwrite: give one (--resume continues the run in OUT, --overwrite "
                         "deletes its results and starts again)")
    # SIGTERM/SIGINT from here on end the run cleanly (status 'interrupted'), start-up included
    with _Stop() as stop:
        _run(source, outdir, tmax, tout, threads, sets, resume, overwrite, dp, quiet, stop)


def _run(source, outdir, tmax, tout, threads, sets, resume, overwrite, dp, quiet, stop, hint=None):
    """OUT from SOURCE and -o, locked for the command's life (:func:`~sphdvi.io.runfolder.run_lock`:
    a second run into it is refused), then :func:`_run_locked`.  ``hint``: rewrites the message of
    a run that did not complete (a sweep's entry: its advice names the sweep's command)."""
    from .errors import InputError
    from .io.runfolder import run_command, run_lock
    is_xml = os.path.isfile(source) and source.lower().endswith(".xml")
    if outdir is None and is_xml:
        from .case.reader import case_name_from_path
        outdir = f"{case_name_from_path(source)}_out"
    elif outdir is None and os.path.isdir(source):
        outdir = source
    if outdir is None or not (is_xml or os.path.isdir(source)):
        raise InputError(f"{source}: not a case XML file or a gencase output folder")
    if resume and not os.path.isdir(outdir):
        raise InputError(f"--resume: {outdir} does not exist: there is no run to continue; start one without "
                         f"--resume: {run_command(source, outdir, tmax=tmax, tout=tout, sets=sets)}")
    with run_lock(outdir):
        _run_locked(source, outdir, tmax, tout, threads, sets, resume, overwrite, dp, quiet, stop, hint)


def _run_locked(source, outdir, tmax, tout, threads, sets, resume, overwrite, dp, quiet, stop, hint=None):
    from .errors import InputError
    from .io.runfolder import (SetAside, case_outputs, check_new_run_folder, check_other_case, earlier_exports,
                               earlier_results, restored_on_bad_input)
    from .simulation import find_case_file, run as run_case
    drawn_dp = None      # --dp where no gencase runs: it must be the case's dp
    set_aside = None     # with --overwrite: what the new gencase and run replace, put back on bad input
    if os.path.isfile(source) and source.lower().endswith(".xml"):
        from .case.gencase import build_case, write_outputs
        from .case.reader import case_name_from_path
        if resume:
            case_h5 = find_case_file(outdir)
            _check_resume_source(source, case_h5, outdir)
            drawn_dp = dp
        else:
            check_new_run_folder(outdir, overwrite)     # before gencase writes into it
            name = case_name_from_path(source)
            replaced = check_other_case(outdir, name, overwrite) + earlier_results(outdir) + earlier_exports(outdir)
            if os.path.isdir(outdir):
                set_aside = SetAside(outdir, replaced + (case_outputs(outdir, name) if replaced else []))
            with restored_on_bad_input(set_aside):
                result = build_case(source, outdir, dp=dp)
            print_warnings(result.warnings)
            case_h5 = write_outputs(result, outdir)[0]
    elif os.path.isdir(source):
        case_h5 = find_case_file(source)
        outdir = outdir or source
        drawn_dp = dp
    else:
        raise InputError(f"{source}: not a case XML file or a gencase output folder")
    result = run_case(case_h5, outdir, tmax=tmax, tout=tout, threads=threads, sets=sets, resume=resume,
                      quiet=quiet, expect_dp=drawn_dp, overwrite=overwrite, stop=stop, set_aside=set_aside)
    if result.status != "completed":
        click.echo(f"{result.status}: {hint(result.message) if hint else result.message}", err=True)
    elif not quiet:
        click.echo(f"completed: t = {result.physical_time:.6g} s, {result.steps} steps, "
                   f"{result.runtime_s:.2f} s of time stepping -> {outdir}", err=True)
    sys.exit(result.exit_code)


def _check_resume_source(case_xml: str, case_h5: str, outdir: str) -> None:
    """``run CASE.xml --resume -o OUT``: the run in OUT goes on with the case gencase drew then, so
    CASE.xml must be that case's file as it was (another case, or an edited file, resumed silently
    with the old case before)."""
    from .case.reader import case_name_from_path
    from .errors import InputError
    from .io.casefile import read_case_h5
    name = case_name_from_path(case_xml)
    drawn = os.path.basename(case_h5)[:-3]
    if drawn != name:
        raise InputError(f"--resume: {outdir} holds a run of the case '{drawn}' ({case_h5}), not of {case_xml} "
                         f"('{name}'); expected that case's file, or 'sphdvi run {outdir} --resume'")
    with open(case_xml, "rb") as fh:
        raw = fh.read()
    try:                                   # decoded as gencase reads it
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        text = raw.decode("latin-1")
    if read_case_h5(case_h5)["source_xml"].strip() != text.strip():
        raise InputError(f"--resume: {case_xml} has changed since gencase drew the case in {outdir}, and a resumed "
                         f"run goes on with the case as drawn then; expected 'sphdvi run {outdir} --resume' to go on "
                         "with it, or a new run of the edited case with --overwrite or another -o")


@main.command(context_settings=CONTEXT)
@click.argument("outdir", type=click.Path(exists=True, file_okay=False))
@click.option("--format", "fmt", type=click.Choice(["vtp"]), default="vtp", show_default=True,
              help="Output format.")
@click.option("--dir", "subdir", default=None,
              help="Folder to write to: relative paths are taken inside OUTDIR, absolute ones as given; "
                   "created when missing (default OUTDIR/vtp, or OUTDIR/iso).")
@click.option("--isosurface", is_flag=True,
              help="Write the free surface (kernel-sum isosurface) of every output time instead: "
                   "Iso_XXXX.vtp + isosurface.pvd (needs vtk).")
@click.option("--iso-spacing", type=FiniteFloat(min=0, min_open=True), default=None,
              help="Isosurface grid spacing [m] (default dp/2).")
@click.option("--iso-threshold", type=FiniteFloat(min=0, min_open=True), default=None,
              help="Kernel-sum level of the surface, no unit (default 0.5 in 3D, 0.4 in 2D).")
@report_errors
def export(outdir, fmt, subdir, isosurface, iso_spacing, iso_threshold):
    """Export particles.vtkhdf as Part_XXXX.vtp files and a .pvd for older ParaView."""
    from .io.export import export_vtp
    if isosurface:
        from .measure.isosurface import export_isosurface
        files = export_isosurface(outdir, subdir or "iso", spacing=iso_spacing, threshold=iso_threshold)
        click.echo(f"wrote {len(files) - 1} isosurface .vtp files and {files[-1]}")
        return
    files = export_vtp(outdir, subdir or "vtp")
    click.echo(f"wrote {len(files) - 1} .vtp files and {files[-1]}")


from .measure.cli import measure as _measure  # noqa: E402
main.add_command(_measure)
from .sweep_cli import sweep as _sweep  # noqa: E402
main.add_command(_sweep)

if __name__ == "__main__":  # pragma: no cover
    main()
