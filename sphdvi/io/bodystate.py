"""The dynamic state of a multibody System (``System.get_state``) in an HDF5 group.

One layout for both checkpoints that hold bodies: the ``bodies`` group of an SPH run's
restart.h5 and the restart.h5 of a body-only run.  Arrays are datasets; the scalars
(time, the previous step size) go to a JSON attribute, where floats round-trip exactly.
"""
from __future__ import annotations

import json

import numpy as np


def write_array(group, name: str, data) -> None:
    """``group.create_dataset(name, data=data)`` through h5py's low-level calls: the same
    contiguous dataset without filters (h5py's default creation properties: no times
    tracked), written in one call, for a fraction of the high-level call's ~0.1 ms of Python
    (a checkpoint writes ~20 of them at every output).  Numeric and boolean arrays only."""
    from h5py import h5d, h5p, h5s, h5t
    a = np.asarray(data)
    if not a.flags.c_contiguous:
        a = a.copy(order="C")           # (np.ascontiguousarray would make a 0-d array 1-d)
    if a.dtype.kind not in "biuf":
        group.create_dataset(name, data=a)
        return
    dcpl = h5p.create(h5p.DATASET_CREATE)
    dcpl.set_obj_track_times(False)
    space = h5s.create_simple(a.shape) if a.ndim else h5s.create(h5s.SCALAR)
    dset = h5d.create(group.id, name.encode(), h5t.py_create(a.dtype, logical=1), space, dcpl=dcpl)
    dset.write(h5s.ALL, h5s.ALL, a)


def write_body_state(group, state: dict) -> None:
    """Write a state returned by ``System.get_state()`` into the h5py ``group``."""
    scalars = {}
    for name, value in state.items():
        if isinstance(value, np.ndarray):
            write_array(group, name, value)
        else:
            scalars[name] = value.item() if isinstance(value, np.generic) else value
    group.attrs["scalars"] = json.dumps(scalars)


def body_state(group) -> dict:
    """The state :func:`write_body_state` wrote to ``group`` (for ``System.set_state``)."""
    state = {name: group[name][...] for name in group}
    state.update(json.loads(group.attrs["scalars"]))
    return state


def read_body_state(group, system) -> None:
    """Restore into ``system`` the state :func:`write_body_state` wrote to ``group``."""
    system.set_state(body_state(group))
