"""A cylinder against a box or a hull (collision._cylinder_polytope).

Before, a cylinder against anything but a plane or a particle cloud collided through its 2 × 16
rim samples: it rolled down a box incline as a 16-sided prism, 17 % slow, its centre dipping
R(1 − cos π/16) at every facet (audit hunt11/b, finding 5).  Now the face of the polytope
that is the axis of least penetration is a plane for the cylinder's exact support (its
generator line, clipped to the face; its cap polygon when it stands on its end), and the
polytope's vertices and edges meet the cylinder's exact signed distance where a cylinder axis
wins (Chrono: Bullet's cylinder–box GJK/EPA, the same contact).

Tolerances: the rolling acceleration within 1 % of g sin θ/(1 + I/(m r²)) (the discrete-time
1/n start-up term divided out, as in the audit's s14_roll.py); the centre height within 1e-6 m
of its start (the old 16-gon dipped 9.6e-4 m); contact gaps to 1e-12 m (the same arithmetic
on exact positions); at rest the contact force equals the weight to 1e-6 and the body moves
less than 1e-9 m.
"""
import math

import numpy as np
import pytest

from sphdvi.dvi import System
from sphdvi.dvi._math import np_quat_to_mat

G = 9.81
R = 0.05
CUBE = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], float)


def qaxis(ax, ang):
    ax = np.asarray(ax, float) / np.linalg.norm(ax)
    return tuple(np.r_[math.cos(ang / 2), math.sin(ang / 2) * ax])


Q_ALONG_Y = qaxis((1, 0, 0), math.pi / 2)     # the cylinder's axis (local z) along world y
Q_ALONG_X = qaxis((0, 1, 0), math.pi / 2)


def _ground(s, ground, half, pos, mat=None):
    g = s.add_body(1.0, (1, 1, 1), pos=pos, kind="fixed")
    if ground == "box":
        s.add_box(g, half, material=mat)
    else:
        s.add_hull(g, CUBE * np.asarray(half), material=mat)
    return g


def _contacts(s):
    if not s._packed:
        s._pack()
    nc = s._collide(np.array([np_quat_to_mat(q) for q in s.quat]))
    c = s._c
    return [dict(a=int(c["a"][k]), b=int(c["b"][k]), pt=c["pt"][k].copy(), n=c["n"][k].copy(),
                 gap=float(c["gap"][k]), key=int(c["key"][k])) for k in range(nc)]


@pytest.mark.parametrize("ground", ["box", "hull"])
@pytest.mark.parametrize("shape", ["cylinder", "sphere", "capsule"])
def test_rolls_down_a_polytope_incline(ground, shape):
    """The audit's roll (s14_roll.py): R = 0.05 m on a 20° incline (tilted gravity), μ 0.5
    above the critical μ, 0.5 s: a = g sin θ/(1 + k²) within 1 % and no height dip beyond
    1e-6 m; a cylinder (k² = 1/2, was −16.9 % with 9.5e-4 m dips) as a sphere (k² = 2/5) and
    a capsule (cylinder inertia, k² = 1/2) always did."""
    th = math.radians(20)
    s = System(gravity=(G * math.sin(th), 0, -G * math.cos(th)))
    s.add_material("m", friction=0.5)
    _ground(s, ground, (10, 1, 0.5), (0, 0, -0.5), "m")
    if shape == "sphere":
        I = 0.4 * R * R
        b = s.add_body(1.0, (I, I, I), pos=(0, 0, R))
        s.add_sphere(b, R, material="m")
        k2 = 0.4
    else:
        b = s.add_body(1.0, (0.01, 0.01, 0.5 * R * R), pos=(0, 0, R), quat=Q_ALONG_Y)
        if shape == "cylinder":
            s.add_cylinder(b, R, 0.05, material="m")
        else:
            s.add_capsule(b, R, 0.05, material="m")
        k2 = 0.5
    n, h = 500, 1e-3
    z = []
    for _ in range(n):
        s.step(h)
        z.append(s.pos[b, 2])
    a = 2 * s.pos[b, 0] / (n * h) ** 2 / (1 + 1 / n)
    expect = G * math.sin(th) / (1 + k2)
    assert abs(a / expect - 1) < 1e-2, (a, expect)
    assert np.max(np.abs(np.array(z) - R)) < 1e-6
    assert abs(s.pos[b, 1]) < 1e-9
    assert s.take_warnings() == []


@pytest.mark.parametrize("ground", ["box", "hull"])
@pytest.mark.parametrize("order", [0, 1])
def test_contact_sets(ground, order):
    """The contact set of a cylinder (R 0.05, half length 0.1) on a 0.4 × 0.4 × 0.2 box or
    cube hull, 1 mm into it, either shape first: lying on the top face, two points (the ends
    of its bottom line) at gap −1e-3; standing on its end, its 16 rim points; tilted 30°, its
    one deepest rim point; lying across the face's edge, its bottom line clipped at the edge;
    lying along the top edge (its side on the edge, normal at 45°), the two ends of its part
    beside the edge; crossing that edge at 30°, one point on the edge with the normal at
    45°.  Normals from the pair's first shape to its second."""
    def make(cpos, cq):
        s = System(envelope=0.002)
        if order == 0:
            _ground(s, ground, (0.2, 0.2, 0.1), (0, 0, 0))
        b = s.add_body(1.0, (1, 1, 1), pos=cpos, quat=cq)
        s.add_cylinder(b, R, 0.1)
        if order == 1:
            _ground(s, ground, (0.2, 0.2, 0.1), (0, 0, 0))
        cs = _contacts(s)
        for c in cs:    # the normal from the ground to the cylinder
            assert {c["a"], c["b"]} == {0, 1}
            if c["a"] == b:
                c["n"] = -c["n"]
        return sorted(cs, key=lambda c: tuple(c["pt"]))

    up = np.array([0, 0, 1.0])
    # lying on the top face
    cs = make((0, 0, 0.1 + R - 1e-3), Q_ALONG_Y)
    assert len(cs) == 2
    np.testing.assert_allclose([c["pt"] for c in cs], [(0, -0.1, 0.0995), (0, 0.1, 0.0995)], atol=1e-12)
    for c in cs:
        np.testing.assert_allclose(c["n"], up, atol=1e-12)
        assert c["gap"] == pytest.approx(-1e-3, abs=1e-12)
    # standing on its end: its 16 rim points
    cs = make((0, 0, 0.2 - 1e-3), (1, 0, 0, 0))
    assert len(cs) == 16
    np.testing.assert_allclose(np.hypot(*np.array([c["pt"][:2] for c in cs]).T), R, atol=1e-12)
    assert all(c["gap"] == pytest.approx(-1e-3, abs=1e-12) for c in cs)
    # tilted 30 deg: one point, the deepest rim point
    t = math.pi / 6
    cs = make((0, 0, 0.1 + 0.1 * math.cos(t) + R * math.sin(t) - 1e-3), qaxis((0, 1, 0), t))
    assert len(cs) == 1 and cs[0]["gap"] == pytest.approx(-1e-3, abs=1e-12)
    np.testing.assert_allclose(cs[0]["pt"], (-0.1 * math.sin(t) + R * math.cos(t), 0, 0.0995), atol=1e-12)
    np.testing.assert_allclose(cs[0]["n"], up, atol=1e-12)
    # lying across the face's edge x = 0.2: the line from x = 0.05 to the edge
    cs = make((0.15, 0, 0.1 + R - 1e-3), Q_ALONG_X)
    assert len(cs) == 2
    np.testing.assert_allclose([c["pt"] for c in cs], [(0.05, 0, 0.0995), (0.2, 0, 0.0995)], atol=1e-12)
    # lying along the top edge (x = 0.2, z = 0.1), its side on the edge: the two ends
    d = (R - 1e-3) / math.sqrt(2)
    cs = make((0.2 + d, 0, 0.1 + d), Q_ALONG_Y)
    assert len(cs) == 2
    for c in cs:
        np.testing.assert_allclose(c["n"], np.array([1, 0, 1]) / math.sqrt(2), atol=1e-12)
        assert c["gap"] == pytest.approx(-1e-3, abs=1e-12)
    np.testing.assert_allclose(sorted(c["pt"][1] for c in cs), (-0.1, 0.1), atol=1e-12)
    # crossing the top edge y = 0.2 at 30 deg, its side on it: one point, normal at 45 deg
    nrm = np.array([0, 1, 1]) / math.sqrt(2)
    ax = np.array([math.cos(t), math.sin(t) / math.sqrt(2), -math.sin(t) / math.sqrt(2)])
    q = qaxis(np.cross([0, 0, 1], ax), math.acos(ax[2]))
    cs = make(tuple(np.array([0, 0.2, 0.1]) + nrm * (R - 1e-3)), q)
    assert len(cs) == 1
    np.testing.assert_allclose(cs[0]["n"], nrm, atol=1e-12)
    assert cs[0]["gap"] == pytest.approx(-1e-3, abs=1e-12)
    np.testing.assert_allclose(cs[0]["pt"], np.array([0, 0.2, 0.1]) - nrm * 5e-4, atol=1e-12)


def _rest(ground, pos, quat, steps=1000):
    """A 1 kg cylinder (R 0.05, half length 0.1) dropped 0.5 mm onto a fixed 1 × 1 × 0.2 box
    or cube hull (half extents 0.2, 0.5, 0.1: top face z = 0.1, edges x = ±0.2), μ 0.5;
    returns the system, the body, and per step the contact force and the key set."""
    s = System(gravity=(0, 0, -G), envelope=0.002)
    s.add_material("m", friction=0.5)
    _ground(s, ground, (0.2, 0.5, 0.1), (0, 0, 0), "m")
    H = 0.1
    Ip = (3 * R * R + 4 * H * H) / 12
    b = s.add_body(1.0, (Ip, Ip, 0.5 * R * R), pos=pos, quat=quat)
    s.add_cylinder(b, R, H, material="m")
    F, keys = [], []
    for _ in range(steps):
        s.step(1e-3)
        F.append(s.contact_force[b, 2])
        keys.append(tuple(sorted(int(k) for k in s._c["key"][:s.n_contacts])))
    return s, b, np.array(F), keys


@pytest.mark.parametrize("ground", ["box", "hull"])
def test_standing_cylinder_rests_on_its_cap(ground):
    """A cylinder standing on its end on a box or hull face: its cap polygon (16 rim points)
    holds it; the contact force is its weight, it neither drifts nor
    tilts, and the contact keys stay the same (warm start)."""
    z0 = 0.1 + 0.1
    s, b, F, keys = _rest(ground, (0.01, 0.02, z0 + 5e-4), (1, 0, 0, 0))
    assert np.all(np.abs(F[-300:] / G - 1) < 1e-6)
    np.testing.assert_allclose(s.pos[b], (0.01, 0.02, z0), atol=1e-6)
    np.testing.assert_allclose(s.quat[b], (1, 0, 0, 0), atol=1e-9)
    assert len(set(keys[-300:])) == 1 and len(keys[-1]) == 16
    assert s.take_warnings() == []


@pytest.mark.parametrize("ground", ["box", "hull"])
def test_lying_cylinder_rests_across_an_edge(ground):
    """A cylinder lying across the face's edge x = 0.2 (axis along x, its centre at 0.15 on the
    face, 0.05 m of it past the edge) rests: its bottom line is clipped at the edge, so the
    contacts span x = 0.05..0.2 about the centre of mass (the rim samples had only the cap on
    the face: it tipped about that cap and sank into the edge)."""
    z0 = 0.1 + R
    s, b, F, keys = _rest(ground, (0.15, 0, z0 + 5e-4), Q_ALONG_X)
    assert np.all(np.abs(F[-300:] / G - 1) < 1e-6)
    np.testing.assert_allclose(s.pos[b], (0.15, 0, z0), atol=1e-6)
    np.testing.assert_allclose(np.abs(s.quat[b]), np.abs(Q_ALONG_X), atol=1e-9)
    assert len(set(keys[-300:])) == 1 and len(keys[-1]) == 2
    pts = s._c["pt"][:s.n_contacts]
    np.testing.assert_allclose(sorted(pts[:, 0]), (0.05, 0.2), atol=1e-9)
    assert s.take_warnings() == []


@pytest.mark.parametrize("ground", ["box", "hull"])
@pytest.mark.parametrize("deg", [2.0, 5.0])
def test_tilted_cylinder_falls_flat(ground, deg):
    """A cylinder released on one rim point, tilted 2° (its cap polygon) or 5° (its support
    line), falls back onto its cap and stays flat, as on a plane (four of its rim points,
    changing as the cap tilted, let it wobble on its rim: 0.5-0.8° after 1.5 s)."""
    t = math.radians(deg)
    H = 0.1
    s, b, F, keys = _rest(ground, (0, 0, 0.1 + H * math.cos(t) + R * math.sin(t)),
                          qaxis((0, 1, 0), t), steps=1500)
    tilt = 2 * math.asin(min(1.0, math.hypot(s.quat[b, 1], s.quat[b, 2])))
    assert tilt < 1e-9
    assert s.pos[b, 2] == pytest.approx(0.1 + H, abs=1e-6)
    assert np.linalg.norm(s.vel[b]) < 1e-6


@pytest.mark.parametrize("ground", ["box", "hull"])
def test_cap_on_a_ridge(ground):
    """A standing cylinder whose cap rests on a box's edge (the box turned 45° about x, its
    edge along x up): the ends of the edge's chord of the cap's disc and its point under the
    axis, normal +z, gap −1e-3 (the edge's point nearest the axis alone would let the cap
    rock about it)."""
    s = System(envelope=0.002)
    g = s.add_body(1.0, (1, 1, 1), kind="fixed", quat=qaxis((1, 0, 0), math.pi / 4))
    half = np.array([0.2, 0.1, 0.1])
    if ground == "box":
        s.add_box(g, half)
    else:
        s.add_hull(g, CUBE * half)
    top = 0.1 * math.sqrt(2)
    b = s.add_body(1.0, (1, 1, 1), pos=(0.03, 0, top + 0.1 - 1e-3))
    s.add_cylinder(b, R, 0.1)
    cs = _contacts(s)
    assert len(cs) == 3
    np.testing.assert_allclose(sorted(c["pt"][0] for c in cs), (0.03 - R, 0.03, 0.03 + R), atol=1e-12)
    for c in cs:
        np.testing.assert_allclose(c["n"], (0, 0, 1), atol=1e-12)
        assert c["gap"] == pytest.approx(-1e-3, abs=1e-12)
        assert c["pt"][2] == pytest.approx(top - 5e-4, abs=1e-12)
