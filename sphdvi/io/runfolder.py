"""The state of a run's output folder OUT: which files of an earlier run it holds, refusing
a new run into them (or deleting them with ``--overwrite``), and the --tmax/--tout/--set the
run recorded in run.json for ``--resume``."""
from __future__ import annotations

import contextlib
import json
import os
import re

from ..errors import InputError
from .checkpoint import RESTART_FILE

# the files a run writes into OUT (Gauges<Type>_<name>.csv too); a gencase output folder
# (<casename>.h5, <casename>_All.vtp) holds none of them
NORMALS_FILE = "normals.vtp"            # with mDBC: the boundary normals at the start
RUN_OUTPUT_FILES = ("particles.vtkhdf", RESTART_FILE, "run.json", "run.log", "run.csv", "bodies.csv", "links.csv",
                    NORMALS_FILE, "excluded.csv", "DtInfo.csv", "DtAllInfo.csv")


# what `sphdvi export` writes into a folder: the collection and its numbered parts
EXPORT_SETS = {"particles.pvd": re.compile(r"Part_\d{4,}\.vtp"), "isosurface.pvd": re.compile(r"Iso_\d{4,}\.vtp")}


def export_files(folder: str) -> list[str]:
    """The files `sphdvi export` wrote into ``folder`` (paths, sorted): each collection
    (particles.pvd, isosurface.pvd) with its numbered .vtp parts; other files are not
    counted, nor parts without their collection."""
    if not os.path.isdir(folder):
        return []
    names = os.listdir(folder)
    found = []
    for pvd, part in EXPORT_SETS.items():
        if pvd in names:
            found += [pvd] + [n for n in names if part.fullmatch(n)]
    return sorted(os.path.join(folder, n) for n in found)


def earlier_exports(outdir: str) -> list[str]:
    """The files of `sphdvi export` in OUT's sub-folders (the default --dir vtp and iso, or
    any other relative --dir one level down), as paths relative to OUT."""
    if not os.path.isdir(outdir):
        return []
    found = []
    for entry in sorted(os.scandir(outdir), key=lambda e: e.name):
        if entry.is_dir(follow_symlinks=False):
            found += [os.path.relpath(f, outdir) for f in export_files(entry.path)]
    return found


def earlier_results(outdir: str) -> list[str]:
    """The names of the files of an earlier run in ``outdir`` (sorted; [] when none)."""
    if not os.path.isdir(outdir):
        return []
    return sorted(name for name in os.listdir(outdir)
                  if name in RUN_OUTPUT_FILES or (name.startswith("Gauges") and "_" in name and name.endswith(".csv")))


def check_new_run_folder(outdir: str, overwrite: bool, command: str = "run") -> None:
    """A new run (or a gencase, ``command="gencase"``) into ``outdir``: refused (InputError)
    when it holds an earlier run's results, unless ``overwrite``: they would be emptied or
    mixed with the new run's, or left beside a case they do not belong to."""
    found = earlier_results(outdir)
    if not found or overwrite:
        return
    status = ""
    with contextlib.suppress(OSError, ValueError, AttributeError):
        with open(os.path.join(outdir, "run.json")) as fh:
            meta = json.load(fh)
        status = f", status '{meta['status']}' at t={float(meta['physical_time']):.6g} s"
    if command == "gencase":
        raise InputError(f"{outdir} holds the results of a run ({', '.join(found)}{status}); a new case there would "
                         "leave them beside a case they do not belong to: use another -o folder, or --overwrite "
                         "(deletes those files)")
    raise InputError(f"{outdir} holds the results of an earlier run ({', '.join(found)}{status}); continue it with "
                     f"'sphdvi run {outdir} --resume', or start again with --overwrite (deletes those files) "
                     "or into another -o folder")


CASE_OUTPUT_SUFFIXES = (".h5", "_All.vtp", "_Normals.vtp")      # what gencase writes for a case


def other_case_outputs(outdir: str, case_name: str) -> list[str]:
    """The gencase outputs in ``outdir`` of cases other than ``case_name`` (a gencase HDF5 file,
    ``format="sphdvi-case"``, and the .vtp files written beside it), sorted names."""
    import h5py
    if not os.path.isdir(outdir):
        return []
    out = []
    for name in sorted(os.listdir(outdir)):
        if not name.endswith(".h5") or name in (RESTART_FILE, f"{case_name}.h5"):
            continue
        with contextlib.suppress(OSError):
            with h5py.File(os.path.join(outdir, name), "r") as f:
                if f.attrs.get("format") != "sphdvi-case":
                    continue
            stem = name[:-3]
            out += [stem + sfx for sfx in CASE_OUTPUT_SUFFIXES if os.path.isfile(os.path.join(outdir, stem + sfx))]
    return out


def check_other_case(outdir: str, case_name: str, overwrite: bool) -> list[str]:
    """A gencase of ``case_name`` into ``outdir``: another case's gencase output there would leave the
    folder with two cases, which ``run OUT``, ``--resume`` and ``measure`` cannot tell apart. Refused
    (InputError) unless ``overwrite``, which deletes it; returns the names deleted."""
    found = other_case_outputs(outdir, case_name)
    if found and not overwrite:
        raise InputError(f"{outdir} holds the gencase output of another case ({', '.join(found)}); a second case there "
                         "leaves the folder ambiguous for 'sphdvi run OUT', --resume and 'sphdvi measure': use another "
                         "-o folder, or --overwrite (deletes those files)")
    for name in found:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(os.path.join(outdir, name))
    return found


def clear_earlier_results(outdir: str) -> list[str]:
    """Delete the files of an earlier run in ``outdir`` (a new run with --overwrite), so that
    nothing of it mixes with the new run's outputs: its own files and what `sphdvi export`
    made of them in OUT's sub-folders (a folder left empty goes too; anything else in it
    stays).  Returns their names, relative to OUT."""
    found = earlier_results(outdir)
    exports = earlier_exports(outdir)
    for name in found + exports:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(os.path.join(outdir, name))
    for folder in sorted({os.path.dirname(name) for name in exports}):
        with contextlib.suppress(OSError):
            os.rmdir(os.path.join(outdir, folder))        # only when empty
    return found + exports


def stored_overrides(outdir: str):
    """The --tmax/--tout/--set of the run in ``outdir`` (run.json ``overrides``); None when
    unknown (no or unreadable run.json, or one written before they were stored)."""
    try:
        with open(os.path.join(outdir, "run.json")) as fh:
            meta = json.load(fh)
    except (OSError, ValueError):
        return None
    stored = meta.get("overrides") if isinstance(meta, dict) else None
    return stored if isinstance(stored, dict) else None
