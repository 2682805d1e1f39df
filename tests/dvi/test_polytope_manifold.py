"""Face-face contact manifold of two polytopes (box/hull pairs; box-box: test_box_manifold.py).

collision._polytope_manifold: the SAT face axis of least penetration is the reference face,
the other polytope's most anti-parallel face the incident one; the incident polygon is clipped
by the reference face's side planes (Sutherland-Hodgman), the points within the envelope are
kept and reduced to 4 (deepest, farthest, largest triangle, largest quadrilateral), each keyed
by the vertex or the edge pair it comes from.  Before, such a contact had only the vertices of
either polytope that lie within the other's face: a cube hull on a cube rotated 45 deg about z
(the overlap an octagon, no vertex inside the other) had none and fell through; an offset stack
had two diagonal points and rocked.

Tolerances: a resting NSC contact with a converged solver holds the weight to round-off; 1 % of
the weight per step (the brief's bound) and 1e-4 rad of tilt leave room for the solver's
tolerance.  Warm start: the key set of a resting contact must not change from step to step.
"""
import math

import numpy as np
import pytest

from sphdvi.dvi import System
from sphdvi.dvi._math import np_quat_to_mat

G = 9.81
H = 0.1                                   # half size of the upper cube
CUBE = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], float)
Q45 = (math.cos(math.pi / 8), 0.0, 0.0, math.sin(math.pi / 8))     # 45 deg about z


def _rest(lower, lower_half, xy=(0.0, 0.0), quat=(1, 0, 0, 0), solver="bb", steps=600):
    """An upper cube hull dropped 1 mm onto a fixed box or hull; returns per-step records."""
    s = System(gravity=(0, 0, -G), solver=solver, max_iter=100, tol=1e-10, envelope=0.005)
    base = s.add_body(1.0, (1, 1, 1), kind="fixed")
    if lower == "hull":
        s.add_hull(base, CUBE * np.asarray(lower_half))
    else:
        s.add_box(base, lower_half)
    top = s.add_body(1.0, (H * H * 2 / 3,) * 3, pos=(xy[0], xy[1], lower_half[2] + H + 0.001),
                     quat=quat)
    s.add_hull(top, CUBE * H)
    rec = dict(F=[], tilt=[], nc=[], keys=[], its=[])
    for _ in range(steps):
        s.step(1e-3)
        rec["F"].append(s.contact_force[top, 2])
        rec["tilt"].append(math.acos(min(1.0, np_quat_to_mat(s.quat[top])[2, 2])))
        rec["nc"].append(s.n_contacts)
        rec["keys"].append(tuple(sorted(s._c["key"][:s.n_contacts])))
        rec["its"].append(s.last_iterations)
    return s, top, {k: np.array(v) if k != "keys" else v for k, v in rec.items()}


def _assert_rests(s, top, rec, z, xy, n_points=4):
    last = slice(-200, None)
    assert abs(s.pos[top, 2] - z) < 1e-6
    np.testing.assert_allclose(s.pos[top, :2], xy, atol=1e-6)
    assert np.all(np.abs(rec["F"][last] / G - 1) < 1e-2)
    assert rec["tilt"][last].max() < 1e-4
    assert np.all(rec["nc"][last] == n_points)
    keys = rec["keys"][-200:]
    assert all(k == keys[0] for k in keys)          # persistent contact keys (warm start)


@pytest.mark.parametrize("lower", ["hull", "box"])
@pytest.mark.parametrize("solver", ["bb", "psor"])
def test_cube_rests_fully_on_a_larger_block(lower, solver):
    """Incident face wholly inside the reference face: its 4 vertices."""
    s, top, rec = _rest(lower, (0.3, 0.3, 0.1), xy=(0.05, -0.04), solver=solver)
    _assert_rests(s, top, rec, 0.1 + H, (0.05, -0.04))


@pytest.mark.parametrize("lower", ["hull", "box"])
@pytest.mark.parametrize("solver", ["bb", "psor", "apgd"])
def test_cube_rests_on_a_cube_turned_45_degrees(lower, solver):
    """The overlap is a regular octagon (8 edge crossings): reduced to 4 points, the same
    ones every step; the old vertex-face contacts found none and the cube fell through."""
    s, top, rec = _rest(lower, (0.1, 0.1, 0.1), quat=Q45, solver=solver)
    _assert_rests(s, top, rec, 0.1 + H, (0.0, 0.0))
    assert rec["its"][-200:].mean() < 10


@pytest.mark.parametrize("lower", ["hull", "box"])
def test_offset_cube_on_a_cube_has_four_steady_points(lower):
    """Offset (0.03, 0.02): the overlap's corners are a vertex of each cube and two edge
    crossings; warm started, BB needs a few iterations a step (the two rocking points of the
    vertex-face samples took 38 on average and changed keys 94 times in 200 steps)."""
    s, top, rec = _rest(lower, (0.1, 0.1, 0.1), xy=(0.03, 0.02))
    _assert_rests(s, top, rec, 0.1 + H, (0.03, 0.02))
    assert rec["its"][-200:].mean() < 10


@pytest.mark.parametrize("lower", ["hull", "box"])
def test_cube_tips_over_the_edge_of_a_cube(lower):
    """Centre of mass 2 cm past the lower cube's edge: the upper cube pivots on that edge (its
    bottom face stays on it: the centre keeps its distance H from the edge line, within the
    solver's penetration) and falls off."""
    s, top, rec = _rest(lower, (0.1, 0.1, 0.1), xy=(0.12, 0.0), steps=0)
    edge = np.array([0.1, 0.1])                          # (x, z) of the pivot edge
    pivoting = []
    for _ in range(600):
        s.step(1e-3)
        R = np_quat_to_mat(s.quat[top])
        tilt = math.acos(min(1.0, R[2, 2]))
        if s.n_contacts and tilt < 0.5:
            # distance of the centre from the edge along the bottom face's normal
            nrm = -R[[0, 2], 2]
            pivoting.append(float((s.pos[top, [0, 2]] - edge) @ -nrm))
    assert len(pivoting) > 50
    assert min(pivoting) > H - 1e-3
    R = np_quat_to_mat(s.quat[top])
    assert math.acos(min(1.0, R[2, 2])) > 1.0           # tipped over
    assert s.pos[top, 0] > 0.15 and s.pos[top, 2] < 0.1  # and fell off the side
