"""The dynamic state of a multibody System (``System.get_state``) in an HDF5 group.

One layout for both checkpoints that hold bodies: the ``bodies`` group of an SPH run's
restart.h5 and the restart.h5 of a body-only run.  Arrays are datasets; the scalars
(time, the previous step size) go to a JSON attribute, where floats round-trip exactly.
"""
from __future__ import annotations

import json

import numpy as np


def write_body_state(group, state: dict) -> None:
    """Write a state returned by ``System.get_state()`` into the h5py ``group``."""
    scalars = {}
    for name, value in state.items():
        if isinstance(value, np.ndarray):
            group.create_dataset(name, data=value)
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
