"""``sphdvi export``: particles.vtkhdf → Part_XXXX.vtp + particles.pvd (ParaView ≤ 5.11)."""
from __future__ import annotations

import os

from ..errors import InputError
from .atomic import make_folder
from .vtkhdf import read_step, step_times
from .vtkxml import write_pvd, write_vtp_points


def export_dir(outdir: str, subdir: str) -> str:
    """The folder ``--dir`` names: a relative path is taken inside OUTDIR (``vtp`` is
    OUTDIR/vtp, ``../x`` is next to it), an absolute one as it is; it need not exist.
    A path that exists and is not a folder is an InputError."""
    dest = os.path.normpath(os.path.join(outdir, os.path.expanduser(subdir)))
    if os.path.exists(dest) and not os.path.isdir(dest):
        raise InputError(f"--dir {subdir}: {dest} exists and is not a folder; expected a folder to write the "
                         ".vtp files into")
    return dest


def remove_stale_parts(dest: str, collection: str, written: list[str]) -> None:
    """Delete the numbered parts of ``collection`` (particles.pvd: Part_XXXX.vtp;
    isosurface.pvd: Iso_XXXX.vtp) in ``dest`` that this export did not write: an earlier
    export of a longer run left them, and ParaView would show them as part of the series."""
    from .runfolder import EXPORT_SETS
    keep = {os.path.basename(f) for f in written}
    for name in os.listdir(dest):
        if EXPORT_SETS[collection].fullmatch(name) and name not in keep:
            os.unlink(os.path.join(dest, name))


def _fluid_particles(outdir: str) -> int | None:
    """The fluid particles of the run in OUTDIR as its run.json records them (the run's
    ``fluid_particles``: 0 for a body-only run); None without a readable run.json."""
    import json
    try:
        with open(os.path.join(outdir, "run.json")) as fh:
            return int(json.load(fh)["fluid_particles"])
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return None


def missing_particles_message(outdir: str, src: str) -> str:
    """Why OUTDIR has no particles.vtkhdf to export: a body-only run writes none (run.json
    says it had no fluid), a fluid run's is missing (deleted or moved), or no run wrote one."""
    nfluid = _fluid_particles(outdir)
    if nfluid == 0:
        return (f"{outdir} holds a body-only run (no fluid): it writes no particles.vtkhdf to export; its results are "
                "bodies.csv and links.csv")
    if nfluid is not None:
        return (f"{src} not found: the run in {outdir} has {nfluid} fluid particles, and its particle file is missing "
                "(deleted or moved?); put it back, or run the case again")
    return f"{src} not found: run 'sphdvi run' first"


def export_vtp(outdir: str, subdir: str = "vtp") -> list[str]:
    """Write every step of OUTDIR/particles.vtkhdf as ``Part_XXXX.vtp`` and ``particles.pvd``
    into :func:`export_dir` (``subdir``), created when missing; the parts of an earlier export
    beyond this run's steps are deleted; returns the files (.pvd last)."""
    src = os.path.join(outdir, "particles.vtkhdf")
    if not os.path.isfile(src):
        raise InputError(missing_particles_message(outdir, src))
    dest = export_dir(outdir, subdir)
    times = step_times(src)
    make_folder(dest, "--dir")
    files, entries = [], []
    for k, t in enumerate(times):
        step = read_step(src, k)
        name = f"Part_{k:04d}.vtp"
        arrays = {key: val for key, val in step.items() if key not in ("time", "points")}
        write_vtp_points(os.path.join(dest, name), step["points"], arrays)
        files.append(os.path.join(dest, name))
        entries.append((float(t), name))
    remove_stale_parts(dest, "particles.pvd", files)
    pvd = os.path.join(dest, "particles.pvd")
    write_pvd(pvd, entries)
    return files + [pvd]
