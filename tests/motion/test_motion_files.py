"""File-driven motion (``mvrectfile``/``mvrotfile``) as DualSPHysics's JMotionObj::ProcesTime plays it:
the file's first row at the movement's start, positions interpolated linearly between rows and held
after the last, the boundary velocity the step's displacement over dt (the slope of the rows'
segment, 0 outside the file's times)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from sphdvi.motion import chain_transform


def write(path, rows):
    path.write_text("".join(" ".join(f"{v:g}" for v in r) + "\n" for r in rows))
    return str(path)


def rect_chain(file, start=0.0):
    m = {"type": "mvrectfile", "id": 1, "duration": 100.0, "next": None, "file": file,
         "fields": {"fieldtime": 0, "fieldx": 1}, "ncols": 2}
    return {"ref": 1, "movements": [m], "begin": {"mov": 1, "start": start, "finish": None}, "parents": []}


def rot_chain(file):
    m = {"type": "mvrotfile", "id": 1, "duration": 100.0, "next": None, "file": file,
         "fields": {"fieldtime": 0, "fieldang": 1}, "ncols": 2, "axisp1": [0, 0, 0], "axisp2": [0, 1, 0],
         "anglesunits": "degrees"}
    return {"ref": 1, "movements": [m], "begin": {"mov": 1, "start": 0.0, "finish": None}, "parents": []}


@pytest.mark.parametrize("start", [0.0, 0.7])
def test_a_file_s_first_row_plays_at_the_movement_start(tmp_path, start):
    """A record stamped 2..4 s (cut out of a longer one): DualSPHysics looks up (t − start) + t_0, so the
    motion begins at once, not 2 s late; the displacement is from row 0."""
    c = rect_chain(write(tmp_path / "f.dat", [(2.0, 0.3), (3.0, 0.4), (4.0, 0.4)]), start)
    for tau, dx, vx in ((0.5, 0.05, 0.1), (1.0, 0.1, 0.0), (2.5, 0.1, 0.0)):
        r = chain_transform(c, start + tau)
        assert r.d[0] == pytest.approx(dx, abs=1e-12) and r.V[0] == pytest.approx(vx, abs=1e-12)


def test_file_velocity_is_zero_after_the_last_row(tmp_path):
    """Position held at the last row (JMotionMovActive::DfGetNewPos) and so no velocity, for a piston
    and a rotation whose files end while they move."""
    c = rect_chain(write(tmp_path / "x.dat", [(0.0, 0.0), (1.0, 0.1), (2.0, 0.2)]))
    for t in (2.5, 5.0):
        r = chain_transform(c, t)
        assert r.d[0] == pytest.approx(0.2) and r.V[0] == 0.0
    assert chain_transform(c, 1.5).V[0] == pytest.approx(0.1)
    c = rot_chain(write(tmp_path / "a.dat", [(0.0, 0.0), (1.0, 10.0)]))
    assert np.linalg.norm(chain_transform(c, 0.5).W) == pytest.approx(math.radians(10.0))
    for t in (1.5, 3.0):
        r = chain_transform(c, t)
        assert np.all(r.W == 0.0)
        assert r.R[0, 0] == pytest.approx(math.cos(math.radians(10.0)))


def test_file_velocity_is_the_slope_of_the_segment(tmp_path):
    """A coarse trapezoid (rest, 0.1 m/s, rest): the velocity is each segment's slope, not the nodal
    central differences interpolated (0.025, 0.05, 0.025 m/s at the segments' middles before)."""
    c = rect_chain(write(tmp_path / "trap.dat", [(0.0, 0.0), (1.0, 0.0), (2.0, 0.1), (3.0, 0.1)]))
    for t, x, v in ((0.5, 0.0, 0.0), (0.9, 0.0, 0.0), (1.1, 0.01, 0.1), (1.5, 0.05, 0.1), (1.9, 0.09, 0.1),
                    (2.1, 0.1, 0.0), (2.5, 0.1, 0.0)):
        r = chain_transform(c, t)
        assert r.d[0] == pytest.approx(x, abs=1e-12) and r.V[0] == pytest.approx(v, abs=1e-12)
