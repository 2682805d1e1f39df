"""The sense of GenCase's rotations: <rotate>, <rotateline> and <initials><rotateaxis>.

DualSPHysics's JMatrix4::MatrixRot(ang, p1, p2) turns by −ang right-handed about p1 → p2 (sphdvi's
<motion> follows it, tests/motion).  GenCase's drawing rotations turn the same way: DesignSPHysics,
the DualSPHysics team's FreeCAD front end, writes FreeCAD's right-handed rotation (angle θ about the
axis a) as <rotate ang="θ" x="-ax" y="-ay" z="-az"/>.  DualSPHysics's examples/others/RotatedBox
turns one gate by <rotateline ang="40"> and its twin by <rotateaxis angle="-40">, each about its own
vertical centre line, into the mirror images of each other about the channel's centre line: the two
share one sense.
"""
import math

import numpy as np
import pytest
from casetext import CONSTANTS, case_xml, write_case
from test_draw import box, draw, nodes

from sphdvi.case.gencase import build_case


def right_handed(theta_deg, axis):
    """The right-handed rotation by theta about axis (Rodrigues), as FreeCAD's Placement."""
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    t = math.radians(theta_deg)
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(t) * kx + (1 - math.cos(t)) * kx @ kx


@pytest.mark.parametrize("theta,axis", [(30, (0, 0, 1)), (-65, (0, 1, 0)), (120, (1, -2, 0.5)),
                                        (90, (1, 0, 0))])
def test_rotate_as_designsphysics_writes_freecad_rotations(tmp_path, theta, axis):
    a = -np.asarray(axis, float)
    body = (f'<setmkbound mk="0"/><rotate ang="{theta}" x="{a[0]}" y="{a[1]}" z="{a[2]}"/>'
            + box((0, 0, 0), (4, 2, 1)))
    m = np.asarray(draw(tmp_path, body, pmin=(-10, -10, -10)).primitives[0]["params"]["matrix"])
    assert np.allclose(m[:3, :3], right_handed(theta, axis), atol=1e-14)


def test_rotate_quarter_turn_about_z_is_clockwise_from_above(tmp_path):
    # a node at (3, 0, 0) goes to (0, -3, 0): the opposite of the right-hand rule about +z
    d = draw(tmp_path, '<setmkfluid mk="0"/><rotate ang="90" x="0" y="0" z="1"/>' + box((3, 0, 0), (0, 0, 0)),
             pmin=(-10, -10, -10))
    assert nodes(d) == {(0, -3, 0)}


def test_rotateline_is_rotate_about_a_shifted_axis(tmp_path):
    p1, p2 = np.array([2.0, 1.0, -1.0]), np.array([3.0, 3.0, 1.0])
    line = ('<setmkfluid mk="0"/><rotateline ang="37"><point x="{}" y="{}" z="{}"/>'.format(*p1)
            + '<point x="{}" y="{}" z="{}"/></rotateline>'.format(*p2) + box((1, 1, 1), (3, 2, 2)))
    a = p2 - p1
    shifted = ('<setmkfluid mk="0"/><move x="{}" y="{}" z="{}"/>'.format(*p1)
               + '<rotate ang="37" x="{}" y="{}" z="{}"/>'.format(*a)
               + '<move x="{}" y="{}" z="{}"/>'.format(*-p1) + box((1, 1, 1), (3, 2, 2)))
    kw = dict(pmin=(-10, -10, -10), pmax=(10, 10, 10))
    m1 = np.asarray(draw(tmp_path, line, **kw).primitives[0]["params"]["matrix"])
    m2 = np.asarray(draw(tmp_path, shifted, **kw).primitives[0]["params"]["matrix"])
    assert np.allclose(m1, m2, atol=1e-13)
    assert np.allclose(m1[:3, :3], right_handed(-37, a), atol=1e-14)


def _long_axis_angle(xy):
    """Direction of the largest spread of points in the plane, degrees in (−90, 90]."""
    c = xy - xy.mean(axis=0)
    w, v = np.linalg.eigh(c.T @ c)
    d = v[:, np.argmax(w)]
    ang = math.degrees(math.atan2(d[1], d[0]))
    return ang - 180 if ang > 90 else (ang + 180 if ang <= -90 else ang)


def test_rotatedbox_example_gates_are_mirror_images(tmp_path):
    """examples/others/RotatedBox: gate mk2 drawn turned by <rotateline ang="40"> about x = 0.45,
    y = 0.145; gate mk3 drawn straight and its particles turned by <rotateaxis angle="-40"> about
    x = 0.45, y = 0.355.  Mirror images about y = 0.25; and the absolute sense: mk2's end at
    y = 0.25 swings downstream (+x), as MatrixRot's −40° right-handed about +z takes it."""
    commands = """
        <setshapemode>real | bound</setshapemode><setdrawmode mode="full"/>
        <setmkfluid mk="0"/>
        <drawbox><boxfill>solid</boxfill><point x="0" y="0" z="0"/><size x="0.1" y="0.1" z="0.02"/></drawbox>
        <setmkbound mk="2"/>
        <rotateline ang="40"><point x="0.45" y="0.145" z="0"/><point x="0.45" y="0.145" z="1"/></rotateline>
        <drawbox><boxfill>all ^ top ^ bottom</boxfill><point x="0.45" y="0.04" z="0"/>
            <size x="0.05" y="0.21" z="0.04"/></drawbox>
        <matrixreset/>
        <setmkbound mk="3"/>
        <drawbox><boxfill>all ^ top ^ bottom</boxfill><point x="0.45" y="0.25" z="0"/>
            <size x="0.05" y="0.21" z="0.04"/></drawbox>"""
    initials = """<initials><rotateaxis mkbound="3" angle="-40" anglesunits="degrees">
        <axisp1 x="0.45" y="0.355" z="0"/><axisp2 x="0.45" y="0.355" z="1"/></rotateaxis></initials>"""
    text = case_xml(dp="0.005", pointmin=("-0.2", "-0.2", "-0.2"), pointmax=("1", "0.7", "0.3"),
                    commands=commands, casedef_extra=initials, constants=CONSTANTS)
    tmp_path.mkdir(parents=True, exist_ok=True)
    r = build_case(write_case(tmp_path, text), str(tmp_path / "out"))
    p = r.particles
    bound = p["type"] != 3
    g2, g3 = (p["pos"][bound & (p["label"] == mkbound)] for mkbound in (2, 3))
    assert len(g2) > 100 and len(g3) > 100
    c2, c3 = g2.mean(axis=0), g3.mean(axis=0)
    # mirror images about y = 0.25 (the centroid, to the lattice's resolution, and the long axis)
    assert c2[0] == pytest.approx(c3[0], abs=0.003) and c2[1] + c3[1] == pytest.approx(0.5, abs=0.003)
    a2, a3 = _long_axis_angle(g2[:, :2]), _long_axis_angle(g3[:, :2])
    assert a2 == pytest.approx(-a3, abs=1.0)
    # the gates' axes (y before turning) turn by −40° right-handed about +z: direction (sin 40, cos 40)
    assert a2 == pytest.approx(90 - 40, abs=1.0) and a3 == pytest.approx(-(90 - 40), abs=1.0)
    # the inner ends (at y = 0.25 before turning) swing downstream to x ≈ 0.45 + 0.105 sin 40
    inner2 = g2[np.argmax(g2[:, 1])]
    assert inner2[0] > 0.45 + 0.05
