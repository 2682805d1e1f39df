"""Several ``<begin>`` of one motion object: events, each starting its own chain of movements at its
start and stopped at its finish (DualSPHysics's JMotion::EventAdd, JMotionObj::BeginEvent/ProcesTime:
every active chain moves the object by its step in turn)."""
from __future__ import annotations

import numpy as np
import pytest
from lxml import etree

from sphdvi.case.reader import read_motion
from sphdvi.case.xmldoc import CaseReader
from sphdvi.errors import CaseError
from sphdvi.motion import MotionSet

RECT = '<mvrect id="{}" duration="{}"{}><vel x="{}" y="{}" z="0"/></mvrect>'
ROT = ('<mvrot id="{}" duration="{}"><vel ang="90"/><axisp1 x="0" y="0" z="0"/>'
       '<axisp2 x="0" y="1" z="0"/></mvrot>')


def read(tmp_path, body):
    """read_motion of one objreal (mkbound 1) holding ``body`` (its <begin> on line 3)."""
    xml = f'<casedef>\n<motion><objreal ref="1">\n{body}\n</objreal></motion>\n</casedef>'
    reader = CaseReader(str(tmp_path / "case.xml"), base_dir=str(tmp_path))
    return read_motion(reader, etree.fromstring(xml)), reader


def test_each_begin_starts_its_own_chain(tmp_path):
    """The auditor's case: +0.1 m/s from 0 to 0.5 s (finish), then -0.1 m/s from 1 s on."""
    body = ('<begin mov="1" start="0" finish="0.5"/><begin mov="2" start="1"/>'
            + RECT.format(1, 100, "", 0.1, 0) + RECT.format(2, 100, "", -0.1, 0))
    motions, reader = read(tmp_path, body)
    assert list(reader.warnings) == []
    assert [e["start"] for e in motions[0]["events"]] == [0.0, 1.0]
    ms = MotionSet(motions)
    for t, x, v in ((0.25, 0.025, 0.1), (0.75, 0.05, 0.0), (1.5, 0.0, -0.1), (2.0, -0.05, -0.1)):
        r = ms.transform(1, t)
        assert r.d[0] == pytest.approx(x, abs=1e-12) and r.V[0] == pytest.approx(v, abs=1e-12)


def test_overlapping_translations_add_up(tmp_path):
    """Two events at once, each moving along its own axis (translations commute: their sum is
    DualSPHysics's per-step composition); a chain of the second one ends after its duration."""
    body = ('<begin mov="1" start="0"/><begin mov="2" start="0.5"/>'
            + RECT.format(1, 100, "", 0.1, 0) + RECT.format(2, 1, "", 0, 0.2))
    ms = MotionSet(read(tmp_path, body)[0])
    for t, d, v in ((0.25, (0.025, 0), (0.1, 0)), (1.0, (0.1, 0.1), (0.1, 0.2)), (2.0, (0.2, 0.2), (0.1, 0))):
        r = ms.transform(1, t)
        assert np.allclose(r.d[:2], d, atol=1e-12) and np.allclose(r.V[:2], v, atol=1e-12)


def test_a_rotation_after_a_translation_event_turns_the_moved_object(tmp_path):
    """Events one after the other: the second one's rotation about its (fixed) axis acts on where the
    first one left the object."""
    body = '<begin mov="1" start="0" finish="1"/><begin mov="2" start="2"/>' + RECT.format(1, 100, "", 1, 0) + \
        ROT.format(2, 100)
    ms = MotionSet(read(tmp_path, body)[0])
    x, v = ms.transform(1, 3.0).apply(np.zeros((1, 3)))       # moved to (1, 0, 0), then turned 90 degrees
    assert np.linalg.norm(x[0]) == pytest.approx(1.0) and abs(x[0, 0]) < 1e-12
    assert np.linalg.norm(v[0]) == pytest.approx(np.pi / 2)


def test_concurrent_events_with_a_rotation_are_a_case_error(tmp_path):
    body = '<begin mov="1" start="0"/><begin mov="2" start="1"/>' + RECT.format(1, 3, "", 1, 0) + ROT.format(2, 1)
    with pytest.raises(CaseError, match="run at the same time .* rotates it") as e:
        read(tmp_path, body)
    assert e.value.element == "begin" and e.value.line == 3


def test_an_object_without_begin_does_not_move(tmp_path):
    """JMotion runs a movement only from an event: movements without a <begin> leave the object
    where it is (sphdvi started the first one at t = 0), and gencase says so."""
    motions, reader = read(tmp_path, RECT.format(1, 100, "", 0.1, 0))
    assert any("without a <begin" in str(w) for w in reader.warnings)
    r = MotionSet(motions).transform(1, 1.0)
    assert np.allclose(r.d, 0.0) and np.allclose(r.V, 0.0)
