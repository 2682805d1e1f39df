"""What every validation scorer reads from a run folder OUT: its gencase case (constants,
parameters, particles), its gauge files, body and link logs, and its run.json."""
from __future__ import annotations

import json
import os


def case_data(outdir: str) -> dict:
    """The gencase file of ``outdir`` (:func:`sphdvi.io.casefile.read_case_h5`)."""
    from ..io.casefile import read_case_h5
    from ..simulation import find_case_file
    return read_case_h5(find_case_file(str(outdir)))


def gauge_table(outdir: str, kind: str, name: str):
    """The rows of the run-time gauge file ``Gauges<kind>_<name>.csv`` of ``outdir`` (time first;
    columns as sphdvi.measure.gauges writes them: for SWL, column 3 is the surface's z)."""
    import numpy as np
    return np.genfromtxt(os.path.join(str(outdir), f"Gauges{kind}_{name}.csv"), delimiter=";", skip_header=1)


def body_log(outdir: str, name: str = "bodies"):
    """The rows of the run's ``bodies.csv`` or ``links.csv`` (``name`` "bodies" or "links") as a
    numpy structured array, one field per header column (time, body or link, x, ..., fx, ...)."""
    import numpy as np
    return np.genfromtxt(os.path.join(str(outdir), f"{name}.csv"), delimiter=",", names=True, dtype=None,
                         encoding="utf-8")


def run_info(outdir: str) -> dict:
    """run.json of ``outdir`` ({} when the run wrote none)."""
    path = os.path.join(str(outdir), "run.json")
    if not os.path.isfile(path):
        return {}
    with open(path) as fh:
        return json.load(fh)
