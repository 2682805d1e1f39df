"""A motion file (mvrectfile, mvrotfile) whose time repeats, as DualSPHysics v5.4's own example
17_WaveRunup ships it (Mov_piston.dat opens with two rows at t = 0): GenCase and DualSPHysics take
it, and JMotionMovActive::DfGetNewPos steps over the segment of zero length (its look-up advances
while t > times[i]; it never divides by a zero interval). sphdvi took it for an input error."""
from __future__ import annotations

import numpy as np
import pytest
from lxml import etree

from sphdvi.case.reader import read_motion
from sphdvi.case.xmldoc import CaseReader
from sphdvi.motion import chain_transform


def _read(tmp_path, content, tag="mvrectfile"):
    (tmp_path / "m.dat").write_text(content)
    fields = 'fields="2" fieldtime="0" fieldx="1"' if tag == "mvrectfile" else 'fields="2" fieldtime="0" fieldang="1"'
    xml = (f'<casedef>\n<motion><objreal ref="1"><begin mov="1" start="0"/>\n'
           f'<{tag} id="1" duration="100"><file name="m.dat" {fields}/>'
           + ('<axisp1 x="0" y="0" z="0"/><axisp2 x="0" y="1" z="0"/>' if tag == "mvrotfile" else "")
           + f'</{tag}>\n</objreal></motion>\n</casedef>')
    reader = CaseReader(str(tmp_path / "case.xml"), base_dir=str(tmp_path))
    (m,) = read_motion(reader, etree.fromstring(xml))
    return m


def _dsph_position(times, values, t):
    """DfGetNewPos's value at t, from its source: the first row i with times[i] >= t (its loop
    advances while t > times[i]), interpolated from row i - 1; the last row's value past the end."""
    i = 1
    while i < len(times) and t > times[i]:
        i += 1
    if i >= len(times):
        return values[-1]
    f = (t - times[i - 1]) / (times[i] - times[i - 1])
    return values[i - 1] + f * (values[i] - values[i - 1])


# the 17_WaveRunup layout (two rows at t = 0), then a step at t = 1 (x jumps from 0.2 to 0.5)
TABLE = [(0.0, 0.0), (0.0, 0.0), (0.5, 0.1), (1.0, 0.2), (1.0, 0.5), (2.0, 0.7)]


def test_repeated_times_are_read_and_played_as_dualsphysics(tmp_path):
    m = _read(tmp_path, "".join(f"{t} {x}\n" for t, x in TABLE))
    times = [t for t, _ in TABLE]
    xs = [x for _, x in TABLE]
    for t in (0.1, 0.25, 0.5, 0.75, 0.999, 1.001, 1.5, 2.0, 3.0):
        x, v = chain_transform(m, t).apply(np.zeros((1, 3)))
        assert x[0, 0] == pytest.approx(_dsph_position(times, xs, t), abs=1e-12), t
        assert np.all(np.isfinite(v))
    # the velocity is the slope of the segment that holds t: the step itself has none
    assert chain_transform(m, 0.25).apply(np.zeros((1, 3)))[1][0, 0] == pytest.approx(0.2)
    assert chain_transform(m, 1.5).apply(np.zeros((1, 3)))[1][0, 0] == pytest.approx(0.2)
    assert chain_transform(m, 0.75).apply(np.zeros((1, 3)))[1][0, 0] == pytest.approx(0.2)


def test_repeated_times_in_a_rotation_file(tmp_path):
    m = _read(tmp_path, "0 0\n0 0\n1 10\n", tag="mvrotfile")
    x, v = chain_transform(m, 0.5).apply(np.array([[1.0, 0.0, 0.0]]))
    assert np.all(np.isfinite(x)) and np.all(np.isfinite(v))
    assert np.hypot(x[0, 0], x[0, 2]) == pytest.approx(1.0)
    assert abs(np.degrees(np.arctan2(x[0, 2], x[0, 0]))) == pytest.approx(5.0)
