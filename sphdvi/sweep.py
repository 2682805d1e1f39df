"""Parameter sweeps and convergence studies (``sphdvi sweep``; conventions.md §4.2, §4.3).

A sweep folder SWEEPDIR holds one independent run folder per entry (``run_0000``, ...; each
becomes self-contained when ``sphdvi run`` writes into it: gencase output, run.json, outputs),
``sweep.json`` (the spec: the case, the fixed --set/--tmax/--tout/--threads, the varied keys and
each entry's values), ``sweep.csv`` (the manifest: ``index``, one column per varied key, ``dir``,
``status``) and ``sweep.sbatch`` (a SLURM job array whose task I runs
``sphdvi run --manifest SWEEPDIR/sweep.csv --index I``).  Each run's run.json is the idempotency
marker: a completed entry is not run again, an interrupted one resumes.

DualSPHysics has no sweep tool: its examples run one case per shell script (GenCase, then
DualSPHysics into a -dirout), and a variation is an edited XML (or GenCase's ``-dp:``).

Pure functions, no click: the command line is :mod:`sphdvi.sweep_cli`.
"""
from __future__ import annotations

import contextlib
import csv
import hashlib
import io
import itertools
import json
import os
import re
import warnings
from dataclasses import dataclass

from ._version import __version__
from .errors import EXIT_DIVERGED, EXIT_FAILURE, EXIT_INPUT, EXIT_OK, InputError

FORMAT = "sphdvi-sweep"
MANIFEST = "sweep.csv"
SPEC = "sweep.json"
SBATCH = "sweep.sbatch"
LOCK = ".sweep.lock"
LOGS = "logs"
DP_KEY = "dp"                   # the varied key that is `sphdvi run --dp`, not a --set key
RESERVED = ("index", "dir", "status")       # the manifest's own columns
DEFAULT_TIME = "24:00:00"
DEFAULT_THROTTLE = 20
# a run.json status -> the exit code `sphdvi run` gave it (README: 0 completed, 1 failed or interrupted, 3 diverged)
STATUS_CODES = {"completed": EXIT_OK, "interrupted": EXIT_FAILURE, "running": EXIT_FAILURE, "failed": EXIT_FAILURE,
                "diverged": EXIT_DIVERGED}
# run.json's figures that `sweep collect` puts in the tidy table, as run.json names them
COLLECT_FIELDS = ("particles", "steps", "physical_time", "runtime_s", "us_per_particle_step")
_SLURM_TIME = re.compile(r"(\d+-)?\d+:[0-5]\d:[0-5]\d")


def run_dir_name(index: int, count: int) -> str:
    """``run_0000`` ... (at least 4 digits, more for sweeps of 10,000 runs and over)."""
    return f"run_{index:0{max(4, len(str(max(count - 1, 0))))}d}"


# ---------------------------------------------------------------------------------
# the parameter space: --vary, --table
# ---------------------------------------------------------------------------------
def parse_vary(items) -> tuple[list[str], list[list[str]]]:
    """``--vary KEY=V1,V2,...`` (repeatable) -> the keys and their value lists, in the order given."""
    keys, values = [], []
    for item in items:
        key, sep, text = (s.strip() for s in str(item).partition("="))
        vals = [v.strip() for v in text.split(",")]
        if not sep or not key or not text or any(not v for v in vals):
            raise InputError(f"--vary {item!r}: expected KEY=V1,V2,... (a key, then values separated by commas, "
                             "none empty)")
        if key in keys:
            raise InputError(f"--vary {key}: given twice; expected each key once, with all its values")
        keys.append(key)
        values.append(vals)
    return keys, values


def product_rows(values: list[list[str]]) -> list[list[str]]:
    """The Cartesian product of the value lists, the first key varying slowest (itertools.product)."""
    return [list(row) for row in itertools.product(*values)]


def read_table(path: str) -> tuple[list[str], list[list[str]]]:
    """``--table FILE.csv``: the header names the keys, each further row is one run (blank lines skipped)."""
    try:
        with open(path, newline="", encoding="utf-8-sig") as fh:
            text = fh.read()
    except OSError as exc:
        raise InputError(f"--table {path}: cannot be read ({exc.strerror or exc}); expected a CSV file whose "
                         "header names the keys and whose rows give one run each") from None
    lines = [(n, row) for n, row in enumerate(csv.reader(io.StringIO(text)), start=1) if any(c.strip() for c in row)]
    if not lines:
        raise InputError(f"--table {path}: empty; expected a header naming the keys, then one row per run")
    keys = [k.strip() for k in lines[0][1]]
    if any(not k for k in keys):
        raise InputError(f"{path}:{lines[0][0]}: an empty column name in the header; expected the keys (dp or "
                         "--set keys)")
    dup = sorted({k for k in keys if keys.count(k) > 1})
    if dup:
        raise InputError(f"{path}:{lines[0][0]}: column {', '.join(dup)} given twice; expected each key once")
    rows = []
    for n, row in lines[1:]:
        cells = [c.strip() for c in row]
        if len(cells) != len(keys) or any(not c for c in cells):
            raise InputError(f"{path}:{n}: {len(cells)} values {cells}; expected {len(keys)} values, none empty "
                             f"({', '.join(keys)})")
        rows.append(cells)
    if not rows:
        raise InputError(f"{path}: a header and no rows; expected one row per run")
    return keys, rows


def _check_key_names(keys, sets) -> None:
    """The varied keys: not the manifest's own columns, not also fixed with --set."""
    fixed = {str(s).partition("=")[0].strip() for s in sets or ()}
    for key in keys:
        if key.lower() in RESERVED:
            raise InputError(f"{key}: a column of the manifest itself ({', '.join(RESERVED)}); expected dp or a "
                             "--set key")
        if key in fixed:
            raise InputError(f"{key}: both varied and fixed with --set {key}=...; expected one of them")


# ---------------------------------------------------------------------------------
# validation: each key and value as `sphdvi run --set` / `--dp` would check them
# ---------------------------------------------------------------------------------
def case_parameters(case_xml: str) -> dict:
    """The case's <execution><parameters> as gencase reads them (what ``--set`` is applied to);
    DualSPHysics's defaults where the case writes them as expressions of what only gencase's
    drawing defines (H, B, a drawing's variables): those are checked when each run's gencase runs."""
    from .case.gencase import define_builtin_variables
    from .case.parameters import default_parameters
    from .case.reader import case_name_from_path, open_case, read_constantsdef, read_parameters
    from .errors import CaseError, Warnings
    if not os.path.isfile(case_xml):
        raise CaseError("case file not found", file=case_xml, expected="an existing XML case file")
    root, reader, _ = open_case(case_xml, Warnings())       # a broken case file: exit 2 here
    try:
        define_builtin_variables(reader, read_constantsdef(reader, root.find("casedef")),
                                 case_name_from_path(case_xml))
        return read_parameters(reader, root.find("execution"))[0]
    except CaseError:
        return default_parameters()


def _entry_sets(keys, row, sets) -> tuple[list[str], float | None]:
    """One entry's --set list (the fixed ones, then its varied keys but dp) and its --dp."""
    varied = [f"{k}={v}" for k, v in zip(keys, row) if k != DP_KEY]
    dp = dict(zip(keys, row)).get(DP_KEY)
    return list(sets or ()) + varied, (float(dp) if dp is not None else None)


def _check_dp(value: str, where: str) -> None:
    """A varied dp: a finite number > 0 (``sphdvi run --dp``'s check)."""
    import math
    try:
        number = float(value)
    except ValueError:
        number = math.nan
    if not (math.isfinite(number) and number > 0):
        raise InputError(f"{where}: dp {value!r}: expected a finite number > 0 (the particle spacing [m], "
                         "sphdvi run --dp)")


def check_entries(case_xml: str, keys, rows, sets, tmax, tout, source: str = "--vary") -> list[str]:
    """Check every key and value of the sweep as ``sphdvi run --set``/``--dp`` would (InputError
    naming the key, exit 2, before anything is written): each value alone, then each entry whole
    (the checks across parameters, e.g. RhopOutMin < RhopOutMax).  Returns the warnings those
    checks give (each once), for the command to print."""
    from .simulation import apply_overrides, conflicting_options
    _check_key_names(keys, sets)
    base = case_parameters(case_xml)
    seen = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        conflicting_options(sets, tmax, tout)
        apply_overrides(base, sets, tmax, tout)
        for col, key in enumerate(keys):
            for value in dict.fromkeys(row[col] for row in rows):
                where = f"{source} {key}={value}"
                if key == DP_KEY:
                    _check_dp(value, where)
                    continue
                try:
                    conflicting_options([f"{key}={value}"], tmax, tout)
                    apply_overrides(base, list(sets or ()) + [f"{key}={value}"], tmax, tout)
                except InputError as exc:
                    raise InputError(f"{where}: {exc}") from None
                _check_data_file(key, value, where)
        for item in sets or ():
            key, _, value = (x.strip() for x in str(item).partition("="))
            _check_data_file(key, value, f"--set {item}")
        for i, row in enumerate(rows):
            entry_sets, _ = _entry_sets(keys, row, sets)
            try:
                apply_overrides(base, entry_sets, tmax, tout)
            except InputError as exc:
                raise InputError(f"run {i} ({describe(keys, row)}): {exc}") from None
    for w in caught:
        text = str(w.message)
        if text not in seen:
            seen.append(text)
    return seen


def _check_data_file(key: str, value: str, where: str) -> None:
    """A ViscoTime or DtFixedFile file (relative to the current folder, as ``--set`` takes it)
    read now, as the runs' start-up would read it (:data:`sphdvi.case.reader.DATA_FILE_KEYS`)."""
    from .case.reader import DATA_FILE_KEYS
    from .errors import CaseError
    if key not in DATA_FILE_KEYS or not value or value.upper() == "NONE":
        return
    try:
        DATA_FILE_KEYS[key](os.path.abspath(os.path.expanduser(value)))
    except CaseError as exc:
        raise InputError(f"{where}: {exc}") from None


def describe(keys, row) -> str:
    """``Visco=0.05 dp=0.02``: an entry's parameters for messages and tables."""
    return " ".join(f"{k}={v}" for k, v in zip(keys, row))


def absolute_values(keys, rows) -> list[list[str]]:
    """Varied file keys (ViscoTime, DtFixedFile) made absolute, as ``--set`` makes them
    (:func:`sphdvi.simulation.absolute_file_sets`): the runs start from other folders."""
    from .simulation import absolute_file_sets
    out = []
    for row in rows:
        new = []
        for k, v in zip(keys, row):
            new.append(v if k == DP_KEY else absolute_file_sets([f"{k}={v}"])[0].partition("=")[2])
        out.append(new)
    return out


def check_slurm_time(text: str) -> str:
    """``--time``: SLURM's ``[D-]HH:MM:SS``."""
    if not _SLURM_TIME.fullmatch(text.strip()):
        raise InputError(f"--time {text!r}: expected HH:MM:SS or D-HH:MM:SS (SLURM's --time)")
    return text.strip()


# ---------------------------------------------------------------------------------
# the sweep folder: sweep.json, sweep.csv, sweep.sbatch, run_XXXX
# ---------------------------------------------------------------------------------
def file_sha256(path: str) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def make_spec(case_xml: str, keys, rows, sets, tmax, tout, threads: int, time_limit: str, throttle: int) -> dict:
    """sweep.json: everything needed to run entry i (its values: ``runs[i]``, in ``keys`` order)."""
    from .simulation import absolute_file_sets
    return {"format": FORMAT, "version": __version__,
            "case": os.path.abspath(case_xml), "case_sha256": file_sha256(case_xml),
            "set": list(absolute_file_sets(sets)), "tmax": tmax, "tout": tout, "threads": int(threads),
            "keys": list(keys), "runs": absolute_values(keys, rows),
            "slurm": {"time": time_limit, "throttle": int(throttle)}}


def spec_differences(old: dict, new: dict) -> list[str]:
    """What differs between two sweep specs (the sphdvi version aside), in words."""
    out = []
    for name in ("case", "case_sha256", "set", "tmax", "tout", "threads", "keys"):
        if old.get(name) != new.get(name):
            what = "the case file's content" if name == "case_sha256" else name
            out.append(f"{what}: {old.get(name)!r} -> {new.get(name)!r}" if name != "case_sha256"
                       else f"{what} (edited since the sweep was made)")
    if old.get("keys") == new.get("keys") and old.get("runs") != new.get("runs"):
        a, b = old.get("runs") or [], new.get("runs") or []
        if len(a) != len(b):
            out.append(f"runs: {len(a)} -> {len(b)}")
        else:
            i = next(i for i, (x, y) in enumerate(zip(a, b)) if x != y)
            out.append(f"run {i}: {describe(new['keys'], a[i])} -> {describe(new['keys'], b[i])}")
    return out


def sbatch_script(sweepdir: str, spec: dict) -> str:
    """sweep.sbatch: a SLURM job array, task I = entry I (``sbatch sweep.sbatch``; submitting it
    again skips the completed entries and resumes the interrupted ones)."""
    import shlex
    sweepdir = os.path.abspath(sweepdir)
    n = len(spec["runs"])
    k = min(int(spec["slurm"]["throttle"]), n)
    name = re.sub(r"[^A-Za-z0-9_.-]", "_", os.path.basename(sweepdir.rstrip(os.sep))) or "sweep"
    keys = ", ".join(spec["keys"])
    return "\n".join([
        "#!/bin/bash",
        f"#SBATCH --job-name=sphdvi-{name}",
        f"#SBATCH --array=0-{n - 1}%{k}",
        "#SBATCH --ntasks=1",
        f"#SBATCH --cpus-per-task={int(spec['threads'])}",
        f"#SBATCH --time={spec['slurm']['time']}",
        f"#SBATCH --output={os.path.join(sweepdir, LOGS)}/%A_%a.out",
        f"# sphdvi sweep of {spec['case']}: {n} runs ({keys}); written by sphdvi {spec['version']}.",
        "# Submit with 'sbatch' from an environment where 'sphdvi' is on PATH (SLURM passes it on). Submitting",
        "# it again skips the completed runs and resumes the interrupted ones; 'sphdvi sweep status' shows them.",
        f"sphdvi run --manifest {shlex.quote(os.path.join(sweepdir, MANIFEST))} --index $SLURM_ARRAY_TASK_ID",
        ""])


def manifest_text(keys, runs, statuses) -> str:
    """sweep.csv: index, the varied keys, dir, status."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["index", *keys, "dir", "status"])
    for i, (row, status) in enumerate(zip(runs, statuses)):
        w.writerow([i, *row, run_dir_name(i, len(runs)), status])
    return buf.getvalue()


def _own_names(name: str) -> bool:
    """What ``sweep new`` writes into SWEEPDIR (a folder holding only these may be written again)."""
    return (name in (MANIFEST, SPEC, SBATCH, LOCK, LOGS) or re.fullmatch(r"run_\d{4,}", name) is not None
            or (name.startswith(".") and name.endswith(".tmp")))


def read_spec(sweepdir: str) -> dict | None:
    """SWEEPDIR/sweep.json (None when there is none); a file that is not one: InputError."""
    path = os.path.join(sweepdir, SPEC)
    if not os.path.isfile(path):
        return None
    try:
        with open(path, encoding="utf-8") as fh:
            spec = json.load(fh)
    except (OSError, ValueError) as exc:
        raise InputError(f"{path}: cannot be read as a sweep spec ({exc}); expected the sweep.json "
                         "'sphdvi sweep new' writes") from None
    if not isinstance(spec, dict) or spec.get("format") != FORMAT or not isinstance(spec.get("runs"), list):
        raise InputError(f"{path}: not a sphdvi sweep spec (format {FORMAT!r}); expected the sweep.json "
                         "'sphdvi sweep new' writes")
    return spec


def create_sweep(sweepdir: str, spec: dict) -> str:
    """Write the sweep folder; returns 'created', 'unchanged' (the same spec is there) or
    'updated' (only --time/--throttle changed: sweep.sbatch is written again).  Another spec
    there, or a folder holding other files: InputError saying what differs."""
    from .io.atomic import make_folder, write_text_atomic
    old = read_spec(sweepdir)
    if old is None and os.path.isdir(sweepdir):
        others = sorted(n for n in os.listdir(sweepdir) if not _own_names(n))
        if others:
            raise InputError(f"-o {sweepdir}: holds other files ({', '.join(others[:5])}"
                             f"{', ...' if len(others) > 5 else ''}) and no {SPEC}; expected a new or empty folder")
    if old is not None:
        diffs = spec_differences(old, spec)
        if diffs:
            raise InputError(f"-o {sweepdir}: holds another sweep ({'; '.join(diffs)}); expected the same "
                             "spec (nothing to do), or another -o folder")
    make_folder(sweepdir)
    runs = spec["runs"]
    for i in range(len(runs)):
        os.makedirs(os.path.join(sweepdir, run_dir_name(i, len(runs))), exist_ok=True)
    os.makedirs(os.path.join(sweepdir, LOGS), exist_ok=True)    # SLURM does not create --output's folder
    if old is not None and old.get("slurm") == spec["slurm"]:
        return "unchanged"
    if old is None:
        write_text_atomic(os.path.join(sweepdir, MANIFEST),
                          manifest_text(spec["keys"], runs, ["pending"] * len(runs)))
    else:
        spec = dict(spec, version=old.get("version", spec["version"]))
    write_text_atomic(os.path.join(sweepdir, SBATCH), sbatch_script(sweepdir, spec))
    write_text_atomic(os.path.join(sweepdir, SPEC), json.dumps(spec, indent=2) + "\n")   # last: the marker
    return "created" if old is None else "updated"


@dataclass
class Sweep:
    """A sweep folder, read: its spec and where its files are."""
    dir: str
    spec: dict

    @property
    def keys(self) -> list[str]:
        return list(self.spec["keys"])

    @property
    def runs(self) -> list[list[str]]:
        return self.spec["runs"]

    def run_dir(self, index: int) -> str:
        return os.path.join(self.dir, run_dir_name(index, len(self.runs)))

    @property
    def manifest(self) -> str:
        return os.path.join(self.dir, MANIFEST)


def open_sweep(path: str, option: str = "SWEEPDIR", check_manifest: bool = True) -> Sweep:
    """A sweep from its folder or its manifest (SWEEPDIR/sweep.csv); anything else: InputError.
    ``check_manifest``: sweep.csv must hold sweep.json's entries (``sweep status`` writes it anew)."""
    folder = os.path.abspath(path) if os.path.isdir(path) else os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(path) and (not os.path.isfile(path) or os.path.basename(path) != MANIFEST):
        raise InputError(f"{option} {path}: not a sweep folder or its {MANIFEST}; expected what 'sphdvi sweep new "
                         "-o SWEEPDIR' wrote")
    spec = read_spec(folder)
    if spec is None:
        raise InputError(f"{option} {path}: no {SPEC} in {folder}: not a sweep made by 'sphdvi sweep new'")
    sweep = Sweep(folder, spec)
    if check_manifest:
        _check_manifest(sweep, option)
    return sweep


def read_manifest(sweep: Sweep) -> list[dict]:
    """sweep.csv's rows (dicts of strings)."""
    try:
        with open(sweep.manifest, newline="", encoding="utf-8") as fh:
            return list(csv.DictReader(fh))
    except OSError as exc:
        raise InputError(f"{sweep.manifest}: cannot be read ({exc.strerror or exc})") from None


def _check_manifest(sweep: Sweep, option: str) -> None:
    """sweep.csv holds sweep.json's entries (index, values, dir) in order."""
    rows = read_manifest(sweep)
    header = ["index", *sweep.keys, "dir", "status"]
    n = len(sweep.runs)
    if not rows or list(rows[0].keys()) != header or len(rows) != n:
        raise InputError(f"{option} {sweep.manifest}: not the manifest of {os.path.join(sweep.dir, SPEC)} (expected "
                         f"the columns {', '.join(header)} and {n} rows); write it again with 'sphdvi sweep status'")
    for i, (row, values) in enumerate(zip(rows, sweep.runs)):
        if row["index"] != str(i) or [row[k] for k in sweep.keys] != list(values) or \
                row["dir"] != run_dir_name(i, n):
            raise InputError(f"{option} {sweep.manifest}: row {i} ({describe(sweep.keys, [row[k] for k in sweep.keys])}"
                             f", {row['dir']}) is not entry {i} of {SPEC} ({describe(sweep.keys, values)}); the "
                             "manifest was edited: 'sphdvi sweep status' writes it again from sweep.json (make a "
                             "new sweep for other values)")


@contextlib.contextmanager
def _manifest_lock(sweep: Sweep):
    """SWEEPDIR/.sweep.lock held exclusively (``flock``, blocking): the array tasks that end at once
    update sweep.csv one after the other."""
    import fcntl
    fd = os.open(os.path.join(sweep.dir, LOCK), os.O_RDWR | os.O_CREAT, 0o644)
    try:
        with contextlib.suppress(OSError):        # a file system without flock: the rename stays atomic
            fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)                           # releases the lock


def update_manifest(sweep: Sweep, statuses: dict) -> None:
    """Set the ``status`` of the entries ``statuses`` names ({index: status}) in sweep.csv: read,
    changed and written again (a temporary file renamed over it) under the sweep's lock."""
    from .io.atomic import write_text_atomic
    if not statuses:
        return
    with _manifest_lock(sweep):
        text = None
        with contextlib.suppress(OSError):
            with open(sweep.manifest, encoding="utf-8") as fh:
                text = fh.read()
        try:
            _check_manifest(sweep, "")
            current = [row["status"] for row in read_manifest(sweep)]
        except (InputError, KeyError):          # missing or edited: written anew from sweep.json
            current = ["pending"] * len(sweep.runs)
        new = manifest_text(sweep.keys, sweep.runs, [statuses.get(i, s) for i, s in enumerate(current)])
        if new != text:
            write_text_atomic(sweep.manifest, new)


# ---------------------------------------------------------------------------------
# one entry: its state, what `sphdvi run --manifest --index` does with it
# ---------------------------------------------------------------------------------
def run_info(rundir: str) -> dict | None:
    """The entry's run.json (None when it has none or it cannot be read)."""
    from .validation.runs import run_info as read
    try:
        meta = read(rundir)
    except (OSError, ValueError):
        return None
    return meta if isinstance(meta, dict) and meta else None


def run_status(rundir: str) -> str:
    """The entry's status: run.json's, ``pending`` when it has none."""
    meta = run_info(rundir)
    return str(meta.get("status") or "pending") if meta else "pending"


@dataclass
class Action:
    """What ``sphdvi run --manifest --index`` does with an entry: ``done`` (completed: nothing),
    ``fresh`` (a new run; ``overwrite`` when the folder holds a dead one's files), ``resume``
    (an interrupted or killed run, from restart.h5) or ``refuse`` (failed/diverged without --retry:
    exit ``exit_code``)."""
    kind: str
    message: str = ""
    overwrite: bool = False
    exit_code: int = EXIT_OK


def entry_action(rundir: str, retry: bool = False) -> Action:
    """The entry's next step from its run.json (conventions.md §4.1: "the idempotency marker for sweeps")."""
    from .io.checkpoint import RESTART_FILE
    from .io.runfolder import earlier_results
    meta = run_info(rundir)
    if meta is None:
        return Action("fresh", "no run yet", overwrite=bool(earlier_results(rundir)))
    status = str(meta.get("status"))
    if status == "completed":
        return Action("done", f"completed at t={float(meta.get('physical_time') or 0):.6g} s, "
                              f"{meta.get('steps')} steps")
    if status in ("interrupted", "running"):
        if os.path.isfile(os.path.join(rundir, RESTART_FILE)):
            return Action("resume", f"'{status}' at its last output: resumed")
        return Action("fresh", f"'{status}' before its first output: started again", overwrite=True)
    code = STATUS_CODES.get(status, EXIT_FAILURE)
    if retry:
        return Action("fresh", f"'{status}' before: started again (--retry)", overwrite=True)
    message = str(meta.get("message") or "").strip()
    return Action("refuse", f"ended '{status}' before" + (f" ({message})" if message else "")
                  + "; --retry runs it again from the start", exit_code=code)


def entry_run_options(sweep: Sweep, index: int, action: Action) -> dict:
    """The options of ``sphdvi run`` for entry ``index`` (keywords of ``sphdvi.cli._run``)."""
    rundir = sweep.run_dir(index)
    if action.kind == "resume":       # the run's own --tmax/--tout/--set are in its run.json
        return dict(source=rundir, outdir=rundir, tmax=None, tout=None, sets=(), resume=True, overwrite=False,
                    dp=None)
    case = sweep.spec["case"]
    if not os.path.isfile(case):
        raise InputError(f"{os.path.join(sweep.dir, SPEC)}: the case file {case} is gone; expected it where it was "
                         "when the sweep was made")
    if file_sha256(case) != sweep.spec.get("case_sha256"):
        raise InputError(f"{case} has changed since the sweep was made ({os.path.join(sweep.dir, SPEC)}): a new run "
                         "would differ from those run before; put the file back as it was, or make a new sweep")
    sets, dp = _entry_sets(sweep.keys, sweep.runs[index], sweep.spec.get("set"))
    return dict(source=case, outdir=rundir, tmax=sweep.spec.get("tmax"), tout=sweep.spec.get("tout"),
                sets=tuple(sets), resume=False, overwrite=action.overwrite, dp=dp)


def check_index(sweep: Sweep, index: int) -> None:
    n = len(sweep.runs)
    if not 0 <= index < n:
        raise InputError(f"--index {index}: the sweep in {sweep.dir} has {n} entries; expected 0 to {n - 1}")


def refresh(sweep: Sweep) -> list[str]:
    """Every entry's status from its run.json (``pending`` without one), written into sweep.csv."""
    statuses = [run_status(sweep.run_dir(i)) for i in range(len(sweep.runs))]
    update_manifest(sweep, dict(enumerate(statuses)))
    return statuses


def sweep_exit_code(codes) -> int:
    """The exit code of a whole sweep: 0 when every run completed, else the worst run's: 3 when
    one diverged, 2 when one was refused on bad input, 1 (failed, interrupted)."""
    codes = set(codes)
    for code in (EXIT_DIVERGED, EXIT_INPUT, EXIT_FAILURE):
        if code in codes:
            return code
    return EXIT_OK if codes <= {EXIT_OK} else EXIT_FAILURE


def default_jobs(threads: int) -> int:
    """Runs at once on this machine: the CPUs of this process's affinity over the threads per run
    (conventions.md §4.3: on 2 cores, 2 runs of 1 thread)."""
    try:
        cpus = len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover
        cpus = os.cpu_count() or 1
    return max(1, cpus // max(1, int(threads)))


def status_rows(sweep: Sweep, statuses) -> list[list[str]]:
    """``sweep status``'s table: index, parameters, status, physical_time/TimeMax, runtime_s."""
    from .io.runfolder import run_lock_holder
    out = [["index", *sweep.keys, "status", "t/TimeMax [s]", "runtime_s"]]
    for i, (values, status) in enumerate(zip(sweep.runs, statuses)):
        meta = run_info(sweep.run_dir(i)) or {}
        shown = status
        if status == "running" and run_lock_holder(sweep.run_dir(i)) is None:
            shown = "running (killed: no process holds it)"
        t, tmax = meta.get("physical_time"), (meta.get("parameters") or {}).get("TimeMax")
        out.append([str(i), *values, shown, f"{t:.6g}/{tmax:.6g}" if t is not None and tmax is not None else "-",
                    f"{meta['runtime_s']:.3g}" if meta.get("runtime_s") is not None else "-"])
    return out


def format_table(rows) -> str:
    widths = [max(len(r[c]) for r in rows) for c in range(len(rows[0]))]
    return "\n".join("  ".join(cell.ljust(w) for cell, w in zip(r, widths)).rstrip() for r in rows)


# ---------------------------------------------------------------------------------
# sweep collect: one tidy CSV
# ---------------------------------------------------------------------------------
def csv_value(v) -> str:
    if v is None:
        return ""
    return repr(v) if isinstance(v, float) else str(v)


def summary_table(sweep: Sweep) -> list[list[str]]:
    """One row per run: index, parameters, dir, run.json's status and :data:`COLLECT_FIELDS`."""
    rows = [["index", *sweep.keys, "dir", "status", *COLLECT_FIELDS]]
    for i, values in enumerate(sweep.runs):
        meta = run_info(sweep.run_dir(i)) or {}
        rows.append([str(i), *values, os.path.basename(sweep.run_dir(i)), str(meta.get("status") or "pending"),
                     *(csv_value(meta.get(f)) for f in COLLECT_FIELDS)])
    return rows


def read_run_csv(path: str) -> tuple[list[str], list[list[str]]]:
    """A run folder's CSV (``,`` or ``;`` separated, as sphdvi's gauge and DtInfo files): header, rows."""
    try:
        with open(path, newline="", encoding="utf-8") as fh:
            text = fh.read()
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot be read as a CSV text file ({getattr(exc, 'strerror', None) or exc})") from None
    first = text.split("\n", 1)[0]
    sep = ";" if first.count(";") > first.count(",") else ("\t" if first.count("\t") > first.count(",") else ",")
    rows = [r for r in csv.reader(io.StringIO(text), delimiter=sep) if r]
    if not rows:
        return [], []
    return [c.strip() for c in rows[0]], rows[1:]


def file_table(sweep: Sweep, names) -> tuple[list[list[str]], list[str]]:
    """The rows of every run's file(s) ``names`` (relative to the run folder), long format: index,
    the parameters (and ``file`` when several names), then the files' columns (their union, in
    order of appearance; a column named as a parameter gets the file's stem as prefix).  Returns
    the table and the runs that hold no such file ("run_0003/NAME")."""
    lead = ["index", *sweep.keys] + (["file"] if len(names) > 1 else [])
    columns: list[str] = []
    body, missing = [], []
    for name in names:
        if os.path.isabs(name) or ".." in name.replace("\\", "/").split("/"):
            raise InputError(f"--file {name}: expected a file name inside each run folder (e.g. bodies.csv)")
    for i, values in enumerate(sweep.runs):
        for name in names:
            path = os.path.join(sweep.run_dir(i), name)
            if not os.path.isfile(path):
                missing.append(os.path.join(os.path.basename(sweep.run_dir(i)), name))
                continue
            header, rows = read_run_csv(path)
            stem = os.path.splitext(os.path.basename(name))[0]
            header = [f"{stem}.{h}" if h in lead else h for h in header]
            for h in header:
                if h not in columns:
                    columns.append(h)
            for r in rows:
                body.append(([str(i), *values] + ([name] if len(names) > 1 else []), dict(zip(header, r))))
    table = [lead + columns] + [prefix + [cells.get(c, "") for c in columns] for prefix, cells in body]
    return table, missing


def table_text(rows) -> str:
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerows(rows)
    return buf.getvalue()
