"""The simulation loop of ``sphdvi run``: time stepping, outputs, stability checks, resume.

Model (the SPH solver ``sphdvi.sph``, the multibody engine ``sphdvi.dvi``, their
coupling ``sphdvi.coupling``) ≠ simulation (this loop: output schedule, divergence
checks, when to checkpoint, resume) ≠ writers (``sphdvi.io``: particles.vtkhdf,
restart.h5 in ``io.checkpoint``, the text outputs in ``io.runfiles``). Outputs in OUT:

* ``particles.vtkhdf``: temporal VTKHDF PolyData, one step per TimeOut (live particles;
  those ``<special><outputparts>`` selects, :mod:`sphdvi.output_parts`);
* ``DtInfo.csv`` (and ``DtAllInfo.csv``) with ``<special><savedt>`` (:mod:`sphdvi.io.dtinfo`);
* ``run.json``: provenance and status, written at the start and at the end;
* ``run.log`` / ``run.csv``: one line per output time (like Run.out and RunPARTs.csv);
* ``restart.h5``: the complete solver state at the last output, written atomically;
  ``--resume`` continues from it (on 1 thread the result is bitwise that of an
  uninterrupted run), with the run's --tmax/--tout/--set (run.json ``overrides``);
* ``normals.vtp`` with mDBC: the boundary normals at the start (Normal, NormalSize, Mk).

A new run into an OUT holding an earlier run's results is refused unless ``--overwrite``
(which deletes them first); SIGTERM/SIGINT, start-up included, end a run as ``interrupted``.

A run that goes unstable (NaN or inf, dt held at DtMin, too many particles
excluded) stops with status ``diverged`` (exit code 3) and a message naming the
time, step, particle id, position and cause; what was written before stays.
"""
from __future__ import annotations

import contextlib
import json
import math
import os
import signal
import sys
import time as _time
import warnings
from dataclasses import dataclass

import numpy as np

from ._version import __version__
from .errors import CaseError, DivergenceError, InputError, SphdviError
from .run_checks import (and_list, box_text, check_boundary_in_domain, check_initial_density, fmt_vec, outside,
                         warn_inward_mdbc_normals, warn_thin_mdbc_walls, warn_undamped_mdbc)
from .run_options import absolute_file_sets, apply_overrides, conflicting_options, resolved_parameters
from .io.checkpoint import (RESTART_FILE, case_identity, checkpoint_time, load_bodies_checkpoint,
                            load_sph_checkpoint, save_bodies_checkpoint, save_sph_checkpoint)
from .io.atomic import make_folder, remove_leftover_temporaries
from .io.runfiles import BodyLog, ExcludedLog, Progress, RunFiles, startup_warnings_logged
from .io.dtinfo import DTINFO_FILE, DtLog
from .sph.periodic import PERIODIC_KEYS as PERIODIC_PARAM_KEYS      # numpy only
from .io.runfolder import (NORMALS_FILE, OVERWRITTEN_DIR, SetAside, check_new_run_folder, earlier_exports,
                           earlier_results, restored_on_bad_input, run_command, run_lock, stored_overrides)
from .sph.damping import damping_zones
from .output_parts import OutputParts
from .output_schedule import OutputSchedule
from .sph.clock import TIME_TOLERANCE, time_reached

POINT_ARRAYS = {"Idp": (np.int64, 1), "Vel": (np.float32, 3), "Rhop": (np.float32, 1),
                "Press": (np.float32, 1), "Type": (np.uint8, 1), "Mk": (np.int32, 1)}
DTMIN_STUCK_STEPS = 200
DEFAULT_MAX_EXCLUDED_FRACTION = 0.5
# fluid excluded in one time step beyond which the run stops: a step limited by the CFL
# condition moves a particle a fraction of h, so no flow loses a quarter of its fluid through
# the domain's limits or the density bounds at once; a far too large DtFixed does (at least
# MIN_EXCLUDED_PER_STEP particles, so that a case of a few particles does not stop for one)
MAX_EXCLUDED_PER_STEP = 0.25
MIN_EXCLUDED_PER_STEP = 10


@dataclass
class RunResult:
    status: str
    message: str
    exit_code: int
    steps: int
    physical_time: float
    runtime_s: float


def default_threads() -> int:
    """SLURM_CPUS_PER_TASK, else the CPU affinity of this process."""
    env = os.environ.get("SLURM_CPUS_PER_TASK")
    if env and env.isdigit() and int(env) > 0:
        return int(env)
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover
        return os.cpu_count() or 1


# ---------------------------------------------------------------------------------
# entry point
# ---------------------------------------------------------------------------------
def find_case_file(folder: str) -> str:
    """The gencase HDF5 file in a run folder (``format="sphdvi-case"``).  With none, an
    .h5 file that cannot be read (truncated, corrupt) is named in the error."""
    import h5py
    from .errors import h5_reason
    if not os.path.isdir(folder):
        raise InputError(f"{folder}: not a folder or case file")
    found, unreadable = [], []
    for name in sorted(os.listdir(folder)):
        if name.endswith(".h5") and name != RESTART_FILE:
            path = os.path.join(folder, name)
            try:
                with h5py.File(path, "r") as f:
                    if f.attrs.get("format") == "sphdvi-case":
                        found.append(path)
            except OSError as exc:
                unreadable.append(f"{path} ({h5_reason(exc)})")
    if not found and unreadable:
        raise InputError(f"{folder}: no readable gencase output: {'; '.join(unreadable)} cannot be read as HDF5 "
                         "(truncated or corrupt?); run 'sphdvi gencase' again")
    if not found:
        elsewhere = _case_file_of_run(folder)
        if elsewhere is not None:
            return elsewhere
        raise InputError(f"{folder}: no gencase output (<casename>.h5) found; run 'sphdvi gencase' first "
                         "or give the case XML")
    if len(found) > 1:
        raise InputError(f"{folder}: several case files ({', '.join(os.path.basename(f) for f in found)})")
    return found[0]


def _case_file_of_run(folder: str) -> str | None:
    """The gencase output a run in ``folder`` read, by its run.json's ``case_file``: a run of a
    gencase folder into another -o (``sphdvi run G -o OUT``) leaves OUT without one.  None when
    there is no such run.json or the file is no longer a gencase output."""
    import h5py
    try:
        with open(os.path.join(folder, "run.json")) as fh:
            path = json.load(fh)["case_file"]
        with h5py.File(path, "r") as f:
            return path if f.attrs.get("format") == "sphdvi-case" else None
    except (OSError, ValueError, KeyError, TypeError):
        return None


def periodic_axes(data: dict, params: dict) -> list[str]:
    """Periodic axes as DualSPHysics switches them on (:func:`sphdvi.sph.periodic.periodic_config`:
    a written ``*PeriodicInc*`` key, or a written XYPeriodic/XZPeriodic/YZPeriodic, whatever its
    value); a periodic y in a 2D case is an InputError."""
    return _periodic_config(data, params)[0]


def periodic_params(data: dict, params: dict) -> dict:
    """``params`` with the periodic keys as DualSPHysics applies them: the increments of the
    periodic axes (all 0 after XYPeriodic/XZPeriodic/YZPeriodic) and no pair key left, for
    the solver, which then takes the axes it is given."""
    incs = _periodic_config(data, params)[1]
    out = {k: v for k, v in params.items() if k not in PERIODIC_PARAM_KEYS}
    out.update(incs)
    return out




def _periodic_config(data: dict, params: dict):
    from .sph.periodic import periodic_config
    # the keys the case writes, and any given a value (--set XZPeriodic=1 is not in the case's list)
    written = set(data["json"].get("parameters_set", [])) | {k for k in PERIODIC_PARAM_KEYS if params.get(k)}
    try:
        return periodic_config(written, params, bool(data["constants"]["is2d"]))
    except ValueError as exc:
        raise InputError(f"case {data.get('casename') or ''}: <execution><parameters> {exc}; "
                         "expected x and/or z periodicity only in a 2D case") from None


def special_parameters(data: dict) -> dict:
    """Parameters with ``<special><shifting>`` applied: its mode, coefficient and fsthreshold set
    Shifting, ShiftCoef and ShiftTFS (the case reader refuses it together with a Shifting parameter,
    as DualSPHysics); its zones go to the solver (:func:`shift_zones`)."""
    params = dict(data["parameters"])
    shifting = (data["json"].get("special") or {}).get("shifting") or {}
    for key, name in (("mode", "Shifting"), ("coefficient", "ShiftCoef"), ("fsthreshold", "ShiftTFS")):
        if key in shifting:
            params[name] = shifting[key]
    return params


def shift_zones(data: dict) -> list:
    """The ``<shiftingzone>`` boxes of ``<special><shifting>`` as posref and edge vectors
    (rows); a gencase output of an older sphdvi kept them as written (size or vecx/vecy/vecz)."""
    zones = []
    for z in ((data["json"].get("special") or {}).get("shifting") or {}).get("zones") or []:
        if "vecs" not in z:
            if z.get("rotateaxis"):
                raise InputError("<shiftingzone> with <rotateaxis> in a gencase output of an older sphdvi: "
                                 "run 'sphdvi gencase' again")
            vecs = (np.diag(z["size"]) if "size" in z else [z["vecx"], z["vecy"], z["vecz"]])
            z = {"posref": z["posref"], "vecs": np.asarray(vecs, float).tolist()}
        zones.append(z)
    return zones


def output_schedule(data: dict, params: dict, tout=None) -> OutputSchedule:
    """The output times: the case's ``<special><timeout>`` rows, unless --tout (``tout``) asks
    for outputs TimeOut apart; without rows, TimeOut apart."""
    rows = (data["json"].get("special") or {}).get("timeout")
    if rows and tout is None:
        return OutputSchedule(rows)
    return OutputSchedule.every(float(params["TimeOut"]))


def resume_overrides(base: dict, outdir: str, tmax, tout, sets):
    """The --tmax/--tout/--set a --resume runs with: the interrupted run's (run.json), with
    --tmax replaced when given (a run may be extended); a --tout or --set that changes a
    parameter of the run is refused (a gap in the outputs, other physics)."""
    stored = stored_overrides(outdir)
    if stored is None:
        warnings.warn(f"--resume: {os.path.join(outdir, 'run.json')} does not say which --tmax/--tout/--set the "
                      "interrupted run used; the case's parameters and the options given now are used")
        return tmax, tout, tuple(sets or ())
    old_tmax, old_tout, old_sets = stored.get("tmax"), stored.get("tout"), tuple(stored.get("set") or ())
    if tout is None and not sets:
        return (old_tmax if tmax is None else tmax), old_tout, old_sets
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        before = apply_overrides(base, old_sets, None, old_tout)
        after = apply_overrides(base, old_sets + tuple(sets or ()), None, old_tout if tout is None else tout)
    changed = [k for k in sorted(set(before) | set(after))
               if k != "TimeMax" and not _same_value(before.get(k), after.get(k))]
    if changed:
        used = " ".join([f"--tout {old_tout:g}"] if old_tout is not None else []) + \
            "".join(f" --set {x}" for x in old_sets)
        diffs = ", ".join(f"{k} {before.get(k)!r} -> {after.get(k)!r}" for k in changed)
        raise InputError(f"--resume: the options given change the run ({diffs}); a resumed run goes on with the "
                         f"parameters it started with ({used.strip() or 'the case file'}; only --tmax may change). "
                         "Resume without them, or start a new run with --overwrite or another -o folder")
    return (old_tmax if tmax is None else tmax), old_tout, old_sets


def _warn_set_aside_left(outdir: str) -> None:
    """A command killed between setting an earlier run's files aside (--overwrite) and deleting
    them leaves them in OUT/.sphdvi-overwritten: say so, as they are out of sight there."""
    left = os.path.join(outdir, OVERWRITTEN_DIR)
    if os.path.isdir(left):
        warnings.warn(f"{left} holds the files of a run that an interrupted --overwrite set aside; move them back "
                      "into the folder to keep that run, or delete it")


def _check_resume_tmax(tmax: float, outdir: str) -> None:
    """``--resume --tmax`` below the time the run has reached is refused (the run was marked
    completed at a time past its TimeMax, and a later --resume kept that TimeMax), unless it is
    the TimeMax the run already had (a completed run resumed again: nothing to do)."""
    reached = checkpoint_time(os.path.join(outdir, RESTART_FILE))
    if reached is None or tmax >= reached * (1 - 1e-9):
        return
    with contextlib.suppress(OSError, ValueError, KeyError, TypeError):
        with open(os.path.join(outdir, "run.json")) as fh:
            if _same_value(float(json.load(fh)["parameters"]["TimeMax"]), tmax):
                return
    raise InputError(f"--tmax {tmax:g}: the run in {outdir} has reached t={reached:.6g} s (its last output): "
                     f"expected a --tmax beyond it to go on, or --resume without --tmax")


def _same_value(a, b) -> bool:
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    try:
        return bool(a == b)
    except ValueError:          # arrays
        return bool(np.array_equal(a, b))


def dem_coefficient_lines(dem, fluidcount: int) -> list:
    """One line per boundary block of a :class:`sphdvi.sph.dem.DemTable`: its mkbound, material,
    (1 − ν²)/E, restitution coefficient, Kfric and body mass (0 for a wall)."""
    out = []
    for mk in np.flatnonzero(dem.mat_of_mk >= 0):
        k = int(dem.mat_of_mk[mk])
        out.append(f"  mkbound {int(mk) - fluidcount - 1} (mk {int(mk)}): {dem.names[k]}  tau={dem.tau[k]:.6g} 1/Pa  "
                   f"restitution={dem.restitution[k]:g}  kfric={dem.kfric[k]:g}  mass={dem.body_mass[k]:g} kg")
    return out


def run(case_h5: str, outdir: str, *, tmax=None, tout=None, threads=None, sets=(), resume=False,
        quiet=False, expect_dp=None, overwrite=False, stop=None, set_aside=None) -> RunResult:
    """Run a gencase output: body-only cases go to the multibody engine, the rest to SPH.

    ``expect_dp``: a dp the user gave where no gencase runs (a gencase folder, --resume);
    it must be the case's, else InputError.  A new run into a folder with an earlier run's
    results is refused unless ``overwrite``: they are set aside (:class:`SetAside`; the caller's
    ``set_aside`` when it made one), put back if the run stops on bad input before its start-up
    is through, deleted once it is; ``--resume`` reuses the
    --tmax/--tout/--set of the interrupted run.  ``stop``: a :class:`_Stop` the caller
    installed before its own start-up work (a signal then interrupts the run cleanly).  The
    start-up's warnings go to run.log too (:func:`startup_warnings_logged`)."""
    files = RunFiles(outdir)
    with run_lock(outdir), startup_warnings_logged(files):    # no second run into OUT meanwhile
        return _run(files, case_h5, outdir, tmax=tmax, tout=tout, threads=threads, sets=sets, resume=resume,
                    quiet=quiet, expect_dp=expect_dp, overwrite=overwrite, stop=stop, set_aside=set_aside)


def _run(files: RunFiles, case_h5: str, outdir: str, *, tmax, tout, threads, sets, resume, quiet, expect_dp,
         overwrite, stop, set_aside) -> RunResult:
    from .io.casefile import read_case_h5
    t_start = _time.perf_counter()
    data = read_case_h5(case_h5)
    if expect_dp is not None:
        _check_dp(expect_dp, data, case_h5, resume)
    base = special_parameters(data)
    conflicting_options(sets, tmax, tout)
    if resume and not os.path.exists(os.path.join(outdir, RESTART_FILE)):
        started = os.path.exists(os.path.join(outdir, "run.json"))
        again = run_command(os.path.dirname(case_h5) or ".", outdir, tmax=tmax, tout=tout, sets=sets,
                            extra="--overwrite" if started else "")
        raise InputError(f"--resume: {outdir} holds no run to continue (no {RESTART_FILE}"
                         + ("; its run stopped before its first output" if started else "") + f"); start it with "
                         f"{again}")
    sets = absolute_file_sets(sets)
    if resume:
        if tmax is not None:
            _check_resume_tmax(float(tmax), outdir)
        tmax, tout, sets = resume_overrides(base, outdir, tmax, tout, sets)
    params = apply_overrides(base, sets, tmax, tout)
    _check_rigid_algorithm(data, params, sets)
    out_times = output_schedule(data, params, tout)
    threads = _usable_threads(threads)
    nfluid = int(np.count_nonzero(data["particles"]["type"] == 3))
    # inlet/outlet zones bring fluid of their own: such a case is an SPH run even with none drawn
    # so do the DEM contacts (RigidAlgorithm 2), which the SPH interaction computes: DualSPHysics's
    # 14_DEM Bowling and ManyFloatings have no fluid
    dem = int(params.get("RigidAlgorithm", 1) or 1) == 2 and bool((data["particles"]["type"] == 2).any())
    # and so do flexible structures (DualSPHysics's CaseTurekHronCSM3 has no fluid)
    special = data["json"].get("special") or {}
    sph_run = nfluid > 0 or bool(special.get("inout")) or dem or bool(special.get("flexstrucs"))
    if sph_run:
        _check_dtfixed(float(params.get("DtFixed") or 0.0), params)
    if not resume:
        check_new_run_folder(outdir, overwrite)
    make_folder(outdir)
    remove_leftover_temporaries(outdir)
    if not overwrite:                  # with --overwrite a new set-aside replaces it
        _warn_set_aside_left(outdir)
    if not resume and set_aside is None:
        set_aside = SetAside(outdir, earlier_results(outdir) + earlier_exports(outdir))
    if set_aside is not None:
        files.on_start = set_aside.discard     # the new run's start-up passed its checks
    base_meta = {
        "version": __version__, "case": data["casename"], "case_file": os.path.abspath(case_h5),
        **resolved_parameters(params, data["constants"], sph_run, _structure_sound_speed(special),
                              no_fluid=nfluid == 0 and not special.get("inout")),
        "overrides": {"tmax": tmax, "tout": tout, "set": list(sets or ())},
        "threads": threads, "particles": int(data["particles"]["type"].size),
        "fluid_particles": nfluid, "python": sys.version.split()[0], "numpy": np.__version__,
    }
    with restored_on_bad_input(set_aside), \
            (contextlib.nullcontext(stop) if stop is not None else _Stop()) as stop:
        if not sph_run:
            return _run_bodies_only(data, params, out_times, outdir, files, base_meta, t_start, quiet, resume, stop)
        return _run_sph(data, params, out_times, outdir, files, base_meta, threads, resume, quiet, t_start, stop)


def _structure_sound_speed(special: dict) -> float:
    """The largest sound speed of the case's flexible structures (0 without), which sets DtIni and DtMin
    where it exceeds the fluid's (sphdvi.sph.solver)."""
    bodies = special.get("flexstrucs") or []
    if not bodies:
        return 0.0
    from .sph.flexstruc import sound_speed
    return max(sound_speed(b["youngmod"], b["poissratio"], b["density"]) for b in bodies)


def _stopped_at_startup(stop, files: RunFiles, meta: dict, outdir: str, resume: bool):
    """A signal caught before the time loop: run.json says ``interrupted``; the RunResult
    (exit 1), or None when no signal came."""
    if stop is None or stop.signal is None:
        return None
    if os.path.exists(os.path.join(outdir, RESTART_FILE)) and resume:
        message = (f"stopped by signal {stop.signal} during start-up; resume with 'sphdvi run {outdir} --resume'")
    else:
        given = meta.get("overrides") or {}
        again = run_command(os.path.dirname(meta.get("case_file") or outdir) or ".", outdir, tmax=given.get("tmax"),
                            tout=given.get("tout"), sets=given.get("set"), extra="--overwrite")
        message = (f"stopped by signal {stop.signal} during start-up, before the first output: nothing to resume; "
                   f"run again with {again}")
    if resume and not files.meta:
        with contextlib.suppress(OSError, ValueError):
            with open(files.json_path) as fh:
                files.meta = dict(json.load(fh))
    if not resume:
        files.start()
    files.log(f"interrupted: {message}")
    files.write_json(**meta, status="interrupted", message=message)
    return RunResult("interrupted", message, 1, int(files.meta.get("steps", 0) or 0),
                     float(files.meta.get("physical_time", 0.0) or 0.0), float(files.meta.get("runtime_s", 0.0) or 0.0))


def _check_dp(dp: float, data: dict, case_h5: str, resume: bool) -> None:
    """--dp where gencase does not run: only the case's own dp (a no-op) is accepted."""
    case_dp = float(data["constants"]["dp"])
    if abs(float(dp) - case_dp) <= 1e-9 * case_dp:
        return
    where = "--resume continues the run of" if resume else "a gencase output folder holds"
    raise InputError(f"--dp {dp:g}: {where} the case {case_h5}, drawn at dp={case_dp:g}; a new dp needs gencase: "
                     f"run 'sphdvi run CASE.xml --dp {dp:g} -o NEWOUT' (or 'sphdvi gencase CASE.xml --dp {dp:g}')")


def _usable_threads(threads) -> int:
    """--threads (or the default), at most numba's thread count NUMBA_NUM_THREADS: more is
    clamped with a warning, and run.json records the count used."""
    if not threads:
        wanted, given = default_threads(), False
    else:
        wanted, given = int(threads), True
    from numba import config
    limit = max(1, int(config.NUMBA_NUM_THREADS))
    if wanted > limit:
        if given:
            warnings.warn(f"--threads {wanted}: numba runs at most {limit} threads here (NUMBA_NUM_THREADS); "
                          f"using {limit}")
        elif os.environ.get("SLURM_CPUS_PER_TASK") == str(wanted):
            warnings.warn(f"SLURM_CPUS_PER_TASK={wanted}: numba runs at most {limit} threads here "
                          f"(NUMBA_NUM_THREADS, the CPUs this process may use); using {limit}")
        wanted = limit
    return wanted


def _check_rigid_algorithm(data: dict, params: dict, sets) -> None:
    """RigidAlgorithm 3 (Chrono) needs the case's <special><chrono> section, as gencase checks for
    the XML's value: a ``--set RigidAlgorithm=3`` on a case without one is refused."""
    if params.get("RigidAlgorithm") == 3 and not data["json"].get("chrono"):
        given = any(str(s).split("=", 1)[0].strip() == "RigidAlgorithm" for s in sets or ())
        raise InputError(("--set RigidAlgorithm=3" if given else "RigidAlgorithm=3") +
                         ": Chrono needs an <execution><special><chrono> section, which this case has not; "
                         "expected RigidAlgorithm 0 or 1, or a <chrono> section in the case file (then gencase again)")


def _check_dtfixed(dt: float, params: dict, what: str = "DtFixed") -> None:
    """A fixed step longer than the whole run is refused (the run would take no step, or one
    step far past TimeMax); one longer than TimeOut is warned about (every step is then an
    output, DtFixed apart instead of TimeOut)."""
    if not dt > 0:
        return
    tmax, tout = float(params["TimeMax"]), float(params["TimeOut"])
    if tmax > 0 and dt > tmax * (1 + 1e-9):
        raise InputError(f"{what} ({dt:g} s) is longer than the whole run (TimeMax {tmax:g} s): the run cannot "
                         f"reach TimeMax in steps of {dt:g} s; expected DtFixed <= TimeMax (or a longer --tmax)")
    if dt > tout * (1 + 1e-9):
        warnings.warn(f"{what} ({dt:g} s) is longer than TimeOut ({tout:g} s): every step is an output, and the "
                      f"outputs are {dt:g} s apart")


def _run_bodies_only(data, params, out_times, outdir, files, meta, t_start, quiet, resume=False,
                     stop=None) -> RunResult:
    """A case with bodies and no fluid: the multibody engine alone, DtFixed steps (default
    1e-3 s), with the outputs, logs, checks, checkpoints and resume of an SPH run."""
    stopped = _stopped_at_startup(stop, files, meta, outdir, resume)
    if stopped is not None:
        return stopped
    from .dvi.runner import StepSchedule, build_system
    from .mechanism import mechanism_from_case
    from .motion import MotionSet
    js = data["json"]
    motions = MotionSet(js.get("motions", []), js.get("special", {}).get("wavepaddles", []))
    mech = mechanism_from_case(data, motions)
    if not mech["bodies"]:
        raise InputError("the case has neither fluid nor bodies: nothing to simulate")
    if js.get("special", {}).get("moorings"):
        raise InputError("<special><moorings>: mooring lines in a body-only run (no fluid) are not supported by "
                         "sphdvi (expected a case with fluid, whose floating bodies the lines hold)")
    dt = params["DtFixed"] if params["DtFixed"] > 0 else 1e-3
    _check_dtfixed(dt, params, "DtFixed" if params["DtFixed"] > 0 else "the default step of a body-only run")
    tout = out_times.rows[0][1] if out_times.uniform else float(params["TimeOut"])
    extra = params.get("TimeOutExtra")
    schedule = StepSchedule(float(params["TimeMax"]), tout, dt,
                            extra if extra is not None and extra >= 0 else None,
                            None if out_times.uniform else out_times)
    system, names = build_system(mech["bodies"], mech["links"], mech["materials"], **mech["system"])
    if not system._packed:
        system._pack()
    run = BodiesOnlyRun(system, names, schedule, outdir, files, case_identity(data["particles"], data["constants"]))
    run.watch = _body_watch(data, params, system, names, mech)
    if resume:
        run.resume()
    else:
        files.start()
    for line in mech["warnings"]:           # inertia far below m L2, contact mass ratios (bodychecks)
        files.log("WARNING: " + line)
        warnings.warn(line)
    for section in ("savedt", "outputparts"):
        if js.get("special", {}).get(section):
            line = (f"<special><{section}>: a body-only run (no fluid) has no SPH time step or particle output "
                    f"to {'record' if section == 'savedt' else 'filter'}; ignored (its steps are DtFixed, {dt:g} s)")
            files.log("WARNING: " + line)
            warnings.warn(line)
    notice = _CompileNotice(None if quiet else sys.stderr)
    try:
        jit_s = _warm_up_bodies(system, dt)
    finally:
        notice.done()
    stopped = _stopped_at_startup(stop, files, meta, outdir, resume)     # a signal during the JIT
    if stopped is not None:
        return stopped
    files.write_json(**meta, mode="bodies", status="running", message="", dt=dt, steps=run.step,
                     physical_time=float(run.system.time), runtime_s=run.runtime,
                     startup_s=_time.perf_counter() - t_start, jit_s=jit_s, bodies=len(names),
                     links=len(system.links))
    return run.run(float(params["TimeMax"]), quiet, stop)


def _body_watch(data, params, system, names, mech):
    """The run-time checks of a body-only run (:class:`sphdvi.bodychecks.BodyWatch`): finite
    states, joints, embedded contacts and the simulation domain (:func:`_bodies_domain`)."""
    from .bodychecks import BodyWatch
    domain = _bodies_domain(data, params)
    return BodyWatch(system, names, mech["mkbounds"], mech["sizes"], mech["dp"], mech["points"], domain)


def _bodies_domain(data, params):
    """The simulation domain of a body-only run, (posmin, posmax, what): along an axis that
    ``<simulationdomain>`` sets to a number, that number, as an SPH run's; where it says ``default``
    (DualSPHysics's default, the particles' extent plus 0.05 h, which a swinging pendulum leaves at
    once: DualSPHysics runs no case without fluid), the drawing box ``<definition>``
    pointmin..pointmax, outside which the case has nothing, and ``default ± v`` / ``default ± v%``
    relative to that box (JSph::ResizeMapLimits' rule, v % of its extent, on the box a body-only
    run takes for default); a 2D case widened by h along y as the SPH run's; unbounded along a
    periodic axis or where the limit cannot be read.  ``what`` says where each limit came from."""
    import xml.etree.ElementTree as ET
    from .case.reader import parse_domain_spec
    c = data["constants"]
    dom = data.get("domain") or {}
    if dom.get("posmin") is None or dom.get("posmax") is None:
        return None
    lo, hi = np.array(dom["posmin"], float), np.array(dom["posmax"], float)
    try:
        root = ET.fromstring(data.get("source_xml") or "")
    except (ET.ParseError, TypeError, ValueError):
        root = None

    def attr(path, a):
        el = root.find(path) if root is not None else None
        return None if el is None else el.get(a)
    what = []
    for i, a in enumerate("xyz"):
        try:
            box = [float(attr(f"casedef/geometry/definition/{p}", a)) for p in ("pointmin", "pointmax")]
        except (TypeError, ValueError):
            box = None
        parts = []
        for k, (bound, key) in enumerate(((lo, "posmin"), (hi, "posmax"))):
            spec = attr(f"execution/parameters/simulationdomain/{key}", a)
            text = (spec or "default").replace(" ", "").lower()
            if not text.startswith("default"):
                parts.append(f"{bound[i]:g}")
                continue                                # the case's own limit
            if box is None:
                bound[i] = -np.inf if key == "posmin" else np.inf
                parts.append("unbounded")
                continue
            bound[i] = parse_domain_spec(text, box[k], box[1] - box[0])
            rel = "" if text == "default" else f" {text[7]} {text[8:]}"
            if rel.endswith("%"):
                rel += f" of {box[1] - box[0]:g}"
            parts.append(f"{bound[i]:g} (<definition>{f' {box[k]:g}' + rel if rel else ''})")
        what.append(f"{a} {parts[0]} .. {parts[1]}")
    if c["is2d"]:
        lo[1] = min(lo[1], float(c["posy2d"])) - c["h"]
        hi[1] = max(hi[1], float(c["posy2d"])) + c["h"]
        what[1] = f"y {lo[1]:g} .. {hi[1]:g} (2D: posy2d +- h)"
    for k in periodic_axes(data, params):
        lo["xyz".index(k)], hi["xyz".index(k)] = -np.inf, np.inf
        what["xyz".index(k)] = f"{k} periodic"
    return lo, hi, "; ".join(what)


def _warm_up_bodies(system, dt: float) -> float:
    """Compile (or load from cache) the multibody kernels on a throw-away copy of the System, two
    steps of ``dt`` and the kernels of a first contact, so that runtime_s holds no JIT (37 s of a 38 s
    pendulum run on an empty cache). A copy that blows up (an absurd load: a NaN state, an error in a
    kernel) is dropped and the steps are taken again without the imposed loads; whatever that copy
    does, the run's own loop reports it (a divergence, exit 3)."""
    import copy
    from .bodychecks import BodyWatch
    t0 = _time.perf_counter()
    for neutral in (False, True):
        clone = copy.deepcopy(system)
        if neutral:
            clone._load_fn = []
            clone.f_ext[:] = 0.0
            clone.t_ext[:] = 0.0
        try:
            with np.errstate(all="ignore"), warnings.catch_warnings():
                warnings.simplefilter("ignore")
                clone.step(dt)
                clone.step(dt)
                BodyWatch(clone, clone.names).after_step(2)     # its compiled checks too
        except Exception:           # noqa: BLE001 -- only compiling here
            continue
        if np.isfinite(clone.pos).all() and np.isfinite(clone.quat).all():
            break
    copy.deepcopy(system).compile_contact_kernels()       # on zero contacts: the state does not matter
    return _time.perf_counter() - t0


# wall time between two checkpoints of a body-only run: its outputs are often a few steps of
# microseconds apart, and an HDF5 checkpoint costs ~0.85 ms (the pendulum case, 901 outputs:
# 1.3 s with one at every output against 0.26 s without)
BODIES_CHECKPOINT_EVERY_S = 1.0


class BodiesOnlyRun:
    """The time loop of a body-only run: one System step of ``schedule.dt`` at a time; at each
    output a run.csv/run.log line, the bodies.csv/links.csv rows (:class:`BodyLog`, appended)
    and the System's state to ``restart.h5`` (atomic); TimeOutExtra rows in between; the
    first non-finite body state stops the run (diverged, exit 3); SIGTERM/SIGINT stop it at
    the next step (interrupted, resumable)."""

    def __init__(self, system, names, schedule, outdir: str, files: RunFiles, case_id: dict | None = None):
        self.system, self.names, self.schedule = system, list(names), schedule
        self.case_id = case_id or {}     # written into restart.h5; --resume checks it
        self.outdir, self.files = outdir, files
        self.ckpt = os.path.join(outdir, RESTART_FILE)
        self.part = 0            # outputs written (TimeOut), t = 0 being part 0
        self.step = 0
        self.runtime = 0.0       # wall time of the time stepping, over all the resumed pieces
        self.resumed = False
        self._at_output = None   # (state, scalars) of the latest output not yet in restart.h5
        self._ckpt_wall = -math.inf      # the first output of a run is always written
        self.watch = None        # the run-time checks (bodychecks.BodyWatch; None: finite states only)

    def resume(self) -> None:
        """Continue from the last output: the System's state from restart.h5 (into the System
        the case builds), run.csv and run.log cut back to that output; bodies.csv/links.csv
        are cut when the run starts."""
        if not os.path.exists(self.ckpt):
            raise InputError(f"--resume: no checkpoint {self.ckpt} in {self.outdir}")
        saved = load_bodies_checkpoint(self.ckpt, self.system, self.case_id or None, self.names)
        if saved["names"] != self.names:
            raise InputError(f"--resume: {self.ckpt} holds the bodies {saved['names']}, the case {self.names}")
        self.part, self.step, self.runtime = int(saved["part"]), int(saved["step"]), float(saved["runtime_s"])
        self.resumed = True
        self.files.load_existing(self.part + 1)
        self.files.log(f"resumed from part {self.part} at t={self.system.time:.6g} s, step {self.step}")

    def _write_part(self, wall: float, stepped: bool, last: bool = False) -> None:
        s, dt = self.system, self.schedule.dt if stepped else 0.0
        self.files.csv(f"{self.part},{s.time:.9g},{self.step},0,0,{dt:.6g},{dt:.6g},{wall:.3f}")
        self.files.log(f"Part {self.part:04d}  t={s.time:.6f} s  steps={self.step}  bodies={len(self.names)}  "
                       f"links={len(s.links)}  dt={dt:.3g} s  wall={wall:.2f} s")
        self.body_log.record()
        # the state at this output, kept in memory; written out at most every
        # BODIES_CHECKPOINT_EVERY_S of wall time, at the last output and when the run stops
        self._at_output = (s.get_state(), dict(part=self.part, step=self.step, runtime_s=wall, names=self.names,
                                                 **self.case_id))
        now = _time.perf_counter()
        if last or now - self._ckpt_wall >= BODIES_CHECKPOINT_EVERY_S:
            self._checkpoint()
            self._ckpt_wall = now

    def _checkpoint(self) -> None:
        """Write the state of the latest output to restart.h5 (once)."""
        if self._at_output is not None:
            state, extra = self._at_output
            save_bodies_checkpoint(self.ckpt, state, **extra)
            self._at_output = None

    def run(self, tmax: float, quiet: bool, stop=None) -> RunResult:
        from .bodychecks import BodyWatch, solver_hint
        s, sch, files = self.system, self.schedule, self.files
        if self.watch is None:
            self.watch = BodyWatch(s, self.names)
        s.defer_warnings = True
        self.body_log = BodyLog(self.outdir, s, self.names, float(s.time) if self.resumed else None)
        progress = Progress(tmax, quiet, counts="bodies")
        wall_prev = self.runtime
        t_loop = _time.perf_counter()
        status, code, message = "completed", 0, ""
        with (contextlib.nullcontext(stop) if stop is not None else _Stop()) as stop:
            try:
                if not self.resumed:
                    self._write_part(wall_prev, stepped=False)
                stepped = False
                while self.step < sch.nsteps:
                    try:
                        s.step(sch.dt)
                    except Exception:
                        self.watch.check_finite(self.step + 1)     # a kernel failing on a blown-up state
                        raise
                    self.step += 1
                    stepped = True
                    try:
                        self.watch.after_step(self.step)    # finite, joints, domain, embedded contacts
                    finally:
                        for line in s.take_warnings():      # an unconverged solve: run.log and stderr
                            line = solver_hint(line)
                            files.log("WARNING: " + line)
                            if not quiet:
                                warnings.warn(line)
                    if sch.is_output(self.step):
                        self.part += 1
                        self._write_part(wall_prev + (_time.perf_counter() - t_loop), stepped,
                                         last=self.step == sch.nsteps)
                        stepped = False
                    elif sch.is_row(self.step):
                        self.body_log.record(flush=False)      # TimeOutExtra rows wait for the output
                    progress.update(s.time, self.step, len(self.names), dt=sch.dt)
                    if stop.signal is not None:
                        status, code, message = "interrupted", 1, _interrupted(stop.signal, s.time, self.outdir,
                                                                               self.part)
                        break
            except DivergenceError as exc:
                status, code, message = "diverged", 3, str(exc)
            except BaseException as exc:
                self.runtime = wall_prev + (_time.perf_counter() - t_loop)
                _clean_up_after_failure(
                    self._checkpoint, progress.close,
                    lambda: files.write_json(status="failed", message=f"{type(exc).__name__}: {exc}",
                                             steps=self.step, physical_time=float(s.time), runtime_s=self.runtime))
                _raise_if_disk_full(exc, self.outdir, float(s.time), self.step, self.part)
                raise
        self._checkpoint()           # the latest output, if the throttle held it back
        self.runtime = wall_prev + (_time.perf_counter() - t_loop)
        progress.update(s.time, self.step, len(self.names), force=True, dt=sch.dt)
        progress.close()
        files.log(f"{status}: t={s.time:.6g} s, {self.step} steps, runtime {self.runtime:.2f} s"
                  + (f" -- {message}" if message else ""))
        files.write_json(status=status, message=message, steps=self.step, physical_time=float(s.time),
                         runtime_s=self.runtime, outputs=self.part + 1)
        return RunResult(status, message, code, self.step, float(s.time), self.runtime)


def _interrupted(signum, t: float, outdir: str, part: int) -> str:
    """The message of a run stopped by a signal."""
    return f"stopped by signal {signum} at t={t:.6g} s; resume with 'sphdvi run {outdir} --resume' from part {part}"


# ---------------------------------------------------------------------------------
# SPH run
# ---------------------------------------------------------------------------------
class ExclusionWarnings:
    """DualSPHysics's warnings on excluded particles (``WrnPartsOut``, JSph::SaveData): at
    each output, when the particles excluded since the previous output reach P % of the
    fluid (P = 1, then 2, 5, 10, 20, ...: each level warns once), and when all particles
    excluded so far reach Q % of all particles (Q = 10, 20, ...)."""

    def __init__(self, enabled: bool, case_nfluid: int, total_np: int):
        self.enabled = enabled
        self.case_nfluid = case_nfluid
        self.total_np = total_np
        self.part_pct = 1
        self.total_pct = 10

    def check(self, new_out: int, nfluid_now: int, total_out: int, t: float, nstep: int) -> list[str]:
        """The warnings of one output (``new_out`` excluded since the previous one)."""
        out = []
        if not self.enabled or new_out <= 0:
            return out
        if self.part_pct <= 100 and new_out >= max(self.case_nfluid, nfluid_now) * self.part_pct / 100.0:
            out.append(f"more than {self.part_pct}% of the fluid particles were excluded since the "
                       f"previous output (t={t:.6g} s, step {nstep})")
            self.part_pct = {1: 2, 2: 5, 5: 10}.get(self.part_pct, self.part_pct + 10)
        if self.total_pct <= 100 and total_out >= self.total_np * self.total_pct / 100.0:
            out.append(f"more than {self.total_pct}% of the particles were excluded "
                       f"(t={t:.6g} s, step {nstep})")
            self.total_pct += 10
        return out


class SPHRun:
    """One SPH run: the solver, its motion/body hook, the output schedule and the checks."""

    inout = None            # the run's inlet/outlet zones (sphdvi.sph.inout.InOut), when the case has them
    relax = ()              # the run's relaxation zones (sphdvi.sph.relaxzones), when the case has them

    @staticmethod
    def _place_paddles(motions, p: dict, fluidcount: int) -> None:
        """Each wave paddle learns where its front face is at rest (a focused piston counts its focus
        from it, every paddle its ``<savemotion xpos>``); a focus behind the face is an InputError."""
        try:
            motions.place_paddles_from_particles(p, fluidcount)
        except ValueError as exc:
            raise InputError(f"<piston_focused>: {exc}") from None

    def __init__(self, data: dict, params: dict, outdir: str, resume: bool = False):
        from .motion import MotionSet
        from .sph.solver import SPHSolver
        from .coupling import FloatingBodies, ImposedMotions, body_labels
        from .sph.state import FluidState
        self.data = data
        self.params = params
        self.outdir = outdir
        p = data["particles"]
        c = dict(data["constants"])
        if "CFLnumber" in params:           # --set CFLnumber: only the time step reads it
            c["cflnumber"] = float(params["CFLnumber"])
        self.consts = c
        fluidcount = int(data["json"]["mkconfig"]["fluidcount"])
        if not resume:          # the initial state's densities (a resumed run's are its own)
            check_initial_density(p["rhop"][p["type"] == 3], params)
        state = FluidState(p["pos"], p["vel"], p["rhop"], p["mass"], p["type"], p["idp"], p["mk"],
                           rhop0=c["rhop0"])
        js = data["json"]
        motions = MotionSet(js.get("motions", []), js.get("special", {}).get("wavepaddles", []),
                            g=float(np.linalg.norm(c["gravity"])))
        self._place_paddles(motions, p, fluidcount)
        if any(paddle.spec.get(k) for paddle in motions.paddles.values()
               for k in ("savemotion", "saveserie", "saveseriewaves")):
            from .io.paddle_motion import write_paddle_motions
            write_paddle_motions(outdir, motions, float(params["TimeMax"]), float(params["TimeOut"]))
        domain = (np.asarray(data["domain"]["posmin"], float), np.asarray(data["domain"]["posmax"], float))
        if c["is2d"]:
            domain[0][1] -= c["h"]
            domain[1][1] += c["h"]
        periodic = periodic_axes(data, params)
        if periodic:
            params = periodic_params(data, params)      # DualSPHysics's increments (reset by XZPeriodic...)
        for k in periodic:
            i = "xyz".index(k)
            domain[1][i] += c["dp"]
        if periodic:
            from .sph.periodic import Periodicity
            try:
                Periodicity(periodic, p["pos"], float(c["dp"]), params).check_length(2.0 * float(c["h"]))
            except ValueError as exc:
                raise InputError(str(exc)) from None
        check_boundary_in_domain(p, domain, fluidcount)
        self.inout = None
        if js.get("special", {}).get("inout"):
            p, state = self._place_inout_buffers(js["special"]["inout"], data, c, domain, periodic)
        normals0 = None
        if int(params.get("Boundary", 1)) == 2:
            from .case.normals import boundary_normals
            from .sph.periodic import Periodicity
            axes = periodic
            if data.get("normals") is not None:       # the case's own (<normals>, <initialize>)
                normals0 = np.array(data["normals"], dtype=np.float64)
                if not np.any(normals0[p["type"] != 3]):
                    raise InputError("Boundary=2 (mDBC), but the normals the case defines (<normals>, <special>"
                                     "<initialize>) reach no boundary particle: nothing for mDBC to correct "
                                     "(expected operations that reach the walls, within maxdisth/distanceh h)")
            else:
                normals0 = boundary_normals(p["pos"], p["type"], float(c["dp"]), bool(c["is2d"]),
                                            Periodicity(axes, p["pos"], float(c["dp"]), params) if axes else None)
            normals0 = self._mdbc_only_on(normals0, p, fluidcount, str(params.get("MdbcMkbound") or "").strip())
            from .case.normals import (ghosts_in_own_wall, inward_normal_mkbounds, layers_needed,
                                       mdbc_floating_mask, thin_wall_mkbounds)
            labels = body_labels(p["mk"], fluidcount)
            args = (p["pos"], normals0, p["type"], labels, float(c["dp"]), float(c["h"]))
            mask = ghosts_in_own_wall(*args)
            inward = inward_normal_mkbounds(*args, inward=mask)
            warn_inward_mdbc_normals(inward, float(c["dp"]))
            thin = thin_wall_mkbounds(*args, inward=mask)
            warn_thin_mdbc_walls({mk: v for mk, v in thin.items() if mk not in inward},
                                  layers_needed(float(c["h"]), float(c["dp"])), float(c["h"]) / float(c["dp"]))
            state.mass[mdbc_floating_mask(p["type"], labels, params, normals0)] = float(c["massbound"])
            warn_undamped_mdbc(params, p, normals0, c)
        # the solids that move boundary particles, and the damping zones: each only when
        # the case has it
        flex_specs = js.get("special", {}).get("flexstrucs") or []
        flex_mks = [int(b["mkbound"]) for b in flex_specs]
        if flex_specs:
            self._check_flex_parameters(params, periodic)
        # the flexible structures' particles are moved by their solid, not by their motion
        moved_by_motion = (p["type"] == 1) & ~np.isin(body_labels(p["mk"], fluidcount), flex_mks)
        self.moving = (ImposedMotions(motions, p["pos"].copy(), fluidcount, normals0, skip_mkbounds=flex_mks)
                       if moved_by_motion.any() else None)
        self.floating = (FloatingBodies(data, motions, fluidcount, normals0, float(params.get("FtPause", 0.0)))
                         if (p["type"] == 2).any() else None)
        if self.floating is not None and self.floating.moorings is not None and periodic:
            raise InputError("<special><moorings> with periodic boundaries is not supported by sphdvi: a moored body "
                             "crossing a periodic end would drag its lines across the domain (expected a case "
                             "without the *Periodic* parameters)")
        if self.floating is not None and periodic and not resume:   # DualSPHysics: not on a restart either
            from .sph.periodic import Periodicity
            self.floating.check_radius(Periodicity(periodic, p["pos"], float(c["dp"]), params),
                                       ignore=int(params.get("FtIgnoreRadius", 0) or 0) != 0)
        self.bodies = self.floating.system if self.floating is not None else None
        if self.bodies is not None:
            self.bodies.defer_warnings = True        # its lines come through take_step_warnings
        self.body_names = self.floating.names if self.floating is not None else None
        self.damping = damping_zones(js.get("special", {}).get("damping", []))
        self.relax = self._relaxation_zones(js.get("special", {}).get("relaxationzones"), state, c, params)
        from .wave_absorption import piston_absorbers
        self.absorbers = piston_absorbers(motions, data, params) if self.moving is not None else []
        hook = (self._hook if (self.moving is not None or self.floating is not None or self.damping or self.relax)
                else None)
        dt_table = None
        if str(params.get("DtFixedFile", "NONE")).upper() != "NONE":
            from .case.datafiles import read_dt_table
            dt_table = read_dt_table(str(params["DtFixedFile"]))
        visco_table = None
        if str(params.get("ViscoTime") or "").strip():
            from .case.datafiles import read_visco_table
            visco_table = read_visco_table(str(params["ViscoTime"]))
        from .sph.accinput import acc_inputs
        bound_corr = self._bound_corr(js.get("special", {}).get("boundcorr"), p, c, fluidcount)
        if not float(c["cs0"]) > 0.0:
            raise InputError(f"the speed of sound c0 is {float(c['cs0']):g} m/s (speedsystem {float(c['speedsystem']):g} "
                             f"m/s: sqrt(|g| hswl) with |g| = {float(np.linalg.norm(c['gravity'])):g} and hswl = "
                             f"{float(c['hswl']):g} m): an SPH run needs c0 > 0 (expected <speedsystem value=\"..\" "
                             "auto=\"false\"/> or <speedsound value=\"..\" auto=\"false\"/> in <constantsdef>, "
                             "then gencase again)")
        dem = None
        if int(params.get("RigidAlgorithm", 1) or 1) == 2 and self.floating is not None:
            if js.get("chrono"):
                from .case.gencase import DEM_WITH_CHRONO
                raise InputError(f"{DEM_WITH_CHRONO} (expected RigidAlgorithm 3, or a case without <chrono>)")
            from .mechanism import dem_table
            try:
                dem = dem_table(data)
            except CaseError as exc:
                raise InputError(f"RigidAlgorithm 2 (DEM): {exc.message} (expected {exc.expected})") from None
        flex = self._flexible_structures(flex_specs, p, c, params, fluidcount) if flex_specs else None
        self.solver = SPHSolver(state, c, params, domain=domain, motion_hook=hook, periodic=periodic or None,
                                normals=normals0, dt_table=dt_table, visco_table=visco_table,
                                acc_inputs=acc_inputs(js.get("special", {}).get("accinputs")),
                                shift_zones=shift_zones(data), inout=self.inout, bound_corr=bound_corr, dem=dem,
                                flex=flex)
        if self.floating is not None:       # Symplectic: the bodies at the half step for the corrector
            self.solver.half_step_hook = self.floating.predict
        for absorber in self.absorbers:
            bias = absorber.calibrate(state)
            if abs(bias) > float(c["dp"]):
                warnings.warn(f"<awas_zsurf> of the piston mkbound={absorber.paddle.spec['mkbound']}: the still water "
                              f"at its gauge is at z = {absorber.level0:.6g} m, {bias:+.3g} m from <swl> "
                              f"{absorber.swl:g}; the absorber measures the elevation from the water's level")
        self.n0_fluid = int(np.count_nonzero(p["type"] == 3))
        self.excluded_limit = self.max_excluded()      # the parameters do not change in a run
        self.excluded_step_limit = max(MIN_EXCLUDED_PER_STEP, int(MAX_EXCLUDED_PER_STEP * self.n0_fluid))
        self.npf_minimum = min_fluid(params, self.n0_fluid)
        self.excluded_seen = 0
        self.case_id = case_identity(p, c)             # written into restart.h5; --resume checks it
        self.dtmin_run = 0
        self.dtmin_seen = 0
        self.dtmin_warn_at = 1          # the next count of DtMin steps warned about (1, 10, 100, ...)
        self.step_warnings = []         # lines for run.log (and stderr) found by check()
        self.out_faces = set()          # faces of the domain that fluid excluded for its position crossed

    @staticmethod
    def _check_flex_parameters(params: dict, periodic) -> None:
        """DualSPHysics's refusals of flexible structures with these parameters (checked again here:
        --set may change what gencase checked): periodic conditions, the original mDBC (SlipMode 1),
        mDBC with Verlet. mDBC2 (Boundary 2 with SlipMode 2 or 3, Symplectic) is run as DualSPHysics
        v5.4 runs it (sphdvi.sph.flexstruc)."""
        from .case.flexstruc_xml import PARAMETER_FIXES, flexstruc_parameter_problem
        problem = flexstruc_parameter_problem(params, bool(periodic))
        if problem:
            fix = PARAMETER_FIXES.get(problem)
            raise InputError(f"<special><flexstrucs>: {problem}" + (f" (expected {fix})" if fix else ""))

    @staticmethod
    def _flexible_structures(specs, p: dict, c: dict, params: dict, fluidcount: int):
        """The flexible bodies of ``<special><flexstrucs>`` (sphdvi.sph.flexstruc) from the particles at
        t = 0 (their reference configuration, also on a resumed run)."""
        from .coupling import body_labels
        from .sph.flexstruc import FlexStruc
        labels = np.where(p["type"] == 3, -1, body_labels(p["mk"], fluidcount))
        try:
            flex = FlexStruc(specs, p["pos"], p["idp"], labels, p["type"], is2d=bool(c["is2d"]), h=float(c["h"]),
                             dp=float(c["dp"]), kernel=int(params.get("Kernel", 2)))
        except ValueError as exc:
            raise InputError(f"<special><flexstrucs>: {exc}") from None
        for spec, (_, nclamp) in zip(specs, flex.counts):
            if not nclamp:
                warnings.warn(f"<special><flexstrucs>: no particle of the clamp mkbound {spec['mkclamp']} lies within "
                              f"2h of the flexible structure mkbound={spec['mkbound']} (line {spec.get('line')}): "
                              "nothing holds it, it moves as a free elastic body")
        return flex

    def _relaxation_zones(self, specs, state, c: dict, params: dict) -> list:
        """``<special><relaxationzones>`` (sphdvi.sph.relaxzones): the zones, their ``<savemotion>`` files
        written; a zone that holds no fluid at the start is warned about (it would make no waves)."""
        if not specs:
            return []
        from .sph.relaxzones import relaxation_zones
        zones = relaxation_zones(specs, g=float(np.linalg.norm(c["gravity"])))
        for zone in zones:
            if zone.count_inside(state) == 0:
                warnings.warn(f"<relaxationzones> {zone.name}: the zone holds no fluid particle at the start, so it "
                              "relaxes nothing (expected a <center> and <width>, or a <domainbox>, over the water)")
        if any(z.spec.get(k) for z in zones for k in ("savemotion", "saveserie", "saveseriewaves")):
            from .io.paddle_motion import write_relaxzone_motions
            write_relaxzone_motions(self.outdir, zones, float(params["TimeMax"]), float(params["TimeOut"]))
        return zones

    def _bound_corr(self, spec, p: dict, c: dict, fluidcount: int):
        """``<special><boundcorr>``: (normals, determlimit) for the solver (sphdvi.sph.inout.boundcorr_normals),
        or None.  With mDBC (Boundary=2) every wall is corrected already: warned and left out."""
        if not spec:
            return None
        if int(self.params.get("Boundary", 1)) == 2:
            warnings.warn("<special><boundcorr> is ignored: Boundary=2 (mDBC) corrects the density of every wall "
                          "with a normal")
            return None
        from .coupling import body_labels
        from .sph.inout import boundcorr_normals
        labels = body_labels(np.asarray(p["mk"]), fluidcount)
        normals = boundcorr_normals(spec, np.asarray(p["pos"], float), np.asarray(p["type"]), labels, float(c["dp"]))
        return normals, float(spec.get("determlimit", 1e3))

    def _place_inout_buffers(self, spec: dict, data: dict, c: dict, domain, periodic):
        """``<special><inout>``: the buffers of the inlet/outlet zones put in place of the fluid in
        them (sphdvi.sph.inout.place_buffers); ``data["particles"]`` (and the case's normals) become
        the run's initial particles.  Returns (particles, state)."""
        from .sph.inout import InOutError, place_buffers
        from .sph.state import FluidState
        try:
            p, extra, self.inout, notes = place_buffers(spec, data["particles"], c, domain,
                                                        {"normals": data.get("normals")},
                                                        kernel=int(self.params.get("Kernel", 2)))
        except InOutError as exc:
            raise InputError(f"<special><inout>: {exc}") from None
        data["particles"] = p
        if extra.get("normals") is not None:
            data["normals"] = extra["normals"]
        self.inout_notes = notes
        state = FluidState(p["pos"], p["vel"], p["rhop"], p["mass"], p["type"], p["idp"], p["mk"],
                           rhop0=c["rhop0"])
        return p, state

    @staticmethod
    def _mdbc_only_on(normals, p, fluidcount: int, mkbound_list: str):
        """``MdbcMkbound``: the normals of the listed mkbounds only (the others keep DBC)."""
        if not mkbound_list:
            return normals
        from .case.normals import keep_normals_of
        from .coupling import body_labels
        try:
            normals, missing = keep_normals_of(normals, body_labels(p["mk"], fluidcount), p["type"], mkbound_list)
        except ValueError as exc:
            raise InputError(f"MdbcMkbound '{mkbound_list}': {exc} (expected mkbound values and ranges "
                             "such as '0-3,7')") from None
        if missing:
            warnings.warn(f"MdbcMkbound '{mkbound_list}': no boundary particles of mkbound "
                          f"{', '.join(map(str, missing))} in this case: that entry does nothing (expected the "
                          "mkbound of a wall or floating body of the case file)")
        return normals

    def _hook(self, solver, t, dt):
        """The end of each step: absorbing pistons' corrections, imposed motions, floating bodies,
        damping zones, relaxation zones (at the step's end time t)."""
        for absorber in self.absorbers:      # the gauge in front of the piston where it stands
            absorber.update(t, dt, absorber.measure(solver.state, t - dt) if absorber.absorbs(t, dt) else math.nan)
        if self.moving is not None:
            self.moving.apply(solver, t, dt)
            self._check_moving_in_domain(solver)
        if self.floating is not None:
            self.floating.step(solver, dt)
        for zone in self.damping:
            zone.apply(solver.state, dt)
        for zone in self.relax:
            zone.apply(solver.state, t, dt)

    def _check_moving_in_domain(self, solver) -> None:
        """Stop the run (DivergenceError, exit 3) when a moving boundary particle has left the
        simulation domain: DualSPHysics excludes it at its next cell division and aborts
        (JSphCpuSingle::RunCellDivide -> JSph::AbortBoundOut, "Fixed, moving or floating particles
        were excluded"); sphdvi's cells would clamp it into the edge cells and go on."""
        dom = solver._domain
        if dom is None or self.moving.first_outside < 0:    # found while placing them (place_moving)
            return
        s = solver.state
        sel = np.flatnonzero(s.ptype == 1)
        out = outside(s.pos[sel], dom)
        if not out.any():
            return
        from .coupling import body_labels
        rows = sel[out]
        k = int(rows[0])
        mkb = int(body_labels(s.mk[k:k + 1], int(self.data["json"]["mkconfig"]["fluidcount"]))[0])
        faces = [f"{a}-{e}" for j, a in enumerate("xyz") for e, bad in
                 (("min", s.pos[rows, j] < dom[0][j]), ("max", s.pos[rows, j] > dom[1][j])) if bad.any()]
        raise DivergenceError(
            f"t={solver.time:.6g} s, step {solver.nstep}: moving boundary mkbound {mkb} left the simulation "
            f"domain {box_text(dom)} through its {and_list(faces)} face{'s' if len(faces) > 1 else ''}: its "
            f"particle {int(s.idp[k])} is at {fmt_vec(s.pos[k])} ({rows.size} moving particles out); DualSPHysics "
            f"stops too (AbortBoundOut: \"Fixed, moving or floating particles were excluded\"): enlarge "
            f"<simulationdomain> or check the motion")

    # -- checks --------------------------------------------------------------------------
    def check(self, events_before: int = 0) -> None:
        """Raise DivergenceError when the run has gone unstable.  ``events_before``: the number of
        exclusion events the solver held before this step; those after it are the step's (a
        Symplectic step may add two: its predictor's and its corrector's), all searched."""
        sol = self.solver
        events = [ev for ev in sol.excluded[events_before:] if len(ev["idp"])]
        for ev in events:
            self._note_faces(ev)
        if events and sol.n_excluded.get("not finite", 0):
            for ev in events:
                bad = [i for i, r in enumerate(ev["reason"]) if r == "not finite"]
                if bad:
                    i = bad[0]
                    raise DivergenceError(
                        f"t={sol.time:.6g} s, step {sol.nstep}: particle {int(ev['idp'][i])} at "
                        f"{fmt_vec(ev['pos'][i])} has a non-finite value (NaN or inf); cause: the solution blew up "
                        f"(try a smaller cflnumber or DtFixed, or more viscosity)")
        if sol.n_dtmin > self.dtmin_seen:
            self.dtmin_run += sol.n_dtmin - self.dtmin_seen
            self.dtmin_seen = sol.n_dtmin
            self._warn_dtmin()
            if self.dtmin_run >= DTMIN_STUCK_STEPS:
                raise DivergenceError(
                    f"t={sol.time:.6g} s, step {sol.nstep}: dt held at DtMin ({sol.dtmin:.3g} s) for "
                    f"{self.dtmin_run} steps; {self._dtmin_cause()}")
        else:
            self.dtmin_run = 0
        excluded = sum(sol.n_excluded.values())
        new, self.excluded_seen = excluded - self.excluded_seen, excluded
        step_limit, base = self.excluded_step_limit, self.n0_fluid
        if self.inout is not None:
            # inlets create fluid: the limits count every fluid particle the run has had
            base = self.n0_fluid + self.inout.counts["created"]
            step_limit = max(step_limit, int(MAX_EXCLUDED_PER_STEP * sol.n_fluid))
        if new > step_limit:
            raise DivergenceError(
                f"t={sol.time:.6g} s, step {sol.nstep}: {new} of {base} fluid particles excluded in one "
                f"step (more than {MAX_EXCLUDED_PER_STEP:.0%} at once; dt {sol.last_dt:.3g} s); "
                + self._last_excluded(events) + "; "
                + self._exclusion_cause("the time step is far too large for the flow (DtFixed?) or the "
                                        "solution blew up"))
        limit = self.excluded_limit
        if self.inout is not None:
            limit = int(self.excluded_limit * base / max(1, self.n0_fluid))
        if excluded > limit:
            raise DivergenceError(
                f"t={sol.time:.6g} s, step {sol.nstep}: {excluded} of {base} fluid particles excluded "
                f"(limit {limit}); " + self._last_excluded(events) + "; excluded so far: "
                + self._excluded_by_reason() + "; " + self._exclusion_cause(self._divergence_hint()))
        if not np.isfinite(sol.last_dt) or sol.last_dt <= 0:
            raise DivergenceError(f"t={sol.time:.6g} s, step {sol.nstep}: time step {sol.last_dt} is not valid")
        if sol.flex is not None and sol.flex.fail[0] >= 0:
            self._flex_failed(sol)
        # the floating bodies' states were checked where they changed (FloatingBodies.step / predict:
        # bodychecks.BodyWatch), before their particles reached the fluid

    @staticmethod
    def _flex_failed(sol) -> None:
        """A flexible particle blew up or left the domain: DualSPHysics's "Issue with FlexStruc particle
        update step" (it aborts too)."""
        from .sph.flexstruc import FAIL_REASONS
        f = sol.flex
        k, why = int(f.fail[0]), int(f.fail[1])
        row = int(f.rows[k])
        spec = f.bodies[int(f.body[k])]
        raise DivergenceError(
            f"t={sol.time:.6g} s, step {sol.nstep}: particle {int(f.idp[k])} of the flexible structure "
            f"mkbound={spec['mkbound']} at {fmt_vec(sol.state.pos[row])} {FAIL_REASONS.get(why, 'failed')}; cause: "
            "the structure blew up or moved out of the domain (try a smaller cflnumber, a larger hgfactor, or a "
            "larger <simulationdomain>)")

    def wall_density_warning(self) -> str:
        """Once a run with inlet/outlet zones: a line when a DBC wall particle (fixed or moving, not
        corrected by ``<boundcorr>``) has passed RhopOutMax.  DualSPHysics excludes fluid there, never
        walls, so nothing else says it: the wall past an outlet's buffer sees buffer particles approach
        and vanish and compresses without end (``<boundcorr>`` or Boundary=2 correct it).  (mDBC walls,
        and DBC walls in runs without zones, reach such densities in impacts: not warned.)"""
        sol = self.solver
        if getattr(self, "_wall_warned", False) or self.inout is None or sol.boundary != 1:
            return ""
        s = sol.state
        limit = float(self.params.get("RhopOutMax", 1300.0))
        dbc = s.ptype < 2
        if sol.bc_normals is not None:
            dbc &= ~sol.bc_normals.any(axis=1)
        walls = np.flatnonzero(dbc)
        if walls.size == 0:
            return ""
        k = walls[int(np.argmax(s.rhop[walls]))]
        if not s.rhop[k] > limit:
            return ""
        self._wall_warned = True
        from .coupling import body_labels
        mkb = int(body_labels(s.mk[k:k + 1], int(self.data["json"]["mkconfig"]["fluidcount"]))[0])
        n = int(np.count_nonzero(s.rhop[walls] > limit))
        hint = ("walls behind an outlet's buffer see buffer particles approach and vanish: give them <boundcorr> "
                "(as DualSPHysics's inlet/outlet examples do) or use Boundary=2")
        return (f"t={self.solver.time:.6g} s: {n} boundary particle{'s' if n > 1 else ''} past RhopOutMax "
                f"({limit:g} kg/m3), the densest mkbound {mkb} particle {int(s.idp[k])} at {fmt_vec(s.pos[k])} "
                f"with {float(s.rhop[k]):.6g} kg/m3; {hint}")

    @staticmethod
    def _last_excluded(events: list) -> str:
        """"last: particle N at (..), reason R": the last row the step wrote to excluded.csv."""
        if not events:
            return "last: none this step"
        ev = events[-1]
        return (f"last: particle {int(ev['idp'][-1])} at {fmt_vec(ev['pos'][-1])}, reason {ev['reason'][-1]}")

    def _note_faces(self, ev: dict) -> None:
        """The faces of the simulation domain the particles excluded for their position in ``ev``
        crossed (DualSPHysics's "exceeded the -X limit (left limit)" lines of its exclusion report)."""
        dom = self.solver._domain
        rows = [i for i, r in enumerate(ev["reason"]) if r == "position"]
        if dom is None or not rows:
            return
        pos = np.asarray(ev["pos"], float)[rows]
        for k, axis in enumerate("xyz"):
            if np.any(pos[:, k] < dom[0][k]):
                self.out_faces.add(f"{axis}-min")
            if np.any(pos[:, k] > dom[1][k]):
                self.out_faces.add(f"{axis}-max")

    def _faces(self) -> str:
        order = [f"{a}-{e}" for a in "xyz" for e in ("min", "max")]
        faces = [f for f in order if f in self.out_faces]
        return and_list(faces) + (" faces" if len(faces) > 1 else " face")

    def _excluded_by_reason(self) -> str:
        """The fluid excluded so far by reason (DualSPHysics's "Excluded for: position=.. rhop=..
        velocity=.."), with the faces of the domain the position exclusions crossed."""
        n = self.solver.n_excluded
        parts = []
        for name in ("position", "rhop", "movement", "not finite"):
            if n.get(name, 0):
                where = f" (through the {self._faces()})" if name == "position" and self.out_faces else ""
                parts.append(f"{name} {n[name]}{where}")
        return ", ".join(parts) or "none"

    def _divergence_hint(self) -> str:
        """The likely cause of a run that lost more than its limit of fluid: the domain's faces
        the fluid left through when most of it went that way, else an unstable solution (naming
        a cflnumber above 0.5: DualSPHysics's cases use 0.2)."""
        sol = self.solver
        n = sol.n_excluded
        if self.out_faces and 2 * n.get("position", 0) > sum(n.values()):
            return (f"the fluid left the simulation domain through its {self._faces()} (no wall there? "
                    f"enlarge <simulationdomain>)")
        if sol.cfl > 0.5:
            return (f"the solution went unstable: cflnumber {sol.cfl:g} is large (DualSPHysics's cases use 0.2: "
                    f"try 0.2-0.4), or more viscosity/density diffusion")
        return ("the solution went unstable (try a smaller cflnumber or DtFixed, or more viscosity/density "
                "diffusion)")

    def _dtmin_cause(self) -> str:
        """Which term of DualSPHysics's dt (JSphCpu::DtVariable, eq. 10) fell below DtMin, with
        its numbers: the force term dt1 = CFL sqrt(h/|a|max) or the speed term
        dt2 = CFL h/(max(c0, 10|v|max) + h ViscDtMax), split into its part that dominates (the
        speed of sound c0, ten times the fastest particle's speed, or the viscous one)."""
        from .sph.timestep import dt_conditions
        sol = self.solver
        s = sol.state
        a2, v2, cv = sol.dtmax.max(axis=0)
        dt1, dt2 = (sol.cfl * d for d in dt_conditions(a2, v2, cv, sol.h, sol.cs0))
        if dt1 <= dt2:
            # as dt_terms: the fluid's acceleration without gravity, the floating particles' as it is
            ace = np.where((s.ptype == 3)[:, None], sol.ace - sol.gravity,
                           np.where((s.ptype == 2)[:, None], sol.ace, 0.0))
            i = int(np.argmax(np.einsum("ij,ij->i", ace, ace)))
            return (f"the force term CFL*sqrt(h/|a|max) = {dt1:.3g} s set dt (the speed term gives {dt2:.3g} s): "
                    f"largest acceleration on particle {int(s.idp[i])} at {fmt_vec(s.pos[i])} "
                    f"({math.sqrt(float(ace[i] @ ace[i])):.3g} m/s2)")
        term = (f"the speed term CFL*h/(max(c0, 10|v|max) + h*ViscDtMax) = {dt2:.3g} s set dt (the force term "
                f"gives {dt1:.3g} s)")
        vmax, c0, visc = math.sqrt(v2), sol.cs0, sol.h * float(cv)
        if visc > max(c0, 10.0 * vmax):
            return (f"{term}: its viscous part h*ViscDtMax = {visc:.3g} m/s is above c0 = {c0:.3g} m/s and "
                    f"10|v|max = {10.0 * vmax:.3g} m/s (ViscDtMax {float(cv):.3g} 1/s): lower the viscosity")
        if 10.0 * vmax > c0:
            speed = np.einsum("ij,ij->i", s.vel, s.vel) * (s.ptype >= sol.dt_vel_type)
            i = int(np.argmax(speed))
            return (f"{term} with 10|v|max = {10.0 * vmax:.3g} m/s > c0 = {c0:.3g} m/s: fastest particle "
                    f"{int(s.idp[i])} at {fmt_vec(s.pos[i])} (|v| {vmax:.3g} m/s); the flow is faster than a tenth "
                    f"of the speed of sound: raise coefsound/speedsound")
        return (f"{term} with the speed of sound c0 = {c0:.3g} m/s (10|v|max = {10.0 * vmax:.3g} m/s): DtMin is "
                f"above the CFL dt of the speed of sound: lower DtMin (or CoefDtMin)")

    def max_excluded(self) -> int:
        """Excluded fluid particles beyond which the run stops as diverged: PartsOutMax (when
        the case sets it below 1), else half the fluid; no such limit when the case gives
        MinFluidStop instead (its own end of the run, a normal one: :meth:`min_fluid_reached`)."""
        p = self.params
        frac = DEFAULT_MAX_EXCLUDED_FRACTION
        if float(p.get("MinFluidStop") or 0.0) > 0:
            frac = 1.0
        if "PartsOutMax" in self.data["json"].get("parameters_set", []) and p.get("PartsOutMax", 1.0) < 1.0:
            frac = float(p["PartsOutMax"])
        return int(frac * self.n0_fluid)

    def min_fluid_reached(self) -> str:
        """MinFluidStop: a message when fewer fluid particles remain than NpfMinimum (DualSPHysics's
        JSphCpuSingle::Run, ``npfnormal < NpfMinimum || !Np``, then a normal end), else ''."""
        if not self.npf_minimum:
            return ""
        sol = self.solver
        left = self.n0_fluid - sum(sol.n_excluded.values())
        if left >= self.npf_minimum and sol.state.n:
            return ""
        return (f"The minimum number of fluid particles ({self.npf_minimum}) was reached: {left} of {self.n0_fluid} "
                f"left at t={sol.time:.6g} s, step {sol.nstep} (MinFluidStop {float(self.params['MinFluidStop']):g})")

    def _exclusion_cause(self, default: str) -> str:
        """The likely cause of a mass exclusion for the divergence messages: dt raised to DtMin in
        the steps before, or ``default``.  (A density window that excludes the initial fluid
        does not start: :func:`sphdvi.run_checks.check_initial_density`.)"""
        sol = self.solver
        if self.dtmin_run > 0:
            return (f"cause: dt was raised to DtMin ({sol.dtmin:.3g} s) in the last {self.dtmin_run} step(s), "
                    f"above what the CFL and force conditions allowed: DtMin is too large for this flow, or the "
                    f"flow blew up")
        return f"cause: {default}"

    def _warn_dtmin(self) -> None:
        """DualSPHysics's DtVariable warning "N DTs adjusted to DtMin (t:..., nstep:...)" at 1, 10,
        100, ... steps whose dt was raised to DtMin (t and nstep of the step that found it)."""
        sol = self.solver
        if sol.n_dtmin < self.dtmin_warn_at:
            return
        while self.dtmin_warn_at <= sol.n_dtmin:
            self.dtmin_warn_at *= 10
        self.step_warnings.append(
            f"{sol.n_dtmin} DTs adjusted to DtMin (t:{sol.time - sol.last_dt:g}, nstep:{sol.nstep - 1}); "
            f"DtMin {sol.dtmin:.4g} s is above the dt the CFL and force conditions ask for")

    def take_step_warnings(self) -> list:
        """The warning lines :meth:`check` found since the last call, and the multibody
        System's (an unconverged solve, :meth:`System.take_warnings`)."""
        lines, self.step_warnings = self.step_warnings, []
        if self.bodies is not None:
            from .bodychecks import solver_hint
            lines += [solver_hint(line) for line in self.bodies.take_warnings()]
        return lines

    # -- snapshots and checkpoints ------------------------------------------------------
    def body_centres(self) -> dict:
        """mkbound -> centre of each floating body now (none without bodies)."""
        if self.floating is None:
            return {}
        return {mkb: self.bodies.pos[i] for i, mkb in enumerate(self.floating.mkbounds)}

    def snapshot(self) -> tuple[np.ndarray, dict]:
        s = self.solver.state
        press = self.solver.press
        return s.pos, {"Idp": s.idp, "Vel": s.vel, "Rhop": s.rhop, "Press": press, "Type": s.ptype,
                       "Mk": s.mk}

    def save_checkpoint(self, path: str, extra: dict) -> None:
        if self.absorbers:
            extra = dict(extra, awas=json.dumps([a.get_state() for a in self.absorbers]))
        moorings = self.floating.moorings if self.floating is not None else None
        save_sph_checkpoint(path, self.solver.get_checkpoint(),
                            dict(extra, dtmin_run=self.dtmin_run, dtmin_seen=self.dtmin_seen, **self.case_id),
                            self.bodies.get_state() if self.bodies is not None else None,
                            arrays={"moorings": moorings.get_state()} if moorings is not None else None)

    def load_checkpoint(self, path: str) -> dict:
        extra = load_sph_checkpoint(path, self.solver, self.bodies, self.case_id, self.data["particles"])
        self.excluded_seen = sum(self.solver.n_excluded.values())
        self.dtmin_run = int(extra["dtmin_run"])
        self.dtmin_seen = int(extra["dtmin_seen"])
        self.dtmin_warn_at = 1              # the levels already warned about follow from the count
        while self.dtmin_warn_at <= self.solver.n_dtmin:
            self.dtmin_warn_at *= 10
        if self.absorbers:
            if "awas" not in extra:
                raise InputError(f"{path}: the restart file has no state of the absorbing pistons (<awas_zsurf>); "
                                 "it was written by a run without them: start the run again without --resume")
            for absorber, state in zip(self.absorbers, json.loads(extra["awas"])):
                absorber.set_state(state)
        moorings = self.floating.moorings if self.floating is not None else None
        if moorings is not None:
            if "moorings" not in extra.get("arrays", {}):
                raise InputError(f"{path}: the restart file has no state of the mooring lines (<moorings>); it was "
                                 "written by a run without them: start the run again without --resume")
            moorings.set_state(extra["arrays"]["moorings"])
        return extra


def min_fluid(params: dict, n0_fluid: int) -> int:
    """DualSPHysics's NpfMinimum = unsigned(MinFluidStop*CaseNfluid), a float product (its
    MinFluidStop is a float); 0 without MinFluidStop."""
    mfs = float(params.get("MinFluidStop") or 0.0)
    if mfs <= 0:
        return 0
    return int(np.float32(mfs) * np.float32(n0_fluid))


def _clean_up_after_failure(*steps) -> None:
    """Run each step (None: skipped) of a failed run's clean-up, whatever the others raise: on a
    full disk they fail too, and a particle file left open crashed the interpreter at exit
    (segmentation fault, exit 139, run.json still 'running')."""
    for step in steps:
        if step is not None:
            with contextlib.suppress(Exception):
                step()


def _disk_full(what: str, outdir: str, t: float, step: int, part: int) -> SphdviError:
    return SphdviError(f"{what} in {outdir} at t={t:.6g} s, step {step}: the outputs up to part {part} are intact; "
                       f"free some space and go on with 'sphdvi run {outdir} --resume'")


def _raise_if_disk_full(exc: BaseException, outdir: str, t: float, step: int, part: int) -> None:
    """A write that failed for want of space (ENOSPC, EDQUOT; HDF5 says it in a RuntimeError's
    text) ends the run with a message that says so and what to do, instead of a bare
    '[Errno 28] No space left on device' or an HDF5 error."""
    import errno
    if isinstance(exc, OSError) and exc.errno in (errno.ENOSPC, errno.EDQUOT):
        where = f" (writing {exc.filename})" if exc.filename else ""
        raise _disk_full(os.strerror(exc.errno).lower() + where, outdir, t, step, part) from None
    if isinstance(exc, RuntimeError) and ("errno = 28" in str(exc) or "No space left" in str(exc)):
        raise _disk_full("no space left on device (HDF5 write)", outdir, t, step, part) from None


# room an output needs besides its own bytes (logs, gauges, run.json)
OUTPUT_SPACE_MARGIN = 1 << 20


def _check_output_space(outdir: str, step_bytes: int, t: float, step: int, part: int) -> None:
    """Before an output: the free space of OUT's device holds the particle step and a new
    restart.h5 beside the old one (an atomic write), else the run stops here, cleanly: a write
    that fails inside HDF5 leaves the file library in a state that crashed the interpreter at exit."""
    try:
        st = os.statvfs(outdir)
    except (OSError, AttributeError):
        return
    free = st.f_bavail * st.f_frsize
    ckpt = os.path.join(outdir, RESTART_FILE)
    ckpt_bytes = os.path.getsize(ckpt) if os.path.exists(ckpt) else 4 * step_bytes
    need = step_bytes + ckpt_bytes + OUTPUT_SPACE_MARGIN
    if free < need:
        raise _disk_full(f"too little space left on the device ({free / 2**20:.1f} MiB free, an output needs "
                         f"about {need / 2**20:.1f} MiB)", outdir, t, step, part)


class _Stop:
    """SIGTERM/SIGINT/SIGHUP (a closed terminal) turn into a clean stop at the next step boundary."""

    def __init__(self):
        self.signal = None
        self._old = {}

    def __enter__(self):
        for sig in (signal.SIGTERM, signal.SIGINT, getattr(signal, "SIGHUP", None)):
            if sig is None or (sig != signal.SIGINT and signal.getsignal(sig) == signal.SIG_IGN):
                continue                # nohup's ignored SIGHUP stays ignored
            try:
                self._old[sig] = signal.signal(sig, self._handle)
            except ValueError:  # not in the main thread
                pass
        return self

    def _handle(self, signum, frame):
        self.signal = signum

    def __exit__(self, *exc):
        for sig, old in self._old.items():
            signal.signal(sig, old)


#: seconds of start-up compilation after which the user is told that kernels are being compiled
COMPILE_NOTICE_AFTER_S = 3.0


class _CompileNotice:
    """A line on ``stream`` (None: quiet) when the start-up's compilation lasts longer than
    COMPILE_NOTICE_AFTER_S, and another when it is done.  A first run with a case's options
    compiles its kernels (10-30 s before any output); a warm cache loads them in under a second,
    and then nothing is said."""

    def __init__(self, stream):
        import threading
        self.stream = stream
        self.t0 = _time.perf_counter()
        self.said = threading.Event()
        self.timer = None
        if stream is not None:
            self.timer = threading.Timer(COMPILE_NOTICE_AFTER_S, self._say)
            self.timer.daemon = True
            self.timer.start()

    def _say(self):
        self.said.set()
        self.stream.write("compiling the kernels for this case's options (a first run with them; later runs "
                          "load them from numba's cache) ...\n")
        self.stream.flush()

    def done(self):
        if self.timer is not None:
            self.timer.cancel()
            self.timer.join()          # a notice being written ends before the "ready" line
        if self.said.is_set():
            self.stream.write(f"kernels ready after {_time.perf_counter() - self.t0:.1f} s\n")
            self.stream.flush()


def _warm_up(sph: "SPHRun") -> float:
    """Compile (or load from cache) the kernels on a throw-away copy of the run: two steps, the
    first of which moves the particles into cell order and the second does not (its kernels compiled
    inside the loop otherwise: 0.6 s of a 0.03 s run on an empty cache).  With an end-of-step hook
    the copy is the whole SPHRun, so that its solver's hook is the copy's: imposed motions, the floating
    bodies' multibody step (31 s of JIT inside a 31.2 s hinged-flap run before) and the damping
    zones compile too, and nothing of the run itself moves; then the kernels of a first contact
    between bodies.  What switches on later in the run is switched on in the copy: the bodies
    move from its first step (FtPause set to 0 there; 21 s of JIT at the pause's end before) and
    each ``<accinput>`` is evaluated once at its start time."""
    import copy
    t0 = _time.perf_counter()
    # without a hook the solver alone (a copy of the run would copy the case's arrays too)
    if sph.solver.motion_hook is None:
        clone, bodies = copy.deepcopy(sph.solver), None
    else:
        run = copy.deepcopy(sph)
        clone, bodies = run.solver, run.bodies
        if run.floating is not None:
            run.floating.ftpause = 0.0
    with contextlib.suppress(DivergenceError):      # a wall or body leaving the domain: the run says it
        clone.step()
        clone.step()
    for inp in clone.acc_inputs:                    # an input active only later (<time start>)
        clone.time = inp.start
        clone._add_acc_inputs()
    if bodies is not None:
        bodies.compile_contact_kernels()
    return _time.perf_counter() - t0


def _warm_up_gauges(gauges, sol) -> None:
    """Compile (or load) the run-time gauges' kernels: every gauge computed once on the current
    state (the solver's arrays, as :meth:`RunGauges.after_step` passes them), the rows thrown
    away.  RunGauges measures at start-up only the gauges due at t=0 of a new run: without this a
    gauge whose ``<computetime>`` starts later, or any gauge after ``--resume``, compiled inside
    the time loop instead of in startup_s.  The gauges read the state and change nothing."""
    from .measure.gauges import StateView
    st = sol.state
    view = StateView(float(sol.time), st.pos, st.vel, st.rhop, st.mass, sol.press, st.ptype, st.mk, gauges.spec,
                     gauges.periodicity)
    for slot in gauges.slots:
        slot.gauge.compute(view)


def _run_sph(data, params, out_times, outdir, files, meta, threads, resume, quiet, t_start, stop=None) -> RunResult:
    """The SPH run on ``threads`` numba threads; the caller's thread count is
    restored afterwards (an in-process run must not change it for the rest of
    the process, e.g. a test session)."""
    import numba
    previous = numba.get_num_threads()
    numba.set_num_threads(max(1, min(threads, numba.config.NUMBA_NUM_THREADS)))
    try:
        return _run_sph_threaded(data, params, out_times, outdir, files, meta, resume, quiet, t_start, stop)
    finally:
        numba.set_num_threads(previous)


def _run_sph_threaded(data, params, out_times, outdir, files, meta, resume, quiet, t_start, stop=None) -> RunResult:
    import numba
    from .io.vtkhdf import VTKHDFParticleWriter
    stopped = _stopped_at_startup(stop, files, meta, outdir, resume)
    if stopped is not None:
        return stopped
    sph = SPHRun(data, params, outdir, resume=resume)
    sol = sph.solver
    tmax, tout = float(params["TimeMax"]), float(params["TimeOut"])
    special = data["json"].get("special") or {}
    sol.keep_dt_terms = bool(special.get("savedt"))
    selection = (OutputParts(special["outputparts"], int(data["json"]["mkconfig"]["fluidcount"]))
                 if special.get("outputparts") else None)
    dtlog = None
    vtk_path = os.path.join(outdir, "particles.vtkhdf")
    ckpt = os.path.join(outdir, RESTART_FILE)
    part = 0
    wall_prev = 0.0
    if resume:
        if not os.path.exists(ckpt):
            raise InputError(f"--resume: no checkpoint {ckpt} in {outdir}")
        extra = sph.load_checkpoint(ckpt)
        _refuse_after_min_fluid(sph, outdir)
        part = int(extra["part"])
        if sol.keep_dt_terms:
            dtlog = _resumed_dtlog(outdir, special["savedt"], tout, extra.get("savedt"), sol, files)
        wall_prev = float(extra.get("runtime_s", 0.0))
        had_vtk = os.path.exists(vtk_path)
        writer = VTKHDFParticleWriter(vtk_path, POINT_ARRAYS, append=True)
        held = int(writer.root["Steps"].attrs["NSteps"])
        writer.truncate_to(part + 1)
        files.load_existing(part + 1)
        files.log(f"resumed from part {part} at t={sol.time:.6g} s, step {sol.nstep}")
        if held < part + 1:
            lost = (f"{vtk_path} was missing: it starts anew" if not had_vtk else
                    f"{vtk_path} holds {held} outputs")
            line = (f"--resume: {lost}, but {ckpt} is at part {part} (t={sol.time:.6g} s): the particles of parts "
                    f"{held}..{part} are not in it and the steps go on from part {part + 1}; restore the file to "
                    "keep them, or run again with --overwrite for a complete one")
            files.log("WARNING: " + line)
            warnings.warn(line)
    else:
        writer = VTKHDFParticleWriter(vtk_path, POINT_ARRAYS, points_per_step=int(data["particles"]["type"].size))
        files.start()
        if sol.keep_dt_terms:
            dtlog = DtLog(outdir, special["savedt"], tout)
        if sol.dem is not None:                 # DualSPHysics's Run.out "Coefficients for DEM:"
            files.log("RigidAlgorithm 2 (DCDEM, Canelas et al. 2016): DEM coefficients per boundary block")
            for line in dem_coefficient_lines(sol.dem, int(data["json"]["mkconfig"]["fluidcount"])):
                files.log(line)
        if sol.flex is not None:                # DualSPHysics's Run.out "Flexible Structures configuration:"
            files.log("Flexible structures (total Lagrangian SPH, O'Connor & Rogers 2021)")
            for line in sol.flex.config_lines():
                files.log(line)
        if sol.boundary == 2:                   # the normals mDBC starts from, for a look in ParaView
            from .io.vtkxml import write_normals_vtp
            st = sol.state
            write_normals_vtp(os.path.join(outdir, NORMALS_FILE), st.pos, st.ptype, st.mk, sol.normals)
    stopped = _stopped_at_startup(stop, files, meta, outdir, resume)
    notice = _CompileNotice(None if quiet else sys.stderr)
    try:
        if stopped is None:
            jit_s = _warm_up(sph)
            stopped = _stopped_at_startup(stop, files, meta, outdir, resume)
        if stopped is None:
            # the run-time gauges measure the initial state here, so that their first JIT
            # compilation counts in startup_s, not in runtime_s
            gauges = _make_gauges(data, params, outdir, resume, float(sol.time), sol.periodicity,
                                  extra.get("gauges") if resume else None)
            if gauges is not None:
                _warm_up_gauges(gauges, sol)
    finally:
        notice.done()
    if stopped is not None:
        writer.close()
        return stopped
    startup = _time.perf_counter() - t_start
    files.write_json(**meta, mode="sph", numba=numba.__version__, threading_layer=_threading_layer(),
                     status="running", message="", steps=int(sol.nstep), physical_time=float(sol.time),
                     runtime_s=wall_prev, startup_s=startup, jit_s=jit_s)
    progress = Progress(tmax, quiet)
    dt_lo, dt_hi = math.inf, 0.0
    runtime = wall_prev
    steps_at_start = int(sol.nstep)
    t_loop = _time.perf_counter()

    step_lines = []     # warnings of the step checks (DtMin, MinFluidStop): run.log with the next output

    def note_step_warnings():
        for line in sph.take_step_warnings():
            step_lines.append(line)
            if not quiet:
                warnings.warn(line)

    def write_part(k):
        pos, arrays = sph.snapshot()
        _check_output_space(outdir, pos.nbytes + sum(a.nbytes for a in arrays.values()), float(sol.time),
                            int(sol.nstep), k - 1)
        written = ""
        if selection is not None and selection.applies_to(k):
            keep = selection.select(pos, arrays["Type"], arrays["Mk"], sph.body_centres())
            pos, arrays = pos[keep], {name: a[keep] for name, a in arrays.items()}
            written = f"  written={int(keep.sum())}"
        writer.append(sol.time, pos, arrays)
        excl = sum(sol.n_excluded.values())
        excl_lines = excl_warn.check(excl - excl_seen[0], sol.n_fluid, excl, sol.time, sol.nstep)
        excl_seen[0] = excl
        wall = runtime + (_time.perf_counter() - t_loop)
        files.csv(f"{k},{sol.time:.9g},{sol.nstep},{sol.state.n},{excl},"
                  f"{dt_lo if dt_lo < math.inf else 0:.6g},{dt_hi:.6g},{wall:.3f}")
        files.log(f"Part {k:04d}  t={sol.time:.6f} s  steps={sol.nstep}  particles={sol.state.n}  "
                  f"excluded={excl}  dt=[{dt_lo if dt_lo < math.inf else 0:.3g}, {dt_hi:.3g}] s  wall={wall:.2f} s"
                  + written + (inout_text(sol.inout) if sol.inout is not None else ""))
        wall_line = sph.wall_density_warning()
        for line in excl_lines + ([wall_line] if wall_line else []):
            files.log("WARNING: " + line)
            warnings.warn(line)
        for line in step_lines:
            files.log("WARNING: " + line)
        step_lines.clear()
        excluded_log.record(sol.take_excluded())
        if body_log is not None:
            body_log.record()
        if mooring_log is not None:
            mooring_log.record_part(k, float(sol.time))
        saved = {"part": k, "runtime_s": wall, "excl_part_pct": excl_warn.part_pct,
                 "excl_total_pct": excl_warn.total_pct}
        if dtlog is not None:
            dtlog.flush()
            saved["savedt"] = json.dumps({"log": dtlog.get_state(), "terms": list(sol.dt_terms)})
        if gauges is not None:      # the rows up to this output reach their files before the checkpoint
            gauges.flush()
            saved["gauges"] = json.dumps(gauges.get_state())
        sph.save_checkpoint(ckpt, saved)

    excl_seen = [sum(sol.n_excluded.values())]
    excl_warn = ExclusionWarnings(int(params.get("WrnPartsOut", 1)) != 0, sph.n0_fluid,
                                  int(data["particles"]["type"].size))
    if resume and "excl_part_pct" in extra:         # the levels already warned about (each warns once)
        excl_warn.part_pct, excl_warn.total_pct = int(extra["excl_part_pct"]), int(extra["excl_total_pct"])
    excluded_log = ExcludedLog(outdir, float(sol.time) if resume else None)
    body_log = (BodyLog(outdir, sph.bodies, sph.body_names, float(sol.time) if resume else None,
                        prepare=sph.floating.held_loads)
                if sph.bodies is not None else None)
    moorings = sph.floating.moorings if sph.floating is not None else None
    mooring_log = None
    if moorings is not None:
        from .io.moorings_out import MooringLog
        floatings = [int(m) for m in data["bodies"]["mkbound"]]
        mooring_log = MooringLog(outdir, moorings, floatings, float(params["TimeOut"]),
                                 float(sol.time) if resume else None)
        if not resume:
            mooring_log.after_step(float(sol.time))
    status, code, message = "completed", 0, ""
    with (contextlib.nullcontext(stop) if stop is not None else _Stop()) as stop:
        try:
            if not resume:
                write_part(0)
            # on resume, the first output after the last one written: that one may be off the
            # schedule (a TimeMax between two outputs, extended by --resume --tmax)
            next_out = (out_times.first_after(float(sol.time), TIME_TOLERANCE * max(1.0, out_times.smallest))
                        if resume else out_times.after(out_times.nth(part)))
            extra = params.get("TimeOutExtra")
            # DualSPHysics's TimeOutExtra: rows whenever it is >= 0 (whatever TimeOut or <timeout> say)
            extra = float(extra) if body_log is not None and extra is not None and extra >= 0 else None
            next_extra = _next_multiple(sol.time, extra) if extra else 0.0
            while not time_reached(sol.time, tmax):
                t_step = sol.time
                events_before = len(sol.excluded)
                sol.step()
                dt_lo, dt_hi = min(dt_lo, sol.last_dt), max(dt_hi, sol.last_dt)
                if dtlog is not None:
                    dtlog.add(t_step, (sol.last_dt,) + sol.step_dt_terms)
                try:
                    sph.check(events_before)
                finally:
                    note_step_warnings()
                if gauges is not None:
                    gauges.after_step(sol)
                if mooring_log is not None:
                    mooring_log.after_step(float(sol.time))
                # MinFluidStop: that instant is written and the run ends normally (DualSPHysics)
                min_fluid = sph.min_fluid_reached() if sph.npf_minimum else ""
                if min_fluid:
                    sph.step_warnings.append(min_fluid)
                    note_step_warnings()
                if time_reached(sol.time, next_out, out_times.smallest) or sol.time >= tmax or min_fluid:
                    part += 1
                    write_part(part)
                    dt_lo, dt_hi = math.inf, 0.0
                    # the first output time after the clock (DualSPHysics's GetNextTime(TimeStep)):
                    # a step longer than the interval skips the times it jumped over
                    next_out = out_times.first_after(float(sol.time), TIME_TOLERANCE * max(1.0, out_times.smallest))
                    if extra:
                        next_extra = _next_multiple(sol.time, extra)
                elif extra is not None and time_reached(sol.time, next_extra, extra):
                    # TimeOutExtra: floating-body rows between the outputs (0: every step)
                    body_log.record(flush=False)
                    if extra:
                        next_extra = _next_multiple(sol.time, extra)
                progress.update(sol.time, sol.nstep, sol.state.n, dt=sol.last_dt)
                if min_fluid:
                    status, code, message = "completed", 0, min_fluid
                    break
                if stop.signal is not None:
                    status, code, message = "interrupted", 1, _interrupted(stop.signal, sol.time, outdir, part)
                    break
        except DivergenceError as exc:
            status, code, message = "diverged", 3, str(exc)
        except BaseException as exc:
            status, code = "failed", 1
            message = str(exc) if isinstance(exc, SphdviError) else f"{type(exc).__name__}: {exc}"
            runtime += _time.perf_counter() - t_loop
            _clean_up_after_failure(
                lambda: excluded_log.record(sol.take_excluded()),
                gauges.close if gauges is not None else None,
                dtlog.close if dtlog is not None else None,
                progress.close,
                lambda: files.write_json(status=status, message=message, steps=int(sol.nstep),
                                         physical_time=float(sol.time), runtime_s=runtime),
                writer.close)
            _raise_if_disk_full(exc, outdir, float(sol.time), int(sol.nstep), part)
            raise
    runtime += _time.perf_counter() - t_loop
    excluded_log.record(sol.take_excluded())       # those after the last output (a stopped run)
    if gauges is not None:
        gauges.close()
    if dtlog is not None:
        dtlog.close()
    progress.update(sol.time, sol.nstep, sol.state.n, force=True,
                    dt=sol.last_dt if sol.nstep > steps_at_start else None)
    progress.close()
    writer.close()
    for line in step_lines:                         # those after the last output (a stopped run)
        files.log("WARNING: " + line)
    files.log(f"{status}: t={sol.time:.6g} s, {sol.nstep} steps, runtime {runtime:.2f} s"
              + (f" -- {message}" if message else ""))
    files.write_json(status=status, message=message, steps=int(sol.nstep), physical_time=float(sol.time),
                     runtime_s=runtime, excluded=dict(sol.n_excluded), dtmin_steps=int(sol.n_dtmin),
                     particles_final=int(sol.state.n), threads_used=sol.threads_in_use(),
                     **({"inout": dict(sol.inout.counts)} if sol.inout is not None else {}),
                     **({"dtfixedfile_max_excess_s": float(sol.dt_error)}
                        if sol.dt_table is not None and np.isfinite(sol.dt_error) else {}),
                     us_per_particle_step=(1e6 * (runtime - wall_prev) / (sol.nstep - steps_at_start)
                                           / max(1, sol.state.n) if sol.nstep > steps_at_start else None))
    return RunResult(status, message, code, int(sol.nstep), float(sol.time), runtime)


def inout_text(io) -> str:
    """The inlet/outlet counts of run.log's output lines: particles created in and removed from
    the buffers, and those that crossed between buffers and fluid, since the start."""
    n = io.counts
    return (f"  inout: created={n['created']} removed={n['removed']} to_fluid={n['to_fluid']} "
            f"to_buffer={n['to_buffer']}")


def _resumed_dtlog(outdir, spec, tout, saved, sol, files) -> DtLog:
    """The ``<savedt>`` files of a resumed run: cut back to the checkpoint, the interval in
    progress and the solver's latest dt terms restored (anew when the checkpoint has none)."""
    if saved is None:
        line = (f"--resume: the checkpoint holds no <savedt> state (its run had none): {DTINFO_FILE} starts anew "
                f"at t={sol.time:.6g} s")
        files.log("WARNING: " + line)
        warnings.warn(line)
        return DtLog(outdir, spec, tout)
    saved = json.loads(saved)
    sol.dt_terms = tuple(float(v) for v in saved["terms"])
    return DtLog(outdir, spec, tout, state=saved["log"])


def _next_multiple(t: float, step: float) -> float:
    """The first multiple of ``step`` after ``t`` (DualSPHysics's TimeOutExtraUpdate)."""
    k = math.floor(t / step * (1 + 1e-12)) + 1
    return k * step


def _refuse_after_min_fluid(sph, outdir: str) -> None:
    """--resume of a run that MinFluidStop ended (its checkpoint holds fewer fluid particles
    than NpfMinimum): DualSPHysics's JSphCpuSingle::Run ends the simulation there, so there is
    nothing to continue, whatever --tmax says; InputError."""
    reached = sph.min_fluid_reached() if sph.npf_minimum else ""
    if reached:
        raise InputError(f"--resume: the run in {outdir} has ended: {reached[0].lower() + reached[1:]}; "
                         "a run that MinFluidStop ended cannot go on (not with a larger --tmax either): start it "
                         f"anew with 'sphdvi run {outdir} --overwrite' (or into another folder with -o)")


def _make_gauges(data, params, outdir, resume, t, periodicity=None, state=None):
    """Run-time gauges of ``<special><gauges>`` (None when the case has none); with periodic
    boundaries they see the fluid's periodic copies as the interaction does; ``state``: the
    checkpoint's gauge schedules on resume."""
    items = (data["json"].get("gauges") or {}).get("items") or []
    if not items:
        return None
    from .measure.gauges import RunGauges
    return RunGauges(data, params, outdir, resume=resume, time=t, periodicity=periodicity, state=state)


def _threading_layer() -> str:
    import numba
    try:
        return numba.threading_layer()
    except ValueError:
        return "not initialised"
