"""Box-box contacts through the polytope face manifold (one code path with hull-hull).

A box is a hull with 6 faces: box-box pairs go through the separating-axis test over face
normals and edge-direction pairs (collision._polytope_sat) and the clipped, keyed face manifold
(collision._polytope_manifold).  Before, box-box had its own clipping that keyed a point by its
place in the clipped polygon (key 0..3: the same key could name another point the next step,
and the warm start then carried one corner's impulse to another).

Tolerances: the hull comparison is to round-off (the same arithmetic on the same vertices; 1e-12
m); keys must be identical over 100 resting steps (the warm start finds every contact: 100 %).
"""
import math

import numpy as np
import pytest

from sphdvi.dvi import System
from sphdvi.dvi import collision as col

G = 9.81
H = 0.1
CUBE = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], float)


def _stack(shape, xy=(0.03, 0.02), yaw=0.0, solver="bb"):
    """A box resting on a box on the ground plane, the upper one offset by xy and turned by
    ``yaw`` about z; ``shape``: "box" or "hull" (the same cubes as hulls)."""
    s = System(gravity=(0, 0, -G), solver=solver, max_iter=100, tol=1e-10, envelope=0.005)
    s.add_plane()
    I = (2 * H) ** 2 / 6.0
    q = (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))
    lo = s.add_body(1.0, (I, I, I), pos=(0, 0, H))
    hi = s.add_body(1.0, (I, I, I), pos=(xy[0], xy[1], 3 * H + 1e-4), quat=q)
    for b in (lo, hi):
        if shape == "box":
            s.add_box(b, (H, H, H))
        else:
            s.add_hull(b, CUBE * H)
    return s, lo, hi


def _pair_contacts(s, sa, sb):
    c = s._c
    n = s.n_contacts
    m = ((c["sa"][:n] == sa) & (c["sb"][:n] == sb)) | ((c["sa"][:n] == sb) & (c["sb"][:n] == sa))
    order = np.argsort(c["key"][:n][m], kind="stable")
    return {k: c[k][:n][m][order] for k in ("key", "pt", "n", "gap")}


@pytest.mark.parametrize("yaw", [0.0, 0.5])
def test_box_box_contacts_are_the_cube_hulls(yaw):
    """One code path: a box-box pair's contacts (points, normals, gaps, keys) are those of the
    same two cubes as hulls."""
    out = []
    for shape in ("box", "hull"):
        s, lo, hi = _stack(shape, yaw=yaw)
        for _ in range(50):
            s.step(1e-3)
        out.append(_pair_contacts(s, 1, 2))
    assert 3 <= out[0]["key"].shape[0] <= 4
    np.testing.assert_array_equal(out[0]["key"], out[1]["key"])
    for k in ("pt", "n", "gap"):
        np.testing.assert_allclose(out[0][k], out[1][k], atol=1e-12)


def test_box_box_keys_name_features():
    """The face manifold's keys name a vertex or an edge crossing (≥ _VKEY0 in the pair's key
    block), not a place in the clipped polygon."""
    s, lo, hi = _stack("box")
    s.step(1e-3)
    keys = _pair_contacts(s, 1, 2)["key"] % 1048576
    assert keys.shape[0] == 4
    assert np.all(keys >= col._VKEY0)


@pytest.mark.parametrize("solver", ["psor", "bb", "apgd"])
@pytest.mark.parametrize("yaw", [0.0, 0.5])
def test_resting_offset_box_stack_keeps_its_keys(solver, yaw):
    """A resting offset box-on-box stack (also turned 0.5 rad: an overlap polygon of more than
    4 points, reduced to 4): the box-box keys are identical over 100 steps and the warm start
    finds every contact of the stack (hit rate 100 %)."""
    s, lo, hi = _stack("box", yaw=yaw, solver=solver)
    for _ in range(300):
        s.step(1e-3)
    ref = _pair_contacts(s, 1, 2)["key"]
    assert ref.shape[0] == 4
    prev = set(s._c["key"][:s.n_contacts].tolist())
    hits = total = 0
    for _ in range(100):
        s.step(1e-3)
        np.testing.assert_array_equal(_pair_contacts(s, 1, 2)["key"], ref)
        keys = s._c["key"][:s.n_contacts].tolist()
        hits += sum(k in prev for k in keys)
        total += len(keys)
        prev = set(keys)
    assert hits == total
    assert abs(s.contact_force[hi, 2] / G - 1) < 1e-2
    assert abs(s.pos[hi, 2] - 3 * H) < 1e-5


def test_box_edge_classes():
    """A box's 12 edges form 3 classes of parallel edges (the SAT tries 3 x 3 edge axes)."""
    s = System()
    b = s.add_body(1.0, (1, 1, 1))
    s.add_box(b, (0.1, 0.2, 0.3))
    rep = s.ed_rep[s.ed_off[0]:s.ed_off[0] + s.ed_cnt[0]]
    assert len(set(rep.tolist())) == 3
    d = s.samp_pts[s.edges[:12, 1]] - s.samp_pts[s.edges[:12, 0]]
    for k in range(12):
        assert np.linalg.norm(np.cross(d[k], d[rep[k]])) == 0.0
