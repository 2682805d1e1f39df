"""``sphdvi measure``: gauges, elevation, forces and body motion from a run folder.

Only click is imported at module level: numpy, h5py and numba are imported
inside the commands, so ``sphdvi --help`` stays fast.
"""
from __future__ import annotations

import os

import click

from ..cli_errors import FiniteFloat, report_errors

CONTEXT = {"help_option_names": ["-h", "--help"], "max_content_width": 100}

# the image formats matplotlib's savefig writes (told by the file's extension)
PLOT_FORMATS = ("png", "pdf", "svg", "svgz", "jpg", "jpeg", "tif", "tiff", "webp", "eps", "ps", "pgf")


SEP_HELP_POINTS = "Separator; ';' writes MeasureTool's layout (PosX/PosY/PosZ rows, Part column)."
SEP_HELP = "Separator; ';' writes MeasureTool's layout (a Part column, ';' between the columns)."


def _output_options(fn=None, *, sep_help: str = SEP_HELP_POINTS):
    """The options every measure command shares (--first/--last/--every, --csv, --sep, --plot);
    ``@_output_options(sep_help=SEP_HELP)`` for a command whose table has no rows of points."""
    if fn is None:
        return lambda f: _output_options(f, sep_help=sep_help)
    fn = click.option("--plot", "plot", type=click.Path(dir_okay=False), default=None,
                      help="Also draw the series into this PNG file (needs matplotlib).")(fn)
    fn = click.option("--sep", type=click.Choice([",", ";"]), default=",", show_default=True, help=sep_help)(fn)
    fn = click.option("--csv", "csv_path", type=click.Path(dir_okay=False), default=None,
                      help="Write the table to this file (default: stdout).")(fn)
    fn = click.option("--every", type=click.IntRange(min=1), default=1, show_default=True,
                      help="Use every N-th output time.")(fn)
    fn = click.option("--last", type=click.IntRange(min=0), default=None, help="Last output index.")(fn)
    fn = click.option("--first", type=click.IntRange(min=0), default=0, show_default=True,
                      help="First output index.")(fn)
    return fn


def _check_outputs(csv_path, plot, outdir=None):
    """--csv and --plot are checked before any work: their folder must exist (a missing one
    is a typo more often than a wish), --plot needs an image extension, and neither may name
    a file of the run in OUTDIR (or of any run or case folder): :func:`_run_file_clash`."""
    for path, hint in ((csv_path, "'--csv'"), (plot, "'--plot'")):
        if path:
            folder = os.path.dirname(os.path.abspath(path))
            if os.path.exists(folder) and not os.path.isdir(folder):
                raise click.BadParameter(f"{path}: {folder} is a file, not a folder", param_hint=hint)
            if not os.path.isdir(folder):
                raise click.BadParameter(f"{path}: the folder {folder} does not exist; create it first",
                                         param_hint=hint)
            clash = _run_file_clash(path, outdir)
            if clash:
                raise click.BadParameter(f"{path} is {clash}: measure does not overwrite it; expected another "
                                         "file name", param_hint=hint)
    if plot:
        ext = os.path.splitext(plot)[1].lower().lstrip(".")
        if ext not in PLOT_FORMATS:
            raise click.BadParameter(f"{plot}: expected an image file name ending in "
                                     f"{', '.join('.' + e for e in PLOT_FORMATS[:4])}, ...", param_hint="'--plot'")


def _run_file_clash(path, outdir=None):
    """What ``path`` is when it is a file sphdvi owns (None otherwise): in OUTDIR, or in a
    folder holding a run's results or a case (.h5), the files a run or gencase writes there
    (particles.vtkhdf, restart.h5, <case>.h5, run.json/csv/log, bodies.csv, links.csv,
    Gauges*.csv, ...); anywhere, an existing HDF5 file (.h5, .vtkhdf).  DualSPHysics's tools
    suffix what -savecsv names (NAME_<Var>.csv), so they never hit Part_XXXX.bi4 or Run.csv."""
    from ..io.runfolder import RUN_OUTPUT_FILES, earlier_results, other_case_outputs
    folder = os.path.realpath(os.path.dirname(os.path.abspath(path)))
    name = os.path.basename(path)
    hdf5 = name.lower().endswith((".h5", ".vtkhdf"))
    case_files = other_case_outputs(folder, "")          # every case's gencase outputs there
    own = (outdir is not None and folder == os.path.realpath(outdir)) or case_files or earlier_results(folder)
    gauge = name.startswith("Gauges") and "_" in name and name.endswith(".csv")
    if own and (name in RUN_OUTPUT_FILES or gauge or hdf5 or name in case_files):
        return f"a file of the run or case in {os.path.dirname(path) or '.'}"
    if hdf5 and os.path.isfile(path):
        return "an HDF5 file (a run's or a case's?)"
    return None


def _warn_y_in_2d(run, pts, option):
    """In a 2D case the kernel uses x and z only: a y off the case's plane is ignored
    (as in DualSPHysics's MeasureTool on a 2D case); say so."""
    if not run.spec.is2d:
        return
    import numpy as np
    y0 = float(run.data["constants"].get("posy2d") or 0.0)
    y = np.asarray(pts)[:, 1]          # 0 also where the point was given without y (x,z or x)
    off = np.flatnonzero((np.abs(y - y0) > 1e-9 * max(1.0, abs(y0))) & (y != 0.0))
    if off.size:
        i = int(off[0])
        click.echo(f"warning: {option}: the case is 2D (the plane y = {y0:g}); the y of {off.size} point(s) is "
                   f"ignored (point {i}: y = {float(pts[i][1]):g})", err=True)


def _warn_outside_domain(run, pts, option, axes=(0, 1, 2)):
    """A point outside the case's simulation domain reads no fluid (an empty column): say so, as
    gencase says of its gauges.  ``axes``: the coordinates compared (x, y for --at); y not in 2D."""
    import numpy as np
    dom = run.data.get("domain") or {}
    if "posmin" not in dom:
        return
    lo, hi = np.asarray(dom["posmin"], float), np.asarray(dom["posmax"], float)
    axes = [a for a in axes if not (run.spec.is2d and a == 1)]
    p = np.asarray(pts, float).reshape(-1, 3)
    tol = 1e-9 * max(1.0, float(np.abs(np.r_[lo, hi]).max()))
    out = np.flatnonzero(np.any((p[:, axes] < lo[axes] - tol) | (p[:, axes] > hi[axes] + tol), axis=1))
    if out.size:
        i = int(out[0])
        click.echo(f"warning: {option}: {out.size} point(s) outside the simulation domain {lo.tolist()} .. "
                   f"{hi.tolist()} read no fluid (point {i}: {np.round(p[i], 9).tolist()})", err=True)


def _emit(table, csv_path, sep, plot):
    from .tables import plot_table, write_table
    write_table(table, csv_path, sep=sep)
    if plot:
        plot_table(table, plot)
    if csv_path:
        click.echo(f"wrote {csv_path} ({table.time.shape[0]} times, {len(table.names)} columns)"
                   + (f" and {plot}" if plot else ""), err=True)


def _points_option(value, param_hint, ncoord=3, is2d=None):
    """The points of --points / --at (:func:`.post.parse_points`); read once before the run
    (its syntax) and again with the case's dimension (``is2d``) once the run is read."""
    from .post import parse_points
    try:
        return parse_points(value, is2d=is2d, ncoord=ncoord)
    except (ValueError, OSError) as exc:
        raise click.BadParameter(str(exc), param_hint=param_hint) from None


def _vector(text, n, param_hint):
    """``n`` comma-separated finite numbers (--point, --axis)."""
    import math
    try:
        vals = [float(v) for v in str(text).replace(";", ",").split(",") if v.strip()]
    except ValueError:
        vals = []
    if len(vals) != n:
        raise click.BadParameter(f"'{text}': expected {n} comma-separated numbers", param_hint=param_hint)
    if not all(math.isfinite(v) for v in vals):
        raise click.BadParameter(f"'{text}': the numbers must be finite", param_hint=param_hint)
    return vals


def _run(outdir):
    from .post import RunOutput
    return RunOutput(outdir)


@click.group(context_settings=CONTEXT)
def measure():
    """Measure a run: kernel-interpolated gauges, free-surface elevation, forces, bodies.

    \b
    Examples:
      sphdvi measure points OUT --points "0.5,0,0.1;1,0,0.1" --vars vel,press
      sphdvi measure elevation OUT --at "0.2;1.0" --csv elevation.csv --plot elevation.png
      sphdvi measure forces OUT --mk 11 --point 2,0,0.2
      sphdvi measure bodies OUT --csv bodies.csv
    """


@measure.command(context_settings=CONTEXT)
@click.argument("outdir", type=click.Path(exists=True, file_okay=False))
@click.option("--points", "points", required=True, metavar='FILE|"x,y,z;..."',
              help="Points [m]: 'x,y,z;x,y,z' (2D: 'x,z' allowed) or a file with one point a line "
                   "(MeasureTool POINTS/POINTSLIST/POINTSENDLIST files too).")
@click.option("--vars", "variables", default="vel,rhop,press", show_default=True,
              help="Comma-separated: vel, rhop, press, mass, vol (kernel averages of the particles' mass and "
                   "volume m/rho), kcorr (the kernel sum sum_b V_b W, MeasureTool's: about 1 inside the water, "
                   "0.5 at a flat surface).")
@click.option("--kclimit", type=FiniteFloat(min=0), default=0.5, show_default=True,
              help="Kernel-sum threshold below which a point has no value (empty field).")
@click.option("--correction", type=click.Choice(["shepard", "linear"]), default="shepard", show_default=True,
              help="shepard: normalised by the kernel sum (MeasureTool); linear: first-order "
                   "MLS correction, exact for linear fields.")
@click.option("--trackmk", default=None, metavar="MK[,MK...]",
              help="The points move with these boundary or floating particles (Mk, as in particles.vtkhdf), "
                   "e.g. the walls of a moving tank: give them where they are at the start (MeasureTool -trackmk).")
@click.option("--trackmkbound", default=None, metavar="MKBOUND[,...]",
              help="As --trackmk, by the case's mkbound.")
@_output_options
@report_errors
def points(outdir, points, variables, kclimit, correction, trackmk, trackmkbound, first, last, every, csv_path,
           sep, plot):
    """Kernel-interpolated fluid values at points, at every output time.

    Points closer than 1.5h to a boundary (DBC) particle are named in a warning:
    DBC keeps the fluid about 1.5h away from walls, so values there are unreliable.
    With --trackmk the points move rigidly with those particles (a pressure sensor
    on the wall of a moving tank).
    """
    _check_outputs(csv_path, plot, outdir)
    track = None
    if trackmk is not None and trackmkbound is not None:
        raise click.UsageError("give at most one of --trackmk and --trackmkbound")
    if trackmk is not None or trackmkbound is not None:
        from .post import parse_mk_list
        try:
            track = (parse_mk_list(trackmk if trackmk is not None else trackmkbound), trackmkbound is not None)
        except ValueError as exc:
            raise click.BadParameter(str(exc), param_hint="'--trackmk'" if trackmk is not None
                                     else "'--trackmkbound'") from None
    pts = _points_option(points, "'--points'")
    from .post import UNITS, measure_points
    names = list(dict.fromkeys(v.strip().lower() for v in variables.split(",") if v.strip()))   # once each
    bad = [v for v in names if v not in UNITS]
    if bad or not names:
        raise click.BadParameter(f"unknown variable(s) {', '.join(bad) or '(none)'}; expected some of "
                                 f"{', '.join(UNITS)}", param_hint="'--vars'")
    run = _run(outdir)
    if not run.spec.is2d:              # x,z was read as a 2D point: not in a 3D case
        pts = _points_option(points, "'--points'", is2d=False)
    _warn_y_in_2d(run, pts, "--points")
    if track is None:                  # tracked points move with their particles
        _warn_outside_domain(run, pts, "--points")
    table, near = measure_points(run, pts, names, kclimit=kclimit, order=1 if correction == "linear" else 0,
                                 first=first, last=last, every=every, track=track)
    for i, d, t in near:
        p = pts[i]
        click.echo(f"warning: point {i} ({p[0]:g}, {p[1]:g}, {p[2]:g}) is {d:.3g} m from a boundary particle "
                   f"(< 1.5h = {1.5 * run.spec.h:.3g} m) at t={t:g} s: values near DBC walls are unreliable",
                   err=True)
    _emit(table, csv_path, sep, plot)


@measure.command(context_settings=CONTEXT)
@click.argument("outdir", type=click.Path(exists=True, file_okay=False))
@click.option("--at", "at", required=True, metavar='"x[,y];..."',
              help="Horizontal positions [m]: 'x;x' (2D) or 'x,y;x,y' (3D), or a file.")
@click.option("--threshold", type=FiniteFloat(min=0, min_open=True), default=None,
              help="Kernel-sum threshold of the surface, no unit: about 1 inside the water, 0 outside "
                   "(default 0.5 in 3D, 0.4 in 2D).")
@click.option("--dz", type=FiniteFloat(min=0, min_open=True), default=None,
              help="Sampling step along the vertical [m] (default dp/4).")
@_output_options
@report_errors
def elevation(outdir, at, threshold, dz, first, last, every, csv_path, sep, plot):
    """Free-surface elevation and water depth along verticals (MeasureTool -elevation).

    Elevation: where the kernel sum sum_b m_b/rho_b W first drops below the
    threshold going up. Depth: elevation minus the bottom (the top boundary
    particle below the surface, plus dp/2).
    """
    _check_outputs(csv_path, plot, outdir)
    if threshold is not None and threshold >= 1.0:
        # inside the water the kernel sum is about 1: a level at or above it is never crossed
        click.echo(f"warning: --threshold {threshold:g}: the kernel sum inside the water is about 1, so the surface "
                   "is found only below that (default 0.4 in 2D, 0.5 in 3D); expect empty columns", err=True)
    xy = _points_option(at, "'--at'", ncoord=2)
    from .post import measure_elevation
    run = _run(outdir)
    if not run.spec.is2d:              # x alone was read as a 2D position: not in a 3D case
        xy = _points_option(at, "'--at'", ncoord=2, is2d=False)
    _warn_y_in_2d(run, xy, "--at")
    _warn_outside_domain(run, xy, "--at", axes=(0, 1))
    _emit(measure_elevation(run, xy, threshold=threshold, dz=dz, first=first, last=last, every=every),
          csv_path, sep, plot)


@measure.command(context_settings=CONTEXT)
@click.argument("outdir", type=click.Path(exists=True, file_okay=False))
@click.option("--mk", "mk", default=None, metavar="N[,M]", help="Global mk of the particles (mkbound+fluidcount+1).")
@click.option("--mkbound", "mkbound", default=None, metavar="N[,M]", help="Or their mkbound.")
@click.option("--point", "point", default=None, metavar="x,y,z",
              help="Moment about this point [m] (default: the centre of the selected particles).")
@click.option("--axis", "axis", default=None, metavar="x1,y1,z1,x2,y2,z2",
              help="Moment about the axis through two points [m] (projected on it).")
@click.option("--no-visco", is_flag=True, help="Pressure term only (no viscous force).")
@_output_options(sep_help=SEP_HELP)
@report_errors
def forces(outdir, mk, mkbound, point, axis, no_visco, first, last, every, csv_path, sep, plot):
    """Fluid force and moment on boundary or floating particles (ComputeForces).

    The SPH force of the fluid on the selected particles, recomputed from each
    snapshot with the momentum equation (pressure, tensile correction for the
    cubic kernel, viscosity). Columns time,fx,fy,fz,mx,my,mz; per metre of width in 2D.
    """
    from .post import measure_forces, parse_mk_list
    _check_outputs(csv_path, plot, outdir)
    if (mk is None) == (mkbound is None):
        raise click.UsageError("give exactly one of --mk or --mkbound")
    try:
        mks = parse_mk_list(mk if mk is not None else mkbound)
    except ValueError as exc:
        raise click.BadParameter(str(exc), param_hint="'--mk'" if mk is not None else "'--mkbound'") from None
    centre = _vector(point, 3, "'--point'") if point else None
    ax = None
    if axis:
        v = _vector(axis, 6, "'--axis'")
        ax = (v[:3], v[3:])
    run = _run(outdir)
    table = measure_forces(run, mks, mkbound=mkbound is not None, point=centre, axis=ax,
                           viscosity=not no_visco, first=first, last=last, every=every)
    _emit(table, csv_path, sep, plot)


@measure.command(context_settings=CONTEXT)
@click.argument("outdir", type=click.Path(exists=True, file_okay=False))
@_output_options(sep_help=SEP_HELP)
@report_errors
def bodies(outdir, first, last, every, csv_path, sep, plot):
    """Body motion and loads per body (FloatingInfo), and link forces.

    Body-only runs: from bodies.csv/links.csv.  SPH runs: derived from the
    floating particles of each snapshot (centre, surge/sway/heave, roll/pitch/
    yaw [deg], linear and angular velocity, fluid force and torque about the
    centre), with the contact force and torque and the link forces taken from
    the run's bodies.csv/links.csv at the snapshot times (empty without them).
    """
    from .post import measure_bodies
    _check_outputs(csv_path, plot, outdir)
    _emit(measure_bodies(outdir, first=first, last=last, every=every), csv_path, sep, plot)
