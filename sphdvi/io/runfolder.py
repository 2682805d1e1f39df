"""The state of a run's output folder OUT: which files of an earlier run it holds, refusing
a new run into them (or deleting them with ``--overwrite``), and the --tmax/--tout/--set the
run recorded in run.json for ``--resume``."""
from __future__ import annotations

import contextlib
import json
import os
import re
import shutil

from ..errors import InputError
from .checkpoint import RESTART_FILE

# the files a run writes into OUT (Gauges<Type>_<name>.csv too); a gencase output folder
# (<casename>.h5, <casename>_All.vtp) holds none of them
NORMALS_FILE = "normals.vtp"            # with mDBC: the boundary normals at the start
RUN_OUTPUT_FILES = ("particles.vtkhdf", RESTART_FILE, "run.json", "run.log", "run.csv", "bodies.csv", "links.csv",
                    NORMALS_FILE, "excluded.csv", "DtInfo.csv", "DtAllInfo.csv")


# what `sphdvi export` writes into a folder: the collection and its numbered parts
EXPORT_SETS = {"particles.pvd": re.compile(r"Part_\d{4,}\.vtp"), "isosurface.pvd": re.compile(r"Iso_\d{4,}\.vtp")}


def is_run_output(name: str) -> bool:
    """Whether a file name in OUT is one a run writes: RUN_OUTPUT_FILES, the gauges'
    Gauges<Type>_<name>.csv and the paddles' PaddleMotion_, PaddleSerie_ and PaddleSerieWaves_ files."""
    return name in RUN_OUTPUT_FILES or (name.endswith(".csv") and "_" in name
                                        and name.startswith(("Gauges", "PaddleMotion_", "PaddleSerie")))


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
    return sorted(name for name in os.listdir(outdir) if is_run_output(name))


def check_new_run_folder(outdir: str, overwrite: bool, command: str = "run") -> None:
    """A new run (or a gencase, ``command="gencase"``) into ``outdir``: refused (InputError)
    when it holds an earlier run's results, unless ``overwrite``: they would be emptied or
    mixed with the new run's, or left beside a case they do not belong to."""
    found = earlier_results(outdir)
    if not found or overwrite:
        return
    status = ""
    with contextlib.suppress(OSError, ValueError, AttributeError, KeyError, TypeError):
        with open(os.path.join(outdir, "run.json")) as fh:
            meta = json.load(fh)
        status = f", status '{meta['status']}' at t={float(meta['physical_time']):.6g} s"
        if meta["status"] == "running":      # run.json is written at the start and the end only
            holder = None if os.path.realpath(outdir) in _HELD else run_lock_holder(outdir)
            status = (f", status 'running': it still runs ({holder})" if holder
                      else ", status 'running' though no run holds the folder: it was killed (SIGKILL, a crash)")
            last = last_output_time(outdir)
            if last is not None:
                status += f"; its last output at t={last:.6g} s"
    if command == "gencase":
        raise InputError(f"{outdir} holds the results of a run ({', '.join(found)}{status}); a new case there would "
                         "leave them beside a case they do not belong to: use another -o folder, or --overwrite "
                         "(deletes those files)")
    raise InputError(f"{outdir} holds the results of an earlier run ({', '.join(found)}{status}); continue it with "
                     f"'sphdvi run {outdir} --resume', or start again with --overwrite (deletes those files) "
                     "or into another -o folder")


def run_command(source, outdir, *, tmax=None, tout=None, sets=(), extra: str = "") -> str:
    """The quoted command 'sphdvi run SOURCE [-o OUT] [--tmax T] [--tout T] [--set K=V]... EXTRA' that a
    message suggests, built from what the user gave (-o left out where it is SOURCE itself)."""
    import shlex
    words = ["sphdvi", "run", str(source)]
    if os.path.normpath(str(outdir)) != os.path.normpath(str(source)):
        words += ["-o", str(outdir)]
    words += [w for opt, v in (("--tmax", tmax), ("--tout", tout)) if v is not None for w in (opt, f"{float(v):g}")]
    words += [w for item in sets or () for w in ("--set", str(item))]
    return "'" + " ".join(shlex.quote(w) for w in words) + (f" {extra}" if extra else "") + "'"


RUN_LOCK_FILE = ".sphdvi.lock"
# OUT folders whose lock this process holds (real path -> [fd, depth, created OUT]): a run that
# the command line locked before its gencase locks it again in :func:`sphdvi.simulation.run`
_HELD: dict = {}


def _lock_holder(path: str) -> str:
    """'pid N on HOST' from a lock file's line (a holder that has not written it yet: '')."""
    with contextlib.suppress(OSError, ValueError, IndexError):
        with open(path) as fh:
            pid, host = fh.read().split()[:2]
        return f"pid {int(pid)} on {host}"
    return ""


def run_lock_holder(outdir: str) -> str | None:
    """The holder of OUT's run lock ('pid N on HOST', or 'another process') while a command holds
    it; None when none does (no lock file, or a stale one left by a killed run)."""
    import fcntl
    path = os.path.join(outdir, RUN_LOCK_FILE)
    if os.path.realpath(outdir) in _HELD:
        return f"pid {os.getpid()} on {_hostname()}"
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return None
    try:
        fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
    except BlockingIOError:
        return _lock_holder(path) or "another process"
    except OSError:
        return None
    finally:
        os.close(fd)
    return None


def _hostname() -> str:
    import socket
    return socket.gethostname() or "localhost"


@contextlib.contextmanager
def run_lock(outdir: str, command: str = "run"):
    """OUT/.sphdvi.lock held with ``flock`` while a run (or a gencase, ``command``) writes into OUT,
    so that a second one into the same OUT (fresh, --resume or --overwrite) is refused (InputError,
    exit 2, naming the pid and host of the first) instead of mixing its files with the first's.
    DualSPHysics has no such lock (nothing stops two runs into one -dirout); sphdvi's particle file
    is written without HDF5's own lock so that readers can open it during the run.  The OS releases
    the lock when the process dies (SIGKILL included): a lock file left by a dead run blocks nothing.
    OUT is created when missing (and removed again when it is left empty); the lock file goes at the
    end.  Re-entrant within a process; a file system without locks gets a warning and no lock."""
    import fcntl
    import warnings
    from .atomic import make_folder
    key = os.path.realpath(outdir)
    if key in _HELD:
        _HELD[key][1] += 1
        try:
            yield
        finally:
            _HELD[key][1] -= 1
        return
    created = not os.path.exists(outdir)
    make_folder(outdir)
    path = os.path.join(outdir, RUN_LOCK_FILE)
    fd = None
    try:
        for _ in range(10):
            fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                holder = _lock_holder(path) or "another process"
                os.close(fd)
                fd = None
                raise InputError(f"{outdir} is in use by a sphdvi command that is running ({holder}; lock file "
                                 f"{path}): a second {command} into it would mix its files with that one's; wait "
                                 "for it to end (a run stopped by SIGINT/SIGTERM goes on with 'sphdvi run "
                                 f"{outdir} --resume'), or use another -o folder") from None
            except OSError as exc:          # a file system without flock (some network mounts)
                os.close(fd)
                fd = None
                warnings.warn(f"{path}: cannot lock it ({exc.strerror or exc}): nothing stops a second run into "
                              f"{outdir} while this one runs")
                break
            with contextlib.suppress(FileNotFoundError):     # not unlinked by a holder that just ended
                if os.path.samestat(os.fstat(fd), os.stat(path)):
                    break
            os.close(fd)
            fd = None
        if fd is not None:
            os.ftruncate(fd, 0)
            os.write(fd, f"{os.getpid()} {_hostname()} {command}\n".encode())
            _HELD[key] = [fd, 1, created]
        yield
    finally:
        if fd is not None:
            _HELD.pop(key, None)
            with contextlib.suppress(OSError):
                os.unlink(path)
            os.close(fd)
        if created:
            with contextlib.suppress(OSError):
                os.rmdir(outdir)            # only when left empty (a command refused on bad input)


def last_output_time(outdir: str) -> float | None:
    """The time of the last complete row of OUT's run.csv (None: no such row)."""
    try:
        with open(os.path.join(outdir, "run.csv")) as fh:
            rows = [line for line in fh.read().split("\n")[1:-1] if line]
        return float(rows[-1].split(",")[1]) if rows else None
    except (OSError, ValueError, IndexError):
        return None


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
    (InputError) unless ``overwrite``; returns the names found (for :class:`SetAside`)."""
    found = other_case_outputs(outdir, case_name)
    if found and not overwrite:
        raise InputError(f"{outdir} holds the gencase output of another case ({', '.join(found)}); a second case there "
                         "leaves the folder ambiguous for 'sphdvi run OUT', --resume and 'sphdvi measure': use another "
                         "-o folder, or --overwrite (deletes those files)")
    return found


def case_outputs(outdir: str, case_name: str) -> list[str]:
    """The gencase outputs of ``case_name`` in ``outdir`` (names), which a new gencase replaces."""
    return [case_name + sfx for sfx in CASE_OUTPUT_SUFFIXES if os.path.isfile(os.path.join(outdir, case_name + sfx))]


OVERWRITTEN_DIR = ".sphdvi-overwritten"


class SetAside:
    """``--overwrite`` as one transaction, so that a command that fails on bad input (exit 2)
    loses nothing: the files it replaces (``names``, relative to OUT: an earlier run's results,
    what `sphdvi export` made of them, gencase outputs) move into OUT/.sphdvi-overwritten
    (renames, on the same file system); :meth:`restore` puts them back and deletes the run and
    gencase outputs the failed command wrote; :meth:`discard` deletes them, once the new run's
    start-up has passed its checks.  A folder left by a killed command is replaced."""

    def __init__(self, outdir: str, names):
        self.outdir = outdir
        self.dir = os.path.join(outdir, OVERWRITTEN_DIR)
        self.moved: list[str] = []
        names = sorted(set(names))
        if not names:
            return
        shutil.rmtree(self.dir, ignore_errors=True)
        for name in names:
            src, dst = os.path.join(outdir, name), os.path.join(self.dir, name)
            if not os.path.isfile(src):
                continue
            os.makedirs(os.path.dirname(dst), exist_ok=True)
            os.replace(src, dst)
            self.moved.append(name)
        for folder in sorted({os.path.dirname(n) for n in self.moved if os.path.dirname(n)}):
            with contextlib.suppress(OSError):
                os.rmdir(os.path.join(outdir, folder))        # only when empty
        self._before = set(os.listdir(outdir))

    def restore(self) -> None:
        """Put the files back; the run and gencase outputs written since are deleted first."""
        if not self.moved:
            return
        for name in set(os.listdir(self.outdir)) - self._before:
            if is_run_output(name) or name.endswith(CASE_OUTPUT_SUFFIXES) or \
                    (name.startswith("Gauges") and name.endswith(".csv")):
                with contextlib.suppress(OSError):
                    os.unlink(os.path.join(self.outdir, name))
        for name in self.moved:
            dst = os.path.join(self.outdir, name)
            os.makedirs(os.path.dirname(dst), exist_ok=True)
            os.replace(os.path.join(self.dir, name), dst)
        self.moved = []
        shutil.rmtree(self.dir, ignore_errors=True)

    def discard(self) -> None:
        """Delete the files set aside (the new run has started)."""
        if self.moved:
            shutil.rmtree(self.dir, ignore_errors=True)
            self.moved = []


def delete_files(outdir: str, names) -> None:
    """Delete ``names`` (relative to ``outdir``) where they exist."""
    for name in names:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(os.path.join(outdir, name))


def clear_earlier_results(outdir: str) -> list[str]:
    """Delete the files of an earlier run in ``outdir`` (a new run with --overwrite), so that
    nothing of it mixes with the new run's outputs: its own files and what `sphdvi export`
    made of them in OUT's sub-folders (a folder left empty goes too; anything else in it
    stays).  Returns their names, relative to OUT."""
    found = earlier_results(outdir)
    exports = earlier_exports(outdir)
    delete_files(outdir, found + exports)
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


@contextlib.contextmanager
def restored_on_bad_input(set_aside: "SetAside | None"):
    """Put ``set_aside``'s files back when the block raises a bad-input error (exit 2)."""
    try:
        yield
    except Exception as exc:
        from ..errors import EXIT_INPUT
        if set_aside is not None and getattr(exc, "exit_code", None) == EXIT_INPUT:
            set_aside.restore()
        raise
