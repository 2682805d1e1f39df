"""GenCase's ``<drawextrude>`` and ``<drawbeach>`` (DualSPHysics v5.4 examples mdbc/01 StillWedge,
mdbc/06 WaveTank, main/02 Periodicity, main/14 Bowling): nodes on small hand-computed lattices
(dp = 1), the attributes, the refused modes and the examples' own geometry through gencase."""
from __future__ import annotations

import h5py
import numpy as np
import pytest
from casetext import case_xml, write_case
from click.testing import CliRunner
from test_draw import draw, nodes

from sphdvi.cli import main
from sphdvi.errors import CaseError

KW3 = dict(pmin=(-3, -2, -3), pmax=(7, 4, 6))
KW2 = dict(pmin=(-3, 0, -3), pmax=(12, 0, 6))


def extrude(points, vec=(0, 2, 0), attrs=' closed="false"', extra="", mode="full", mk="0"):
    pts = "".join(f'<point x="{x}" y="{y}" z="{z}"/>' for x, y, z in points)
    return (f'<setdrawmode mode="{mode}"/><setmkbound mk="{mk}"/><drawextrude{attrs}>{pts}'
            f'<extrude x="{vec[0]}" y="{vec[1]}" z="{vec[2]}"/>{extra}</drawextrude>')


def beach(points, mask="0", mode="full", y=1):
    pts = "".join(f'<point x="{x}" y="{y}" z="{z}"/>' for x, z in points)
    return f'<setdrawmode mode="{mode}"/><setmkbound mk="0"/><drawbeach mask="{mask}">{pts}</drawbeach>'


L_SHAPE = [(0, 0, 3), (0, 0, 0), (4, 0, 0)]      # a wall x=0 (z 0..3) and a floor z=0 (x 0..4)
U_2D = [(0, 0, 3), (0, 0, 0), (4, 0, 0), (4, 0, 3)]


def grid(xs, ys, zs):
    return {(x, y, z) for x in xs for y in ys for z in zs}


# ---------------------------------------------------------------- drawextrude
def test_extrude_3d_is_the_swept_polyline(tmp_path):
    d = draw(tmp_path, extrude(L_SHAPE), **KW3)
    want = grid([0], range(0, 3), range(0, 4)) | grid(range(0, 5), range(0, 3), [0])
    assert nodes(d) == want and len(d.pos) == 24 and d.count_fluid == 0
    p = d.primitives[0]
    assert p["shape"] == "extrude" and p["params"]["extrude"] == [0.0, 2.0, 0.0]
    assert p["params"]["closed"] is False and p["nodes"] == 24


@pytest.mark.parametrize("mode", ["face", "solid"])
def test_extrude_is_a_surface_in_every_mode_but_wire(tmp_path, mode):
    assert nodes(draw(tmp_path, extrude(L_SHAPE, mode=mode), **KW3)) == \
        nodes(draw(tmp_path, extrude(L_SHAPE), **KW3))


def test_extrude_wire_draws_the_quadrilateral_edges(tmp_path):
    d = draw(tmp_path, extrude(L_SHAPE, mode="wire"), **KW3)
    line = {(0, z) for z in range(4)} | {(x, 0) for x in range(5)}
    want = {(x, y, z) for x, z in line for y in (0, 2)} | {(0, 1, 3), (0, 1, 0), (4, 1, 0)}
    assert nodes(d) == want and len(d.pos) == 19


def test_extrude_layers_move_along_the_face_normal(tmp_path):
    # normals (P_i+1 - P_i) x e: +x for the wall, +z for the floor; layer -1 lies behind both,
    # the corner (0,0,0) goes to (-1,0,-1) (mitred), the ends keep their length
    d = draw(tmp_path, extrude(L_SHAPE, extra='<layers vdp="0,-1*"/>'), **KW3)
    layer0 = grid([0], range(0, 3), range(0, 4)) | grid(range(0, 5), range(0, 3), [0])
    layer1 = grid([-1], range(0, 3), range(-1, 4)) | grid(range(-1, 5), range(0, 3), [-1])
    assert nodes(d) == layer0 | layer1 and len(d.pos) == 24 + 30
    assert [p["params"]["layer"] for p in d.primitives] == [0.0, -1.0]
    assert d.primitives[1]["params"]["points"] == [[-1, 0, 3], [-1, 0, -1], [4, 0, -1]]
    up = draw(tmp_path, extrude(L_SHAPE, extra='<layers vdp="1"/>'), **KW3)
    assert nodes(up) == grid([1], range(0, 3), range(1, 4)) | grid(range(1, 5), range(0, 3), [1])


def test_extrude_2d_wedge_counts(tmp_path):
    # CaseStillWedge's profile on a dp = 1 lattice: walls, floor and a 45-degree wedge, its
    # slopes as thick as 4-connected lines in 2D (the staircase nodes above them)
    pts = [(0, 0, 3), (0, 0, 0), (4, 0, 0), (6, 0, 2), (8, 0, 0), (10, 0, 0), (10, 0, 3)]
    d = draw(tmp_path, extrude(pts, vec=(0, 1, 0)), **KW2)
    want = ({(0, 0, z) for z in range(4)} | {(x, 0, 0) for x in range(5)}
            | {(5, 0, 1), (6, 0, 2), (7, 0, 1), (8, 0, 0), (9, 0, 0)}
            | {(4, 0, 1), (5, 0, 2), (7, 0, 2), (8, 0, 1)}
            | {(10, 0, z) for z in range(4)})
    assert d.is2d and nodes(d) == want and len(d.pos) == 21


def test_extrude_2d_tank_layers_and_fluid_inside(tmp_path):
    # CaseWaveTank pattern: layers 0 and -1 of a U; the fluid filled from inside stays inside
    body = extrude(U_2D, vec=(0, 2, 0), extra='<layers vdp="0,-1"/>').replace(
        '<point x="0" y="0"', '<point x="0" y="-1"').replace('y="0" z', 'y="-1" z')
    body += ('<setmkfluid mk="0"/><fillbox x="2" y="0" z="2"><modefill>void</modefill>'
             '<point x="-2" y="-1" z="-2"/><size x="9" y="2" z="5"/></fillbox>')
    d = draw(tmp_path, body, **KW2)
    bound = nodes(d, fluid=False)
    layer0 = {(0, 0, z) for z in range(4)} | {(x, 0, 0) for x in range(5)} | {(4, 0, z) for z in range(4)}
    layer1 = ({(-1, 0, z) for z in range(-1, 4)} | {(x, 0, -1) for x in range(-1, 6)}
              | {(5, 0, z) for z in range(-1, 4)})
    assert bound == layer0 | layer1 and len(bound) == 11 + 15
    # up to z=2: z=3 lies on the fill box's top (GenCase fills the nodes at least dp/2 inside a <fillbox> (see test_draw_gencase_counts.py))
    assert nodes(d, fluid=True) == {(x, 0, z) for x in (1, 2, 3) for z in (1, 2)}


def test_extrude_under_a_transform_and_repeated_points(tmp_path):
    # <move> applies to the points and the sweep; a repeated point is dropped
    pts = [(0, 0, 3), (0, 0, 3), (0, 0, 0), (4, 0, 0)]
    d = draw(tmp_path, '<move x="1" y="0" z="2"/>' + extrude(pts), **KW3)
    assert nodes(d) == {(x + 1, y, z + 2) for x, y, z in nodes(draw(tmp_path, extrude(L_SHAPE), **KW3))}


def test_extrude_closed_absent_means_open(tmp_path):
    assert nodes(draw(tmp_path, extrude(L_SHAPE, attrs=""), **KW3)) == \
        nodes(draw(tmp_path, extrude(L_SHAPE), **KW3))


@pytest.mark.parametrize("body,match", [
    (extrude(L_SHAPE, attrs=' closed="true"'), 'closed="true"> is not supported by sphdvi'),
    (extrude(L_SHAPE, vec=(0, 0, 0)), "vector .* is zero"),
    (extrude(L_SHAPE, vec=(0, 0, 2)), "is parallel to the <extrude> vector"),
    (extrude([(1, 0, 1), (1, 0, 1)]), "all the points coincide"),
    (extrude([(1, 0, 1)]), "1 <point> elements"),
    (extrude(L_SHAPE, attrs=' closed="maybe"'), "not a boolean"),
    (extrude(L_SHAPE).replace('<extrude x="0" y="2" z="0"/>', ""), "extrude"),
    (extrude(L_SHAPE, extra="<size/>"), "size"),
])
def test_extrude_errors(tmp_path, body, match):
    with pytest.raises(CaseError, match=match) as e:
        draw(tmp_path, body, **KW3)
    assert e.value.element in ("drawextrude", "extrude", "size") and e.value.line is not None


# ---------------------------------------------------------------- drawbeach
RECT = [(0, 0), (4, 0), (4, 3), (0, 3)]        # faces 3 bottom, 4 right, 5 top, 6 left


def test_beach_2d_closed_is_solid(tmp_path):
    d = draw(tmp_path, beach(RECT), **KW2)
    assert nodes(d) == grid(range(0, 5), [0], range(0, 4)) and len(d.pos) == 20
    assert d.primitives[0]["shape"] == "beach" and d.primitives[0]["solid"]


def test_beach_mask_1_2_is_the_hollow_outline(tmp_path):
    # CasePeriodicity: mask="1|2" leaves the two profile polygons out: an open shape, hollow in
    # full mode, which <fillvoidpoint> then fills with another mk
    outline = grid(range(0, 5), [0], range(0, 4)) - grid(range(1, 4), [0], range(1, 3))
    d = draw(tmp_path, beach(RECT, mask="1|2"), **KW2)
    assert nodes(d) == outline and len(d.pos) == 14
    d = draw(tmp_path, beach(RECT, mask="1|2") + '<setmkbound mk="1"/><fillvoidpoint x="2" y="0" z="1"/>',
             **KW2)
    assert len(d.pos) == 20 and {tuple(p) for p in np.round(d.pos[d.mk == 1]).astype(int)} == \
        grid(range(1, 4), [0], range(1, 3))
    assert nodes(draw(tmp_path, beach(RECT, mode="face"), **KW2)) == outline


def test_beach_sides_numbered_like_a_prism(tmp_path):
    # face 5 = the side from point 3 to point 4 (the top z=3); CaseBowling's 3-point ramp hides
    # face 5, its closing side
    d = draw(tmp_path, beach(RECT, mask="1|2|5"), **KW2)
    assert nodes(d) == grid(range(0, 5), [0], range(0, 4)) - grid(range(1, 4), [0], range(1, 4))
    ramp = draw(tmp_path, beach([(0, 4), (4, 0), (10, 0)], mask="1|2|5", y=2), **KW2)
    assert nodes(ramp) == ({(x, 0, 4 - x) for x in range(5)} | {(x, 0, 0) for x in range(4, 11)}
                           | {(x, 0, 5 - x) for x in range(1, 5)})        # the 4-connected staircase
    assert len(ramp.pos) == 15


def test_beach_y_of_points_and_moves(tmp_path):
    # in 2D the beach crosses the plane whatever the y of its points; a move applies in x-z
    ref = nodes(draw(tmp_path, beach(RECT, mask="1|2"), **KW2))
    assert nodes(draw(tmp_path, beach(RECT, mask="1|2", y=-7), **KW2)) == ref
    moved = draw(tmp_path, '<move x="2" y="5" z="1"/>' + beach(RECT, mask="1|2"), **KW2)
    assert nodes(moved) == {(x + 2, 0, z + 1) for x, _, z in ref}


@pytest.mark.parametrize("body,kw,match", [
    (beach(RECT), KW3, "<drawbeach> in a 3D case is not supported by sphdvi"),
    (beach(RECT).replace('<point x="4" y="1" z="0"/>', '<point x="4" y="2" z="0"/>'), KW2,
     "the profile points have different y"),
    ('<rotate ang="30" x="1" y="0" z="0"/>' + beach(RECT), KW2, "tilts the y axis"),
    (beach(RECT[:2]), KW2, "2 <point> elements"),
])
def test_beach_errors(tmp_path, body, kw, match):
    with pytest.raises(CaseError, match=match) as e:
        draw(tmp_path, body, **kw)
    assert e.value.element == "drawbeach" and e.value.line is not None


# ---------------------------------------------------------------- the v5.4 examples
PERIODICITY = """
                    <setshapemode>actual | bound</setshapemode>
                    <setdrawmode mode="full" />
                    <setmkbound mk="0" />
                    <drawbeach mask="1|2">
                        <point x="-0.01" y="1" z="0.3" />
                        <point x="0" y="1" z="0.3" />
                        <point x="0" y="1" z="0" />
                        <point x="0.45" y="1" z="0" />
                        <point x="0.45" y="1" z="0.02" />
                        <point x="0.48" y="1" z="0.02" />
                        <point x="0.48" y="1" z="0" />
                        <point x="0.8" y="1" z="0" />
                        <point x="0.8" y="1" z="-0.01" />
                        <point x="-0.01" y="1" z="-0.01" />
                    </drawbeach>
                    <drawbeach mask="1|2">
                        <point x="0.25" y="1" z="0.01" />
                        <point x="0.30" y="1" z="0.01" />
                        <point x="0.30" y="1" z="0.04" />
                        <point x="0.26" y="1" z="0.08" />
                        <point x="0.26" y="1" z="0.34" />
                        <point x="0.25" y="1" z="0.34" />
                    </drawbeach>
                    <setmkbound mk="1" />
                    <fillvoidpoint x="0.01" y="0" z="-0.005" />
                    <fillvoidpoint x="0.26" y="0" z="0.02" />
                    <setmkfluid mk="0" />
                    <fillbox x="0.1" y="0" z="0.1">
                        <modefill>void</modefill>
                        <point x="0" y="-0.1" z="0" />
                        <size x="0.25" y="0.2" z="0.25" />
                    </fillbox>
                    <fillbox x="0.31" y="0" z="0.01">
                        <modefill>void</modefill>
                        <point x="0.2" y="-0.1" z="0" />
                        <size x="0.6" y="0.2" z="0.03" />
                    </fillbox>
                    <shapeout file="" />"""

WEDGE_LIST = """
                <list name="GeometryForNormals">
                    <setactive drawpoints="0" drawshapes="1"/>
                    <setshapemode>actual | bound</setshapemode>
                    <setmkbound mk="0" />
                    <drawextrude closed="false">
                        <point x="0.01" y="-0.1" z="0.71" />
                        <point x="0.01" y="-0.1" z="0.01" />
                        <point x="0.84" y="-0.1" z="0.01" />
                        <point x="1.1" y="-0.1" z="0.27" />
                        <point x="1.36" y="-0.1" z="0.01" />
                        <point x="2.19" y="-0.1" z="0.01" />
                        <point x="2.19" y="-0.1" z="0.71" />
                        <extrude x="0" y="0.2" z="0" />
                    </drawextrude>
                    <shapeout file="hdp" />
                    <resetdraw />
                </list>"""

WEDGE = """
                    <runlist name="GeometryForNormals" />
                    <setdrawmode mode="full" />
                    <setmkbound mk="0" />
                    <drawextrude closed="false">
                        <point x="0" y="0" z="0.7" />
                        <point x="0" y="0" z="0" />
                        <point x="0.84" y="0" z="0" />
                        <point x="1.1" y="0" z="0.25" />
                        <point x="1.35" y="0" z="0" />
                        <point x="2.2" y="0" z="0" />
                        <point x="2.2" y="0" z="0.7" />
                        <extrude x="0" y="0.1" z="0" />
                        <layers vdp="0,-0.5,-1,-1.5,-2" />
                    </drawextrude>
                    <setmkfluid mk="0" />
                    <fillbox x="0.1" y="0" z="0.1">
                        <modefill>void</modefill>
                        <point x="-0.1" y="-1" z="-0.1" />
                        <size x="2.3" y="2" z="0.6" />
                    </fillbox>"""

WEDGE_NORMALS = """
        <normals>
            <distanceh value="2.0" />
            <geometryfile file="[CaseName]_hdp_Actual.vtk" />
        </normals>"""

# CaseWaveTank's piston and tank (mdbc/06), without its <setfrdrawmode> (drawn on the lattice by sphdvi, with a warning)
WAVETANK = """
                    <newvar Tankx0="-0.5" Tankz0="0" />
                    <newvar Tankx1="6" Tankz1="0" />
                    <newvar Tankx2="16" Tankz2="1" />
                    <setdrawmode mode="full" />
                    <setmkbound mk="10" />
                    <drawbox>
                        <boxfill>solid</boxfill>
                        <point x="#-Dp*3" y="-1" z="#Tankz0" />
                        <size x="#Dp*3" y="2" z="#Tankz2-Tankz0" />
                    </drawbox>
                    <setmkbound mk="0" />
                    <drawextrude closed="false">
                        <extrude x="0" y="2" z="0" />
                        <point x="#Tankx0" y="-1" z="#Tankz0" />
                        <point x="#Tankx1" y="-1" z="#Tankz1" />
                        <point x="#Tankx2" y="-1" z="#Tankz2" />
                        <layers vdp="0,-1,-2" />
                    </drawextrude>
                    <setmkfluid mk="0" />
                    <fillbox x="0.5" y="0" z="0.05">
                        <modefill>void</modefill>
                        <point x="-1" y="-1" z="-1" />
                        <size x="20" y="2" z="1.66" />
                    </fillbox>"""


def gencase(tmp_path, text):
    out = tmp_path / "g"
    r = CliRunner().invoke(main, ["gencase", write_case(tmp_path, text), "-o", str(out), "-q"])
    return r, out / "Case.h5"


def read_mk(h5):
    with h5py.File(h5) as f:
        return f["particles/mk"][:], f["particles/type"][:], f["particles/pos"][:]


def test_example_periodicity_gencases(tmp_path):
    r, h5 = gencase(tmp_path, case_xml(dp="0.005", pointmin=("-0.1", "0", "-0.1"),
                                       pointmax=("1", "0", "1"), commands=PERIODICITY))
    assert r.exit_code == 0, r.output
    mk, typ, pos = read_mk(h5)
    wall, filled, fluid = pos[mk == 10], pos[mk == 11], pos[typ == 3]
    # the outline of the flume and of the inner wall, hollow (mkbound 1 fills the inner wall)
    assert len(wall) > 0.9 * (2.28 + 0.74) / 0.005 and len(filled) > 0 and len(fluid) > 1000
    # mkbound 1 fills the inside of the two profiles (the body of the walls: the slab under the
    # floor, the left wall, the bump, the inner wall), never the water side
    in_wall = (filled[:, 0] > 0.24) & (filled[:, 0] < 0.31) & (filled[:, 2] > 0.005)
    assert in_wall.sum() > 30 and np.isclose(filled[:, 2], -0.005).sum() > 150
    water = (filled[:, 0] > 0.002) & (filled[:, 0] < 0.248) & (filled[:, 2] > 0.002)
    assert not water.any()
    assert not np.any((wall[:, 0] > 0.02) & (wall[:, 0] < 0.24) & (wall[:, 2] > 0.01))


def test_example_still_wedge_gencases(tmp_path):
    r, h5 = gencase(tmp_path, case_xml(dp="0.02", pointmin=("-1", "0", "-1"), pointmax=("2.5", "0", "2"),
                                       commands=WEDGE, lists=WEDGE_LIST, casedef_extra=WEDGE_NORMALS,
                                       parameters='<parameter key="Boundary" value="2"/>'))
    assert r.exit_code == 0, r.output
    assert (tmp_path / "g" / "Case_hdp.vtk").exists()
    mk, typ, pos = read_mk(h5)
    wall = pos[typ == 0]
    # 5 layers 0 .. -2 dp below the floor at z = 0 (the half layers land on the lattice rows)
    floor = wall[(wall[:, 0] > 0.1) & (wall[:, 0] < 0.8)]
    assert set(np.round(floor[:, 2] / 0.02).astype(int)) == {0, -1, -2}
    fluid = pos[typ == 3]
    assert fluid[:, 2].min() > 0.01 and fluid[:, 0].min() > 0.01 and len(fluid) > 2000


def test_example_wave_tank_gencases(tmp_path):
    r, h5 = gencase(tmp_path, case_xml(dp="0.05", pointmin=("-0.6", "0", "-0.6"), pointmax=("25", "0", "2"),
                                       commands=WAVETANK))
    assert r.exit_code == 0, r.output
    mk, typ, pos = read_mk(h5)
    wall, fluid = pos[mk == 10], pos[typ == 3]
    flat = wall[(wall[:, 0] > 0) & (wall[:, 0] < 5)]
    assert set(np.round(flat[:, 2] / 0.05).astype(int)) == {0, -1, -2}
    assert fluid[:, 2].min() > 0.01 and len(fluid) > 0


def test_refused_mode_exits_2(tmp_path):
    text = case_xml(commands='<setmkbound mk="0"/><drawextrude closed="true"><point x="0" y="-1" z="0"/>'
                             '<point x="1" y="-1" z="0"/><extrude x="0" y="2" z="0"/></drawextrude>')
    r, _ = gencase(tmp_path, text)
    assert r.exit_code == 2
    assert "Case_Def.xml:" in r.output and "<drawextrude>" in r.output
    assert 'closed="true"> is not supported by sphdvi' in r.output and "expected" in r.output
