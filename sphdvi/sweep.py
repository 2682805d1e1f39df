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
def canonical_key(key: str) -> str:
    """A varied or fixed key as ``sphdvi run --set`` identifies it: the <constantsdef> constants it
    takes in any letter case (CFLnumber, :data:`sphdvi.run_options.RUN_CONSTANTS`) under their one
    name; the <parameters> keys as written (case-sensitive, as in the XML)."""
    from .run_options import RUN_CONSTANTS
    key = key.strip()
    return RUN_CONSTANTS.get(key.lower(), key)


def _same_value_key(value: str):
    """What makes two values of a key the same run: the number (``0.01``, ``0.010``, ``1e-2``),
    else the text."""
    try:
        return float(value)
    except ValueError:
        return value


def _check_repeats(key: str, values, where: str) -> None:
    """Values of one key that are the same number (``0.01,0.010``): the same runs twice."""
    seen = {}
    for v in values:
        k = _same_value_key(v)
        if k in seen:
            raise InputError(f"{where} {key}: {seen[k]} and {v} are the same value (the same runs twice); "
                             "expected each value once")
        seen[k] = v


def parse_vary(items) -> tuple[list[str], list[list[str]]]:
    """``--vary KEY=V1,V2,...`` (repeatable) -> the keys and their value lists, in the order given."""
    keys, values = [], []
    for item in items:
        key, sep, text = (s.strip() for s in str(item).partition("="))
        vals = [v.strip() for v in text.split(",")]
        if not sep or not key or not text or any(not v for v in vals):
            raise InputError(f"--vary {item!r}: expected KEY=V1,V2,... (a key, then values separated by commas, "
                             "none empty)")
        key = canonical_key(key)
        if key in keys:
            raise InputError(f"--vary {key}: given twice; expected each key once, with all its values")
        _check_repeats(key, vals, "--vary")
        keys.append(key)
        values.append(vals)
    return keys, values


def product_rows(values: list[list[str]]) -> list[list[str]]:
    """The Cartesian product of the value lists, the first key varying slowest (itertools.product)."""
    return [list(row) for row in itertools.product(*values)]


def read_table(path: str) -> tuple[list[str], list[list[str]]]:
    """``--table FILE.csv``: the header names the keys, each further row is one run (blank lines
    skipped; blanks after a comma allowed, as in hand-written CSV files)."""
    try:
        with open(path, newline="", encoding="utf-8-sig") as fh:
            text = fh.read()
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"--table {path}: cannot be read ({getattr(exc, 'strerror', None) or exc}); expected a "
                         "CSV text file whose header names the keys and whose rows give one run each") from None
    lines = [(n, row) for n, row in enumerate(csv.reader(io.StringIO(text), skipinitialspace=True), start=1)
             if any(c.strip() for c in row)]
    if not lines:
        raise InputError(f"--table {path}: empty; expected a header naming the keys, then one row per run")
    keys = [canonical_key(k) for k in lines[0][1]]
    if len(keys) == 1 and (";" in keys[0] or "\t" in keys[0]):
        raise InputError(f"{path}:{lines[0][0]}: the header has one column {keys[0]!r}; expected the keys "
                         "separated by ',' (a ';' or tab separated table: save it with commas)")
    if any(not k for k in keys):
        raise InputError(f"{path}:{lines[0][0]}: an empty column name in the header; expected the keys (dp or "
                         "--set keys)")
    dup = sorted({k for k in keys if keys.count(k) > 1})
    if dup:
        raise InputError(f"{path}:{lines[0][0]}: column {', '.join(dup)} given twice; expected each key once "
                         "(CFLnumber in any letter case is one key)")
    rows, seen = [], {}
    for n, row in lines[1:]:
        cells = [c.strip() for c in row]
        if len(cells) != len(keys) or any(not c for c in cells):
            raise InputError(f"{path}:{n}: {len(cells)} values {cells}; expected {len(keys)} values, none empty "
                             f"({', '.join(keys)})")
        same = tuple(_same_value_key(c) for c in cells)
        if same in seen:
            raise InputError(f"{path}:{n}: the same run as line {seen[same]} ({describe(keys, cells)}); expected "
                             "each run once")
        seen[same] = n
        rows.append(cells)
    if not rows:
        raise InputError(f"{path}: a header and no rows; expected one row per run")
    return keys, rows


def _check_key_names(keys, sets) -> None:
    """The varied keys: not the manifest's own columns, not also fixed with --set (CFLnumber in any
    letter case is one key, as for ``--set``)."""
    fixed = {canonical_key(str(s).partition("=")[0]) for s in sets or ()}
    for key in keys:
        if key.lower() in RESERVED:
            raise InputError(f"{key}: a column of the manifest itself ({', '.join(RESERVED)}); expected dp or a "
                             "--set key")
        if canonical_key(key) in fixed:
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
    naming the key, exit 2, before anything is written): each entry whole (the checks across
    parameters, e.g. RhopOutMin < RhopOutMax), an entry's error named by the value that fails
    alone where one does (per-key messages; a value valid only with the other values of its
    entry is accepted).  Returns the warnings those checks give (each once), for the command to
    print."""
    from .run_options import apply_overrides, conflicting_options
    _check_key_names(keys, sets)
    base = case_parameters(case_xml)
    seen = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        conflicting_options(sets, tmax, tout)
        apply_overrides(base, sets, tmax, tout)
        alone = {}          # (key, value) -> its message when it fails against the case's other values
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
                    alone[(key, value)] = f"{where}: {exc}"
                    continue
                _check_data_file(key, value, where)
        for item in sets or ():
            key, _, value = (x.strip() for x in str(item).partition("="))
            _check_data_file(key, value, f"--set {item}")
        for i, row in enumerate(rows):
            entry_sets, _ = _entry_sets(keys, row, sets)
            try:
                conflicting_options(entry_sets, tmax, tout)
                apply_overrides(base, entry_sets, tmax, tout)
            except InputError as exc:
                failed = [alone[(k, v)] for k, v in zip(keys, row) if (k, v) in alone]
                raise InputError(failed[0] if failed else f"run {i} ({describe(keys, row)}): {exc}") from None
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
    (:func:`sphdvi.run_options.absolute_file_sets`): the runs start from other folders."""
    from .run_options import absolute_file_sets
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


def case_data_files(case_xml: str) -> dict:
    """The files a case names ({path relative to its folder: sha256}): every attribute value or
    element text of the XML that names a file in the case's folder or below (``[CaseName]``
    replaced), as GenCase and DualSPHysics resolve them (against DirCase, the case's folder):
    motion tables (<mvrotfile>, <file>), STL/PLY/VTK drawings, ViscoTime/DtFixedFile, property
    and model files.  Each new run's gencase reads them again, so they are part of the case."""
    import xml.etree.ElementTree as ET
    from .case.reader import case_name_from_path
    base = os.path.dirname(os.path.abspath(case_xml))
    name = case_name_from_path(case_xml)
    try:
        root = ET.parse(case_xml).getroot()
    except (OSError, ET.ParseError):
        return {}
    found = {}
    for el in root.iter():
        for value in [*el.attrib.values(), el.text or ""]:
            value = value.strip()
            if not value or value.startswith("#") or "\n" in value or "\x00" in value or len(value) > 4096:
                continue
            value = re.sub(r"\[casename\]", lambda _: name, value.replace("\\", "/"), flags=re.IGNORECASE)
            path = os.path.normpath(os.path.join(base, value))
            if os.path.commonpath([path, base]) != base or path == os.path.abspath(case_xml) or \
                    not os.path.isfile(path):
                continue
            rel = os.path.relpath(path, base)
            if rel not in found:
                found[rel] = file_sha256(path)
    return dict(sorted(found.items()))


def make_spec(case_xml: str, keys, rows, sets, tmax, tout, threads: int, time_limit: str, throttle: int,
              command: str | None = None) -> dict:
    """sweep.json: everything needed to run entry i (its values: ``runs[i]``, in ``keys`` order);
    the case's checksum and those of the files it names (:func:`case_data_files`)."""
    from .run_options import absolute_file_sets
    return {"format": FORMAT, "version": __version__,
            "case": os.path.abspath(case_xml), "case_sha256": file_sha256(case_xml),
            "case_files": case_data_files(case_xml),
            "set": list(absolute_file_sets(sets)), "tmax": tmax, "tout": tout, "threads": int(threads),
            "keys": list(keys), "runs": absolute_values(keys, rows),
            "slurm": {"time": time_limit, "throttle": int(throttle), "command": command}}


def spec_differences(old: dict, new: dict) -> list[str]:
    """What differs between two sweep specs (the sphdvi version aside), in words."""
    out = []
    for name in ("case", "case_sha256", "case_files", "set", "tmax", "tout", "threads", "keys"):
        if name == "case_files" and name not in old:        # a sweep made before they were recorded
            continue
        if old.get(name) != new.get(name):
            if name == "case_sha256":
                out.append("the case file's content (edited since the sweep was made)")
            elif name == "case_files":
                a, b = old.get(name) or {}, new.get(name) or {}
                changed = sorted(k for k in set(a) | set(b) if a.get(k) != b.get(k))
                out.append(f"the case's data files ({', '.join(changed)}: edited, added or removed since the "
                           "sweep was made)")
            else:
                out.append(f"{name}: {old.get(name)!r} -> {new.get(name)!r}")
    if old.get("keys") == new.get("keys") and old.get("runs") != new.get("runs"):
        a, b = old.get("runs") or [], new.get("runs") or []
        if len(a) != len(b):
            out.append(f"runs: {len(a)} -> {len(b)}")
        else:
            i = next(i for i, (x, y) in enumerate(zip(a, b)) if x != y)
            out.append(f"run {i}: {describe(new['keys'], a[i])} -> {describe(new['keys'], b[i])}")
    return out


# SLURM's default MaxArraySize (slurm.conf): an --array index above MaxArraySize - 1 is refused
SLURM_MAX_ARRAY = 1001


def _sbatch_path(path: str, tail: str = "") -> str:
    """A path in an ``#SBATCH`` line as sbatch's parser reads it (slurm src/sbatch/opt.c
    _get_argument: blanks split words, an unescaped ``#`` starts a comment, ``\\`` escapes, quotes
    group) and as --output's pattern reads it (``%%`` is a literal ``%``): in double quotes, with
    ``"`` and ``#`` escaped.  A backslash (it turns off --output's %A/%a) or a line break cannot
    be written: InputError.  ``tail``: a pattern put after the path as it is (``/%A_%a.out``)."""
    if "\\" in path or "\n" in path or "\r" in path:
        raise InputError(f"-o {path}: the sweep folder's path holds a backslash or a line break, which an #SBATCH "
                         "line cannot hold (SLURM's --output); expected another -o folder")
    text = path.replace("%", "%%").replace('"', '\\"').replace("#", "\\#")
    return f'"{text}{tail}"'


def check_sweep_path(sweepdir: str) -> None:
    """The sweep folder can be named in sweep.sbatch (InputError before anything is written)."""
    _sbatch_path(os.path.join(os.path.abspath(sweepdir), LOGS))


def sbatch_script(sweepdir: str, spec: dict) -> str:
    """sweep.sbatch: a SLURM job array, task I = entry I (``sbatch sweep.sbatch``; submitting it
    again skips the completed entries and resumes the interrupted ones).  The task runs this
    Python's sphdvi (``sys.executable -m sphdvi``, found without the submitting shell's PATH) or
    the sweep's ``--command``, with ``--threads`` SLURM's --cpus-per-task."""
    import shlex
    import sys
    sweepdir = os.path.abspath(sweepdir)
    n = len(spec["runs"])
    slurm = spec["slurm"]
    k = min(int(slurm["throttle"]), n)
    name = re.sub(r"[^A-Za-z0-9_.-]", "_", os.path.basename(sweepdir.rstrip(os.sep))) or "sweep"
    keys = ", ".join(spec["keys"])
    threads = int(spec["threads"])
    command = slurm.get("command") or f"{shlex.quote(sys.executable)} -m sphdvi"
    return "\n".join([
        "#!/bin/bash",
        f"#SBATCH --job-name=sphdvi-{name}",
        f"#SBATCH --array=0-{n - 1}%{k}",
        "#SBATCH --ntasks=1",
        f"#SBATCH --cpus-per-task={threads}",
        f"#SBATCH --time={slurm['time']}",
        f"#SBATCH --output={_sbatch_path(os.path.join(sweepdir, LOGS), '/%A_%a.out')}",
        f"# sphdvi sweep of {spec['case']}: {n} runs ({keys}); written by sphdvi {spec['version']}.",
        "# Submitting it again skips the completed runs and resumes the interrupted ones; 'sphdvi sweep status'",
        "# shows them. --threads follows --cpus-per-task (SLURM_CPUS_PER_TASK).",
        f"{command} run --manifest {shlex.quote(os.path.join(sweepdir, MANIFEST))} --index $SLURM_ARRAY_TASK_ID "
        f"--threads ${{SLURM_CPUS_PER_TASK:-{threads}}}",
        ""])


def manifest_text(keys, runs, statuses) -> str:
    """sweep.csv: index, the varied keys, dir, status."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["index", *keys, "dir", "status"])
    for i, (row, status) in enumerate(zip(runs, statuses)):
        w.writerow([i, *row, run_dir_name(i, len(runs)), status])
    return buf.getvalue()


def _own_names(name: str, sweepdir: str) -> bool:
    """What ``sweep new`` writes into SWEEPDIR (a folder holding only these may be written again):
    its files, logs/, and run_XXXX folders that are empty (one holding a run is another sweep's)."""
    if re.fullmatch(r"run_\d{4,}", name):
        path = os.path.join(sweepdir, name)
        return os.path.isdir(path) and not os.listdir(path)
    return (name in (MANIFEST, SPEC, SBATCH, LOCK, LOGS)
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
    """Write the sweep folder; returns 'created', 'unchanged' (the same spec is there),
    'updated' (only --time/--throttle/--command changed: sweep.sbatch is written again) or
    'moved' (the same spec, but sweep.sbatch named another folder or Python: written again).
    Another spec there, or a folder holding other files (a run_XXXX holding a run among them):
    InputError saying what differs."""
    from .io.atomic import make_folder, write_text_atomic
    check_sweep_path(sweepdir)
    old = read_spec(sweepdir)
    if old is None and os.path.isdir(sweepdir):
        others = sorted(n for n in os.listdir(sweepdir) if not _own_names(n, sweepdir))
        if others:
            raise InputError(f"-o {sweepdir}: holds other files ({', '.join(others[:5])}"
                             f"{', ...' if len(others) > 5 else ''}) and no {SPEC}; expected a new or empty folder "
                             "(a run_XXXX folder holding a run belongs to another sweep)")
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
    if old is not None:
        spec = dict(spec, version=old.get("version", spec["version"]))
        if "case_files" not in old:
            spec.pop("case_files", None)
    if old is not None and _same_slurm(old.get("slurm"), spec["slurm"]):
        script = sbatch_script(sweepdir, dict(spec, slurm=old["slurm"]))
        path = os.path.join(sweepdir, SBATCH)
        text = None
        with contextlib.suppress(OSError, UnicodeDecodeError):
            with open(path, encoding="utf-8") as fh:
                text = fh.read()
        if text == script:
            return "unchanged"
        write_text_atomic(path, script)
        return "moved"
    if old is None:
        write_text_atomic(os.path.join(sweepdir, MANIFEST),
                          manifest_text(spec["keys"], runs, ["pending"] * len(runs)))
    write_text_atomic(os.path.join(sweepdir, SBATCH), sbatch_script(sweepdir, spec))
    write_text_atomic(os.path.join(sweepdir, SPEC), json.dumps(spec, indent=2) + "\n")   # last: the marker
    return "created" if old is None else "updated"


def _same_slurm(old, new) -> bool:
    """The same job settings (a spec written before --command: no command, the default)."""
    old = dict(old or {})
    old.setdefault("command", None)
    return old == new


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
    ``check_manifest``: sweep.csv must hold sweep.json's entries (an edited one: InputError;
    ``sweep status`` writes it anew).  A missing or unreadable sweep.csv (a view of sweep.json
    and the runs' run.json) is a warning: the next update of the manifest writes it again."""
    is_manifest = os.path.basename(os.path.abspath(path)) == MANIFEST and not os.path.isdir(path)
    folder = os.path.abspath(path) if os.path.isdir(path) else os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(path) and not (is_manifest and os.path.isfile(os.path.join(folder, SPEC))):
        raise InputError(f"{option} {path}: not a sweep folder or its {MANIFEST}; expected what 'sphdvi sweep new "
                         "-o SWEEPDIR' wrote")
    spec = read_spec(folder)
    if spec is None:
        raise InputError(f"{option} {path}: no {SPEC} in {folder}: not a sweep made by 'sphdvi sweep new'")
    sweep = Sweep(folder, spec)
    if check_manifest:
        try:
            rows = read_manifest(sweep)
        except InputError as exc:
            warnings.warn(f"{exc}: the statuses are read from the runs' run.json; it is written again from "
                          f"{SPEC} at the next update ('sphdvi sweep status')")
        else:
            _check_manifest(sweep, option, rows)
    return sweep


def read_manifest(sweep: Sweep) -> list[dict]:
    """sweep.csv's rows (dicts of strings)."""
    try:
        with open(sweep.manifest, newline="", encoding="utf-8") as fh:
            return list(csv.DictReader(fh))
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        raise InputError(f"{sweep.manifest}: cannot be read ({getattr(exc, 'strerror', None) or exc})") from None


def _check_manifest(sweep: Sweep, option: str, rows=None) -> None:
    """sweep.csv holds sweep.json's entries (index, values, dir) in order."""
    rows = read_manifest(sweep) if rows is None else rows
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


_UNLOCKED_WARNED: set = set()      # sweep folders whose lock failed (warned once per process)


@contextlib.contextmanager
def _manifest_lock(sweep: Sweep):
    """SWEEPDIR/.sweep.lock held exclusively (``flock``, blocking): the array tasks that end at once
    update sweep.csv one after the other.  A file system without flock (Lustre -o noflock, some
    NFS mounts): a warning (once), and the update goes on unlocked (each writer reads every
    entry's run.json, so the next one repairs an update lost meanwhile)."""
    import fcntl
    fd = os.open(os.path.join(sweep.dir, LOCK), os.O_RDWR | os.O_CREAT, 0o644)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX)
        except OSError as exc:
            if sweep.dir not in _UNLOCKED_WARNED:
                _UNLOCKED_WARNED.add(sweep.dir)
                warnings.warn(f"{os.path.join(sweep.dir, LOCK)}: cannot lock it ({exc.strerror or exc}): "
                              f"{MANIFEST} is updated without the lock (a status written at the same time by "
                              "another task may be lost until 'sphdvi sweep status')")
        yield
    finally:
        os.close(fd)                           # releases the lock


def update_manifest(sweep: Sweep, indices=None) -> tuple[list[str], dict]:
    """Set the ``status`` of the entries ``indices`` (all when None) in sweep.csv from their
    run.json, read *under* the sweep's lock (so that the last writer writes the current truth,
    not what it read before another task's update), and write it again (a temporary file renamed
    over it).  An entry whose run.json cannot be read or belongs to another run keeps its status.
    Returns every entry's status and {index: message} of those problems."""
    from .io.atomic import write_text_atomic
    n = len(sweep.runs)
    indices = range(n) if indices is None else list(indices)
    problems = {}
    with _manifest_lock(sweep):
        text = None
        with contextlib.suppress(OSError, UnicodeDecodeError):
            with open(sweep.manifest, encoding="utf-8") as fh:
                text = fh.read()
        try:
            rows = read_manifest(sweep)
            _check_manifest(sweep, "", rows)
            current = [row["status"] for row in rows]
        except (InputError, KeyError):          # missing or edited: written anew from sweep.json
            current = ["pending"] * n
        for i in indices:
            try:
                current[i] = entry_status(sweep, i)
            except InputError as exc:
                problems[i] = str(exc)
        new = manifest_text(sweep.keys, sweep.runs, current)
        if new != text:
            write_text_atomic(sweep.manifest, new)
    return current, problems


# ---------------------------------------------------------------------------------
# one entry: its state, what `sphdvi run --manifest --index` does with it
# ---------------------------------------------------------------------------------
REFUSED = ".sweep-refused"      # in a run folder: the message of the start-up that refused the entry


def run_info(rundir: str) -> dict | None:
    """The entry's run.json (None when it has none); one that exists but cannot be read or is not
    a run.json: InputError naming it (never taken for "no run yet": the folder holds results)."""
    path = os.path.join(rundir, "run.json")
    try:
        with open(path, encoding="utf-8") as fh:
            meta = json.load(fh)
    except FileNotFoundError:
        return None
    except (OSError, ValueError) as exc:
        raise InputError(f"{path}: cannot be read ({getattr(exc, 'strerror', None) or exc}); the entry's results "
                         "are left as they are: put a whole run.json back, or move the folder's files away to run "
                         "the entry again") from None
    if not isinstance(meta, dict) or "status" not in meta:
        raise InputError(f"{path}: not a run's run.json (no status); the entry's results are left as they are: "
                         "move the folder's files away to run the entry again")
    return meta


def entry_sets(sweep: Sweep, index: int) -> tuple[list[str], float | None]:
    """Entry ``index``'s --set list and --dp, as ``sphdvi run --manifest --index`` runs it."""
    return _entry_sets(sweep.keys, sweep.runs[index], sweep.spec.get("set"))


def _norm_set(item) -> tuple[str, str]:
    key, _, value = (x.strip() for x in str(item).partition("="))
    return canonical_key(key), value


def _same_number(a, b) -> bool:
    try:
        a, b = float(a), float(b)
    except (TypeError, ValueError):
        return False
    return a == b or abs(a - b) <= 1e-9 * max(abs(a), abs(b))


def foreign_run(sweep: Sweep, index: int, meta: dict) -> list[str]:
    """What in run.json says the run in entry ``index``'s folder is not that entry's run: its case
    (run.json ``case``), --tmax/--tout/--set (``overrides``), dp (``constants``), or for a run.json
    without ``overrides`` the varied parameters' values (``parameters``); [] when it is the
    entry's.  Fields run.json lacks are not compared."""
    from .case.reader import case_name_from_path
    sets, dp = entry_sets(sweep, index)
    out = []
    case = case_name_from_path(sweep.spec.get("case") or "")
    if meta.get("case") is not None and meta.get("case") != case:
        out.append(f"case {meta.get('case')!r}, not {case!r}")
    given = meta.get("overrides")
    if isinstance(given, dict):
        for name in ("tmax", "tout"):
            want, got = sweep.spec.get(name), given.get(name)
            if (want is None) != (got is None) or (want is not None and not _same_number(want, got)):
                out.append(f"--{name} {got}, not {want}")
        if [_norm_set(x) for x in given.get("set") or ()] != [_norm_set(x) for x in sets]:
            out.append(f"--set {' '.join(map(str, given.get('set') or ())) or '(none)'}, not "
                       f"{' '.join(sets) or '(none)'}")
    constants = meta.get("constants") if isinstance(meta.get("constants"), dict) else {}
    if dp is not None and constants.get("dp") is not None and not _same_number(constants["dp"], dp):
        out.append(f"dp {constants['dp']}, not {dp:g}")
    params = meta.get("parameters") if isinstance(meta.get("parameters"), dict) and not isinstance(given, dict) \
        else {}             # --set says it exactly; the parameters only for a run.json without overrides
    for key, value in zip(sweep.keys, sweep.runs[index]):
        got = constants.get("cflnumber") if key == "CFLnumber" else params.get(key)
        if key == DP_KEY or got is None or isinstance(got, (str, bool)):
            continue
        try:
            float(value)
        except ValueError:
            continue
        if not _same_number(got, value):
            out.append(f"{key} {got}, not {value}")
    return out


def entry_meta(sweep: Sweep, index: int) -> dict | None:
    """Entry ``index``'s run.json when it is this entry's run (None: no run yet); InputError when
    it cannot be read (:func:`run_info`) or the folder holds another run (:func:`foreign_run`:
    a sweep folder made again where another sweep's runs were, a run copied in by hand)."""
    rundir = sweep.run_dir(index)
    meta = run_info(rundir)
    if meta is None:
        return None
    diffs = foreign_run(sweep, index, meta)
    if diffs:
        raise InputError(f"{rundir} holds another run than entry {index} ({describe(sweep.keys, sweep.runs[index])}) "
                         f"of {os.path.join(sweep.dir, SPEC)}: its run.json has {'; '.join(diffs)}; move that "
                         "folder's files away (or delete them) to run the entry, or make the sweep in another folder")
    return meta


def refused_message(rundir: str) -> str | None:
    """Why the entry's last start-up refused it (exit 2, before its run.json), or None."""
    with contextlib.suppress(OSError, UnicodeDecodeError):
        with open(os.path.join(rundir, REFUSED), encoding="utf-8") as fh:
            return fh.read().strip() or "refused"
    return None


def mark_refused(rundir: str, message: str) -> None:
    """Record a start-up's refusal (bad input, exit 2) in the run folder, for ``sweep status``."""
    from .io.atomic import write_text_atomic
    with contextlib.suppress(OSError):
        write_text_atomic(os.path.join(rundir, REFUSED), message.strip() + "\n")


def clear_refused(rundir: str) -> None:
    with contextlib.suppress(OSError):
        os.unlink(os.path.join(rundir, REFUSED))


def entry_status(sweep: Sweep, index: int) -> str:
    """The entry's status: run.json's; ``refused`` when its last start-up refused it on bad
    input; ``pending`` when it has no run yet.  InputError from :func:`entry_meta`."""
    meta = entry_meta(sweep, index)
    if meta:
        return str(meta.get("status") or "pending")
    return "refused" if refused_message(sweep.run_dir(index)) is not None else "pending"


def run_status(rundir: str) -> str:
    """The status in a run folder's run.json (``pending`` when it has none); InputError when it
    cannot be read."""
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


def entry_action(sweep: Sweep, index: int, retry: bool = False) -> Action:
    """The entry's next step from its run.json (conventions.md §4.1: "the idempotency marker for
    sweeps"), once :func:`entry_meta` has checked that it is this entry's run (InputError when not,
    or when it cannot be read)."""
    from .io.checkpoint import RESTART_FILE
    from .io.runfolder import earlier_results
    rundir = sweep.run_dir(index)
    meta = entry_meta(sweep, index)
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


def check_case_unchanged(sweep: Sweep) -> None:
    """The case file and the data files it names are as when the sweep was made (a new run's
    gencase reads them again): InputError naming the first that changed."""
    case = sweep.spec["case"]
    where = os.path.join(sweep.dir, SPEC)
    if not os.path.isfile(case):
        raise InputError(f"{where}: the case file {case} is gone; expected it where it was when the sweep was made")
    if file_sha256(case) != sweep.spec.get("case_sha256"):
        raise InputError(f"{case} has changed since the sweep was made ({where}): a new run would differ from "
                         "those run before; put the file back as it was, or make a new sweep")
    base = os.path.dirname(case)
    for rel, digest in (sweep.spec.get("case_files") or {}).items():
        path = os.path.join(base, rel)
        try:
            same = file_sha256(path) == digest
        except OSError:
            same = False
        if not same:
            raise InputError(f"{path}, a file the case {case} names, has changed (or is gone) since the sweep was "
                             f"made ({where}): a new run would differ from those run before; put the file back as "
                             "it was, or make a new sweep")


def entry_run_options(sweep: Sweep, index: int, action: Action) -> dict:
    """The options of ``sphdvi run`` for entry ``index`` (keywords of ``sphdvi.cli._run``)."""
    rundir = sweep.run_dir(index)
    if action.kind == "resume":       # the run's own --tmax/--tout/--set are in its run.json
        return dict(source=rundir, outdir=rundir, tmax=None, tout=None, sets=(), resume=True, overwrite=False,
                    dp=None)
    check_case_unchanged(sweep)
    sets, dp = entry_sets(sweep, index)
    return dict(source=sweep.spec["case"], outdir=rundir, tmax=sweep.spec.get("tmax"), tout=sweep.spec.get("tout"),
                sets=tuple(sets), resume=False, overwrite=action.overwrite, dp=dp)


def check_index(sweep: Sweep, index: int) -> None:
    n = len(sweep.runs)
    if not 0 <= index < n:
        raise InputError(f"--index {index}: the sweep in {sweep.dir} has {n} entries; expected 0 to {n - 1}")


def refresh(sweep: Sweep) -> tuple[list[str], dict]:
    """Every entry's status from its run.json (``pending`` without one), written into sweep.csv
    (:func:`update_manifest`); and {index: message} of the entries whose run.json cannot be read
    or is another run's."""
    return update_manifest(sweep, None)


def read_statuses(sweep: Sweep) -> tuple[list[str], dict]:
    """As :func:`refresh`, without writing sweep.csv (a sweep folder this user cannot write)."""
    statuses, problems = [], {}
    for i in range(len(sweep.runs)):
        try:
            statuses.append(entry_status(sweep, i))
        except InputError as exc:
            statuses.append("?")
            problems[i] = str(exc)
    return statuses, problems


def sweep_exit_code(codes) -> int:
    """The exit code of a whole sweep: 0 when every run completed, else the worst run's: 3 when
    one diverged, 2 when one was refused on bad input, 1 (failed, interrupted, or run elsewhere
    by another live process)."""
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


FINAL = ("completed", "diverged", "failed")        # statuses whose run.json figures are the run's last


def run_progress(rundir: str) -> dict:
    """A running (or killed) run's progress from the last complete row of its run.csv (run.json is
    written at the start and the end only): {'time': t, 'steps': n}, {} when it has no row yet."""
    from .io.atomic import complete_lines
    try:
        lines = [ln for ln in complete_lines(os.path.join(rundir, "run.csv")) if ln.strip()]
    except (OSError, UnicodeDecodeError):
        return {}
    if len(lines) < 2:
        return {}
    head = [h.strip() for h in lines[0].split(",")]
    last = lines[-1].split(",")
    out = {}
    for name, conv in (("time", float), ("steps", int)):
        with contextlib.suppress(ValueError, IndexError):
            out[name] = conv(last[head.index(name)])
    return out


def status_rows(sweep: Sweep, statuses, problems=None) -> list[list[str]]:
    """``sweep status``'s table: index, parameters, status, t/TimeMax (a running or killed run's
    t from its run.csv), runtime_s; a folder that holds another run or an unreadable run.json said
    so (:func:`refused_notes`: why the refused entries were refused)."""
    from .io.runfolder import run_lock_holder
    problems = problems or {}
    out = [["index", *sweep.keys, "status", "t/TimeMax [s]", "runtime_s"]]
    for i, (values, status) in enumerate(zip(sweep.runs, statuses)):
        rundir = sweep.run_dir(i)
        if i in problems:
            what = "run.json unreadable" if "cannot be read" in problems[i] or "not a run's" in problems[i] \
                else "another run in the folder"
            out.append([str(i), *values, f"? ({what})", "-", "-"])
            continue
        meta = run_info(rundir) or {}
        shown = status
        t, tmax = meta.get("physical_time"), (meta.get("parameters") or {}).get("TimeMax")
        if status == "running":
            if run_lock_holder(rundir) is None:
                shown = "running (killed: no process holds it)"
            t = run_progress(rundir).get("time", t)
        runtime = meta.get("runtime_s") if status != "running" else None
        out.append([str(i), *values, shown, f"{t:.6g}/{tmax:.6g}" if t is not None and tmax is not None else "-",
                    f"{runtime:.3g}" if runtime is not None else "-"])
    return out


def refused_notes(sweep: Sweep, statuses) -> list[str]:
    """``run_0003 refused at its start-up: MESSAGE`` for each entry whose status is ``refused``."""
    return [f"{os.path.basename(sweep.run_dir(i))} refused at its start-up: {refused_message(sweep.run_dir(i))}"
            for i, status in enumerate(statuses) if status == "refused"]


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
    """One row per run: index, parameters, dir, status and :data:`COLLECT_FIELDS` from run.json
    (:func:`entry_meta`: InputError for a folder holding another run or an unreadable run.json).
    A running run (run.json written at its start only) gets its steps and physical_time from its
    run.csv's last row and no runtime_s / us_per_particle_step (figures of a finished run)."""
    rows = [["index", *sweep.keys, "dir", "status", *COLLECT_FIELDS]]
    for i, values in enumerate(sweep.runs):
        meta = dict(entry_meta(sweep, i) or {})
        status = str(meta.get("status") or entry_status(sweep, i))
        if status == "running":
            progress = run_progress(sweep.run_dir(i))
            meta.update(steps=progress.get("steps"), physical_time=progress.get("time"), runtime_s=None,
                        us_per_particle_step=None)
        rows.append([str(i), *values, os.path.basename(sweep.run_dir(i)), status,
                     *(csv_value(meta.get(f)) for f in COLLECT_FIELDS)])
    return rows


_POSITION_ROW = re.compile(r"^\s*;\s*Pos[XYZ]\b[^;]*:")      # MeasureTool's ' ;PosX [m]:;x0;x1...'


def _guess_separator(header: str, first_row: str | None) -> str:
    """The separator of a CSV from its column-header line (and the first data row): ``;`` (sphdvi's
    and DualSPHysics's gauge files, MeasureTool), tab, or ``,`` (bodies.csv, run.csv, measure's
    default); the one that splits the header into several cells and the row into as many."""
    def cells(line, sep):
        return len(next(csv.reader([line], delimiter=sep), []))
    fits = [sep for sep in (";", "\t", ",") if cells(header, sep) > 1]
    if first_row is not None:
        same = [sep for sep in fits if cells(first_row, sep) == cells(header, sep)]
        fits = same or fits
    return fits[0] if fits else ","


def read_run_csv(path: str, complete_only: bool = True) -> tuple[list[str], list[list[str]]]:
    """A CSV of a run folder as sphdvi and DualSPHysics write them: gauge files (``;``), bodies.csv
    and run.csv (``,``), ``sphdvi measure ... --csv`` with either ``--sep`` (MeasureTool's layout:
    `` ;PosX [m]:;x0;x1...`` / PosY / PosZ rows before the column header, left out here), ``#``
    comment lines skipped; the separator read from the column-header line.  ``complete_only``: the
    text after the last line break is left out (the torn last row of a file a running run is
    appending to).  Returns the header and the rows (a trailing empty cell of DualSPHysics's
    ``a;b;`` lines dropped)."""
    try:
        with open(path, newline="", encoding="utf-8-sig") as fh:
            text = fh.read()
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot be read as a CSV text file ({getattr(exc, 'strerror', None) or exc})") from None
    if "\x00" in text:
        raise InputError(f"{path}: cannot be read as a CSV text file (it holds NUL bytes)")
    lines = text.replace("\r\n", "\n").split("\n")
    if complete_only or lines[-1] == "":
        lines = lines[:-1]
    lines = [ln for ln in lines if ln.strip() and not ln.lstrip().startswith("#") and not _POSITION_ROW.match(ln)]
    if not lines:
        return [], []
    sep = _guess_separator(lines[0], lines[1] if len(lines) > 1 else None)
    rows = list(csv.reader(lines, delimiter=sep))
    header = [c.strip() for c in rows[0]]
    if len(header) > 1 and header[-1] == "":
        header = header[:-1]
        rows = [rows[0]] + [r[:-1] if len(r) == len(header) + 1 and r[-1].strip() == "" else r for r in rows[1:]]
    return header, rows[1:]


def file_table(sweep: Sweep, names) -> tuple[list[list[str]], list[str]]:
    """The rows of every run's file(s) ``names`` (relative to the run folder), long format: index,
    the parameters (and ``file`` when several names), then the files' columns (their union, in
    order of appearance; a column named as a parameter gets the file's stem as prefix).  Returns
    the table and the runs that hold no such file ("run_0003/NAME"); a name no run folder holds
    (a typo): InputError.  A folder holding another run or an unreadable run.json: InputError."""
    lead = ["index", *sweep.keys] + (["file"] if len(names) > 1 else [])
    columns: list[str] = []
    body, missing = [], []
    for name in names:
        if os.path.isabs(name) or ".." in name.replace("\\", "/").split("/"):
            raise InputError(f"--file {name}: expected a file name inside each run folder (e.g. bodies.csv)")
    found = dict.fromkeys(names, 0)
    for i, values in enumerate(sweep.runs):
        entry_meta(sweep, i)
        for name in names:
            path = os.path.join(sweep.run_dir(i), name)
            if not os.path.isfile(path):
                missing.append(os.path.join(os.path.basename(sweep.run_dir(i)), name))
                continue
            found[name] += 1
            header, rows = read_run_csv(path)
            stem = os.path.splitext(os.path.basename(name))[0]
            header = [f"{stem}.{h}" if h in lead else h for h in header]
            for h in header:
                if h not in columns:
                    columns.append(h)
            for r in rows:
                body.append(([str(i), *values] + ([name] if len(names) > 1 else []), dict(zip(header, r))))
    absent = [n for n, k in found.items() if k == 0]
    if absent:
        raise InputError(f"--file {', '.join(absent)}: no run folder of {sweep.dir} holds it (nothing to collect); "
                         f"expected a file the runs write, e.g. run.csv, a gauge file (Gauges*.csv), bodies.csv")
    table = [lead + columns] + [prefix + [cells.get(c, "") for c in columns] for prefix, cells in body]
    return table, missing


def table_text(rows) -> str:
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerows(rows)
    return buf.getvalue()
