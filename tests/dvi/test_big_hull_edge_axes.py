"""Edge–edge separating axes of large hulls (collision._polytope_sat).

The edge–edge axes used to be skipped when the two hulls had more than 4096 pairs of EDGES:
two 40-sided prisms (120 × 120 edges) crossed edge on edge got a face normal tilted by half
a facet, 3-4 contacts at wrong gaps, and a resting prism drifted under the false lateral
component (audit hunt11/b, finding 6).  The limit now counts pairs of classes of parallel
edges, the axes actually tried (a 64-sided prism has 33 classes).

Tolerances: normals and gaps to 1e-12 (exact arithmetic on the prisms' vertices); at rest the
upper prism's speeds below 1e-9.
"""
import numpy as np
import pytest

from sphdvi.dvi import System
from sphdvi.dvi._math import np_quat_to_mat

R = 0.05
L = 0.3


def _prism(n, axis, edge_down=False):
    """An n-sided prism of circumradius R, half length L along x or y, a vertex (an edge of
    the prism) up, or down when ``edge_down``."""
    a = np.pi / 2 + 2 * np.pi * np.arange(n) / n
    pts = []
    for s in (-L, L):
        for t in a:
            u, v = R * np.cos(t), R * np.sin(t)
            pts.append((s, u, v) if axis == "x" else (u, s, v))
    pts = np.array(pts)
    if edge_down:
        pts[:, 2] *= -1
    return pts


def _pair(n, z):
    s = System(envelope=0.002)
    a = s.add_body(1.0, (1, 1, 1), kind="fixed")
    s.add_hull(a, _prism(n, "x"))
    b = s.add_body(1.0, (0.01,) * 3, pos=(0, 0, z))
    s.add_hull(b, _prism(n, "y", edge_down=True))
    return s, b


@pytest.mark.parametrize("n", [8, 20, 40, 64])
@pytest.mark.parametrize("gap", [1e-3, -1e-3])
def test_crossed_prisms_touch_edge_on_edge(n, gap):
    """Two n-gon prisms crossed at 90°, an edge up under an edge down, 1 mm apart or 1 mm into
    each other: one contact, normal +z, the gap exact."""
    s, b = _pair(n, 2 * R + gap)
    s._pack()
    nc = s._collide(np.array([np_quat_to_mat(q) for q in s.quat]))
    c = s._c
    assert nc == 1
    np.testing.assert_allclose(c["n"][0], (0, 0, 1), atol=1e-12)
    assert c["gap"][0] == pytest.approx(gap, abs=1e-12)
    np.testing.assert_allclose(c["pt"][0], (0, 0, R + 0.5 * gap), atol=1e-12)


@pytest.mark.parametrize("n", [40, 64])
def test_crossed_prism_rests_still(n):
    """The upper prism resting edge on edge for 0.3 s stays where it is (the tilted normal
    of the skipped edge axes pushed it sideways: |v| 2.6e-4 m/s after 0.5 s at n = 40)."""
    s, b = _pair(n, 2 * R + 5e-4)
    for _ in range(300):
        s.step(1e-3)
    assert np.linalg.norm(s.vel[b]) < 1e-9 and np.linalg.norm(s.omega_b[b]) < 1e-9
    np.testing.assert_allclose(s.pos[b], (0, 0, 2 * R), atol=1e-6)
