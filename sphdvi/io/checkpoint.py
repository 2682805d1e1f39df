"""``restart.h5``: the checkpoint a run writes at its outputs and ``--resume`` reads.

Two kinds, told apart by the file's ``format`` attribute:

* an SPH run's (no attribute): groups ``state`` (the particle arrays), ``aux`` (the
  solver's work arrays), ``scalars`` (attributes: clock, counters, exclusion counts as
  JSON, and the run loop's own scalars) and, with floating bodies, ``bodies``;
* a body-only run's (``sphdvi-bodies-restart``): the ``bodies`` group and the loop's
  scalars as a JSON attribute.

Both are written atomically (a temporary file renamed over the previous one), so a run
killed while writing keeps its previous checkpoint.
"""
from __future__ import annotations

import json
import warnings

import numpy as np

from ..errors import InputError, h5_reason
from .atomic import atomic_path
from .bodystate import body_state, read_body_state, write_array, write_body_state

RESTART_FILE = "restart.h5"            # in a run's output folder
BODIES_RESTART_FORMAT = "sphdvi-bodies-restart"


def _plain(value):
    return value.item() if isinstance(value, np.generic) else value


def save_sph_checkpoint(path: str, solver_state: dict, extra: dict, body_state: dict | None = None,
                        arrays: dict | None = None) -> None:
    """Write ``solver_state`` (``SPHSolver.get_checkpoint()``), the loop's scalars ``extra``,
    the floating bodies' ``System.get_state()`` and ``arrays`` ({group: {name: array}}, e.g. the
    mooring lines' nodes) to ``path``, atomically."""
    import h5py
    with atomic_path(path) as tmp:
        with h5py.File(tmp, "w") as f:
            for group in ("state", "aux"):
                g = f.create_group(group)
                for name, a in solver_state[group].items():
                    write_array(g, name, a)
            sc = f.create_group("scalars")
            for name, value in solver_state["scalars"].items():
                sc.attrs[name] = value
            sc.attrs["n_excluded"] = json.dumps(solver_state["n_excluded"])
            for k, v in extra.items():
                sc.attrs[k] = v
            if body_state is not None:
                write_body_state(f.create_group("bodies"), body_state)
            for group, items in (arrays or {}).items():
                g = f.create_group(f"arrays/{group}")
                for name, a in items.items():
                    g.create_dataset(name, data=np.asarray(a))


def _unreadable(path: str, exc: BaseException, what: str = "checkpoint") -> InputError:
    return InputError(f"--resume: {path} is not a readable {what} ({h5_reason(exc)}; truncated or corrupt?): "
                      "it cannot be resumed; run without --resume to start again (into another folder with "
                      "-o to keep these outputs)")


def check_case_identity(path: str, saved: dict, case_id: dict | None) -> None:
    """Refuse a checkpoint written for another case: ``saved`` (its scalars) holds the
    ``case_*`` keys of :func:`case_identity` since they were introduced; older checkpoints
    without them pass (the caller checks what it can)."""
    if case_id is None or "case_hash" not in saved or saved["case_hash"] == case_id["case_hash"]:
        return
    diffs = [f"{label} {saved[k]:g} in the checkpoint, {case_id[k]:g} in the case"
             for k, label in (("case_np", "particles"), ("case_dp", "dp"), ("case_h", "h"))
             if k in saved and saved[k] != case_id[k]]
    raise InputError(f"--resume: {path} was written by a run of another case ("
                     + ("; ".join(diffs) or "the particles differ") + "): the case file was written again "
                     "(gencase) after that run; run without --resume to start the new case (into another folder "
                     "with -o to keep the old outputs)")


def case_identity(particles: dict, constants: dict) -> dict:
    """What ties a checkpoint to its case: the particle count, dp, h and a hash of the
    initial particles (ids, types, mk, positions, masses)."""
    import hashlib
    digest = hashlib.sha256()
    for name in ("idp", "type", "mk", "pos", "mass"):
        a = np.ascontiguousarray(particles[name])
        digest.update(f"{name}:{a.dtype.str}:{a.shape}".encode())
        digest.update(a.tobytes())
    return {"case_np": int(np.asarray(particles["type"]).size), "case_dp": float(constants["dp"]),
            "case_h": float(constants["h"]), "case_hash": digest.hexdigest()[:32]}


def _older_checkpoint_matches(path: str, state: dict, case_particles: dict | None) -> None:
    """A checkpoint without the case identity (older sphdvi): its particles must be particles
    of the case (ids within it, the same type per id) and its boundary particles, which are
    never excluded, all of the case's."""
    if case_particles is None:
        return
    idp = np.asarray(state["idp"], np.int64)
    cidp = np.asarray(case_particles["idp"], np.int64)
    ctype = np.asarray(case_particles["type"])
    problem = None
    order = np.argsort(cidp)
    pos = np.searchsorted(cidp[order], idp)
    pos = np.minimum(pos, max(0, cidp.size - 1))
    if idp.size and (cidp.size == 0 or not np.array_equal(cidp[order][pos], idp)):
        problem = "particle ids that the case does not have"
    elif not np.array_equal(ctype[order][pos], np.asarray(state["ptype"])):
        problem = "particles of another type than the case's"
    else:
        nb_ck = int(np.count_nonzero(np.asarray(state["ptype"]) != 3))
        nb_case = int(np.count_nonzero(ctype != 3))
        if nb_ck != nb_case:
            problem = f"{nb_ck} boundary particles, the case {nb_case}"
    if problem:
        raise InputError(f"--resume: {path} holds {problem}: it was written by a run of another case (the case "
                         "file was written again by gencase after that run); run without --resume to start the "
                         "new case (into another folder with -o to keep the old outputs)")


def load_sph_checkpoint(path: str, solver, system=None, case_id: dict | None = None,
                        case_particles: dict | None = None) -> dict:
    """Restore into ``solver`` (and the floating bodies' ``system``) the state saved by
    :func:`save_sph_checkpoint`; returns the scalars (the loop's ``extra`` among them).

    A file that is not such a checkpoint (corrupt, truncated, a body-only run's, one with a
    missing dataset) or one written for another case (``case_id``, :func:`case_identity`;
    older checkpoints: ``case_particles``) raises InputError naming it."""
    import h5py
    try:
        with h5py.File(path, "r") as f:
            if f.attrs.get("format") == BODIES_RESTART_FORMAT:
                raise InputError(f"--resume: {path} is the checkpoint of a body-only run, and the case now has "
                                 "fluid: the case file was written again (gencase) after that run; run without "
                                 "--resume (into another folder with -o to keep the old outputs)")
            for group in ("state", "aux", "scalars"):
                if group not in f:
                    raise KeyError(f"no group '{group}'")
            sc = {k: _plain(v) for k, v in f["scalars"].attrs.items()}
            need = [n for n in ("n_excluded", "part") + tuple(solver.CHECKPOINT_SCALARS)
                    if n not in sc and n not in getattr(solver, "CHECKPOINT_DEFAULTS", {})]
            need += [f"state/{n}" for n in solver.state.FIELDS if n not in f["state"]]
            if need:
                raise KeyError(f"no {', '.join(need)}")
            state = {name: f["state"][name][...] for name in f["state"]}
            aux = {name: f["aux"][name][...] for name in f["aux"]}
            n_excluded = json.loads(sc["n_excluded"])
            has_bodies = "bodies" in f
            sc["arrays"] = {group: {name: f["arrays"][group][name][()] for name in f["arrays"][group]}
                            for group in (f["arrays"] if "arrays" in f else ())}
            bodies = None
            if system is not None and has_bodies:
                bodies = body_state(f["bodies"])
    except InputError:
        raise
    except (OSError, KeyError, ValueError, TypeError) as exc:
        raise _unreadable(path, exc) from None
    check_case_identity(path, sc, case_id)
    if "case_hash" not in sc:
        _older_checkpoint_matches(path, state, case_particles)
    if (system is not None) != has_bodies:
        raise InputError(f"--resume: {path} " + ("has no floating bodies, the case has" if system is not None
                                                  else "has floating bodies, the case has none")
                         + ": it was written by a run of another case; run without --resume")
    missing = solver.set_checkpoint({"state": state, "aux": aux, "scalars": sc, "n_excluded": n_excluded})
    for name in missing:
        warnings.warn(f"checkpoint {path} has no '{name}' (older sphdvi); it restarts from zero")
    if bodies is not None:
        try:
            system.set_state(bodies)
        except (KeyError, ValueError, IndexError) as exc:
            raise InputError(f"--resume: the floating bodies in {path} do not match the case's "
                             f"({type(exc).__name__}: {exc}); run without --resume") from None
    return sc


def checkpoint_time(path: str) -> float | None:
    """The simulated time of a restart.h5 (an SPH or a body-only run's); None when it cannot
    be read (the resume itself then says why)."""
    import h5py
    try:
        with h5py.File(path, "r") as f:
            if f.attrs.get("format") == BODIES_RESTART_FORMAT:
                return float(json.loads(f["bodies"].attrs["scalars"])["time"])
            return float(f["scalars"].attrs["time"])
    except (OSError, KeyError, ValueError, TypeError):
        return None


def save_bodies_checkpoint(path: str, state: dict, **extra) -> None:
    """Write the state of a body-only run to ``path`` atomically: a System's dynamic state
    (``System.get_state()``, in the layout of an SPH run's restart.h5) and the scalars
    ``extra`` (part, step, runtime_s, names)."""
    import h5py
    with atomic_path(path) as tmp:
        with h5py.File(tmp, "w") as f:
            f.attrs["format"] = BODIES_RESTART_FORMAT
            f.attrs["extra"] = json.dumps(extra)
            write_body_state(f.create_group("bodies"), state)


def load_bodies_checkpoint(path: str, system, case_id: dict | None = None, names: list | None = None) -> dict:
    """Restore into ``system`` (built from the case) the state saved by
    :func:`save_bodies_checkpoint`; returns its scalars.  An unreadable file, an SPH run's
    checkpoint or one written for another case (``case_id``; older checkpoints: the body
    ``names``) raises InputError."""
    import h5py
    try:
        with h5py.File(path, "r") as f:
            if f.attrs.get("format") != BODIES_RESTART_FORMAT:
                if "state" in f and "scalars" in f:
                    raise InputError(f"--resume: {path} is the checkpoint of an SPH run, and the case now has no "
                                     "fluid: the case file was written again (gencase) after that run; run without "
                                     "--resume (into another folder with -o to keep the old outputs)")
                raise KeyError("no body-only checkpoint format attribute")
            extra = json.loads(f.attrs["extra"])
            check_case_identity(path, extra, case_id)
            if names is not None and extra.get("names") != list(names):
                raise InputError(f"--resume: {path} holds the bodies {extra.get('names')}, the case {list(names)}: "
                                 "it was written by a run of another case; run without --resume")
            read_body_state(f["bodies"], system)
    except InputError:
        raise
    except (OSError, KeyError, ValueError, TypeError) as exc:
        raise _unreadable(path, exc, "body-only checkpoint") from None
    return extra
