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

from ..errors import InputError
from .atomic import atomic_path
from .bodystate import read_body_state, write_body_state

RESTART_FILE = "restart.h5"            # in a run's output folder
BODIES_RESTART_FORMAT = "sphdvi-bodies-restart"


def _plain(value):
    return value.item() if isinstance(value, np.generic) else value


def save_sph_checkpoint(path: str, solver_state: dict, extra: dict, body_state: dict | None = None) -> None:
    """Write ``solver_state`` (``SPHSolver.get_checkpoint()``), the loop's scalars ``extra``
    and the floating bodies' ``System.get_state()`` to ``path``, atomically."""
    import h5py
    with atomic_path(path) as tmp:
        with h5py.File(tmp, "w") as f:
            for group in ("state", "aux"):
                g = f.create_group(group)
                for name, a in solver_state[group].items():
                    g.create_dataset(name, data=a)
            sc = f.create_group("scalars")
            for name, value in solver_state["scalars"].items():
                sc.attrs[name] = value
            sc.attrs["n_excluded"] = json.dumps(solver_state["n_excluded"])
            for k, v in extra.items():
                sc.attrs[k] = v
            if body_state is not None:
                write_body_state(f.create_group("bodies"), body_state)


def load_sph_checkpoint(path: str, solver, system=None) -> dict:
    """Restore into ``solver`` (and the floating bodies' ``system``) the state saved by
    :func:`save_sph_checkpoint`; returns the scalars (the loop's ``extra`` among them)."""
    import h5py
    with h5py.File(path, "r") as f:
        sc = {k: _plain(v) for k, v in f["scalars"].attrs.items()}
        missing = solver.set_checkpoint({
            "state": {name: f["state"][name][...] for name in f["state"]},
            "aux": {name: f["aux"][name][...] for name in f["aux"]},
            "scalars": sc, "n_excluded": json.loads(sc["n_excluded"])})
        for name in missing:
            warnings.warn(f"checkpoint {path} has no '{name}' (older sphdvi); it restarts from zero")
        if system is not None and "bodies" in f:
            read_body_state(f["bodies"], system)
    return sc


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


def load_bodies_checkpoint(path: str, system) -> dict:
    """Restore into ``system`` (built from the case) the state saved by
    :func:`save_bodies_checkpoint`; returns its scalars."""
    import h5py
    try:
        with h5py.File(path, "r") as f:
            if f.attrs.get("format") != BODIES_RESTART_FORMAT:
                raise InputError(f"{path}: not a body-only checkpoint of this sphdvi")
            extra = json.loads(f.attrs["extra"])
            read_body_state(f["bodies"], system)
    except InputError:
        raise
    except (OSError, KeyError, ValueError) as exc:
        raise InputError(f"{path}: not a readable body-only checkpoint ({type(exc).__name__}: {exc})") from None
    return extra
