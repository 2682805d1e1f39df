"""The maxz gauge's window as sphdvi documents it (hunt8/t finding 3): fluid with
point0.z <= z <= point0.z + height strictly, within distlimit horizontally, distlimit 1.5 dp
when the case gives none.  DualSPHysics's JGaugeMaxZ searches whole cells (it also sees fluid
up to a cell beyond either end) and requires <distlimit>; see MaxZGauge's docstring."""
from types import SimpleNamespace

import numpy as np

from sphdvi.measure import core
from sphdvi.measure.gauges import MaxZGauge

SPEC = SimpleNamespace(h=0.0346, dp=0.02, is2d=False)


def gauge(**item):
    return MaxZGauge({"name": "m", "point0": [0.0, 0.0, 0.1], "height": 0.3, **item}, SPEC, {})


def zmax(g, pos):
    pos = np.asarray(pos, float)
    return g.compute(SimpleNamespace(pos=pos, ptype=np.full(pos.shape[0], core.FLUID)))[0]


def test_window_ends_are_strict():
    g = gauge()
    assert zmax(g, [[0, 0, 0.35], [0, 0, 0.4 + 1e-6]]) == 0.35        # just above point0.z + height: not seen
    assert zmax(g, [[0, 0, 0.4]]) == 0.4                               # at the top: seen
    assert zmax(g, [[0, 0, 0.1 - 1e-6]]) == 0.1                        # just below point0: dry (point0's z)


def test_default_distlimit_is_one_and_a_half_dp():
    g = gauge()
    assert g.radius == 1.5 * SPEC.dp
    assert zmax(g, [[0.029, 0, 0.2], [0.031, 0, 0.3]]) == 0.2          # 1.45 dp in, 1.55 dp out
    assert gauge(distlimit={"coefh": "1"}).radius == SPEC.h
    assert gauge(distlimit={"value": "0.05"}).radius == 0.05
