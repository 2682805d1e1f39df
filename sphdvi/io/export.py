"""``sphdvi export``: particles.vtkhdf → Part_XXXX.vtp + particles.pvd (ParaView ≤ 5.11)."""
from __future__ import annotations

import os

from ..errors import InputError
from .vtkhdf import read_step, step_times
from .vtkxml import write_pvd, write_vtp_points


def export_vtp(outdir: str, subdir: str = "vtp") -> list[str]:
    src = os.path.join(outdir, "particles.vtkhdf")
    if not os.path.isfile(src):
        raise InputError(f"{src} not found: run 'sphdvi run' first")
    dest = os.path.join(outdir, os.path.basename(os.path.normpath(subdir)) or "vtp")
    os.makedirs(dest, exist_ok=True)
    times = step_times(src)
    files, entries = [], []
    for k, t in enumerate(times):
        step = read_step(src, k)
        name = f"Part_{k:04d}.vtp"
        arrays = {key: val for key, val in step.items() if key not in ("time", "points")}
        write_vtp_points(os.path.join(dest, name), step["points"], arrays)
        files.append(os.path.join(dest, name))
        entries.append((float(t), name))
    pvd = os.path.join(dest, "particles.pvd")
    write_pvd(pvd, entries)
    return files + [pvd]
